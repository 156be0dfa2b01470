"""What a careless or hostile user can put in a mannequin file: every bad file is one MannequinError naming
the file or the field (and the accepted type or range), never another exception."""

import copy
import json
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from devkit import synthetic
from devkit.poses import make_apose_toy
from devkit.toy import make_toy_mannequin
from ellimann_addon.core.constants import CENTER_LIMIT, SEMI_AXIS_LIMITS
from ellimann_addon.core.drape import garments
from ellimann_addon.core.errors import ElliMannError, MannequinError, ReferenceSetError
from ellimann_addon.core.mannequin.model import FORMAT_VERSION, Mannequin
from ellimann_addon.core.measurements import ABSURD_LIMITS, MEASUREMENTS
from ellimann_addon.core.synthesis import synthesize as synthesis
from ellimann_addon.core.synthesis.manifest import MANIFEST_FILE

TOY = make_toy_mannequin()
TOY.measurements = {"He": 160.0, "Sh": 40.0, "Br": 90.0, "Wa": 70.0, "Hi": 95.0}
GOOD = json.loads(TOY.to_json())


def edited(change):
    data = copy.deepcopy(GOOD)
    change(data)
    return data


def refused(data, *words):
    """The MannequinError of from_dict(data), checked to name every word; returns its message."""
    with pytest.raises(MannequinError) as info:
        Mannequin.from_dict(data)
    text = str(info.value)
    assert "\n" not in text
    for word in words:
        assert word in text, text
    return text


def write(tmp_path, content, name="m.json"):
    path = tmp_path / name
    path.write_bytes(content if isinstance(content, bytes) else content.encode("utf-8"))
    return path


# ------------------------------------------------------------------------------------------------ measurements_cm


@pytest.mark.parametrize(
    "value, kind", [([1, 2], "a list"), ("tall", "a string"), (160, "a number"), (True, "a boolean")]
)
def test_measurements_that_are_not_an_object_are_refused(value, kind):
    # Before: AttributeError: 'list' object has no attribute 'items' (measure, drape, --references).
    refused(edited(lambda d: d.update(measurements_cm=value)), "measurements_cm", "must be an object", kind)


def test_measurements_that_are_not_a_dict_are_refused_in_python_too():
    for value, kind in (([1, 2], "list"), ("tall", "string")):
        mannequin = Mannequin(TOY.topology, TOY.rotation, TOY.center, TOY.semi_axes, measurements=value)
        assert [str(p) for p in mannequin.problems()] == [
            f"measurements: must be a dict of He, Sh, Br, Wa, Hi in cm (or None), got a {kind}"
        ]


@pytest.mark.parametrize(
    "values, words",
    [
        ({"He": "tall"}, ["He='tall' is not a positive measurement", "accepted range 50-250 cm"]),
        ({"He": 1000}, ["He=1000 cm is not a plausible value", "accepted range 50-250 cm"]),
        ({"Sh": 5}, ["Sh=5 cm", "accepted range 10-100 cm"]),
        ({"He": 10**400}, ["He=", "is not a positive measurement"]),
        ({"He": [160]}, ["He=[160] is not a positive measurement"]),
        ({"Xx": 3}, ["'Xx' is not a measurement", "He, Sh, Br, Wa, Hi"]),
    ],
)
def test_measurement_values_name_the_key_and_the_accepted_range(values, words):
    refused(edited(lambda d: d.update(measurements_cm=values)), "measurements:", *words)


def _with_measurement(key, value):
    return edited(lambda d: d["measurements_cm"].update({key: value}))


def test_the_measurement_limits_are_those_of_a_request():
    for key, (low, high) in ABSURD_LIMITS.items():
        for value in (low, high):
            assert Mannequin.from_dict(_with_measurement(key, value)).measurements[key] == value
        for value in (low * 0.99, high * 1.01):
            refused(_with_measurement(key, value), key, f"{low:g}-{high:g} cm")


# ------------------------------------------------------------------------------------------------ the file


@pytest.mark.parametrize(
    "encoding, words",
    [
        ("utf-16", ["UTF-16"]),
        ("utf-16-le", ["UTF-16"]),
        ("utf-16-be", ["UTF-16"]),
        ("utf-32", ["UTF-32"]),
        ("latin-1", ["not UTF-8", "byte"]),
    ],
)
def test_a_file_not_in_utf8_is_named(tmp_path, encoding, words):
    text = json.dumps(dict(GOOD, name="Zoë"), ensure_ascii=False)  # the ë makes latin-1 differ from UTF-8
    path = write(tmp_path, text.encode(encoding))
    with pytest.raises(MannequinError) as info:
        Mannequin.load(path)
    assert str(path) in str(info.value) and "UTF-8" in str(info.value)
    for word in words:
        assert word in str(info.value)


