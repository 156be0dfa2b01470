"""Batches at population scale: --format npz (one archive, a loader returning the same mannequins as the JSON
files, the same bytes twice), --dask on a local cluster (files byte for byte those of a serial run with the BLAS's
default threads), a chunk the
cluster fails reported without losing the others, an unreachable scheduler refused with nothing written, and the
progress line; exact mode on the whole 243 grid, one request at a time the same bits as the batch."""

import csv
import io
import itertools
import os
import pathlib
import socket
import subprocess
import sys

import numpy as np
import pytest

from devkit import synthetic
from devkit.cli_runs import ROOT, assert_one_line_error, run
from devkit.same_answer import environment
from ellimann_addon.cli import distributed, output
from ellimann_addon.core.constants import quartile_points
from ellimann_addon.core.formats.npz_bundle import BatchFileError, load_batch_file, read_batch_file
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER, REFERENCE_NAMES, load_reference_set
from ellimann_addon.core.synthesis.refine import EXACT_TOLERANCE, FACTOR_LIMITS
from ellimann_addon.core.synthesis.synthesize import synthesize_batch


@pytest.fixture(scope="module")
def references(tmp_path_factory):
    return str(synthetic.write_reference_folder(tmp_path_factory.mktemp("rm")))


def requests_csv(path, count):
    """``count`` requests spread over the reference range (a grid walk), named r0…"""
    levels = [
        np.linspace(150, 170, 4),
        np.linspace(36, 44, 3),
        np.linspace(88, 110, 3),
        np.linspace(70, 95, 3),
        np.linspace(95, 118, 2),
    ]
    rows = itertools.islice(itertools.cycle(itertools.product(*levels)), count)
    lines = ["name,He,Sh,Br,Wa,Hi"] + [f"r{i}," + ",".join(f"{v:.2f}" for v in row) for i, row in enumerate(rows)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return str(path)


def test_npz_holds_what_the_json_files_hold(tmp_path, capsys, references):
    source = requests_csv(tmp_path / "in.csv", 7)
    code, _, err = run(
        ["batch", source, "-o", str(tmp_path / "out"), "--format", "json,npz", "--references", references, "-q"], capsys
    )
    assert code == 0, err
    loaded = load_batch_file(tmp_path / "out" / "mannequins.npz")
    assert [m.name for m in loaded] == [f"r{i}" for i in range(7)]
    for mannequin in loaded:
        written = Mannequin.load(tmp_path / "out" / f"{mannequin.name}.json")
        assert written.topology == mannequin.topology and written.measurements == mannequin.measurements
        for key in ("rotation", "center", "semi_axes"):
            np.testing.assert_array_equal(getattr(written, key), getattr(mannequin, key))
    arrays = read_batch_file(tmp_path / "out" / "mannequins.npz")
    report = list(csv.DictReader((tmp_path / "out" / "report.csv").open(encoding="utf-8")))
    assert [f"{v:.4f}" for v in arrays["measured_cm"][:, 2]] == [row["Br_measured"] for row in report]
    assert "joints" not in arrays and arrays["converged"].all() and str(arrays["mode"]) == "exact"
    first = (tmp_path / "out" / "mannequins.npz").read_bytes()
    code, _, _ = run(
        ["batch", source, "-o", str(tmp_path / "out"), "--format", "npz", "--references", references, "-q"], capsys
    )
    assert code == 0 and (tmp_path / "out" / "mannequins.npz").read_bytes() == first  # no time stamps inside


def test_a_file_that_is_not_a_batch_is_refused_naming_the_field(tmp_path):
    np.savez(tmp_path / "other.npz", names=np.array(["a"]))
    with pytest.raises(BatchFileError, match="format is not an ElliMann batch file"):
        load_batch_file(tmp_path / "other.npz")
    (tmp_path / "cut.npz").write_bytes(b"PK\x03\x04 not really")
    with pytest.raises(BatchFileError, match="not a readable .npz archive"):
        load_batch_file(tmp_path / "cut.npz")


def loaded_by(statement, where):
    """The modules ``statement`` loads (in a fresh interpreter at the repository's root) that ``where(name)``
    picks, sorted."""
    code = f"import sys; {statement}; print(sorted(m for m in sys.modules if ({where})(m)))"
    done = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=True,
        cwd=os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
    )
    return done.stdout.strip()


def test_the_command_line_imports_dask_only_for_dask():
    dask = "lambda m: m.split('.')[0] in ('dask', 'distributed')"
    assert loaded_by("import ellimann_addon.cli as cli; cli.build_parser()", dask) == "[]"


