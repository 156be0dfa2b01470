"""m_T: closed forms, agreement with a brute-force hull, invariants."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull
from scipy.special import ellipe

from devkit.hull_before import hull_perimeter_before
from devkit.reference import brute_force_measure, random_mannequin_arrays
from devkit.toy import rotation_from_vector
from ellimann_addon.core.constants import SECTION_FRACTIONS
from ellimann_addon.core.geometry.cushion import cushion_mesh
from ellimann_addon.core.geometry.mesh import icosphere
from ellimann_addon.core.measure import tailor as measure


def perimeter(centres, ks):
    c, k = np.asarray(centres, float)[None], np.asarray(ks, float)[None]
    return measure.hull_perimeter(c, k, np.ones(c.shape[:2], bool))[0]


def test_circle_through_sphere_centre_is_two_pi_r():
    r = 0.23
    assert perimeter([(0.1, 0.2)], [np.eye(2) * r * r]) == pytest.approx(2 * np.pi * r, rel=1e-12)


@pytest.mark.parametrize("a,b,angle", [(0.5, 0.2, 0.0), (0.3, 0.29, 1.0), (0.4, 0.05, 2.5), (0.2, 0.2, 0.3)])
def test_ellipse_perimeter_is_the_complete_elliptic_integral(a, b, angle):
    rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    k = rot @ np.diag([a * a, b * b]) @ rot.T
    exact = 4 * a * ellipe(1 - (b / a) ** 2)
    assert perimeter([(0.0, 0.0)], [k]) == pytest.approx(exact, rel=1e-12)


@pytest.mark.parametrize("aspect", [1.05, 1.5, 2.0, 2.9, 5.0, 8.0, 12.0])
@pytest.mark.parametrize("angle", [0.0, 0.3, 1.1])
def test_ellipse_perimeter_to_rounding_with_the_nodes_the_error_bound_chooses(aspect, angle):
    """8 Gauss-Legendre nodes per cell up to aspect ~2 (every girth section of the shipped sets), more for flatter
    ellipses (core.geometry.section_hull._gauss_orders): within a few ulps of the complete elliptic integral
    throughout."""
    rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    k = rot @ np.diag([aspect**2 * 0.01, 0.01]) @ rot.T
    exact = 4 * 0.1 * aspect * ellipe(1 - aspect**-2)
    assert perimeter([(0.3, -0.2)], [k]) == pytest.approx(exact, rel=2e-15)


@pytest.mark.parametrize("d", [0.0, 0.05, 0.7, 3.0])
def test_two_equal_circles_give_the_stadium(d):
    r = 0.15
    k = np.eye(2) * r * r
    assert perimeter([(0, 0), (d * 0.6, d * 0.8)], [k, k]) == pytest.approx(2 * np.pi * r + 2 * d, rel=1e-12)


def test_a_circle_inside_another_does_not_count():
    big, small = np.eye(2) * 0.3**2, np.eye(2) * 0.1**2
    assert perimeter([(0, 0), (0.1, 0.05)], [big, small]) == pytest.approx(2 * np.pi * 0.3, rel=1e-12)


@pytest.mark.parametrize("turn", np.arange(8) * np.pi / 128)  # across a cell of either grid, 128 or 32
def test_a_small_ellipse_rising_through_a_flat_side_between_grid_directions_counts(turn):
    """A circle pokes 1 mm through the flat side of a long ellipse, over a few degrees, between the detection grid's
    directions: it adds 1.3e-5 of the perimeter (the implementation before bounded the rise by the small ellipse's
    curvature instead of the flat side's and missed it). Truth: the hull of 100k points on each."""
    a, b, r, rise = 0.5, 0.05, 0.02, 1e-3
    rot = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
    centres = np.array([(0.0, 0.0), rot @ (0.0, b + rise - r)])
    ks = [rot @ np.diag([a * a, b * b]) @ rot.T, np.eye(2) * r * r]
    t = np.linspace(0.0, 2 * np.pi, 100_000, endpoint=False)
    circle = np.stack([np.cos(t), np.sin(t)], axis=1)
    points = np.concatenate([circle * (a, b) @ rot.T, centres[1] + r * circle])
    assert perimeter(centres, ks) == pytest.approx(ConvexHull(points).area, rel=1e-8)


def test_empty_section_has_zero_perimeter():
    k = np.eye(2)[None, None] * 0.01
    assert measure.hull_perimeter(np.zeros((1, 1, 2)), k, np.zeros((1, 1), bool))[0] == 0.0


@pytest.mark.slow
def test_agrees_with_brute_force_hull_on_random_mannequins():
    rng = np.random.default_rng(7)
    worst = 0.0
    for _ in range(40):
        r, c, d, g = random_mannequin_arrays(rng)
        closed = measure.tailor_measurements(r, c, d, g)
        brute = brute_force_measure(r, c, d, g)
        nonzero = brute > 0
        assert np.all(closed[~nonzero] == 0)
        worst = max(worst, np.max(np.abs(closed[nonzero] - brute[nonzero]) / brute[nonzero]))
    assert worst < 1e-6


def test_agrees_with_the_implementation_it_replaced():
    """The implementation before issue 14's speed-up (devkit.hull_before: a 128-direction grid, 16 times finer
    where the outermost ellipse changes, 12 nodes per piece) gives the same perimeters to rounding on random
    bodies (none of them has an ellipse its bound on hidden ones missed)."""
    rng = np.random.default_rng(11)
    for count in (1, 5, 70):  # 70 mannequins: sections of unequal ellipse counts are measured in groups
        r, c, d, g = zip(*[random_mannequin_arrays(rng, 24) for _ in range(count)])
        r, c, d = np.stack(r), np.stack(c), np.stack(d)
        _, _, z = measure.section_heights(r, c, d)
        heights = np.stack([z[key] for key in ("Br", "Wa", "Hi")], axis=1)
        centre, k, hit = measure.section_at_height(r[:, None], c[:, None], d[:, None], heights[:, :, None])
        active = (hit & g[0]).reshape(-1, 24)
        centre, k = centre.reshape(-1, 24, 2), k.reshape(-1, 24, 2, 2)
        np.testing.assert_allclose(
            measure.hull_perimeter(centre, k, active), hull_perimeter_before(centre, k, active), rtol=1e-13, atol=0.0
        )


def test_batch_equals_one_by_one():
    rng = np.random.default_rng(3)
    r, c, d, g = zip(*[random_mannequin_arrays(rng, 20) for _ in range(40)])  # 120 sections: grouped by size
    batch = measure.tailor_measurements(np.stack(r), np.stack(c), np.stack(d), g[0])
    single = np.stack([measure.tailor_measurements(r[i], c[i], d[i], g[0]) for i in range(40)])
    np.testing.assert_array_equal(batch, single)  # the same bits: no sum's order depends on the batch


def test_known_two_sphere_body():
    """A 'body' of two stacked spheres: every measurement has a closed form."""
    r = 0.2
    rotation = np.stack([np.eye(3)] * 2)
    center = np.array([[0.0, 0.0, r], [0.0, 0.0, 3 * r]])
    semi = np.full((2, 3), r)
    he, sh, br, wa, hi = measure.tailor_measurements(rotation, center, semi, np.ones(2, bool))
    assert he == pytest.approx(400 * r)
    z_sh = 4 * r * SECTION_FRACTIONS["Sh"]  # 0.632 -> upper sphere
    assert sh == pytest.approx(200 * np.sqrt(r * r - (z_sh - 3 * r) ** 2))
    assert hi == pytest.approx(0.0, abs=1e-9)  # z = 2r: the spheres touch at a point
    # Br and Wa cut only the upper sphere (above z = 2r): circles of radius sqrt(r^2 - (z - 3r)^2).
    for value, key in ((br, "Br"), (wa, "Wa")):
        z = 4 * r * SECTION_FRACTIONS[key]
        assert 2 * r < z < 4 * r
        assert value == pytest.approx(200 * np.pi * np.sqrt(r * r - (z - 3 * r) ** 2), rel=1e-12)


@settings(max_examples=30, deadline=None)
@given(st.floats(-2, 2), st.floats(-2, 2), st.floats(-1, 1), st.floats(-np.pi, np.pi), st.integers(0, 10**6))
def test_invariant_to_horizontal_moves_and_turns_about_z(dx, dy, dz, angle, seed):
    r, c, d, g = random_mannequin_arrays(np.random.default_rng(seed), 12)
    before = measure.tailor_measurements(r, c, d, g)
    turn = rotation_from_vector((0, 0, angle))
    moved = measure.tailor_measurements(turn @ r, c @ turn.T + (dx, dy, dz), d, g)
    # Sh is measured along X, so it changes under a turn; perimeters and height do not.
    assert np.allclose(np.delete(moved, 1), np.delete(before, 1), rtol=1e-9, atol=1e-9)
    shifted = measure.tailor_measurements(r, c + (dx, dy, dz), d, g)
    assert np.allclose(shifted, before, rtol=1e-9, atol=1e-9)


def test_measurements_scale_linearly():
    r, c, d, g = random_mannequin_arrays(np.random.default_rng(11), 25)
    assert np.allclose(
        measure.tailor_measurements(r, 1.7 * c, 1.7 * d, g), 1.7 * measure.tailor_measurements(r, c, d, g), rtol=1e-9
    )


def test_hull_boundary_points_lie_on_the_hull():
    c = np.array([(0, 0), (0.5, 0.1)])
    k = np.stack([np.eye(2) * 0.04, np.diag([0.01, 0.03])])
    pts = measure.hull_boundary(c, k, np.ones(2, bool), samples=512)
    hull = ConvexHull(pts)
    assert hull.area == pytest.approx(perimeter(c, k), rel=1e-3)


def ellipsoid_meshes(mannequin, subdivisions):
    unit, faces = icosphere(subdivisions)
    return [
        (unit * mannequin.semi_axes[i] @ mannequin.rotation[i].T + mannequin.center[i], faces)
        for i in range(len(mannequin))
    ]


def test_mesh_measure_converges_to_the_closed_form_from_inside(toy):
    closed = measure.tailor_measurements(toy.rotation, toy.center, toy.semi_axes, toy.topology.girth_mask)
    errors = []
    for subdivisions in (3, 4, 5):
        values, _ = measure.measure_meshes(ellipsoid_meshes(toy, subdivisions), toy.topology.girth_mask)
        # Vertices lie on the ellipsoids, so each mesh is inside its ellipsoid: never more than m_T.
        assert np.all(values <= closed * (1 + 1e-12))
        errors.append(np.abs(values / closed - 1.0).max())
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 3e-4


def test_mesh_measure_of_a_capsule_cushion():
    r, length = 0.1, 0.6
    sphere = (np.eye(3), np.zeros(3), np.full(3, r))
    top = (np.eye(3), np.array([0.0, 0.0, length]), np.full(3, r))
    vertices, faces = cushion_mesh(sphere, top, subdivisions=5)
    values, sections = measure.measure_meshes([(vertices, faces)], [True])
    he, sh, br, wa, hi = values / 100.0
    assert he == pytest.approx(length + 2 * r, rel=1e-9)
    # Every section cuts the cylindrical part: a circle of radius r.
    assert sh == pytest.approx(2 * r, rel=2e-3)
    for girth in (br, wa, hi):
        assert girth == pytest.approx(2 * np.pi * r, rel=2e-3) and girth < 2 * np.pi * r
    for key, fraction in SECTION_FRACTIONS.items():
        z, polygon = sections[key]
        assert z == pytest.approx(-r + fraction * (length + 2 * r))
        assert np.allclose(np.linalg.norm(polygon, axis=1), r, rtol=2e-3)


def test_mesh_measure_girths_use_only_girth_meshes(toy):
    meshes = ellipsoid_meshes(toy, 3)
    none = np.zeros(len(toy), bool)
    values, sections = measure.measure_meshes(meshes, none)
    assert values[2:] == pytest.approx([0, 0, 0]) and len(sections["Br"][1]) == 0
    assert values[0] > 0 and values[1] > 0
    with pytest.raises(ValueError, match="one girth flag per mesh"):
        measure.measure_meshes(meshes, none[:-1])
    with pytest.raises(ValueError, match="at least one mesh"):
        measure.measure_meshes([], [])


def test_section_hulls_trace_the_measured_sections(toy):
    r, c, d, g = toy.rotation, toy.center, toy.semi_axes, toy.topology.girth_mask
    values = measure.as_dict(measure.tailor_measurements(r, c, d, g))
    hulls = measure.section_hulls(r, c, d, g, samples=1024)
    bottom, height, z = measure.section_heights(r, c, d)
    assert set(hulls) == set(SECTION_FRACTIONS)
    for key, (height_z, points) in hulls.items():
        assert height_z == pytest.approx(z[key])
        if key == "Sh":
            assert np.ptp(points[:, 0]) * 100 == pytest.approx(values["Sh"], rel=1e-4)
        else:
            assert ConvexHull(points).area * 100 == pytest.approx(values[key], rel=1e-4)


def _mirror_pairs(rng, pairs, central):
    """A section symmetric about x = 0 bit for bit: random ellipses right of the mid-plane, their mirror images, and
    central ones (k_xy = 0)."""
    centres, ks = [], []
    for _ in range(pairs):
        a, b, angle = rng.uniform(0.03, 0.2), rng.uniform(0.02, 0.1), rng.uniform(0, np.pi)
        rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
        k = rot @ np.diag([a * a, b * b]) @ rot.T
        c = (rng.uniform(-0.05, 0.25), rng.uniform(-0.1, 0.1))
        centres += [c, (-c[0], c[1])]
        ks += [k, k * np.array([[1.0, -1.0], [-1.0, 1.0]])]
    for _ in range(central):
        centres.append((0.0, rng.uniform(-0.1, 0.1)))
        ks.append(np.diag(rng.uniform(0.02, 0.2, 2) ** 2))
    return np.array(centres), np.array(ks)


def _hull_of_points(centres, ks, count=20_000):
    t = np.linspace(0.0, 2 * np.pi, count, endpoint=False)
    circle = np.stack([np.cos(t), np.sin(t)], axis=1)
    return ConvexHull(np.concatenate([c + circle @ np.linalg.cholesky(k).T for c, k in zip(centres, ks)])).area


@pytest.mark.parametrize("seed", range(12))
def test_a_symmetric_section_measured_on_its_right_half_equals_the_whole_circle(seed):
    """core.geometry.section_hull integrates a section that is its own mirror image over the right half only, without
    the left
    ellipses that cannot reach into it: the same perimeter as the whole circle's (the section moved by 1e-12 m, no
    longer symmetric bit for bit) and as a brute-force hull. Some ellipses cross the mid-plane (kept both)."""
    from ellimann_addon.core.geometry import section_hull as hull

    rng = np.random.default_rng(seed)
    centres, ks = _mirror_pairs(rng, pairs=int(rng.integers(1, 4)), central=int(rng.integers(0, 3)))
    active = np.ones((1, len(centres)), bool)
    mirrored, used = hull._right_half(centres[None], ks[None], active)
    assert mirrored[0]
    half = measure.hull_perimeter(centres[None], ks[None], active)[0]
    moved = centres.copy()
    moved[0, 0] += 1e-12
    assert not hull._right_half(moved[None], ks[None], active)[0][0]
    whole = measure.hull_perimeter(moved[None], ks[None], active)[0]
    assert half == pytest.approx(whole, rel=1e-11)  # 1e-12 m moved, perimeter ~1 m
    assert half == pytest.approx(_hull_of_points(centres, ks), rel=1e-6)


def test_the_right_half_drops_the_left_ellipses_their_mirror_images_cover():
    from ellimann_addon.core.geometry import section_hull as hull

    centres, ks = _mirror_pairs(np.random.default_rng(5), pairs=3, central=1)
    centres[:6:2, 0] = np.abs(centres[:6:2, 0]) + 0.3  # every pair well apart
    centres[1:6:2, 0] = -centres[:6:2, 0]
    mirrored, used = hull._right_half(centres[None], ks[None], np.ones((1, 7), bool))
    assert mirrored[0] and list(used[0]) == [True, False] * 3 + [True]


def test_a_left_ellipse_reaching_across_the_mid_plane_is_kept():
    """A long ellipse tilted across x = 0 (|c_x| b < |k_xy|): its mirror image does not cover it on the right half,
    so both are integrated (dropping the left one would miss the hull's right tip)."""
    from ellimann_addon.core.geometry import section_hull as hull

    angle = 0.6
    rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    k = rot @ np.diag([0.3**2, 0.03**2]) @ rot.T
    centres = np.array([(0.02, 0.0), (-0.02, 0.0)])
    ks = np.stack([k, k * np.array([[1.0, -1.0], [-1.0, 1.0]])])
    mirrored, used = hull._right_half(centres[None], ks[None], np.ones((1, 2), bool))
    assert mirrored[0] and used.all()
    assert perimeter(centres, ks) == pytest.approx(_hull_of_points(centres, ks, 100_000), rel=1e-7)


@pytest.mark.parametrize("d", [0.0, 0.05, 0.7])
def test_two_mirrored_circles_give_the_stadium(d):
    r = 0.15
    k = np.eye(2) * r * r
    assert perimeter([(d / 2, 0.1), (-d / 2, 0.1)], [k, k]) == pytest.approx(2 * np.pi * r + 2 * d, rel=1e-14)


def _moved_grid_sections(scale_x=1.01, scale_y=0.995):
    """The girth sections of a few random bodies (full circle) and of the same sections symmetrised (half), then moved
    a little (a horizontal scaling, as a refinement step does)."""
    rng = np.random.default_rng(21)
    r, c, d, g = zip(*[random_mannequin_arrays(rng, 20) for _ in range(6)])
    r, c, d = np.stack(r), np.stack(c), np.stack(d)
    _, _, z = measure.section_heights(r, c, d)
    heights = np.stack([z[key] for key in ("Br", "Wa", "Hi")], axis=1)
    centre, k, hit = measure.section_at_height(r[:, None], c[:, None], d[:, None], heights[:, :, None])
    centre, k, active = centre.reshape(-1, 20, 2), k.reshape(-1, 20, 2, 2), (hit & g[0]).reshape(-1, 20)
    flip = np.array([[1.0, -1.0], [-1.0, 1.0]])
    # the same sections padded to 40 ellipses, and each with its mirror image added (measured on the right half)
    centre = np.concatenate(
        [np.concatenate([centre, centre], axis=1), np.concatenate([centre, centre * (-1, 1)], axis=1)]
    )
    k = np.concatenate([np.concatenate([k, k], axis=1), np.concatenate([k, k * flip], axis=1)])
    active = np.concatenate(
        [np.concatenate([active, np.zeros_like(active)], axis=1), np.concatenate([active, active], axis=1)]
    )
    scale = np.array([scale_x, scale_y])
    return (centre, k, active), (centre * scale, k * scale[:, None] * scale[None, :], active)


def test_followed_sections_give_the_searched_perimeters():
    """hull_perimeter(warm=structure) solves the kinks again from where they were instead of searching: after a
    small move it gives the perimeters a search gives, and the same structure; one section alone gives the bits it
    gives in the batch."""
    from ellimann_addon.core.geometry import section_hull as hull

    before, after = _moved_grid_sections()
    _, structure = measure.hull_perimeter(*before, structure=True)
    half = len(structure.mirrored) // 2
    np.testing.assert_array_equal(structure.mirrored, (np.arange(2 * half) >= half) & before[2].any(axis=1))
    assert len(structure.kink_theta)
    searched, found = measure.hull_perimeter(*after, structure=True)
    followed, moved = measure.hull_perimeter(*after, warm=structure, structure=True)
    np.testing.assert_allclose(followed, searched, rtol=1e-14)
    np.testing.assert_array_equal(moved.kink_section, found.kink_section)
    np.testing.assert_array_equal(moved.kink_after, found.kink_after)
    np.testing.assert_allclose(moved.kink_theta, found.kink_theta, atol=1e-12)
    for i in (0, 5, len(followed) - 1):
        one = measure.hull_perimeter(*(a[i : i + 1] for a in after), warm=structure.take([i]))
        assert one[0] == followed[i]
    assert isinstance(structure.take([0]), hull.HullStructure)


def test_a_structure_that_no_longer_holds_is_searched_again():
    """Kinks that swap, a structure from other sections, an outermost ellipse no longer cut: the section is measured
    by the search (the same perimeters)."""
    before, after = _moved_grid_sections()
    searched = measure.hull_perimeter(*after)
    _, structure = measure.hull_perimeter(*before, structure=True)
    reversed_rows = structure.take(np.arange(len(structure.first))[::-1])  # every section another's structure
    np.testing.assert_allclose(measure.hull_perimeter(*after, warm=reversed_rows), searched, rtol=1e-14)
    centre, k, active = after
    cut = active.copy()
    cut[np.arange(len(cut)), np.maximum(structure.first, 0)] = False  # the first outermost ellipse gone
    np.testing.assert_allclose(
        measure.hull_perimeter(centre, k, cut, warm=structure), measure.hull_perimeter(centre, k, cut), rtol=1e-14
    )


def test_the_elliptic_integral_of_the_pieces_matches_scipys_for_any_angle():
    """core.geometry.elliptic.elliptic_e, E(u | m) for any real u (whole turns of pi add twice the complete
    integral), against
    scipy.special.ellipeinc, up to aspect ratios of 100 (m = 1 - 1e-4)."""
    from scipy.special import ellipeinc

    from ellimann_addon.core.geometry import elliptic

    rng = np.random.default_rng(4)
    m = np.concatenate([rng.uniform(0.0, 1.0, 4000), 1.0 - 10.0 ** rng.uniform(-4, -1, 1000), [0.0, 0.0]])
    u = np.concatenate([rng.uniform(-np.pi, 2.5 * np.pi, len(m) - 2), [np.pi / 2, -np.pi]])
    np.testing.assert_allclose(elliptic.elliptic_e(u, m), ellipeinc(u, m), rtol=0, atol=3e-14)
    sharp = m < 1.0 - 1.0 / 150.0  # aspect below about 12
    np.testing.assert_allclose(
        elliptic.elliptic_e(u[sharp], m[sharp]), ellipeinc(u[sharp], m[sharp]), rtol=0, atol=1e-14
    )