@pytest.mark.parametrize("depth", [10_000, 100_000])
def test_deeply_nested_json_is_refused(tmp_path, depth):
    for text in (
        "[" * depth + "]" * depth,
        '{"a":' * depth + "1" + "}" * depth,
        json.dumps(GOOD)[:-1] + ', "extra": ' + "[" * depth + "]" * depth + "}",
    ):
        with pytest.raises(MannequinError, match="nested too deeply"):
            Mannequin.load(write(tmp_path, text))


@pytest.mark.parametrize(
    "text, words",
    [
        ("", ["not valid JSON"]),
        ("{not json", ["not valid JSON"]),
        ("1" * 5000, ["not valid JSON"]),  # an integer too long to convert: ValueError, not JSONDecodeError
        ("[1, 2]", ["holds a list", "not an ElliMann mannequin"]),
        ('"text"', ["holds a string"]),
        ("null", ["holds null"]),
        ("3.5", ["holds a number"]),
    ],
)
def test_a_file_that_is_not_a_mannequin_object(tmp_path, text, words):
    with pytest.raises(MannequinError) as info:
        Mannequin.load(write(tmp_path, text))
    for word in words:
        assert word in str(info.value)


@pytest.mark.parametrize(
    "change, words",
    [
        (lambda d: d.update(version=True), ["version", f"reads versions 1 to {FORMAT_VERSION}"]),
        (lambda d: d.update(version=0), ["version"]),
        (lambda d: d.update(version="1"), ["version"]),
        (lambda d: d.update(units="cm"), ["units", "metres"]),
        (lambda d: d.update(name=["x"]), ["name: must be a string, got a list"]),
        (lambda d: d.update(role=3), ["role: must be one of base, reference, synthesized, got a number"]),
        (lambda d: d.update(role="hero"), ["role: is 'hero'"]),
        (lambda d: d.update(ellipsoids={"1.a Head": {}}), ["ellipsoids: must be a non-empty list", "got an object"]),
        (lambda d: d.update(ellipsoids="none"), ["ellipsoids", "got a string"]),
        (lambda d: d.update(ellipsoids=[]), ["ellipsoids", "it is empty"]),
        (lambda d: d.pop("ellipsoids"), ["ellipsoids", "it is missing"]),
        (lambda d: d["ellipsoids"].__setitem__(3, [1, 2, 3]), ["ellipsoids[3]: must be an object", "got a list"]),
        (lambda d: d["ellipsoids"].append(None), ["ellipsoids[12]: must be an object", "got null"]),
        (lambda d: d["ellipsoids"][2].pop("region"), ["'2.b Belly' region: missing or not a str"]),
        (lambda d: d["ellipsoids"][2].update(girth="yes"), ["'2.b Belly' girth: missing or not a bool"]),
        (lambda d: d["ellipsoids"][6].update(depends=["He", 1]), ["'5.a Arm.L' depends: must list measurement names"]),
        (lambda d: d["ellipsoids"][6].update(depends=[["He"]]), ["'5.a Arm.L' depends"]),
        (lambda d: d["ellipsoids"][6].update(depends="He"), ["'5.a Arm.L' depends: missing or not a list"]),
        (lambda d: d["ellipsoids"][0].update(center="abc"), ["'1.a Head' center: missing or not a 3 array"]),
        (lambda d: d["ellipsoids"][0].update(center=[10**400, 0, 0]), ["'1.a Head' center: missing or not a 3"]),
        (lambda d: d["ellipsoids"][0].update(axes=[[1, 0], [0, 1]]), ["'1.a Head' axes: missing or not a 3x3"]),
        (lambda d: d["ellipsoids"][0].update(semi_axes={"a": 1}), ["'1.a Head' semi_axes: missing or not a 3"]),
        (lambda d: d["ellipsoids"].append(copy.deepcopy(d["ellipsoids"][0])), ["'1.a Head' name: is used twice"]),
    ],
)
def test_malformed_structures_name_the_field(change, words):
    refused(edited(change), *words)


