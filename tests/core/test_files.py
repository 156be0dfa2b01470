"""Whole-or-nothing writes (core.files): the completeness checks, the read-back before the rename and the
clean-up of what killed runs left behind. Every truncation of a file must be caught."""

import errno
import gzip
import json
import os
import struct
import subprocess
import sys
import time

import pytest

from ellimann_addon.core import files
from ellimann_addon.core.files import atomic_write_bytes, clean_stale_temporaries, incomplete, temp_prefix

# ------------------------------------------------------------------------------------------------ .blend


def blend_4x(pointer=8, order="<", blocks=((b"REND", 72), (b"GLOB", 1000), (b"DATA", 0), (b"DNA1", 3000))):
    """An uncompressed Blender 4.x file: ``BLENDER-v402`` (or ``_``/``V``) and BHead4/BHead8 block headers."""
    header = b"BLENDER" + (b"-" if pointer == 8 else b"_") + (b"v" if order == "<" else b"V") + b"402"
    head = struct.Struct(f"{order}4si{'Q' if pointer == 8 else 'I'}ii")
    body = b"".join(
        head.pack(code, length, 0x1000 + i, 0, 1) + bytes([i % 251]) * length for i, (code, length) in enumerate(blocks)
    )
    return header + body + head.pack(b"ENDB", 0, 0, 0, 0)


def blend_5x(order="<", blocks=((b"REND", 264), (b"GLOB", 1200), (b"DATA", 8), (b"DNA1", 4000))):
    """An uncompressed Blender 5.x file: ``BLENDER17-01v0500`` and 32-byte block headers with 64-bit lengths."""
    header = b"BLENDER17-01" + (b"v" if order == "<" else b"V") + b"0500"
    head = struct.Struct(f"{order}4siQqq")
    body = b"".join(
        head.pack(code, 0, 0x1000 + i, length, 1) + bytes([i % 251]) * length for i, (code, length) in enumerate(blocks)
    )
    return header + body + head.pack(b"ENDB", 0, 0, 0, 0)


def zstd_seekable(frames=(b"\x28\xb5\x2f\xfd" + b"x" * 500, b"\x28\xb5\x2f\xfd" + b"y" * 700), checksums=False):
    """Frames (stand-ins starting with the zstd magic) and the seek table Blender appends."""
    entries = b"".join(struct.pack("<II", len(f), 4 * len(f)) + (b"abcd" if checksums else b"") for f in frames)
    footer = struct.pack("<IBI", len(frames), 0x80 if checksums else 0, 0x8F92EAB1)
    table = entries + footer
    return b"".join(frames) + struct.pack("<II", 0x184D2A5E, len(table)) + table


def every_truncation_is_caught(tmp_path, data, name):
    path = tmp_path / name
    path.write_bytes(data)
    assert incomplete(path) is None
    accepted = []
    for size in range(len(data) - 1, -1, -1):  # every prefix, the file cut one byte shorter each time
        os.truncate(path, size)
        if incomplete(path) is None:
            accepted.append(size)
    assert path.stat().st_size == 0 and accepted == []


@pytest.mark.parametrize(
    "data",
    [blend_4x(), blend_4x(pointer=4), blend_4x(order=">"), blend_5x(), blend_5x(">")],
    ids=["4x", "4x-32bit", "4x-big-endian", "5x", "5x-big-endian"],
)
def test_a_cut_short_blend_is_caught_in_4x_and_5x_layouts(tmp_path, data):
    every_truncation_is_caught(tmp_path, data, "m.blend")


@pytest.mark.parametrize("checksums", [False, True])
def test_a_cut_short_zstd_blend_is_caught_by_its_seek_table(tmp_path, checksums):
    every_truncation_is_caught(tmp_path, zstd_seekable(checksums=checksums), "m.blend")