def test_dask_local_cluster_writes_the_serial_files_byte_for_byte(tmp_path, capsys):
    """The shipped female set read from its files (its frames a transposed view until the model made them
    C-contiguous: a Dask worker's copy is, and numpy's sums of products followed the layout, 19 of 40 files once
    differing in a last digit), two rows with extra measurements; the serial run in a process of its own with the
    BLAS's default threads (the workers have one each)."""
    source = requests_csv(tmp_path / "in.csv", 40)
    with open(source, encoding="utf-8") as handle:
        lines = handle.read().splitlines()
    lines[0] += ",neck,thigh"
    lines[1:3] = [lines[1] + ",33.5,57.0", lines[2] + ",34.0,58.5"]
    lines[3:] = [line + ",," for line in lines[3:]]
    pathlib.Path(source).write_text("\n".join(lines) + "\n", encoding="utf-8")
    (tmp_path / "serial").mkdir()
    serial = subprocess.run(
        [sys.executable, "-m", "ellimann_addon", "batch", source, "-o", "out", "--format", "json,npz", "-q"],
        cwd=tmp_path / "serial",
        env=environment(threads=None, base={**os.environ, "PYTHONPATH": str(ROOT)}),
        capture_output=True,
        text=True,
    )
    assert serial.returncode == 0, serial.stderr
    (tmp_path / "dask").mkdir()
    here = os.getcwd()
    os.chdir(tmp_path / "dask")
    try:
        code, _, err = run(["batch", source, "-o", "out", "--format", "json,npz", "-q", "--dask", "local:2"], capsys)
    finally:
        os.chdir(here)
    assert code == 0, err
    serial, dask = tmp_path / "serial" / "out", tmp_path / "dask" / "out"
    names = sorted(os.listdir(serial))
    assert names == sorted(os.listdir(dask)) and len(names) == 43  # 40 rows, the batch file, the report, made_from/
    files = sorted(p.relative_to(serial) for p in serial.rglob("*") if p.is_file())  # made_from/'s records too
    assert files == sorted(p.relative_to(dask) for p in dask.rglob("*") if p.is_file()) and len(files) == 82
    for name in files:
        assert (serial / name).read_bytes() == (dask / name).read_bytes(), name


class FakeFuture:
    def __init__(self, key, outcome):
        self.key, self.outcome = key, outcome

    def result(self):
        if isinstance(self.outcome, Exception):
            raise self.outcome
        return self.outcome

    def release(self):
        pass


class FakeClient:
    """Runs each chunk here; the second task fails as a worker would report it."""

    def __init__(self):
        self.submitted = 0

    def scatter(self, value, broadcast):
        return value

    def submit(self, function, reference, requests, options, extras, retries, pure):
        self.submitted += 1
        key = f"chunk-{self.submitted}"
        if self.submitted == 2:
            return FakeFuture(key, RuntimeError("worker lost"))
        return FakeFuture(key, function(reference, requests, options, extras))


def test_a_failed_chunk_is_reported_row_by_row_and_the_others_kept(references):
    from ellimann_addon.core.synthesis.reference_set import load_reference_set
    from ellimann_addon.core.synthesis.synthesize import SynthesisOptions

    reference = load_reference_set(references)
    chunks = [[[160, 40, 95, 80, 105]] * 2, [[165, 41, 100, 82, 110]] * 3, [[170, 42, 100, 85, 110]]]
    cluster = distributed.Cluster(FakeClient(), None)
    sent = [
        cluster.submit([(reference, np.array(chunk, float), [{}] * len(chunk))], SynthesisOptions()) for chunk in chunks
    ]
    results = [cluster.results(submitted)[0] for submitted in reversed(sent)][::-1]  # taken in any order
    assert results[0].errors == [None, None] and results[2].errors == [None]
    assert len(results[1].errors) == 3 and all(
        "failed on the Dask cluster" in e and "worker lost" in e for e in results[1].errors
    )
    assert np.isnan(results[1].center).all() and not results[1].converged.any()
    alone = synthesize_batch(reference, chunks[2])
    np.testing.assert_array_equal(results[2].center, alone.center)


