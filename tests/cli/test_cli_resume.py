"""``batch --resume`` keeps a row's files only when they were made from the same row and settings: each row's files
get a record of what they were made from (``cli.provenance``, DIR/made_from/NAME.json), compared before a file is
kept; a changed row, reference set, mode, skin, pose or cushions makes the row again and the report says why."""

import csv
import json
import shutil

import pytest

from devkit import synthetic
from devkit.cli_runs import run
from ellimann_addon.cli.provenance import RECORD_FOLDER
from ellimann_addon.core.mannequin.model import Mannequin

TABLE_ROW = "x1,165,41.5,101.25,82.75,117.5\n"
OTHER_ROW = "x1,150,35,90,70,95\n"


def write_csv(path, *rows):
    path.write_text("name,He,Sh,Br,Wa,Hi\n" + "".join(rows), encoding="utf-8")
    return str(path)


def report(folder, name="report.csv"):
    return list(csv.DictReader((folder / name).open(encoding="utf-8")))


def batch(source, out, capsys, *options):
    code, stdout, stderr = run(["batch", source, "-o", str(out), "-q", *options], capsys)
    assert code == 0, stderr
    return stdout, stderr


def test_a_resume_after_a_changed_row_makes_that_row_again_and_says_so(tmp_path, capsys):
    out = tmp_path / "out"
    batch(write_csv(tmp_path / "a.csv", TABLE_ROW), out, capsys)
    first = (out / "x1.json").stat().st_ino
    stdout, stderr = batch(write_csv(tmp_path / "b.csv", OTHER_ROW), out, capsys, "--resume")
    assert "(0 already complete, kept; 1 made again: their row or settings changed)" in stdout
    assert "line 2: x1's files were made from another row or settings (He, Sh, Br, Wa, Hi changed)" in stderr
    row = report(out)[0]
    assert row["status"] == "ok" and "redone (--resume: He, Sh, Br, Wa, Hi changed)" in row["message"]
    assert "kept" not in row["message"]
    assert (out / "x1.json").stat().st_ino != first
    assert Mannequin.load(out / "x1.json").measure()["He"] == pytest.approx(150.0, abs=1e-3)  # the file says 150
    assert float(row["He_measured"]) == pytest.approx(150.0, abs=1e-3)
    record = json.loads((out / RECORD_FOLDER / "x1.json").read_text())
    assert record["request_cm"] == {"He": 150.0, "Sh": 35.0, "Br": 90.0, "Wa": 70.0, "Hi": 95.0}


def test_a_resume_with_the_same_row_and_settings_keeps_the_files(tmp_path, capsys):
    out = tmp_path / "out"
    source = write_csv(tmp_path / "a.csv", TABLE_ROW)
    batch(source, out, capsys, "--format", "json,obj")
    files = {name: (out / name).stat().st_ino for name in ("x1.json", "x1.obj")}
    stdout, stderr = batch(source, out, capsys, "--format", "json,obj", "--resume")
    assert "(1 already complete, kept)" in stdout and "made again" not in stdout + stderr
    assert report(out)[0]["message"] == "kept (--resume)"
    assert {name: (out / name).stat().st_ino for name in files} == files


@pytest.mark.parametrize(
    "change, reason",
    [
        (["--references", "male"], "the references changed"),
        (["--mode", "idw"], "mode changed"),
        (["--normalize", "none"], "normalize changed"),
        (["--power", "3"], "power changed"),
        (["--cushions"], "cushions changed"),
        (["--pose", "t_pose"], "pose changed"),
    ],
)
def test_a_resume_with_other_settings_makes_the_row_again(tmp_path, capsys, change, reason):
    out = tmp_path / "out"
    source = write_csv(tmp_path / "a.csv", TABLE_ROW)
    batch(source, out, capsys)
    stdout, _ = batch(source, out, capsys, "--resume", *change)
    assert "1 made again" in stdout
    assert f"redone (--resume: {reason})" in report(out)[0]["message"]
    stdout, _ = batch(source, out, capsys, "--resume", *change)  # now made with these: kept
    assert "(1 already complete, kept)" in stdout


