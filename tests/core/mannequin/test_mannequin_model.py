import json

import numpy as np
import pytest

from devkit.toy import TOY_PARTS, make_toy_mannequin
from ellimann_addon.core.errors import MannequinError
from ellimann_addon.core.mannequin.model import Mannequin, stack
from ellimann_addon.core.mannequin.topology import Part, Topology, twin_name
from ellimann_addon.core.measurements import MEASUREMENTS


def problems_of(parts):
    with pytest.raises(MannequinError) as info:
        Topology(parts)
    return [str(p) for p in info.value.problems]


def replace(parts, target, **changes):
    return [Part(**{**p.__dict__, **changes}) if p.name == target else p for p in parts]


def test_toy_topology_is_valid_and_indexed(toy):
    topo = toy.topology
    assert len(topo) == 12
    assert topo.names[topo.twin_indices[topo.index["6.a Thigh.L"]]] == "6.a Thigh.R"
    assert topo.twin_indices[topo.index["1.a Head"]] == topo.index["1.a Head"]
    pairs = {(topo.names[a], topo.names[b]) for a, b in topo.cushion_pairs}
    assert pairs == {("2.a Chest", "2.b Belly"), ("6.a Thigh.L", "6.b Shin.L"), ("6.a Thigh.R", "6.b Shin.R")}
    names = [topo.names[i] for i in topo.single_parts()]
    assert names == ["1.a Head", "3.a Pelvis", "4.a Trapezius.L", "4.a Trapezius.R", "5.a Arm.L", "5.a Arm.R"]
    assert topo.single_parts(cushions=False) == list(range(12))
    assert topo.girth_mask.sum() == 9
    assert topo.dependency_mask.shape == (12, 5)
    assert topo.dependency_mask.tolist() == [[m in p.depends for m in MEASUREMENTS] for p in topo.parts]
    topo.girth_mask[:] = False  # the masks are built once; a caller changing its copy changes nothing
    topo.dependency_mask[:] = False
    assert topo.girth_mask.sum() == 9 and topo.dependency_mask.sum() == sum(len(p.depends) for p in topo.parts)
    assert twin_name("4.a Trapezius.L") == "4.a Trapezius.R"


def test_duplicate_names():
    assert any("used twice" in p for p in problems_of(TOY_PARTS + [TOY_PARTS[0]]))


def test_unpaired_left_right():
    parts = [p for p in TOY_PARTS if p.name != "5.a Arm.R"]
    assert any("'5.a Arm.L'" in p and "no mirror twin" in p for p in problems_of(parts))


def test_missing_or_one_sided_cushion_partner():
    parts = replace(TOY_PARTS, "1.a Head", partner="1.b Face")
    assert any("'1.b Face' does not exist" in p for p in problems_of(parts))
    parts = replace(TOY_PARTS, "3.a Pelvis", partner="1.a Head")
    assert any("does not name it back" in p for p in problems_of(parts))


def test_bad_side_name_and_depends():
    assert any("suffix" in p for p in problems_of(replace(TOY_PARTS, "1.a Head", side="L")))
    assert any("depends" in p for p in problems_of(replace(TOY_PARTS, "1.a Head", depends=("Xx",))))
    assert any("must look like" in p for p in problems_of(replace(TOY_PARTS, "1.a Head", name="Head")))


def test_geometry_problems_name_the_ellipsoid_and_field(toy):
    bad = toy.copy()
    bad.semi_axes[0, 1] = 0.0
    bad.center[1, 2] = np.nan
    bad.rotation[4] = bad.rotation[4] @ np.diag([1.0, 1.0, -1.0])
    bad.rotation[5] = bad.rotation[5] * 1.1
    text = [str(p) for p in bad.problems()]
    assert any("'1.a Head' semi_axes: must be > 0" in t for t in text)
    assert any("'2.a Chest' center: contains NaN" in t for t in text)
    assert any("'4.a Trapezius.L' rotation: is a left-handed frame" in t for t in text)
    assert any("'4.a Trapezius.R' rotation: is not orthonormal" in t for t in text)
    with pytest.raises(MannequinError):
        bad.check()


@pytest.mark.parametrize("attr,index", [("center", (1, 2)), ("semi_axes", (3, 0)), ("rotation", (6, 1, 1))])
@pytest.mark.parametrize("value", [np.inf, -np.inf])
def test_infinite_geometry_names_the_ellipsoid_and_field(toy, attr, index, value):
    bad = toy.copy()
    getattr(bad, attr)[index] = value
    name = toy.topology.names[index[0]]
    text = [str(p) for p in bad.problems()]
    assert f"'{name}' {attr}: contains NaN or infinity" in text
    assert all(t.startswith(f"'{name}' ") for t in text)  # no other part is blamed
    with pytest.raises(MannequinError, match=f"'{name}' {attr}: contains NaN or infinity"):
        bad.check()


