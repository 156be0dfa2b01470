"""MJCF export: the file loads in MuJoCo, its geoms are the mannequin's pieces, and things land on it."""

import pathlib
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from devkit.toy import make_toy_mannequin
from ellimann_addon.core.constants import MJCF_CUSHION_LEVEL
from ellimann_addon.core.drape.fit_metrics import BodyPieces
from ellimann_addon.core.errors import ElliMannError, MannequinError
from ellimann_addon.core.formats.mjcf import mannequin_to_mjcf, write_mjcf
from ellimann_addon.core.geometry import mesh
from ellimann_addon.core.geometry.cushion import cushion_mesh, cushion_name
from ellimann_addon.core.geometry.ellipsoid import bounds, contains
from ellimann_addon.core.mannequin.model import Mannequin
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.manifest import MANIFEST_FILE

mujoco = pytest.importorskip("mujoco")  # a dev dependency (requirements-dev.txt); CI always has it

REFERENCE_DIR = pathlib.Path(__file__).resolve().parents[3] / "reference_blends"
DENSITY = 1000.0  # MuJoCo's default geom density: body mass / DENSITY is the piece's volume


def mannequins(only=None):
    """The toy, plus the shipped reference mannequins once reference_blends/ has them (or just ``only``)."""
    out = [pytest.param(make_toy_mannequin, id="toy")]
    for path in sorted(REFERENCE_DIR.glob("*.json")):
        if path.name == MANIFEST_FILE:  # the set's manifest, not a mannequin
            continue
        if only is None or path.stem == only:
            out.append(pytest.param(lambda p=path: Mannequin.load(p), id=path.stem))
    return out


def load(text):
    model = mujoco.MjModel.from_xml_string(text)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def geom_type(name):
    return int(getattr(mujoco.mjtGeom, f"mjGEOM_{name.upper()}"))


@pytest.mark.parametrize("make", mannequins())
def test_ellipsoids_become_native_ellipsoid_geoms_in_place(make):
    mannequin = make()
    model, data = load(mannequin_to_mjcf(mannequin))
    assert model.ngeom == len(mannequin) + 1  # + floor
    assert model.nv == 0  # static: no joints
    for i, name in enumerate(mannequin.topology.names):
        g = model.geom(name)
        assert g.type[0] == geom_type("ellipsoid")
        assert np.allclose(g.size, mannequin.semi_axes[i], rtol=1e-8)
        assert np.allclose(data.geom_xpos[g.id], mannequin.center[i], atol=1e-8)
        assert np.allclose(data.geom_xmat[g.id].reshape(3, 3), mannequin.rotation[i], atol=1e-8)
        assert model.body(name).id == model.geom_bodyid[g.id]
    assert model.geom("floor").type[0] == geom_type("plane")


