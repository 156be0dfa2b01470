"""Reference-set folders (manifest, N >= 3, legacy layout) and the selections a traced part records."""

import json

import numpy as np
import pytest

from devkit.synthetic import make_reference_mannequins, write_reference_folder
from devkit.toy import make_toy_mannequin
from ellimann_addon.core.constants import RANGES, SECTION_FRACTIONS
from ellimann_addon.core.errors import MannequinError, ReferenceSetError
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.mannequin.traces import FitSettings, PartTrace, format_runs, parse_runs
from ellimann_addon.core.measurements import ABSURD_LIMITS, MEASUREMENTS
from ellimann_addon.core.synthesis.manifest import (
    MANIFEST_FILE,
    Manifest,
    read_manifest,
    targets_range,
    write_reference_set,
)
from ellimann_addon.core.synthesis.reference_set import REFERENCE_FOLDER, load_reference_set
from ellimann_addon.core.synthesis.synthesize import synthesize_batch


def _trace(count=500, seed=0):
    rng = np.random.default_rng(seed)
    vertices = np.unique(rng.integers(0, count, 120))
    return PartTrace(
        "body",
        count,
        12345,
        vertices,
        FitSettings(margin=0.2, frame="limb", level="Wa", kept=2),
        np.array([3, 4, 5, 9]),
        "enclosing",
    )


def test_runs_round_trip_any_sorted_indices():
    rng = np.random.default_rng(1)
    for _ in range(20):
        indices = np.unique(rng.integers(0, 300, rng.integers(1, 200)))
        assert np.array_equal(parse_runs(format_runs(indices), 300), indices)
    assert format_runs([0, 1, 2, 3, 7, 9, 10]) == "0-3 7 9-10"


@pytest.mark.parametrize("text, why", [("5-3", "within"), ("1 1", "increasing"), ("x", "index"), ("0-600", "within")])
def test_bad_runs_name_the_field(text, why):
    with pytest.raises(MannequinError, match=why):
        parse_runs(text, 500, "7.a Thigh.L", "traces.vertices")


def test_traces_survive_json_save_and_load(tmp_path):
    mannequin = make_toy_mannequin()
    traces = {name: _trace(seed=i) for i, name in enumerate(mannequin.topology.names)}
    path = tmp_path / "base.json"
    mannequin.copy(traces=traces).save(path)
    loaded = Mannequin.load(path)
    assert set(loaded.traces) == set(traces)
    for name, trace in traces.items():
        assert loaded.traces[name].to_dict() == trace.to_dict()
        assert np.array_equal(loaded.traces[name].vertices, trace.vertices)
    assert json.loads(path.read_text())["traces"]["version"] == 1


def test_an_older_file_without_traces_loads_with_none(tmp_path):
    path = tmp_path / "old.json"
    make_toy_mannequin().save(path)
    assert "traces" not in json.loads(path.read_text())
    assert Mannequin.load(path).traces is None


def test_a_trace_for_an_unknown_part_or_a_bad_setting_is_refused():
    data = make_toy_mannequin().copy(traces={"9.z Nothing": _trace()}).to_dict()
    with pytest.raises(MannequinError, match="names no ellipsoid"):
        Mannequin.from_dict(data)
    name = make_toy_mannequin().topology.names[0]
    data = make_toy_mannequin().copy(traces={name: _trace()}).to_dict()
    data["traces"]["parts"][name]["fit"]["frame"] = "sideways"
    with pytest.raises(MannequinError, match="traces.fit.frame"):
        Mannequin.from_dict(data)


def test_a_parts_own_fit_settings_are_written_only_when_set_and_checked():
    plain = FitSettings()
    # written only when set: older files read the same
    assert not {"clearance", "shared", "wall_spacing", "outside_cost"} & set(plain.to_dict())
    own = FitSettings(clearance=0.0125, shared=0.05, wall_spacing=0.01, outside_cost=1.0)
    assert FitSettings.from_dict(own.to_dict(), "1.a Cranium") == own
    for key, value, accepted in (
        ("clearance", 0.3, "0 to 0.2"),
        ("shared", -0.1, "0 to 1"),
        ("shared", True, "0 to 1"),
        ("wall_spacing", 0.0, "0.001 to 0.1"),
        ("wall_spacing", float("nan"), "0.001 to 0.1"),
        ("outside_cost", -1.0, "0 to 10"),
        ("outside_cost", "1", "0 to 10"),
    ):
        with pytest.raises(MannequinError, match=f"traces.fit.{key}: must be null or a number from {accepted}"):
            FitSettings.from_dict({key: value}, "1.a Cranium")