# ------------------------------------------------------------------------------------------------ plausibility


@pytest.mark.parametrize("value", [1e300, 3.01, 1e-300, 9.9e-6])
def test_implausible_semi_axes_name_the_part_and_the_range(value):
    low, high = SEMI_AXIS_LIMITS
    text = refused(
        edited(lambda d: d["ellipsoids"][3]["semi_axes"].__setitem__(1, value)),
        "'3.a Pelvis' semi_axes:",
        f"{value:g} m",
        f"accepted range {low:g} to {high:g} m",
    )
    assert text.count("(and") == 0  # only that part is blamed


@pytest.mark.parametrize("value", [1e308, -1e308, 100.5, -250.0])
def test_implausible_centres_name_the_part_and_the_range(value):
    refused(
        edited(lambda d: d["ellipsoids"][5]["center"].__setitem__(2, value)),
        "'4.a Trapezius.R' center:",
        f"z = {value:g} m",
        f"accepted range {-CENTER_LIMIT:g} to {CENTER_LIMIT:g} m",
    )


def test_the_limits_themselves_are_accepted():
    low, high = SEMI_AXIS_LIMITS
    data = edited(
        lambda d: d["ellipsoids"][3].update(semi_axes=[low, high, 0.1], center=[CENTER_LIMIT, 0.0, -CENTER_LIMIT])
    )
    assert Mannequin.from_dict(data).semi_axes[3].tolist() == [low, high, 0.1]


def test_the_limits_apply_to_mannequins_made_in_python(toy):
    bad = toy.copy()
    bad.semi_axes[0, 0] = 1e300
    bad.center[1, 0] = 1e6
    assert [str(p) for p in bad.problems()] == [
        "'1.a Head' semi_axes: 1e+300 m is not a plausible semi-axis (accepted range 1e-05 to 3 m)",
        "'2.a Chest' center: x = 1e+06 m is too far from the origin (accepted range -100 to 100 m)",
    ]


def test_every_shipped_mannequin_is_plausible():
    import pathlib

    folder = pathlib.Path(synthesis.REFERENCE_FOLDER)
    for path in sorted(folder.glob("*.json")):
        if path.name == MANIFEST_FILE:  # the set's manifest, not a mannequin
            continue
        mannequin = Mannequin.load(path)
        # An order of magnitude or more inside the limits.
        low, high = SEMI_AXIS_LIMITS
        assert mannequin.semi_axes.min() > 100 * low and mannequin.semi_axes.max() < high / 10
        assert np.abs(mannequin.center).max() < CENTER_LIMIT / 10


def test_synthesis_output_is_checked_against_the_same_limits():
    reference = synthetic.make_reference_set()
    result = synthesis.synthesize_batch(reference, reference.measurements[:2], mode="idw")
    synthesis.check_plausible(reference.topology, result.requests, result.rotation, result.center, result.semi_axes)
    center = result.center.copy()
    center[1, 4, 0] = 1e5
    with pytest.raises(ElliMannError, match=r"synthesis at He \S+, .* implausible mannequin: .*center: x = 100000 m"):
        synthesis.check_plausible(reference.topology, result.requests, result.rotation, center, result.semi_axes)
    semi = result.semi_axes.copy()
    semi[0, 2, 1] = np.inf
    with pytest.raises(ElliMannError, match="semi_axes: contains NaN or infinity"):
        synthesis.check_plausible(reference.topology, result.requests, result.rotation, result.center, semi)


