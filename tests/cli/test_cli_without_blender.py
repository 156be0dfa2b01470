"""The command line needs numpy only: synth to .json/.xml, batch to json/mjcf, measure of a .json, --skin to
.obj/.json/.xml and every --help run with the bpy module blocked (a meta-path finder refusing it), and never
import ``ellimann_addon.blender``; what needs Blender (.blend/.glb, drape, demo) is refused in one line that says
so."""

import ast
import json
import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest

from devkit import synthetic
from devkit.cli_runs import WITHOUT_BLENDER
from ellimann_addon.core.measurements import EXTRA_MEASUREMENTS

ROOT = pathlib.Path(__file__).resolve().parents[2]
REQUEST = ["--he", "165", "--sh", "41.5", "--br", "101.25", "--wa", "82.75", "--hi", "117.5"]


@pytest.fixture(scope="module")
def references(tmp_path_factory):
    return str(synthetic.write_reference_folder(tmp_path_factory.mktemp("rm")))


def without_blender(*args):
    done = subprocess.run(
        [sys.executable, "-c", WITHOUT_BLENDER, *args], cwd=ROOT, capture_output=True, text=True, timeout=120
    )
    *lines, loaded = done.stderr.strip().splitlines()
    assert loaded == "LOADED []", done.stderr
    return done.returncode, done.stdout, "\n".join(lines)