def test_a_parts_own_clearance_replaces_the_fits_in_its_section_bounds():
    from ellimann_addon.core.fitting.mannequin_fit import FitConstants, section_bounds

    constants = FitConstants()
    part = next(p for p in make_toy_mannequin().topology if p.girth and "Wa" not in p.depends and "Br" in p.depends)
    centre = constants.section_fractions["Wa"] + 0.05  # above the waist it does not follow
    floor, _ = section_bounds(part, FitSettings(), centre, constants)
    assert floor == pytest.approx(constants.section_fractions["Wa"] + constants.section_clearance)
    floor, _ = section_bounds(part, FitSettings(clearance=0.01), centre, constants)
    assert floor == pytest.approx(constants.section_fractions["Wa"] + 0.01)


def _write_set(folder, mannequins, **fields):
    targets = {m.name: dict(m.measurements) for m in mannequins}
    manifest = Manifest(
        name="three", mannequins=list(targets), targets_cm=targets, ranges_cm=targets_range(targets), **fields
    )
    write_reference_set(folder, {m.name: m for m in mannequins}, manifest)
    return manifest


@pytest.mark.parametrize("count", [3, 4])
def test_a_manifest_set_of_n_loads_and_idw_is_exact_at_its_own_references(tmp_path, count):
    mannequins = make_reference_mannequins()[:count]
    _write_set(tmp_path, mannequins, sex="female")
    reference = load_reference_set(tmp_path)
    assert len(reference) == count and reference.name == "three"
    assert reference.names == [m.name for m in mannequins]
    for key in MEASUREMENTS:
        column = reference.measurements[:, MEASUREMENTS.index(key)]
        assert reference.ranges[key] == (column.min(), column.max())
    for metric in ("raw", "normalized"):
        batch = synthesize_batch(reference, reference.measurements, mode="idw", metric=metric)
        assert np.allclose(batch.center, reference.center, atol=1e-12)
        assert np.allclose(batch.semi_axes, reference.semi_axes, atol=1e-12)


def test_exact_mode_on_three_references_meets_a_request_between_them(tmp_path):
    mannequins = make_reference_mannequins()[:3]
    _write_set(tmp_path, mannequins)
    reference = load_reference_set(tmp_path)
    request = reference.measurements.mean(axis=0)
    batch = synthesize_batch(reference, [request], mode="exact")
    assert batch.converged[0]
    assert np.allclose(batch.measured[0], request, rtol=1e-5)


def test_without_a_manifest_a_folder_is_the_legacy_five_with_todays_constants(tmp_path):
    write_reference_folder(tmp_path)
    assert read_manifest(tmp_path) is None
    reference = load_reference_set(tmp_path)
    assert len(reference) == 5
    assert reference.section_fractions == SECTION_FRACTIONS
    assert reference.ranges == RANGES and reference.absurd_limits == ABSURD_LIMITS


def test_the_shipped_set_has_a_manifest_with_todays_constants():
    manifest = read_manifest(REFERENCE_FOLDER)
    reference = load_reference_set()
    assert manifest is not None and manifest.base == "base_mannequin" and manifest.sex == "female"
    assert reference.section_fractions == SECTION_FRACTIONS
    assert reference.ranges == RANGES and reference.absurd_limits == ABSURD_LIMITS


@pytest.mark.parametrize(
    "change, field",
    [
        (lambda d: d.update(mannequins=d["mannequins"][:2]), "mannequins"),
        (lambda d: d.update(version=99), "version"),
        (lambda d: d["section_fractions"].pop("Wa"), "section_fractions"),
        (lambda d: d["ranges_cm"].update(He=[200.0, 100.0]), "ranges_cm"),
        (lambda d: d.update(mannequins=["../escape", "b", "c"]), "mannequins"),
        (lambda d: d.update(sex="other"), "sex"),
    ],
)
def test_a_broken_manifest_is_refused_naming_the_field(tmp_path, change, field):
    _write_set(tmp_path, make_reference_mannequins()[:3])
    data = json.loads((tmp_path / MANIFEST_FILE).read_text())
    change(data)
    (tmp_path / MANIFEST_FILE).write_text(json.dumps(data))
    with pytest.raises(ReferenceSetError, match=field):
        load_reference_set(tmp_path)


def test_a_manifest_naming_a_missing_file_says_which(tmp_path):
    mannequins = make_reference_mannequins()[:3]
    _write_set(tmp_path, mannequins)
    (tmp_path / f"{mannequins[1].name}.json").unlink()
    with pytest.raises(ReferenceSetError, match=f"{mannequins[1].name}.json: file is missing"):
        load_reference_set(tmp_path)