def test_an_unreachable_scheduler_is_one_line_and_nothing_written(tmp_path, capsys, monkeypatch, references):
    with socket.socket() as probe:  # a port nobody listens on
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    monkeypatch.setattr(distributed, "CONNECT_TIMEOUT", "1s")
    source = requests_csv(tmp_path / "in.csv", 3)
    code, out, err = run(
        ["batch", source, "-o", str(tmp_path / "out"), "--dask", f"tcp://127.0.0.1:{port}", "--references", references],
        capsys,
    )
    assert_one_line_error(code, err, f"--dask tcp://127.0.0.1:{port}: cannot reach the scheduler")
    assert not (tmp_path / "out").exists() and out == ""


@pytest.mark.parametrize("address", ["local:0", "localhost:8786", "local:x"])
def test_a_malformed_address_is_one_line(tmp_path, capsys, references, address):
    source = requests_csv(tmp_path / "in.csv", 2)
    code, _, err = run(["batch", source, "-o", str(tmp_path / "out"), "--dask", address], capsys)
    assert_one_line_error(code, err, "--dask")
    assert not (tmp_path / "out").exists()


def test_progress_shows_count_rate_and_time_left_and_is_quiet_with_q(monkeypatch):
    stream = io.StringIO()
    monkeypatch.setattr(output.sys, "stderr", stream)
    clock = iter(range(100))
    monkeypatch.setattr(output.time, "perf_counter", lambda: float(next(clock)))
    progress = output.Progress(40, "batch")  # starts at t = 0; each step is a second later
    for i in range(40):
        progress.step(f"row {i}")
    lines = stream.getvalue().splitlines()
    assert len(lines) == 20  # every 5% in a log
    assert lines[0] == "ellimann batch: 2/40 (1.0/s, 38 s left) row 1"
    assert lines[-1].startswith("ellimann batch: 40/40 (1.0/s, 0 s left)")
    quiet = output.Progress(40, "batch", quiet=True)
    stream.truncate(0)
    for _ in range(40):
        quiet.step("row")
    quiet.done()
    assert stream.getvalue().strip("\x00") == ""
    assert output.duration(3725) == "1 h 2 min" and output.duration(75) == "1 min 15 s"


GRID = np.array(list(itertools.product(*[quartile_points(key) for key in MEASUREMENTS])))
SETS = ["synthetic"] + (["shipped"] if all((REFERENCE_FOLDER / f"{n}.json").is_file() for n in REFERENCE_NAMES) else [])


@pytest.mark.parametrize("which", SETS)
def test_exact_mode_converges_on_the_whole_grid_and_one_at_a_time_is_the_batch_bit_for_bit(which):
    reference = load_reference_set() if which == "shipped" else synthetic.make_reference_set()
    batch = synthesize_batch(reference, GRID, mode="exact")
    assert batch.converged.all()
    assert np.abs(np.log(batch.measured / GRID)).max() <= EXACT_TOLERANCE
    assert np.all((batch.factors >= FACTOR_LIMITS[0]) & (batch.factors <= FACTOR_LIMITS[1]))
    for i in range(0, len(GRID), 5):  # what a chunk of a serial or Dask batch gives is what a request alone gives
        alone = synthesize_batch(reference, GRID[i : i + 1], mode="exact")
        for key in ("center", "semi_axes", "measured", "factors"):
            np.testing.assert_array_equal(getattr(alone, key)[0], getattr(batch, key)[i])


def test_a_row_the_core_refuses_fails_alone_and_its_chunk_keeps_the_others(monkeypatch, references):
    from ellimann_addon.core.errors import ElliMannError
    from ellimann_addon.core.synthesis import batch as chunking
    from ellimann_addon.core.synthesis import synthesize as synthesis
    from ellimann_addon.core.synthesis.reference_set import load_reference_set

    real = synthesis.synthesize_checked

    def refusing(reference, requests, options, **fields):  # as check_plausible refuses a whole batch
        if any(values[0] == 161.0 for values in requests):
            raise ElliMannError("synthesis at He 161 cm gives an implausible mannequin")
        return real(reference, requests, options, **fields)

    monkeypatch.setattr(chunking, "synthesize_checked", refusing)
    reference = load_reference_set(references)
    chunk = [[160.0, 40, 95, 80, 105], [161.0, 40, 95, 80, 105], [162.0, 41, 96, 81, 106]]
    result = chunking.synthesize_chunk(reference, chunk, synthesis.SynthesisOptions())
    assert result.errors[0] is None and result.errors[2] is None and "implausible" in result.errors[1]
    alone = synthesis.synthesize_batch(reference, [chunk[0], chunk[2]])
    np.testing.assert_array_equal(result.center[[0, 2]], alone.center)
    assert np.isnan(result.center[1]).all() and not result.converged[1]


# ------------------------------------------------------------------------------------------------ streaming