def test_the_blocker_blocks():
    code = (
        "import sys\n"
        + WITHOUT_BLENDER.split("sys.meta_path.insert(0, NoBlender())")[0]
        + ("sys.meta_path.insert(0, NoBlender())\ntry:\n    import bpy\nexcept ImportError:\n    print('blocked')\n")
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "blocked"


@pytest.mark.parametrize("kind", ["json", "xml"])
def test_synth_and_measure_run_without_blender(tmp_path, references, kind):
    out = tmp_path / f"woman.{kind}"
    code, stdout, stderr = without_blender("synth", *REQUEST, "--cushions", "-o", str(out), "--references", references)
    assert code == 0, stderr
    assert stdout.startswith(f"wrote {out}: 'ElliMann 165-41.5-101.25-82.75-117.5' (exact), m_T He 165.00, ")
    assert out.is_file()
    if kind == "json":
        code, stdout, stderr = without_blender("measure", str(out), "--json")
        assert code == 0 and stderr == ""
        printed = json.loads(stdout)  # the five, then the extra measurements (docs/measurements.md)
        assert list(printed) == ["He", "Sh", "Br", "Wa", "Hi", *EXTRA_MEASUREMENTS]
        assert {key: printed[key] for key in ("He", "Sh", "Br", "Wa", "Hi")} == pytest.approx(
            dict(zip(("He", "Sh", "Br", "Wa", "Hi"), (165, 41.5, 101.25, 82.75, 117.5))), rel=1e-4
        )
        code, stdout, _ = without_blender("measure", str(out))
        assert code == 0 and re.search(r"^  He +Height +165\.00 cm$", stdout, re.M)


def test_batch_to_core_formats_runs_without_blender(tmp_path, references):
    source = tmp_path / "in.csv"
    source.write_text("He,Sh,Br,Wa,Hi,name\n160,40,95,80,105,a\n170,42,100,85,110,b\n", encoding="utf-8")
    code, stdout, stderr = without_blender(
        "batch", str(source), "-o", str(tmp_path / "out"), "--format", "json,mjcf", "--references", references
    )
    assert code == 0, stderr
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [
        "a.json",
        "a.xml",
        "b.json",
        "b.xml",
        "made_from",
        "report.csv",
    ]


def test_posed_core_formats_run_without_blender(tmp_path):
    rest = tmp_path / "rest.json"
    code, _, stderr = without_blender("synth", *REQUEST, "-o", str(rest))
    assert code == 0, stderr
    for pose, out in (("sit", "sit.obj"), ("walk", "walk.xml"), ("t_pose", "t.json")):
        code, stdout, stderr = without_blender(
            "pose", str(rest), "--pose", pose, "--cushions", "-o", str(tmp_path / out)
        )
        assert code == 0, stderr
        assert stdout.startswith(f"wrote {tmp_path / out}: 'ElliMann 165-41.5-101.25-82.75-117.5' in pose {pose}")
    code, _, stderr = without_blender("synth", *REQUEST, "--pose", "attention", "-o", str(tmp_path / "a.obj"))
    assert code == 0, stderr


def test_a_bvh_clip_is_read_retargeted_and_written_without_blender(tmp_path, references):
    """--pose clip.bvh on synth, pose and batch to .json and MJCF: the clip read and retargeted by numpy alone."""
    from devkit import bvh, clips
    from ellimann_addon.core.mannequin.model import Mannequin
    from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER

    joints = Mannequin.load(REFERENCE_FOLDER / "average.json").joints
    clip = str(bvh.write_bvh(tmp_path / "clip.bvh", clips.convention_clip("mixamo", joints, frames=6)))
    for out in ("c.json", "c.xml"):
        code, stdout, stderr = without_blender("synth", *REQUEST, "--pose", clip, "-o", str(tmp_path / out))
        assert code == 0 and "joints placed from 26 bones by Mixamo names" in stderr, stderr
    code, stdout, stderr = without_blender(
        "pose", str(tmp_path / "c.json"), "--pose", clip, "--fps", "60", "-o", str(tmp_path / "p.xml")
    )
    assert code == 0 and stdout.startswith(f"wrote {tmp_path / 'p.xml'}") and "(11 frames)" in stdout, stderr
    source = tmp_path / "in.csv"
    source.write_text("He,Sh,Br,Wa,Hi,name\n160,40,95,80,105,a\n", encoding="utf-8")
    code, _, stderr = without_blender(
        "batch", str(source), "-o", str(tmp_path / "out"), "--format", "json,mjcf", "--pose", clip
    )
    assert code == 0, stderr
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["a.json", "a.xml", "made_from", "report.csv"]


def test_obj_rest_and_posed_are_written_without_blender_standing_in_y_up_axes(tmp_path):
    """One OBJ convention (Y up, -Z forward, as Blender imports it): rest, posed and cushioned files all stand
    with their height along Y and their feet at y = 0."""
    for argv, out in ((["-o"], "rest.obj"), (["--pose", "t_pose", "-o"], "t.obj"), (["--cushions", "-o"], "c.obj")):
        code, _, stderr = without_blender("synth", *REQUEST, *argv, str(tmp_path / out))
        assert code == 0, stderr
        text = (tmp_path / out).read_text()
        assert "Y up, -Z forward" in text.splitlines()[0]
        points = np.array([line.split()[1:] for line in text.splitlines() if line.startswith("v ")], dtype=float)
        extent = np.ptp(points, axis=0)
        assert extent[1] == pytest.approx(1.65, abs=0.01) and extent[1] > 1.5 * extent[2], out  # upright along Y
        assert abs(points[:, 1].min()) < 0.01, out  # feet on the floor y = 0


def test_the_skin_is_made_and_written_to_core_formats_without_blender(tmp_path):
    """--skin on synth (.obj, .json, .xml), pose (rebuilt from the .json's record) and batch: numpy alone."""
    skin = ["--skin", "--skin-level", "preview", "--mode", "idw"]
    for out in ("w.obj", "w.json", "w.xml"):
        code, stdout, stderr = without_blender("synth", *REQUEST, *skin, "-o", str(tmp_path / out))
        assert code == 0 and "(idw, skin 10 mm), skin He " in stdout, stderr
    code, stdout, stderr = without_blender(
        "pose", str(tmp_path / "w.json"), "--pose", "sit", "--skin", "-o", str(tmp_path / "s.obj")
    )
    assert code == 0 and stdout.endswith("with its skin 10 mm\n"), stderr
    source = tmp_path / "in.csv"
    source.write_text("He,Sh,Br,Wa,Hi,name\n160,40,95,80,105,a\n", encoding="utf-8")
    code, _, stderr = without_blender("batch", str(source), "-o", str(tmp_path / "out"), "--format", "obj,mjcf", *skin)
    assert code == 0, stderr
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["a.obj", "a.xml", "made_from", "report.csv"]


@pytest.mark.parametrize(
    "argv",
    [
        ["--help"],
        ["synth", "--help"],
        ["batch", "--help"],
        ["measure", "--help"],
        ["demo", "--help"],
        ["drape", "--help"],
        ["population", "--help"],
        ["pose", "--help"],
    ],
)
def test_help_runs_without_blender(argv):
    code, stdout, _ = without_blender(*argv)
    assert code == 0 and "usage: ellimann" in stdout
    if argv[0] == "drape":
        assert "(default 60, at 24 fps)" in " ".join(stdout.split())


@pytest.mark.parametrize(
    "argv, what",
    [
        (["synth", *REQUEST, "-o", "{tmp}/w.blend"], "writing {tmp}/w.blend"),
        (["synth", *REQUEST, "-o", "{tmp}/w.glb"], "writing {tmp}/w.glb"),
        (["batch", "{tmp}/in.csv", "-o", "{tmp}/out", "--format", "json,blend"], "--format blend"),
        (["measure", "{tmp}/w.blend"], "reading {tmp}/w.blend"),
        (["synth", *REQUEST, "--pose", "walk", "-o", "{tmp}/w.glb"], "writing {tmp}/w.glb"),
        (["drape", "{tmp}/w.json", "-o", "{tmp}/d.blend"], "the cloth simulation"),
        (["demo", "-o", "{tmp}/demo"], "the demo (.blend files and a line-up picture)"),
    ],
)
def test_what_needs_blender_is_refused_in_one_line(tmp_path, argv, what):
    code, stdout, stderr = without_blender(*(a.format(tmp=tmp_path) for a in argv))
    assert code == 1 and stdout == ""
    lines = stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in stderr, stderr
    assert lines[0].startswith(
        f"ellimann {argv[0]}: error: {what.format(tmp=tmp_path)} needs Blender: the bpy module is not installed"
    )
    assert not list(tmp_path.iterdir())


def test_the_cli_imports_blender_only_inside_functions():
    """No module of ellimann_addon/cli imports bpy or the bpy layer at its top level."""
    offenders = []
    for path in (ROOT / "ellimann_addon" / "cli").glob("*.py"):
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                names = [("." * node.level) + (node.module or "")]
            else:
                continue
            offenders += [
                f"{path.name}: {n}"
                for n in names
                if n.split(".")[0] in ("bpy", "bmesh", "mathutils")
                or n.lstrip(".").startswith("blender")
                or n.startswith("ellimann_addon.blender")
            ]
    assert offenders == []


def test_one_table_for_the_options_of_the_cli_and_the_panels():
    from ellimann_addon.cli import build_parser
    from ellimann_addon.core.drape import garments
    from ellimann_addon.core.drape.settings import DrapeSettings
    from ellimann_addon.core.settings import DRAPE
    from ellimann_addon.core.synthesis.options import SYNTHESIS, SynthesisOptions

    assert SynthesisOptions() == SynthesisOptions(**{k: o.default for k, o in SYNTHESIS.items()})
    assert SynthesisOptions().mode == "exact"
    args = build_parser().parse_args(["synth", *REQUEST, "-o", "x.json"])
    assert {k: getattr(args, k) for k in SYNTHESIS} == {k: o.default for k, o in SYNTHESIS.items()}
    assert DRAPE["garment"].values == tuple(garments.BUILDERS)
    defaults = DrapeSettings()
    assert all(getattr(defaults, k) == o.default for k, o in DRAPE.items() if k != "garment")
    with pytest.raises(TypeError):
        SynthesisOptions("exact")  # keyword-only


def test_building_the_parser_loads_no_drape_skin_or_fitting_module():
    """The parser is built from tables on the core's ground floor (core.settings, the format table): what draws,
    skins or fits is loaded when a command runs it, not to print --help."""
    code = (
        "import sys\nfrom ellimann_addon.cli import build_parser\nbuild_parser()\n"
        "print(sorted(m for m in sys.modules if m.split('.')[:3] in (['ellimann_addon', 'core', 'drape'], "
        "['ellimann_addon', 'core', 'skin'], ['ellimann_addon', 'core', 'fitting'])))"
    )
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"
