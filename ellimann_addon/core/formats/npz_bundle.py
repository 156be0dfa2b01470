"""Every mannequin of a batch in one compressed NumPy archive (``batch --format npz``): the layout, a writer
that gives the same bytes for the same mannequins (no time stamps), and a loader returning Mannequins.

Layout (docs/batch_file.md): ``format`` = "ellimann-batch", ``version`` = 1; per mannequin (B rows)
``names``, ``requests_cm`` (B, 5), ``measured_cm`` (B, 5), ``factors`` (B, 5), ``converged`` (B,); per piece
(n parts, the topology's order) ``rotation`` (B, n, 3, 3) with the local axes as columns, ``center`` (B, n, 3)
m, ``semi_axes`` (B, n, 3) m; ``measurement_keys`` (5,), ``part_names`` (n,), ``topology_json`` (the parts as in
the mannequin JSON, without geometry), ``mode``; optional ``joints`` (B, J, 3) m with ``joint_names`` (J,).
"""

import io
import json
import os
import zipfile

import numpy as np

from ..constants import MEASUREMENTS
from ..errors import ElliMannError, MannequinError
from ..files import atomic_write_bytes
from ..mannequin.model import Mannequin
from ..mannequin.topology import Topology

BATCH_FORMAT = "ellimann-batch"
BATCH_VERSION = 1
_FIXED_TIME = (1980, 1, 1, 0, 0, 0)  # the zip entries' time stamp: the same bytes for the same mannequins
_REQUIRED = (
    "format",
    "version",
    "names",
    "requests_cm",
    "measured_cm",
    "factors",
    "converged",
    "rotation",
    "center",
    "semi_axes",
    "measurement_keys",
    "part_names",
    "topology_json",
    "mode",
)


def batch_arrays(
    topology,
    names,
    requests,
    measured,
    factors,
    converged,
    rotation,
    center,
    semi_axes,
    mode,
    joints=None,
    joint_names=None,
):
    """The arrays of a batch file, by name (shapes checked against each other)."""
    count, parts = len(names), len(topology)
    arrays = {
        "format": np.array(BATCH_FORMAT),
        "version": np.array(BATCH_VERSION, dtype=np.int64),
        "names": np.array(list(names), dtype=str).reshape(count),
        "requests_cm": np.asarray(requests, dtype=np.float64).reshape(count, len(MEASUREMENTS)),
        "measured_cm": np.asarray(measured, dtype=np.float64).reshape(count, len(MEASUREMENTS)),
        "factors": np.asarray(factors, dtype=np.float64).reshape(count, len(MEASUREMENTS)),
        "converged": np.asarray(converged, dtype=bool).reshape(count),
        "rotation": np.asarray(rotation, dtype=np.float64).reshape(count, parts, 3, 3),
        "center": np.asarray(center, dtype=np.float64).reshape(count, parts, 3),
        "semi_axes": np.asarray(semi_axes, dtype=np.float64).reshape(count, parts, 3),
        "measurement_keys": np.array(MEASUREMENTS),
        "part_names": np.array(topology.names, dtype=str),
        "topology_json": np.array(json.dumps([part.to_dict() for part in topology])),
        "mode": np.array(mode),
    }
    if joints is not None:
        joints = np.asarray(joints, dtype=np.float64)
        arrays["joints"] = joints.reshape(count, -1, 3)
        arrays["joint_names"] = np.array(list(joint_names), dtype=str).reshape(arrays["joints"].shape[1])
    return arrays


def batch_bytes(arrays):
    """The .npz file's bytes: one deflated .npy entry per array, entries in the order given, fixed time stamps."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for key, array in arrays.items():
            info = zipfile.ZipInfo(f"{key}.npy", date_time=_FIXED_TIME)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.create_system = 3  # the same bytes on every system
            info.external_attr = 0o644 << 16
            with archive.open(info, "w", force_zip64=True) as stream:
                np.lib.format.write_array(stream, np.asarray(array).copy(order="C"), allow_pickle=False)
    return buffer.getvalue()


def write_batch_file(path, arrays):
    """Write :func:`batch_arrays` to ``path`` atomically (a temporary file checked whole, then renamed)."""
    atomic_write_bytes(path, batch_bytes(arrays))
    return os.fspath(path)


class BatchFileError(ElliMannError):
    """A batch file that cannot be read: the message names the file and the field."""


def _problem(path, field, text):
    return BatchFileError(f"{os.fspath(path)}: {field} {text}")


def read_batch_file(path):
    """The arrays of a batch file (dict), checked: format, version, every array there with consistent shapes.
    Raises BatchFileError naming the file and the field."""
    try:
        with np.load(path, allow_pickle=False) as archive:
            arrays = {key: archive[key] for key in archive.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as error:
        raise _problem(path, "file", f"is not a readable .npz archive ({error})") from None
    if "format" not in arrays or str(arrays["format"]) != BATCH_FORMAT:
        raise _problem(path, "format", f"is not an ElliMann batch file (expected format '{BATCH_FORMAT}')")
    version = arrays.get("version")
    if version is None or version.shape != () or not 1 <= int(version) <= BATCH_VERSION:
        raise _problem(path, "version", f"is {version!r}; this ElliMann reads version {BATCH_VERSION}")
    missing = [key for key in _REQUIRED if key not in arrays]
    if missing:
        raise _problem(path, missing[0], "is missing")
    count, parts = len(arrays["names"]), len(arrays["part_names"])
    shapes = {
        "requests_cm": (count, 5),
        "measured_cm": (count, 5),
        "factors": (count, 5),
        "converged": (count,),
        "rotation": (count, parts, 3, 3),
        "center": (count, parts, 3),
        "semi_axes": (count, parts, 3),
    }
    for key, shape in shapes.items():
        if arrays[key].shape != shape:
            raise _problem(path, key, f"has shape {arrays[key].shape}, expected {shape}")
    if "joints" in arrays and (arrays["joints"].ndim != 3 or arrays["joints"].shape[0] != count):
        raise _problem(path, "joints", f"has shape {arrays['joints'].shape}, expected ({count}, J, 3)")
    return arrays


def load_batch_file(path):
    """The mannequins of a batch file, in its order: a list of Mannequin (requests as their measurements;
    ``joints`` set where the file has them and Mannequin carries joints)."""
    arrays = read_batch_file(path)
    try:
        topology = Topology.from_list(json.loads(str(arrays["topology_json"])))
    except (ValueError, TypeError) as error:
        raise _problem(path, "topology_json", f"cannot be read ({error})") from None
    except MannequinError as error:
        raise _problem(path, "topology_json", str(error)) from None
    if topology.names != tuple(str(n) for n in arrays["part_names"]):
        raise _problem(path, "part_names", "differ from the topology's")
    keys = [str(k) for k in arrays["measurement_keys"]]
    joints = arrays.get("joints")
    mannequins = []
    for i, name in enumerate(arrays["names"]):
        mannequins.append(
            Mannequin(
                topology,
                arrays["rotation"][i],
                arrays["center"][i],
                arrays["semi_axes"][i],
                name=str(name),
                role="synthesized",
                measurements={k: float(v) for k, v in zip(keys, arrays["requests_cm"][i])},
                joints=None if joints is None else joints[i],
            )
        )
    return mannequins