@pytest.mark.parametrize(
    "field, index, value, words",
    [
        ("semi_axes", (2, 3, 0), np.nan, "semi_axes: contains NaN or infinity"),
        ("semi_axes", (1, 0, 2), 1e-9, "semi_axes: 1e-09 m is not a plausible semi-axis"),
        ("semi_axes", (3, 5, 1), 4.0, "semi_axes: 4 m is not a plausible semi-axis"),
        ("semi_axes", (0, 1, 0), -1.0, "semi_axes: must be > 0"),
        ("center", (2, 0, 2), np.nan, "center: contains NaN or infinity"),
        ("center", (4, 3, 1), -np.inf, "center: contains NaN or infinity"),
        ("center", (0, 2, 2), -101.0, "center: z = -101 m is too far from the origin"),
        ("rotation", (1, 2, 0, 1), np.nan, "rotation: contains NaN or infinity"),
        ("rotation", (3, 0, 2, 2), np.inf, "rotation: contains NaN or infinity"),
    ],
)
def test_every_kind_of_implausible_result_is_refused_at_its_request(field, index, value, words):
    reference = synthetic.make_reference_set()
    result = synthesis.synthesize_batch(reference, reference.measurements, mode="idw")
    arrays = {name: getattr(result, name).copy() for name in ("rotation", "center", "semi_axes")}
    arrays[field][index] = value
    request = ", ".join(f"{k} {v:g}" for k, v in zip(MEASUREMENTS, reference.measurements[index[0]]))
    with pytest.raises(ElliMannError) as info:
        synthesis.check_plausible(reference.topology, result.requests, **arrays)
    assert str(info.value).startswith(f"synthesis at {request} cm gives an implausible mannequin: ")
    assert words in str(info.value)
    arrays[field][index] = getattr(result, field)[index]
    synthesis.check_plausible(reference.topology, result.requests, **arrays)  # the rest was plausible


# ------------------------------------------------------------------------------------------------ reference sets


@pytest.fixture
def folder(tmp_path):
    return synthetic.write_reference_folder(tmp_path / "rm")


def test_references_that_name_a_file_say_so(folder):
    path = folder / "average.json"
    with pytest.raises(ReferenceSetError, match=r"average\.json: path is a file, not a folder"):
        synthesis.load_reference_set(path)
    with pytest.raises(ReferenceSetError, match="folder does not exist"):
        synthesis.load_reference_set(folder / "nothing")


@pytest.mark.parametrize("value, kind", [([159, 43, 117, 104, 117], "a list"), ("average", "a string")])
def test_a_reference_file_with_bad_measurements_is_named(folder, value, kind):
    path = folder / "average.json"
    data = json.loads(path.read_text())
    data["measurements_cm"] = value
    path.write_text(json.dumps(data))
    with pytest.raises(ReferenceSetError, match=rf"average\.json: file cannot be read: measurements_cm: .*got {kind}"):
        synthesis.load_reference_set(folder)


def test_a_reference_file_in_utf16_is_named(folder):
    path = folder / "tall_slim.json"
    path.write_bytes(path.read_text().encode("utf-16"))
    with pytest.raises(ReferenceSetError, match=r"tall_slim\.json: file cannot be read: .*UTF-16"):
        synthesis.load_reference_set(folder)


# ------------------------------------------------------------------------------------------------ garbage


JSON = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-(10**30), 10**30)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4),
    max_leaves=12,
)


def _paths(value, prefix=()):
    yield prefix
    if isinstance(value, dict):
        for key, item in value.items():
            yield from _paths(item, prefix + (key,))
    elif isinstance(value, list):
        for index, item in enumerate(value):
            yield from _paths(item, prefix + (index,))


PATHS = list(_paths(GOOD))


def _replace(data, path, value):
    if not path:
        return value
    data = copy.deepcopy(data)
    target = data
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    return data


def _loads_or_refuses(data):
    """from_dict(data) returns a valid mannequin with finite m_T, or raises MannequinError; nothing else."""
    try:
        mannequin = Mannequin.from_dict(data)
    except MannequinError as error:
        assert str(error) and "\n" not in str(error)
        return
    assert mannequin.problems() == []
    assert all(math.isfinite(v) for v in mannequin.measure().values())


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(path=st.sampled_from(PATHS), value=JSON)
@example(path=("ellipsoids", 6, "name"), value="\n")  # once gave a two-line message
def test_garbage_anywhere_in_a_mannequin_never_raises_anything_else(path, value):
    _loads_or_refuses(_replace(GOOD, path, value))


@settings(max_examples=200, deadline=None)
@given(
    path=st.sampled_from(
        [
            p
            for p in PATHS
            if len(p) >= 3 and p[0] == "ellipsoids" and p[2] in ("center", "semi_axes", "axes") and len(p) >= 4
        ]
    ),
    value=st.floats(allow_nan=True, allow_infinity=True) | st.integers(-(10**400), 10**400),
)
def test_any_number_in_the_geometry_is_accepted_only_if_plausible(path, value):
    _loads_or_refuses(_replace(GOOD, path, value))


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    content=st.binary(max_size=200)
    | st.text(max_size=200).map(lambda t: t.encode("utf-8"))
    | JSON.map(lambda v: json.dumps(v).encode("utf-16"))
)
def test_garbage_bytes_never_raise_anything_else(tmp_path, content):
    path = tmp_path / "garbage.json"
    path.write_bytes(content)
    with pytest.raises(MannequinError):
        Mannequin.load(path)