def test_infinity_in_a_file_and_in_the_measurements_is_refused(toy):
    data = json.loads(json.dumps(toy.to_dict()))
    data["ellipsoids"][2]["center"][0] = float("inf")  # written as JSON's Infinity
    with pytest.raises(MannequinError, match="'2.b Belly' center: contains NaN or infinity"):
        Mannequin.from_dict(json.loads(json.dumps(data)))
    bad = toy.copy(measurements={"He": float("inf"), "Sh": 40.0})
    assert [str(p) for p in bad.problems()] == [
        "measurements: He=inf is not a positive measurement (accepted range 50-250 cm)"
    ]


@pytest.mark.parametrize("name", ["", None, 7])
def test_an_ellipsoid_without_a_name_is_refused(toy, name):
    data = toy.to_dict()
    if name is None:
        del data["ellipsoids"][4]["name"]
    else:
        data["ellipsoids"][4]["name"] = name
    data["ellipsoids"][7]["side"] = 3
    with pytest.raises(MannequinError) as info:
        Mannequin.from_dict(data)
    # A nameless entry cannot be named, so the problem names the field; the others are still reported.
    assert [str(p) for p in info.value.problems] == [
        "name: every ellipsoid needs a non-empty name",
        "'5.a Arm.R' side: missing or not a str",
    ]
    assert info.value.problems[0].field == "name" and info.value.problems[0].ellipsoid == ""


def test_an_empty_part_name_is_refused_by_the_topology():
    assert problems_of(replace(TOY_PARTS, "1.a Head", name="")) == [
        "name: must look like '10.a Trapezius.L' (number.letter label[.L|.R])"
    ]


def test_json_round_trip_is_exact(toy, tmp_path):
    toy.measurements = {"He": 160.0, "Sh": 40.0, "Br": 90.0, "Wa": 70.0, "Hi": 95.0}
    path = tmp_path / "toy.json"
    toy.save(path)
    back = Mannequin.load(path)
    assert back.topology == toy.topology and back.name == "toy" and back.role == "reference"
    for attr in ("rotation", "center", "semi_axes"):
        assert np.array_equal(getattr(back, attr), getattr(toy, attr))
    assert back.measurements == toy.measurements
    assert list(tmp_path.iterdir()) == [path]  # no temporary file left behind


def test_loading_bad_files(tmp_path, toy):
    broken = tmp_path / "broken.json"
    broken.write_text("{not json")
    with pytest.raises(MannequinError, match="not valid JSON"):
        Mannequin.load(broken)
    data = toy.to_dict()
    data["version"] = 99
    with pytest.raises(MannequinError, match="version"):
        Mannequin.from_dict(data)
    data = toy.to_dict()
    del data["ellipsoids"][3]["semi_axes"]
    with pytest.raises(MannequinError, match="'3.a Pelvis' semi_axes: missing"):
        Mannequin.from_dict(data)
    data = toy.to_dict()
    data["ellipsoids"][0]["semi_axes"][0] = -1
    with pytest.raises(MannequinError, match="'1.a Head' semi_axes"):
        Mannequin.from_dict(json.loads(json.dumps(data)))
    with pytest.raises(MannequinError, match="format"):
        Mannequin.from_dict({"ellipsoids": []})


def test_topology_mismatch_and_reordering(toy):
    other_parts = [p for p in TOY_PARTS if not p.name.startswith("5.a")]
    other = Topology(other_parts)
    text = [str(p) for p in toy.topology.mismatch(other)]
    assert "'5.a Arm.L' topology: is missing from the other mannequin" in text
    reversed_topology = Topology(list(reversed(TOY_PARTS)))
    flipped = toy.reordered(reversed_topology)
    assert np.array_equal(flipped.center[::-1], toy.center)
    r, c, d = stack([toy, flipped])
    assert np.array_equal(r[0], r[1]) and np.array_equal(c[1], toy.center)
    with pytest.raises(MannequinError):
        toy.reordered(other)


def test_measure_returns_centimetres(toy):
    me = toy.measure()
    assert list(me) == ["He", "Sh", "Br", "Wa", "Hi"]
    assert 150 < me["He"] < 170 and all(v > 0 for v in me.values())


def test_fixture_is_symmetric():
    from ellimann_addon.core.mannequin.clean import asymmetry

    assert asymmetry(make_toy_mannequin()) < 1e-12
