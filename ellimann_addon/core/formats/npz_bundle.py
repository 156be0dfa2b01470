"""Every mannequin of a batch in one compressed NumPy archive (``batch --format npz``): the layout, a writer
that gives the same bytes for the same mannequins (no time stamps), and a loader returning Mannequins.

Layout (docs/formats/batch_npz.md): ``format`` = "ellimann-batch", ``version`` = 1; per mannequin (B rows)
``names``, ``requests_cm`` (B, 5), ``measured_cm`` (B, 5), ``factors`` (B, 5), ``converged`` (B,); per piece
(n parts, the topology's order) ``rotation`` (B, n, 3, 3) with the local axes as columns, ``center`` (B, n, 3)
m, ``semi_axes`` (B, n, 3) m; ``measurement_keys`` (5,), ``part_names`` (n,), ``topology_json`` (the parts as in
the mannequin JSON, without geometry), ``mode``; optional ``joints`` (B, J, 3) m with ``joint_names`` (J,).
"""

import io
import json
import os
import shutil
import struct
import tempfile
import zipfile

import numpy as np

from ..errors import ElliMannError, MannequinError
from ..files import atomic_write_bytes, atomic_write_stream, temp_prefix
from ..mannequin.model import Mannequin
from ..mannequin.topology import Topology
from ..measurements import MEASUREMENTS

BATCH_FORMAT = "ellimann-batch"
BATCH_VERSION = 1
_LENGTH = struct.Struct("<I")  # a name's length, before its UTF-32 code points, in BatchFileWriter's rows
_FIXED_TIME = (1980, 1, 1, 0, 0, 0)  # the zip entries' time stamp: the same bytes for the same mannequins
_ORDER = (  # the archive's entries, in order (joints and joint_names only where the mannequins have joints)
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
    "joints",
    "joint_names",
    "made_from_json",
)
_OPTIONAL = ("joints", "joint_names", "made_from_json")
_REQUIRED = tuple(key for key in _ORDER if key not in _OPTIONAL)


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
    made_from=None,
):
    """The arrays of a batch file, by name (shapes checked against each other); ``made_from``: what the batch made
    them from (a JSON-able dict: the reference set, the options; ``cli.provenance``), if given."""
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
    if made_from is not None:
        arrays["made_from_json"] = np.array(json.dumps(made_from, sort_keys=True))
    return arrays


def batch_bytes(arrays):
    """The .npz file's bytes: one deflated .npy entry per array, entries in the order given, fixed time stamps."""
    buffer = io.BytesIO()
    _write_archive(buffer, ((key, array) for key, array in arrays.items()))
    return buffer.getvalue()


def write_batch_file(path, arrays):
    """Write :func:`batch_arrays` to ``path`` atomically (a temporary file checked whole, then renamed)."""
    atomic_write_bytes(path, batch_bytes(arrays))
    return os.fspath(path)


