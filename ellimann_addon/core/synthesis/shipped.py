"""The reference sets that ship, by name: ``female`` (reference_blends/, the default) and ``male``
(reference_blends/male/), the paper's 40 ellipsoids, and the same bodies on the fine topology (docs/topology_fine.md),
``female-fine`` and ``male-fine`` (reference_blends/female-fine/, reference_blends/male-fine/). A name or a folder is
what ``--references``, a batch CSV's ``references`` column and the Synthesize panel choose."""

import pathlib

from ..constants import FEMALE_SET
from ..errors import ReferenceSetError
from .reference_set import REFERENCE_FOLDER, cached_reference_set

MALE_SET = "male"
FEMALE_FINE_SET = "female-fine"
MALE_FINE_SET = "male-fine"
SHIPPED_SETS = {
    FEMALE_SET: REFERENCE_FOLDER,
    MALE_SET: REFERENCE_FOLDER / MALE_SET,
    FEMALE_FINE_SET: REFERENCE_FOLDER / FEMALE_FINE_SET,
    MALE_FINE_SET: REFERENCE_FOLDER / MALE_FINE_SET,
}


def reference_folder(name_or_dir=None):
    """The folder of a shipped set's name (``None`` or "": the female set) or of a folder path as given.

    A name that is not shipped and not a folder is refused naming both choices, so a typo does not read as a
    missing folder."""
    if not name_or_dir:
        return SHIPPED_SETS[FEMALE_SET]
    text = str(name_or_dir)
    if text.casefold() in SHIPPED_SETS:
        return SHIPPED_SETS[text.casefold()]
    folder = pathlib.Path(text)
    if not folder.exists() and not any(sep in text for sep in ("/", "\\")) and not text.startswith("."):
        raise ReferenceSetError(
            text, "references", f"is neither a shipped set ({', '.join(SHIPPED_SETS)}) nor a folder"
        )
    return folder


def named_reference_set(name_or_dir=None):
    """The ReferenceSet of a shipped set's name or of a folder (cached on the files' modification times)."""
    return cached_reference_set(reference_folder(name_or_dir))