def test_a_reference_set_whose_files_changed_is_another_set(tmp_path, capsys):
    folder = synthetic.write_reference_folder(tmp_path / "rm")
    out = tmp_path / "out"
    source = tmp_path / "a.csv"
    source.write_text("name,He,Sh,Br,Wa,Hi\nr,160,40,95,80,105\n", encoding="utf-8")
    batch(str(source), out, capsys, "--references", str(folder))
    moved = shutil.copytree(folder, tmp_path / "elsewhere")  # the same set in another folder: the same set
    assert "(1 already complete, kept)" in batch(str(source), out, capsys, "--resume", "--references", str(moved))[0]
    first = sorted(p for p in moved.glob("*.json") if p.name != "reference_set.json")[0]
    data = json.loads(first.read_text())
    data["ellipsoids"][0]["center"][2] += 1e-4  # one RM moved by 0.1 mm
    first.write_text(json.dumps(data))
    batch(str(source), out, capsys, "--resume", "--references", str(moved))
    assert "redone (--resume: the references changed)" in report(out)[0]["message"]


def test_files_without_a_record_are_made_again_and_a_row_s_record_goes_before_its_files_are_rewritten(
    tmp_path, capsys, monkeypatch
):
    out = tmp_path / "out"
    source = write_csv(tmp_path / "a.csv", TABLE_ROW)
    batch(source, out, capsys)
    (out / RECORD_FOLDER / "x1.json").unlink()  # files an older ElliMann wrote: no record
    batch(source, out, capsys, "--resume")
    assert "redone (--resume: no record of what they were made from)" in report(out)[0]["message"]
    from ellimann_addon.cli import writing

    def killed(*args, **keywords):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(writing, "write", killed)  # the row fails while its files are written again
    code, _, _ = run(["batch", write_csv(tmp_path / "b.csv", OTHER_ROW), "-o", str(out), "-q", "--resume"], capsys)
    assert code == 1 and not (out / RECORD_FOLDER / "x1.json").exists()  # no record says the old file is the new row
    monkeypatch.undo()
    assert "(0 already complete" in batch(source, out, capsys, "--resume")[0]


def test_shards_record_their_own_rows_and_resume_each(tmp_path, capsys):
    rows = [f"r{i},{160 + i},40,95,80,105\n" for i in range(4)]
    source = write_csv(tmp_path / "a.csv", *rows)
    out = tmp_path / "out"
    for shard in ("1/2", "2/2"):
        batch(source, out, capsys, "--shard", shard)
    assert sorted(p.name for p in (out / RECORD_FOLDER).iterdir()) == [f"r{i}.json" for i in range(4)]
    rows[1] = "r1,170,40,95,80,105\n"
    changed = write_csv(tmp_path / "b.csv", *rows)
    assert "(2 already complete, kept)" in batch(changed, out, capsys, "--shard", "1/2", "--resume")[0]
    stdout, _ = batch(changed, out, capsys, "--shard", "2/2", "--resume")
    assert "(1 already complete, kept; 1 made again" in stdout
    messages = {row["name"]: row["message"] for row in report(out, "report-2-of-2.csv")}
    assert messages == {"r1": "redone (--resume: He changed)", "r3": "kept (--resume)"}


def test_an_extra_measurement_asked_is_part_of_the_row(tmp_path, capsys):
    out = tmp_path / "out"
    source = tmp_path / "a.csv"
    source.write_text("name,He,Sh,Br,Wa,Hi,neck\nx1,165,41.5,101.25,82.75,117.5,\n", encoding="utf-8")
    batch(str(source), out, capsys, "--mode", "idw")
    source.write_text("name,He,Sh,Br,Wa,Hi,neck\nx1,165,41.5,101.25,82.75,117.5,30\n", encoding="utf-8")
    batch(str(source), out, capsys, "--mode", "idw", "--resume")
    assert "redone (--resume: neck changed)" in report(out)[0]["message"]


def test_the_batch_file_says_what_it_was_made_from(tmp_path, capsys):
    from ellimann_addon.core.formats.npz_bundle import read_batch_file

    out = tmp_path / "out"
    batch(write_csv(tmp_path / "a.csv", TABLE_ROW), out, capsys, "--format", "npz,json", "--mode", "idw")
    made = json.loads(str(read_batch_file(out / "mannequins.npz")["made_from_json"]))
    row = json.loads((out / RECORD_FOLDER / "x1.json").read_text())
    assert made["format"] == "ellimann.batch-file" and made["mode"] == "idw"
    assert made["references"] == {key: row["references"][key] for key in ("name", "sha256")}  # no folder
    assert {key: made[key] for key in ("metric", "power", "normalize", "cushions", "skin", "pose")} == {
        key: row[key] for key in ("metric", "power", "normalize", "cushions", "skin", "pose")
    }