@pytest.mark.parametrize("make", mannequins())
def test_cushions_become_convex_mesh_geoms_of_the_right_volume(make):
    mannequin = make()
    topology = mannequin.topology
    model, data = load(mannequin_to_mjcf(mannequin, cushions=True))
    pairs = topology.cushion_pairs
    assert pairs, "the test needs cushion pairs"
    assert model.ngeom == len(mannequin) - len(pairs) + 1
    assert model.nmesh == len(pairs)
    rng = np.random.default_rng(0)
    directions = rng.normal(size=(200, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    for first, second in pairs:
        label = cushion_name(topology.names[first], topology.names[second])
        g = model.geom(label)
        assert g.type[0] == geom_type("mesh")
        body = model.body(label)
        assert np.allclose(data.xpos[body.id], mannequin.center[first], atol=1e-8)
        assert np.allclose(data.xmat[body.id].reshape(3, 3), mannequin.rotation[first], atol=1e-8)
        frames = [(mannequin.rotation[i], mannequin.center[i], mannequin.semi_axes[i]) for i in (first, second)]
        vertices, faces = cushion_mesh(*frames, subdivisions=MJCF_CUSHION_LEVEL)
        # MuJoCo's own mass properties of the mesh: its volume is the core's (float32 vertices).
        assert model.body_mass[body.id] / DENSITY == pytest.approx(mesh.volume(vertices, faces), rel=1e-4)
        # MuJoCo keeps the mesh in its inertial frame; placed by the geom pose it is the cushion.
        start, count = model.mesh_vertadr[g.dataid[0]], model.mesh_vertnum[g.dataid[0]]
        local = model.mesh_vert[start : start + count].astype(float)
        world = local @ data.geom_xmat[g.id].reshape(3, 3).T + data.geom_xpos[g.id]
        assert np.allclose((world @ directions.T).max(axis=0), (vertices @ directions.T).max(axis=0), atol=2e-6)
    for i in set(range(len(mannequin))) - {i for pair in pairs for i in pair}:
        assert model.geom(topology.names[i]).type[0] == geom_type("ellipsoid")


def test_measurements_and_names_are_stored(toy):
    toy.measurements = {"He": 161.0, "Sh": 40.0, "Br": 86.0, "Wa": 70.0, "Hi": 88.0}
    text = mannequin_to_mjcf(toy)
    model, _ = load(text)
    measured = toy.measure()
    for key in MEASUREMENTS:
        assert model.numeric(f"measured_{key}").data[0] == pytest.approx(measured[key], rel=1e-8)
        assert model.numeric(f"target_{key}").data[0] == pytest.approx(toy.measurements[key])
    assert ET.fromstring(text).find("custom/text[@name='ellimann_name']").get("data") == "toy"
    body_names = {model.body(i).name for i in range(model.nbody)}
    assert set(toy.topology.names) <= body_names
    # No target: only the measured fields.
    toy.measurements = None
    model, _ = load(mannequin_to_mjcf(toy))
    names = {model.numeric(i).name for i in range(model.nnumeric)}
    assert names == {f"measured_{k}" for k in MEASUREMENTS}


def test_names_need_no_sanitising_and_comments_stay_valid(toy):
    toy.name = 'Tall -- "chubby" <&>'
    model, _ = load(mannequin_to_mjcf(toy))
    assert _text(model, "ellimann_name") == 'Tall -- "chubby" <&>'


def _text(model, name):
    i = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TEXT, name)
    start = model.text_adr[i]
    return bytes(model.text_data[start : start + model.text_size[i] - 1]).decode()


def test_write_is_atomic_and_bad_input_writes_nothing(toy, tmp_path):
    path = tmp_path / "out" / "toy.xml"
    assert write_mjcf(toy, path, cushions=True) == path
    model = mujoco.MjModel.from_xml_path(str(path))
    assert model.nmesh == len(toy.topology.cushion_pairs)
    assert [p.name for p in path.parent.iterdir()] == ["toy.xml"]  # no temporary left behind

    bad = toy.copy()
    bad.semi_axes[3, 1] = -0.1
    with pytest.raises(MannequinError, match="3.a Pelvis"):
        write_mjcf(bad, tmp_path / "bad.xml")
    for level in (0, 7, 2.0, True):
        with pytest.raises(ElliMannError, match=f"subdivisions: must be an integer from 1 to 6, got {level!r}"):
            write_mjcf(toy, tmp_path / "bad.xml", cushions=True, subdivisions=level)
    with pytest.raises(ElliMannError, match="timestep"):
        write_mjcf(toy, tmp_path / "bad.xml", timestep=-1)
    assert not (tmp_path / "bad.xml").exists()


BALL_RADIUS = 0.02
SETTLE_SECONDS = 3.0
CHECK_EVERY = 10  # steps between penetration checks along the fall
SAMPLES_PER_QUERY = 12  # checks measured in one distance query (some 2000 centres: a few MB per piece mesh)
# Distances beyond it are only known to be beyond it: a centre that far (a ball's diameter) is clear of the body by
# more than the radius, all the checks below need; nearer ones are exact.
CUTOFF = 2 * BALL_RADIUS


def drop_balls(mannequin, cushions):
    """Drop a grid of small free spheres onto the exported mannequin; return what happened."""
    root = ET.fromstring(mannequin_to_mjcf(mannequin, cushions=cushions))
    world = root.find("worldbody")
    lo, hi = bounds(mannequin.rotation, mannequin.center, mannequin.semi_axes)
    lo, hi = lo.min(axis=0), hi.max(axis=0)
    spacing = 0.05
    names = []
    for i, x in enumerate(np.arange(lo[0] - 0.03, hi[0] + 0.03, spacing)):
        for j, y in enumerate(np.arange(lo[1] - 0.03, hi[1] + 0.03, spacing)):
            name = f"ball {len(names)}"
            z = hi[2] + 0.05 + 0.03 * ((i + j) % 3)  # staggered so neighbours do not land together
            body = ET.SubElement(world, "body", name=name, pos=f"{x} {y} {z}")
            ET.SubElement(body, "freejoint")
            # Rolling friction lets balls settle on slopes instead of rolling forever.
            ET.SubElement(
                body,
                "geom",
                name=name,
                type="sphere",
                size=str(BALL_RADIUS),
                mass="0.05",
                condim="6",
                friction="1.5 0.05 0.05",
            )
            names.append(name)
    model = mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))
    data = mujoco.MjData(model)
    balls = np.array([model.body(n).id for n in names])
    ball_geoms = {model.geom(n).id for n in names}
    is_ball = np.zeros(model.ngeom, dtype=bool)
    is_ball[list(ball_geoms)] = True
    is_body = ~is_ball
    is_body[model.geom("floor").id] = False
    hit_body = np.zeros(model.ngeom, dtype=bool)
    deepest_contact = 0.0
    sampled = []  # the balls' centres every CHECK_EVERY steps
    for step in range(int(SETTLE_SECONDS / model.opt.timestep)):
        mujoco.mj_step(model, data)
        pair = data.contact.geom[: data.ncon]
        ball_on_body = (is_body[pair[:, 0]] & is_ball[pair[:, 1]]) | (is_ball[pair[:, 0]] & is_body[pair[:, 1]])
        if ball_on_body.any():
            hit_body[pair[ball_on_body].ravel()] = True
            deepest_contact = min(deepest_contact, float(data.contact.dist[: data.ncon][ball_on_body].min()))
        if step % CHECK_EVERY == 0:
            sampled.append(data.xpos[balls].copy())
    # The sampled centres' signed distances to the body, SAMPLES_PER_QUERY samples a query (a query sets up every
    # piece's mesh again): the smallest along the fall, per ball.
    pieces = BodyPieces(mannequin, cushions=cushions, subdivisions=MJCF_CUSHION_LEVEL)
    closest = np.full(len(names), np.inf)
    for start in range(0, len(sampled), SAMPLES_PER_QUERY):
        d, _ = pieces.signed_distance(np.concatenate(sampled[start : start + SAMPLES_PER_QUERY]), cutoff=CUTOFF)
        closest = np.minimum(closest, d.reshape(-1, len(names)).min(axis=0))
    final = data.xpos[balls].copy()
    speed = np.linalg.norm(data.cvel[balls][:, 3:], axis=1)
    # Held by something: within a millimetre of the floor, the body or another ball. (A resting
    # ball can sit a hair above its support at the last step, with no contact listed.)
    apart = np.linalg.norm(final[:, None] - final[None], axis=-1) + np.eye(len(final))
    supported = (
        (final[:, 2] - BALL_RADIUS <= 1e-3)
        | (pieces.signed_distance(final)[0] - BALL_RADIUS <= 1e-3)
        | (apart.min(axis=1) - 2 * BALL_RADIUS <= 1e-3)
    )
    return dict(
        final=final,
        speed=speed,
        closest=closest,
        hit_body=int((hit_body & is_ball).sum()),
        count=len(names),
        supported=supported,
        deepest_contact=deepest_contact,
    )


