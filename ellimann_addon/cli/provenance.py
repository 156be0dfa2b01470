"""What a batch row's files were made from, so that ``batch --resume`` keeps them only when they answer the same row
and settings, and makes them again, saying why, otherwise.

When a row's files are written, ``DIR/made_from/NAME.json`` records (``RECORD_FORMAT`` version ``RECORD_VERSION``):
the row's request (the five and the extra measurements asked, cm), the reference set (its name, its folder and a
SHA-256 of its manifest and RM files), the synthesis options (mode, metric, power, normalize), ``--cushions``, the
skin's settings (``--skin``) and the pose (its name, or a pose file's or clip's SHA-256 with --fps, --rig and
--keep-on-floor). A resumed row is kept only when its files are all there and whole and its record says the same
of every one of these (the reference set by name and digest: the same set elsewhere is the same set; the ElliMann
version that wrote it is recorded, not compared). The record is removed before a row's files are written again and
written once they all are, so a run killed in between leaves no record, and the row is made again.

One small file per row: every shard (``--shard``) writes its own rows' records, and a record is read only when its
row comes, so a batch's memory stays flat. The batch file (``--format npz``) is not a row's file: it is written again
on every run, whole, from the rows as they are now; its ``made_from_json`` says what (:meth:`Provenance.bundle_record`).
"""

import hashlib
import json
import os

from ..core.constants import VERSION
from ..core.files import atomic_write_text
from ..core.measurements import EXTRA_MEASUREMENTS, MEASUREMENTS
from ..core.synthesis.manifest import MANIFEST_FILE

RECORD_FOLDER = "made_from"
RECORD_FORMAT = "ellimann.batch-row"
BUNDLE_FORMAT = "ellimann.batch-file"  # the batch file's made_from_json (docs/formats/batch_npz.md)
RECORD_VERSION = 1
NOT_COMPARED = ("ellimann",)  # recorded for the reader, not a reason to make a row again
SAID = 20  # rows made again said on stderr, before the rest go to the report only


def file_digest(paths):
    """SHA-256 (hex) of the files' bytes, in the order given, each with its name and length (so no two file sets can
    run together into the same bytes)."""
    digest = hashlib.sha256()
    for path in paths:
        with open(path, "rb") as stream:
            data = stream.read()
        digest.update(f"{os.path.basename(path)}\0{len(data)}\0".encode())
        digest.update(data)
    return digest.hexdigest()


class Provenance:
    """The records of a batch writing into ``folder``: the settings every row shares (its ``command``'s job,
    ``core.job.request.Job``, once) and, per reference set, its identity (digested once)."""

    def __init__(self, folder, command):
        self.folder = os.path.join(folder, RECORD_FOLDER)
        options, request = command.options, command.request
        self.settings = {
            "mode": options.mode,
            "metric": options.metric,
            "power": float(options.power),
            "normalize": options.normalize,
            "cushions": bool(request.cushions),
            "skin": None if request.skin is None else {"voxel_mm": request.skin.voxel_mm, "blend": request.skin.blend},
            "pose": _pose(request.pose),
        }
        self.sets = {}
        self.redone = 0

    def path(self, name):
        return os.path.join(self.folder, f"{name}.json")

    def record(self, row):
        """What ``row``'s files are made from (a plain dict, JSON as it is written)."""
        request = dict(zip(MEASUREMENTS, (float(v) for v in row.values)))
        request.update((key, float(row.extra[key])) for key in EXTRA_MEASUREMENTS if key in row.extra)
        return {
            "format": RECORD_FORMAT,
            "version": RECORD_VERSION,
            "name": row.name,
            "request_cm": request,
            "references": self._identity(row.reference),
            **self.settings,
            "ellimann": VERSION,
        }

    def changed(self, row):
        """Why ``row``'s files, all there and whole, may not be kept: None if its record says they were made from
        this very row and these settings, else a short reason ("He, Sh changed", "the references changed", "no
        record of what they were made from")."""
        try:
            with open(self.path(row.name), encoding="utf-8") as stream:
                old = json.load(stream)
        except FileNotFoundError:
            return "no record of what they were made from"
        except (OSError, UnicodeDecodeError, ValueError):
            return "their record cannot be read"
        if not isinstance(old, dict) or (old.get("format"), old.get("version")) != (RECORD_FORMAT, RECORD_VERSION):
            return "their record is of another format"
        new = self.record(row)
        reasons = []
        asked, was = new["request_cm"], old.get("request_cm")
        if asked != was:
            was = was if isinstance(was, dict) else {}
            keys = [key for key in MEASUREMENTS + EXTRA_MEASUREMENTS if asked.get(key) != was.get(key)]
            reasons.append(", ".join(keys))
        if (new["references"]["name"], new["references"]["sha256"]) != _set_key(old.get("references")):
            reasons.append("the references")
        reasons += [
            key for key in new if key not in ("request_cm", "references", *NOT_COMPARED) and new[key] != old.get(key)
        ]
        return f"{', '.join(reasons)} changed" if reasons else None

    def bundle_record(self, reference):
        """What a batch file (``--format npz``, one per reference set) is made from: the reference set and the
        settings every row shares (each row's request is in the file's ``requests_cm``)."""
        return {
            "format": BUNDLE_FORMAT,
            "version": RECORD_VERSION,
            "references": {key: value for key, value in self._identity(reference).items() if key != "folder"},
            **self.settings,
            "ellimann": VERSION,
        }  # no folder: the same mannequins from the same set give the same bytes wherever the set lies

    def forget(self, name):
        """Remove ``name``'s record (before its files are written again)."""
        try:
            os.unlink(self.path(name))
        except FileNotFoundError:
            pass

    def write(self, row):
        """Record what ``row``'s files were made from (once they are all written)."""
        os.makedirs(self.folder, exist_ok=True)
        atomic_write_text(self.path(row.name), json.dumps(self.record(row), indent=1) + "\n")

    def _identity(self, reference):
        key = id(reference)
        if key not in self.sets:
            sources = [str(source) for source in reference.sources]
            folder = os.path.dirname(os.path.abspath(sources[0])) if sources else ""
            manifest = os.path.join(folder, MANIFEST_FILE)
            files = [path for path in [manifest, *sources] if os.path.isfile(path)]  # a set made in memory: none
            digest = file_digest(files) if files else None
            self.sets[key] = {"name": reference.name, "folder": folder if files else "", "sha256": digest}
        return self.sets[key]


def _set_key(recorded):
    return (recorded.get("name"), recorded.get("sha256")) if isinstance(recorded, dict) else None


def _pose(ask):
    """The pose part of a record: None, or the pose's name (a standard pose) or its file's digest, with the options
    that change what a pose file or clip becomes (``ask``: a ``core.job.request.PoseAsk``)."""
    if ask is None:
        return None
    out = {"name": ask.source, "fps": ask.fps}
    if os.path.isfile(ask.source):
        out = {"file": os.path.basename(ask.source), "sha256": file_digest([ask.source]), "fps": ask.fps}
        if ask.source.lower().endswith(".bvh"):
            out.update(rig=ask.rig, keep_on_floor=bool(ask.keep_on_floor))
    return out