def test_the_streamed_batch_file_is_the_whole_file_writers_bytes(tmp_path):
    """BatchFileWriter (rows appended as they come, each array on disk) writes the bytes write_batch_file writes
    for the same rows in one go: with joints, without, and with no row at all."""
    from ellimann_addon.core.formats.npz_bundle import BatchFileWriter, batch_arrays, write_batch_file
    from ellimann_addon.core.mannequin.skeleton import JOINT_NAMES
    from ellimann_addon.core.synthesis.shipped import named_reference_set

    for reference in (named_reference_set("female"), synthetic.make_reference_set()):
        requests = np.array([[150.0 + i, 36 + i % 5, 95, 80, 100] for i in range(7)])
        result = synthesize_batch(reference, requests, mode="idw")
        names = [f"{'m' * (1 + i % 4)}{i}" for i in range(7)]  # names of several lengths: the str width is the longest
        for count in (7, 0):
            rows = slice(0, count)
            joints = None if result.joints is None or not count else result.joints[rows]  # as the batch gave them
            arrays = [result.requests, result.measured, result.factors, result.converged]
            arrays += [result.rotation, result.center, result.semi_axes]
            whole = write_batch_file(
                tmp_path / "whole.npz",
                batch_arrays(reference.topology, names[rows], *[a[rows] for a in arrays], "idw", joints, JOINT_NAMES),
            )
            writer = BatchFileWriter(tmp_path / "streamed.npz", reference.topology, "idw", JOINT_NAMES)
            for part in (slice(0, min(count, 3)), slice(min(count, 3), count)):
                if part.stop > part.start:
                    writer.add(names[part], *[a[part] for a in arrays], None if joints is None else joints[part])
            streamed = writer.finish()
            assert open(streamed, "rb").read() == open(whole, "rb").read(), (reference.name, count)
            assert sorted(p.name for p in tmp_path.iterdir()) == ["streamed.npz", "whole.npz"]  # no temporaries
            assert ("joints" in read_batch_file(streamed)) == (count > 0 and result.joints is not None)


def test_a_discarded_batch_file_leaves_nothing(tmp_path):
    from ellimann_addon.core.formats.npz_bundle import BatchFileWriter

    reference = synthetic.make_reference_set()
    result = synthesize_batch(reference, [[160.0, 40, 95, 80, 105]], mode="idw")
    writer = BatchFileWriter(tmp_path / "m.npz", reference.topology, "idw")
    writer.add(
        ["a"],
        result.requests,
        result.measured,
        result.factors,
        result.converged,
        result.rotation,
        result.center,
        result.semi_axes,
    )
    assert len(list(tmp_path.iterdir())) == 1  # its rows, in a temporary folder beside the file
    writer.discard()
    assert list(tmp_path.iterdir()) == []


def test_a_batch_streams_in_the_csvs_order_across_chunks_and_reference_sets(tmp_path, capsys, monkeypatch, references):
    """Chunks of 3 rows, two reference sets taking turns, refused rows and a name used twice two chunks apart: the
    report keeps the CSV's order, each set's batch file holds its rows in that order, and every mannequin is the
    bits of its request synthesized alone."""
    from ellimann_addon.core.synthesis import batch as chunking
    from ellimann_addon.core.synthesis.shipped import named_reference_set

    monkeypatch.setattr(chunking, "CHUNK", 3)
    male = named_reference_set("male")
    middle = {key: round(sum(male.ranges[key]) / 2, 2) for key in MEASUREMENTS}
    lines = ["name,He,Sh,Br,Wa,Hi,references"]
    for i in range(10):
        if i % 2:
            lines.append(f"m{i}," + ",".join(f"{middle[key] + i / 10:g}" for key in MEASUREMENTS) + ",male")
        else:
            lines.append(f"f{i},{160 + i},40,95,80,105,")
    lines[4] = "f3,160,40,abc,80,105,"  # refused: not a number
    lines[9] = "F0,161,40,95,80,105,"  # refused: f0's name, two chunks on
    (tmp_path / "in.csv").write_text("\n".join(lines) + "\n")
    out = tmp_path / "out"
    code, _, err = run(
        ["batch", str(tmp_path / "in.csv"), "-o", str(out), "--format", "json,npz", "--references", references], capsys
    )
    assert code == 1 and "line 5: skipped: Br: 'abc'" in err and "line 10: skipped: name: 'F0' is already used" in err
    report = list(csv.DictReader((out / "report.csv").open(encoding="utf-8")))
    assert [int(row["line"]) for row in report] == list(range(2, 12))
    assert [row["status"] for row in report] == ["ok"] * 3 + ["error"] + ["ok"] * 4 + ["error", "ok"]
    files = {"female": out / "mannequins-female.npz", "male": out / "mannequins-male.npz"}
    assert sorted(p.name for p in out.iterdir() if p.suffix != ".json") == sorted(
        [p.name for p in files.values()] + ["made_from", "report.csv"]
    )
    for name, path in files.items():
        expected = [row["name"] for row in report if row["status"] == "ok" and row["references"] == name]
        loaded = load_batch_file(path)
        assert [m.name for m in loaded] == expected
        reference = male if name == "male" else load_reference_set(references)
        for mannequin in loaded:
            alone = synthesize_batch(reference, [[mannequin.measurements[key] for key in MEASUREMENTS]])
            np.testing.assert_array_equal(mannequin.center, alone.center[0])
            np.testing.assert_array_equal(Mannequin.load(out / f"{mannequin.name}.json").semi_axes, mannequin.semi_axes)