# MuJoCo's contacts are soft: a 2 cm ball dropped onto a thin piece sinks in by up to ~3.5 mm.
SOFT_CONTACT_DEPTH = 0.005


@pytest.mark.slow
@pytest.mark.parametrize("cushions", [False, True], ids=["ellipsoids", "cushions"])
@pytest.mark.parametrize("make", mannequins(only="average"))  # a few seconds each: the toy and one RM
def test_falling_balls_never_pass_through_the_mannequin(make, cushions):
    mannequin = make()
    out = drop_balls(mannequin, cushions)
    r = BALL_RADIUS
    # Collisions really happened: a good share of the balls struck the body on their way down.
    assert out["hit_body"] >= 0.1 * out["count"]
    # Along the whole fall no ball centre came closer to the body than its radius, up to MuJoCo's
    # soft-contact penetration (a few millimetres when a ball lands on a finger); sampled every
    # CHECK_EVERY steps. Passing through would take at least the thinnest piece's half-thickness.
    thinnest = mannequin.semi_axes.min()
    tolerance = min(SOFT_CONTACT_DEPTH, 0.5 * thinnest)
    assert np.min(out["closest"]) > r - tolerance, f"deepest approach {np.min(out['closest']) - r:.4f} m"
    assert out["deepest_contact"] > -tolerance
    # At the end: no centre inside any ellipsoid grown by most of the radius (the brief's check)...
    grown = mannequin.semi_axes + 0.8 * r
    inside = contains(mannequin.rotation[None], mannequin.center[None], grown[None], out["final"][:, None])
    assert not inside.any()
    # ... all balls at rest, above the floor, each held by the floor, the body or another ball.
    assert np.all(out["final"][:, 2] > r - SOFT_CONTACT_DEPTH)
    assert np.all(out["speed"] < 0.05), f"fastest {out['speed'].max():.3f} m/s"
    assert out["supported"].all()