def test_a_zstd_blend_whose_frames_do_not_add_up_is_refused(tmp_path):
    data = bytearray(zstd_seekable())
    data[504:508] = b"zzzz"  # where the second frame's magic should be
    (tmp_path / "m.blend").write_bytes(bytes(data))
    assert "frame 2" in incomplete(tmp_path / "m.blend")
    (tmp_path / "m.blend").write_bytes(b"\x28\xb5\x2f\xfd" + b"q" * 100)  # zstd, but no seek table
    assert "seek table" in incomplete(tmp_path / "m.blend")


def test_a_gzip_blend_is_read_through(tmp_path):
    data = gzip.compress(blend_5x())
    (tmp_path / "m.blend").write_bytes(data)
    assert incomplete(tmp_path / "m.blend") is None
    (tmp_path / "m.blend").write_bytes(gzip.compress(blend_5x()[:-40]))  # whole gzip, cut-short blend inside
    assert "ENDB" in incomplete(tmp_path / "m.blend")
    (tmp_path / "m.blend").write_bytes(data[: len(data) // 2])
    assert incomplete(tmp_path / "m.blend") is not None


def test_what_is_not_a_blend_is_refused(tmp_path):
    for data, words in ((b"", "empty"), (b"PK\x03\x04 a zip", ".blend header"), (b"BLENDERxy", "not one Blender")):
        (tmp_path / "m.blend").write_bytes(data)
        assert words in incomplete(tmp_path / "m.blend")


# ------------------------------------------------------------------------------------------------ others


def glb(json_chunk=b'{"asset":{"version":"2.0"}}  ', binary=b"\x00" * 64):
    chunks = struct.pack("<I4s", len(json_chunk), b"JSON") + json_chunk + struct.pack("<I4s", len(binary), b"BIN\x00")
    chunks += binary
    return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


def test_a_cut_short_glb_is_caught(tmp_path):
    every_truncation_is_caught(tmp_path, glb(), "m.glb")
    data = bytearray(glb())
    data[8:12] = struct.pack("<I", len(data) + 4)
    (tmp_path / "m.glb").write_bytes(bytes(data))
    assert "header says" in incomplete(tmp_path / "m.glb")


def test_json_xml_png_and_obj_checks(tmp_path):
    every_truncation_is_caught(tmp_path, json.dumps({"a": [1, 2, 3], "b": "x"}).encode(), "m.json")
    every_truncation_is_caught(tmp_path, b"<mujoco><worldbody><geom/></worldbody></mujoco>", "m.xml")
    png = b"\x89PNG\r\n\x1a\n" + b"\x00" * 40 + b"\x00\x00\x00\x00IEND\xaeB`\x82"
    every_truncation_is_caught(tmp_path, png, "m.png")
    (tmp_path / "m.obj").write_bytes(b"o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    assert incomplete(tmp_path / "m.obj") is None
    (tmp_path / "m.obj").write_bytes(b"o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2")
    assert "complete line" in incomplete(tmp_path / "m.obj")
    assert "No such file" in incomplete(tmp_path / "missing.json")
    # The measurement files core.sizing.writers writes: a .vit is XML, a chart's .csv ends with a complete line
    every_truncation_is_caught(
        tmp_path,
        b'<smis><unit>cm</unit><body-measurements><m name="height" value="165"/></body-measurements></smis>',
        "m.vit",
    )
    (tmp_path / "m.csv").write_bytes(b"size,He\nunit,cm\nM,165\n")
    assert incomplete(tmp_path / "m.csv") is None
    (tmp_path / "m.csv").write_bytes(b"size,He\nunit,cm\nM,16")
    assert "complete line" in incomplete(tmp_path / "m.csv")


# ------------------------------------------------------------------------------------------------ atomic writes


def test_a_write_the_disk_cut_short_raises_and_keeps_the_old_file(tmp_path, monkeypatch):
    """As when a disk fills: fewer bytes reach the file than were written, and no error is raised."""
    target = tmp_path / "m.json"
    target.write_text('{"mine": true}')
    real_fsync = os.fsync

    def cut_short(fd):
        os.ftruncate(fd, 10)
        real_fsync(fd)

    monkeypatch.setattr(files.os, "fsync", cut_short)
    with pytest.raises(OSError) as raised:
        atomic_write_bytes(target, json.dumps({"new": list(range(100))}).encode())
    assert raised.value.errno == errno.EIO and raised.value.filename == str(target)
    assert "incomplete" in raised.value.strerror and "10 of" in raised.value.strerror
    assert target.read_text() == '{"mine": true}'
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.json"]  # no temporary left


def test_a_json_that_does_not_parse_back_is_not_put_in_place(tmp_path):
    target = tmp_path / "m.json"
    with pytest.raises(OSError, match="not valid JSON"):
        atomic_write_bytes(target, b'{"cut": ')
    assert not target.exists() and not list(tmp_path.iterdir())


def test_temporaries_are_named_after_this_process(tmp_path):
    atomic_write_bytes(tmp_path / "m.json", b"{}")
    assert temp_prefix().startswith(f".ellimann-{os.getpid()}@")
    assert files._TEMP_NAME.match(temp_prefix() + "abc_0123.tmp")


# ------------------------------------------------------------------------------------------------ stale temporaries


def dead_pid():
    process = subprocess.Popen([sys.executable, "-c", "pass"])
    process.wait()
    return process.pid


@pytest.mark.skipif(os.name != "posix", reason="tells running processes apart with os.kill(pid, 0)")
def test_stale_temporaries_of_killed_runs_are_removed_and_running_ones_kept(tmp_path):
    host = files._host()
    dead = dead_pid()
    old = time.time() - 2 * files.STALE_AGE
    made = {
        f".ellimann-{dead}@{host}-abcdefgh.tmp": "file",  # a killed run of this machine: removed
        f".ellimann-{dead}@{host}-ijklmnop": "dir",  # its Blender scratch folder: removed
        f".ellimann-{os.getpid()}@{host}-qrstuvwx.tmp": "file",  # this process is running: kept
        f".ellimann-{dead}@other-host-abcdefgh.tmp": "file",  # another machine, recent: kept
        f".ellimann-{dead}@old-host-abcdefgh.tmp": "old",  # another machine, untouched for long: removed
        ".ellimann-k2j4h6g8.tmp": "old",  # before temporaries named their process, old: removed
        ".ellimann-k2j4h6g9.tmp": "file",  # the same, recent: kept
        ".ellimann-notes.txt": "old",  # not a name ElliMann makes: kept
        ".ellimann-abcdefgh.tmp.d": "olddir",  # neither: kept
        "m.blend": "old",  # the user's: kept
    }
    for name, kind in made.items():
        path = tmp_path / name
        if kind.endswith("dir"):
            path.mkdir()
            (path / "m.blend").write_bytes(b"half")
        else:
            path.write_bytes(b"half")
        if kind.startswith("old"):
            os.utime(path, (old, old))
            if kind == "olddir":
                os.utime(path / "m.blend", (old, old))
    removed = clean_stale_temporaries(tmp_path)
    assert sorted(removed) == sorted(
        [
            f".ellimann-{dead}@{host}-abcdefgh.tmp",
            f".ellimann-{dead}@{host}-ijklmnop",
            f".ellimann-{dead}@old-host-abcdefgh.tmp",
            ".ellimann-k2j4h6g8.tmp",
        ]
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(set(made) - set(removed))
    assert clean_stale_temporaries(tmp_path / "missing") == []


@pytest.mark.skipif(os.name != "posix", reason="tells running processes apart with os.kill(pid, 0)")
def test_a_temporary_named_after_an_impossible_pid_is_a_dead_runs(tmp_path):
    name = f".ellimann-99999999999999999999@{files._host()}-abcdefgh.tmp"  # os.kill would overflow
    (tmp_path / name).write_bytes(b"half")
    assert clean_stale_temporaries(tmp_path) == [name]
