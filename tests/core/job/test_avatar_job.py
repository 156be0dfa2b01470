"""An avatar in a job (the format table's fbx row): refused before any work without a skin, without Blender, or in a
pose that is not a rest pose; its options checked and its pose the job's; what it must still measure once
decimated (``Result.avatar_request``); and the body skin measured again as a decimated mesh would be
(``core.formats.avatar.remeasure``: its arms carried over from the nearest original vertices' labels)."""

import numpy as np
import pytest

from ellimann_addon.core.errors import ElliMannError
from ellimann_addon.core.formats.avatar import AvatarOptions, remeasure
from ellimann_addon.core.formats.table import FORMATS, check_outputs
from ellimann_addon.core.job.make import make
from ellimann_addon.core.job.request import NeedsBlenderError, PoseAsk, Request, check
from ellimann_addon.core.job.result import Result, SkinMade
from ellimann_addon.core.mannequin.skin_record import SkinSettings
from ellimann_addon.core.measurements import MEASUREMENTS
from ellimann_addon.core.synthesis.misses import SKIN_MISS_CM
from ellimann_addon.core.synthesis.shipped import named_reference_set

FIVE = dict(zip(MEASUREMENTS, (165.0, 41.5, 101.25, 82.75, 117.5)))
BODY = SkinSettings(kind="body")


@pytest.fixture(scope="module")
def female():
    return named_reference_set("female")


@pytest.fixture(scope="module")
def made(female):
    return make(check(Request(FIVE, female, {"neck": 33.0}, skin=BODY)))


def test_the_fbx_row_needs_blender_and_a_skin():
    row = check_outputs(["a.fbx"])["a.fbx"]
    assert row is FORMATS["fbx"] and row.needs_skin and row.needs_blender_for(False) and not row.animated
    assert [name for name, kind in FORMATS.items() if kind.needs_skin] == ["fbx"]


@pytest.mark.parametrize(
    "request_options, words",
    [
        ({}, "a.fbx: an FBX avatar is the mannequin's skin on its bones: ask for a skin (--skin)"),
        ({"skin": BODY, "pose": PoseAsk("sit")}, "a.fbx: an FBX avatar stands in its rest pose, a_pose or t_pose, not"),
        ({"skin": BODY, "pose": PoseAsk("walk")}, "--pose walk is an animation and a .fbx file holds none"),
        ({"skin": BODY, "avatar": AvatarOptions(naming="unreal")}, "bone names: 'unreal' is not one of smpl, mixamo"),
        ({"skin": BODY, "avatar": AvatarOptions(max_triangles=100)}, "at least 5,000"),
    ],
)
def test_an_avatar_the_job_cannot_write_is_refused_in_one_line(female, request_options, words):
    with pytest.raises(ElliMannError) as refused:
        check(Request(FIVE, female, outputs=("a.fbx",), **request_options))
    assert words in str(refused.value) and "\n" not in str(refused.value)


def test_without_blender_an_fbx_is_refused_before_any_work(female):
    with pytest.raises(NeedsBlenderError, match="writing a.fbx needs Blender"):
        check(Request(FIVE, female, skin=BODY, outputs=("a.fbx",)), blender=False)


def test_the_avatar_s_pose_is_the_job_s_and_a_job_without_one_has_none(female):
    job = check(Request(FIVE, female, skin=BODY, outputs=("a.fbx", "a.json")))
    assert job.avatar == AvatarOptions()
    asked = AvatarOptions(naming="mixamo", proxy=True, max_triangles=20_000)
    job = check(Request(FIVE, female, skin=BODY, pose=PoseAsk("t_pose"), outputs=("a.fbx",), avatar=asked))
    assert job.avatar == AvatarOptions("t_pose", "mixamo", True, 20_000)
    assert check(Request(FIVE, female, skin=BODY, outputs=("a.json",), avatar=asked)).avatar is None


def test_an_avatar_must_measure_the_request_where_the_skin_meets_it_and_else_what_the_skin_measures(made):
    assert made.avatar_request() == {**FIVE, "neck": 33.0}  # the body skin meets it within 1 mm
    off = Result(made.mannequin, made.measured, dict(made.request), skin=SkinMade(made.skin.skin, {}, True))
    off.skin.measured = {**made.skin.measured, "Wa": FIVE["Wa"] + 3 * SKIN_MISS_CM, "neck": float("nan")}
    assert off.avatar_request() == {**FIVE, "Wa": FIVE["Wa"] + 3 * SKIN_MISS_CM}  # missed: the skin's; nan: none
    off.skin.exact = False  # a skin exact mode did not make: what it measures
    assert off.avatar_request() == {key: off.skin.measured[key] for key in MEASUREMENTS}
    assert Result(made.mannequin, made.measured, dict(made.request)).avatar_request() is None


def test_a_body_skin_is_measured_again_as_it_measures_itself_whatever_its_vertices_order(made):
    skin = made.skin.skin
    assert not hasattr(skin, "pieces")
    whole, problems = remeasure(skin, skin.vertices, skin.faces, np.arange(len(skin.vertices)))
    own = skin.measure().values
    assert problems == [] and whole == pytest.approx(own, abs=1e-9)
    # The same mesh with its vertices shuffled: each takes its arm label from the original vertex it came from
    order = np.random.default_rng(7).permutation(len(skin.vertices))
    where = np.empty_like(order)
    where[order] = np.arange(len(order))
    shuffled, _ = remeasure(skin, skin.vertices[order], where[skin.faces], order)
    assert shuffled == pytest.approx(own, abs=1e-6)
    # Labels carried over wrongly (the arms as the trunk) change it: the arms are what it was told
    wrong, _ = remeasure(skin, skin.vertices[order], where[skin.faces], np.zeros(len(order), np.int64))
    assert wrong.get("Br", np.nan) != pytest.approx(own["Br"], abs=0.1)