def _write_archive(stream, entries):
    """The .npz archive into ``stream``: for each (key, array or :class:`_Streamed`), one deflated ``key.npy``
    entry with a fixed time stamp."""
    with zipfile.ZipFile(stream, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for key, array in entries:
            info = zipfile.ZipInfo(f"{key}.npy", date_time=_FIXED_TIME)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.create_system = 3  # the same bytes on every system
            info.external_attr = 0o644 << 16
            with archive.open(info, "w", force_zip64=True) as entry:
                if isinstance(array, _Streamed):
                    array.write(entry)
                else:
                    np.lib.format.write_array(entry, np.asarray(array).copy(order="C"), allow_pickle=False)


class _Streamed:
    """An array whose rows are in a file on disk (C order, its dtype's bytes): written into an archive as the .npy
    ``np.lib.format.write_array`` makes of the whole array, its rows read a block at a time."""

    BLOCK = 1 << 22

    def __init__(self, path, dtype, shape):
        self.path, self.dtype, self.shape = path, np.dtype(dtype), tuple(int(n) for n in shape)

    def write(self, entry):
        header = {"descr": np.lib.format.dtype_to_descr(self.dtype), "fortran_order": False, "shape": self.shape}
        np.lib.format.write_array_header_1_0(entry, header)
        with open(self.path, "rb") as rows:
            for block in iter(lambda: rows.read(self.BLOCK), b""):
                entry.write(block)


class BatchFileWriter:
    """A batch file written as its rows come (``batch --format npz`` streams a batch of any size through it): each
    per-mannequin array's rows are appended to a file of their own in a temporary folder beside ``path``, so memory
    stays flat in the row count; :meth:`finish` assembles the archive, an entry at a time, into the bytes
    :func:`write_batch_file` gives for the same rows, and puts it in place atomically. :meth:`discard` (or an
    interrupted run, its folder removed by ``core.files.clean_stale_temporaries``) leaves no half archive."""

    _ROWS = {  # per-mannequin arrays: dtype, shape of one row (n: the topology's pieces)
        "requests_cm": (np.float64, (len(MEASUREMENTS),)),
        "measured_cm": (np.float64, (len(MEASUREMENTS),)),
        "factors": (np.float64, (len(MEASUREMENTS),)),
        "converged": (np.bool_, ()),
        "rotation": (np.float64, ("n", 3, 3)),
        "center": (np.float64, ("n", 3)),
        "semi_axes": (np.float64, ("n", 3)),
        "joints": (np.float64, ("J", 3)),
    }

    def __init__(self, path, topology, mode, joint_names=None, made_from=None):
        self.path, self.topology, self.mode, self.made_from = os.fspath(path), topology, mode, made_from
        self.joint_names = None if joint_names is None else list(joint_names)
        self.count, self.width, self.with_joints = 0, 1, None  # rows, longest name, whether rows carry joints
        folder = os.path.dirname(os.path.abspath(self.path))
        self.scratch = tempfile.mkdtemp(prefix=temp_prefix(), dir=folder)
        self.files = {key: open(os.path.join(self.scratch, f"{key}.bin"), "wb") for key in ("names", *self._ROWS)}

    def _row_shape(self, key):
        sizes = {"n": len(self.topology), "J": len(self.joint_names or ())}
        return tuple(sizes.get(size, size) for size in self._ROWS[key][1])

    def add(self, names, requests, measured, factors, converged, rotation, center, semi_axes, joints=None):
        """Append rows (each argument holds them all: names (k,), requests (k, 5) cm, ..., joints (k, J, 3) m or
        None, the same for every row of a file)."""
        names = [str(name) for name in names]
        if self.with_joints is None:
            self.with_joints = joints is not None and self.joint_names is not None
        elif self.with_joints != (joints is not None):
            raise ValueError("every row of a batch file has joints, or none has")
        arrays = dict(
            requests_cm=requests,
            measured_cm=measured,
            factors=factors,
            converged=converged,
            rotation=rotation,
            center=center,
            semi_axes=semi_axes,
            joints=joints if self.with_joints else None,
        )
        for key, array in arrays.items():
            if array is None:
                continue
            dtype = self._ROWS[key][0]
            self.files[key].write(
                np.ascontiguousarray(np.asarray(array, dtype=dtype).reshape((len(names),) + self._row_shape(key)))
            )
        self.files["names"].write(b"".join(_LENGTH.pack(len(name)) + name.encode("utf-32-le") for name in names))
        self.width = max([self.width] + [len(name) for name in names])
        self.count += len(names)

    def finish(self):
        """Write the archive (atomically) and remove the temporary folder; returns the path."""
        for stream in self.files.values():
            stream.close()
        try:
            names_path = os.path.join(self.scratch, "names.npy-rows")
            with open(os.path.join(self.scratch, "names.bin"), "rb") as names, open(names_path, "wb") as out:
                for _ in range(self.count):  # as numpy holds str: UTF-32 code points, padded to the longest name
                    length = _LENGTH.unpack(names.read(_LENGTH.size))[0]
                    out.write(names.read(4 * length).ljust(4 * self.width, b"\0"))
            fixed = {
                "format": np.array(BATCH_FORMAT),
                "version": np.array(BATCH_VERSION, dtype=np.int64),
                "measurement_keys": np.array(MEASUREMENTS),
                "part_names": np.array(self.topology.names, dtype=str),
                "topology_json": np.array(json.dumps([part.to_dict() for part in self.topology])),
                "mode": np.array(self.mode),
            }
            if self.with_joints:
                fixed["joint_names"] = np.array(self.joint_names, dtype=str)
            if self.made_from is not None:
                fixed["made_from_json"] = np.array(json.dumps(self.made_from, sort_keys=True))
            entries = []
            for key in _ORDER:  # batch_arrays' order
                if key == "names":
                    entries.append((key, _Streamed(names_path, f"<U{self.width}", (self.count,))))
                elif key in self._ROWS and (key != "joints" or self.with_joints):
                    shape = (self.count,) + self._row_shape(key)
                    rows = os.path.join(self.scratch, f"{key}.bin")
                    entries.append((key, _Streamed(rows, self._ROWS[key][0], shape)))
                elif key in fixed:
                    entries.append((key, fixed[key]))
            atomic_write_stream(self.path, lambda stream: _write_archive(stream, entries))
        finally:
            self.discard()
        return self.path

    def discard(self):
        """Remove the temporary folder (the archive is not written)."""
        for stream in self.files.values():
            stream.close()
        shutil.rmtree(self.scratch, ignore_errors=True)


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