def test_the_dask_worker_imports_the_core_only():
    outside_core = "lambda m: m.startswith('ellimann_addon.') and not m.startswith('ellimann_addon.core')"
    assert loaded_by("import ellimann_addon.core.synthesis.batch", outside_core) == "[]"


def test_batch_meets_extra_measurements_as_synth_does_and_reports_each(tmp_path, capsys):
    """A row's extra measurements are met by synth's own core function: the batch's file is synth's bit for bit, the
    batch file holds that mannequin, and the report has requested, measured and error cells for every measurement
    a row asked for; one out of reach is a miss (status, exit code 3, its line), as data."""
    from ellimann_addon.cli import reporting
    from ellimann_addon.core.measurements import EXTRA_MEASUREMENTS

    slim = "148,31.11,84.97,63,83"
    source = tmp_path / "in.csv"
    source.write_text(
        f"name,He,Sh,Br,Wa,Hi,neck,thigh,calf\nslim,{slim},29.68,43.85,\nplain,{slim},,,\nfar,{slim},,,82\n"
    )
    out = tmp_path / "out"
    code, _, err = run(["batch", str(source), "-o", str(out), "--format", "json,npz", "-q"], capsys)
    assert code == 3 and "line 4: warning: exact mode missed calf by" in err, err
    report = list(csv.DictReader((out / "report.csv").open(encoding="utf-8")))
    assert list(report[0]) == reporting.REPORT_COLUMNS
    assert [row["status"] for row in report] == ["ok", "ok", "missed"]
    slim_row, plain_row, far_row = report
    assert (slim_row["neck"], slim_row["thigh"], slim_row["calf"]) == ("29.68", "43.85", "")
    for key in ("neck", "thigh"):
        assert abs(float(slim_row[f"{key}_measured"]) - float(slim_row[key])) <= 0.1
        assert float(slim_row[f"{key}_error_pct"]) == pytest.approx(
            abs(float(slim_row[f"{key}_measured"]) / float(slim_row[key]) - 1) * 100, abs=1e-3
        )
    assert all(plain_row[key] == plain_row[f"{key}_measured"] == "" for key in EXTRA_MEASUREMENTS)
    assert far_row["calf"] == "82" and float(far_row["calf_error_pct"]) > 1 and "missed calf" in far_row["message"]
    code, _, _ = run(
        [
            "synth",
            *("--he 148 --sh 31.11 --br 84.97 --wa 63 --hi 83 --neck 29.68 --thigh 43.85".split()),
            "-o",
            str(tmp_path / "synth.json"),
            "--name",
            "slim",
        ],
        capsys,
    )
    assert code == 0
    synthesized, batched = Mannequin.load(tmp_path / "synth.json"), Mannequin.load(out / "slim.json")
    bundled = load_batch_file(out / "mannequins.npz")[0]
    for key in ("rotation", "center", "semi_axes", "joints"):
        np.testing.assert_array_equal(getattr(batched, key), getattr(synthesized, key))
        np.testing.assert_array_equal(getattr(bundled, key), getattr(synthesized, key))
    code, _, err = run(["batch", str(source), "-o", str(tmp_path / "idw"), "--mode", "idw", "-q"], capsys)
    idw = list(csv.DictReader((tmp_path / "idw" / "report.csv").open(encoding="utf-8")))
    assert code == 0 and [row["status"] for row in idw] == ["ok"] * 3
    assert "met in exact mode only" in idw[0]["message"] and idw[0]["neck_measured"] != ""