# ------------------------------------------------------------------------------------------------ the skin section

SKIN_RECORD = {"version": 1, "voxel_mm": 5.0, "blend": 0.6, "method": "how it was made"}
WITH_SKIN = {**GOOD, "skin": SKIN_RECORD}


@pytest.mark.parametrize(
    "skin, words",
    [
        ([], ["skin: must be an object (version, voxel_mm, blend, method) or absent, got a list"]),
        ({**SKIN_RECORD, "version": 3}, ["skin.version: is 3; this ElliMann reads skin versions 1 and 2"]),
        ({**SKIN_RECORD, "version": 2}, ['skin.kind: must be "body" in version 2, got None']),
        ({"version": 2, "kind": "body", "method": "m", "request": {"He": "tall"}}, ["skin.request: must be an object"]),
        ({"version": 2, "kind": "body", "method": "m", "request": {"waist": 70}}, ["skin.request: must be an object"]),
        ({**SKIN_RECORD, "version": True}, ["skin.version"]),
        ({k: v for k, v in SKIN_RECORD.items() if k != "version"}, ["skin.version: is None"]),
        ({**SKIN_RECORD, "voxel_mm": "5"}, ["skin.voxel_mm: must be a number from 1 to 40, got '5'"]),
        ({**SKIN_RECORD, "voxel_mm": 0.5}, ["skin.voxel_mm: is 0.5; accepted range 1 to 40"]),
        ({**SKIN_RECORD, "voxel_mm": float("nan")}, ["skin.voxel_mm: must be a number"]),
        ({**SKIN_RECORD, "blend": -1}, ["skin.blend: is -1; accepted range 0 to 3"]),
        ({**SKIN_RECORD, "blend": None}, ["skin.blend: must be a number from 0 to 3"]),
        ({**SKIN_RECORD, "method": 3}, ["skin.method: must be a string"]),
        ({**SKIN_RECORD, "colour": "pink"}, ["skin.'colour': is not a field of the skin section"]),
    ],
)
def test_a_bad_skin_section_names_its_field(skin, words):
    refused({**GOOD, "skin": skin}, *words)


def test_a_skin_section_round_trips_and_is_checked_in_python_too():
    mannequin = Mannequin.from_dict(WITH_SKIN)
    assert mannequin.skin == SKIN_RECORD and Mannequin.from_dict(mannequin.to_dict()).skin == SKIN_RECORD
    assert "skin" not in TOY.to_dict()  # no skin made: no section
    problems = mannequin.copy(skin={**SKIN_RECORD, "blend": 9}).problems()
    assert [(p.field, p.message) for p in problems] == [("skin.blend", "is 9; accepted range 0 to 3")]


@settings(max_examples=100, deadline=None)
@given(path=st.sampled_from([("skin", key) for key in SKIN_RECORD] + [("skin",)]), value=st.deferred(lambda: JSON))
def test_garbage_in_the_skin_section_never_raises_anything_else(path, value):
    _loads_or_refuses(_replace(WITH_SKIN, path, value))


# ------------------------------------------------------------------------------------------------ cloth size


@pytest.mark.parametrize("kind", list(garments.BUILDERS))
@pytest.mark.parametrize("edge", [0.05, 0.03, 0.02])
def test_the_cloth_estimate_is_close_to_the_garment_built(kind, edge):
    body = make_apose_toy()
    built = len(garments.make_garment(body, kind, edge=edge).vertices)
    estimate = garments.estimate_vertices(body, kind, edge)
    assert built * 0.95 <= estimate <= built * 1.5, (estimate, built)


def test_the_cloth_estimate_grows_with_one_over_edge_squared_and_checks_its_input():
    body = make_apose_toy()
    coarse, fine = (garments.estimate_vertices(body, "tube_dress", edge) for edge in (0.02, 0.002))
    assert 80 <= fine / coarse <= 110
    with pytest.raises(ElliMannError, match="edge: must be a number from 0.002 to 0.2"):
        garments.estimate_vertices(body, "tube_dress", 0.001)
    with pytest.raises(ElliMannError, match="garment: must be one of"):
        garments.estimate_vertices(body, "cape", 0.02)
