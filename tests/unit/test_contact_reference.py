"""Tests of the slow reference Munjiza potential contact (solid/kernels/reference.py).

The reference is checked against exact results where they exist (homothetic intersections of a
simplex with its translate, containment), against symmetries it must have (antisymmetry,
translation), and against independent Monte Carlo estimates that share no code with it: points
are classified with barycentric coordinates from ``numpy.linalg.inv``, never by clipping.
Monte Carlo comparisons use a fixed seed and allow ``MC_SIGMAS`` standard errors.
"""
import numpy as np
import pytest
from scipy.spatial import Delaunay

from riprap.errors import MeshError
from riprap.solid.kernels.reference import (
    brute_force_overlapping_tet_pairs,
    reference_body_contact,
    reference_wall_contact,
    tet_intersection_volume_centroid,
)

# Clipping is exact up to round-off: a few hundred operations on O(1) numbers, ~1e-14 relative.
CLIP_TOLERANCE = 1e-12
# Antisymmetry compares two different clipping orders of the same polyhedra (round-off only).
ANTISYMMETRY_TOLERANCE = 1e-12
# Translating by |d| ~ 5 for bodies of size ~1 rounds every coordinate at ~5 * 2.2e-16 absolute.
TRANSLATION_TOLERANCE = 1e-11
# Four standard errors: a correct code fails one comparison with probability ~6e-5 per component;
# the seeds are fixed, so the tests are deterministic.
MC_SIGMAS = 4.0
MC_SAMPLES = 400_000
PENALTY = 1.0e7  # Pa, a typical rock contact penalty; the checks are relative so its value is free

UNIT_TET = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
ONE_TET = np.array([[0, 1, 2, 3]], dtype=np.int64)


# ------------------------------------------------------------------------------------------
# independent helpers (plain numpy, no clipping)
# ------------------------------------------------------------------------------------------
def _six_volume(tet):
    return float(np.dot(tet[1] - tet[0], np.cross(tet[2] - tet[0], tet[3] - tet[0])))


def _random_tet(rng, center=(0.0, 0.0, 0.0), size=1.0):
    """A positively oriented random tetrahedron that is not too flat."""
    while True:
        tet = np.asarray(center) + size * rng.uniform(-0.5, 0.5, size=(4, 3))
        six_volume = _six_volume(tet)
        if abs(six_volume) > 0.05 * size**3:
            return tet if six_volume > 0 else tet[[0, 2, 1, 3]]


def _random_mesh(rng, n_points, offset):
    """Delaunay tetrahedra of random points in a unit cube, positively oriented, slivers removed."""
    points = rng.uniform(0.0, 1.0, size=(n_points, 3)) + np.asarray(offset)
    tets = Delaunay(points).simplices.astype(np.int64)
    corners = points[tets]
    six_volumes = np.einsum("ij,ij->i", corners[:, 1] - corners[:, 0],
                            np.cross(corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 0]))
    tets[six_volumes < 0] = tets[six_volumes < 0][:, [0, 2, 1, 3]]
    keep = np.abs(six_volumes) > 1e-3 * np.abs(six_volumes).mean()
    return points, tets[keep]


def _barycentric(tet, points):
    """Barycentric coordinates (n, 4) of points (n, 3) in a tetrahedron (4, 3)."""
    inverse = np.linalg.inv((tet[1:] - tet[0]).T)
    tail = (points - tet[0]) @ inverse.T
    return np.column_stack([1.0 - tail.sum(axis=1), tail])


def _potential_gradients(tet):
    """4 grad lambda_k, row k (4, 3): grad phi on sub-tet k."""
    inverse = np.linalg.inv((tet[1:] - tet[0]).T)
    return 4.0 * np.vstack([-inverse.sum(axis=0), inverse])


def _uniform_in_simplex(rng, vertices, count):
    weights = rng.dirichlet(np.ones(len(vertices)), size=count)
    return weights @ vertices


def _mc_mean_and_error(values, measure):
    """measure * mean and its standard error, per column."""
    mean = values.mean(axis=0)
    error = values.std(axis=0, ddof=1) / np.sqrt(values.shape[0])
    return measure * mean, measure * error


def _cube_tets(low, size):
    """Unit cube split into 6 positively oriented tets around its main diagonal (Kuhn split)."""
    corners = np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], dtype=float)
    nodes = np.asarray(low) + size * corners
    tets = []
    for path in ([1, 2, 4], [1, 4, 2], [2, 1, 4], [2, 4, 1], [4, 1, 2], [4, 2, 1]):
        chain = [0]
        for step in path:
            chain.append(chain[-1] + step)
        tet = np.array(chain)
        if _six_volume(nodes[tet]) < 0:
            tet = tet[[0, 2, 1, 3]]
        tets.append(tet)
    return nodes, np.array(tets, dtype=np.int64)


def _rotation(rng):
    matrix, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return matrix * np.sign(np.linalg.det(matrix))


def _overlapping_tet_pair(seed):
    """Two random tets; the target's centroid is interior to the contactor, so they overlap."""
    rng = np.random.default_rng(seed)
    tet_c = _random_tet(rng)
    centroid_c = tet_c.mean(axis=0)
    inner_point = centroid_c + 0.3 * (_uniform_in_simplex(rng, tet_c, 1)[0] - centroid_c)
    rotation = _rotation(rng)
    tet_t = inner_point + 1.2 * (tet_c - centroid_c) @ rotation.T
    return tet_c, tet_t


# ------------------------------------------------------------------------------------------
# tet ∩ tet
# ------------------------------------------------------------------------------------------
def test_intersection_of_identical_tets_is_the_tet():
    tet = _random_tet(np.random.default_rng(1))
    volume, centroid = tet_intersection_volume_centroid(tet, tet)
    exact = _six_volume(tet) / 6.0
    assert abs(volume - exact) <= CLIP_TOLERANCE * exact
    assert np.all(np.abs(centroid - tet.mean(axis=0)) <= CLIP_TOLERANCE)


def test_intersection_of_disjoint_tets_is_zero():
    volume, centroid = tet_intersection_volume_centroid(UNIT_TET, UNIT_TET + [0.6, 0.6, 0.0])
    # Boxes overlap but the tets do not (x + y <= 1 against x + y >= 1.2): exercised by clipping.
    assert volume == 0.0
    assert np.all(np.isnan(centroid))
    far_volume, _ = tet_intersection_volume_centroid(UNIT_TET, UNIT_TET + [5.0, 0.0, 0.0])
    assert far_volume == 0.0


def test_intersection_touching_face_is_zero():
    mirrored = UNIT_TET * [-1.0, 1.0, 1.0]
    volume, _ = tet_intersection_volume_centroid(UNIT_TET, mirrored)
    assert volume == 0.0


@pytest.mark.parametrize("seed", [2, 3, 4, 5])
def test_intersection_with_translate_matches_homothety(seed):
    """T ∩ (T + d) is T scaled by 1 - sum_i max(0, d·grad lambda_i): exact volume and centroid."""
    rng = np.random.default_rng(seed)
    tet = _random_tet(rng)
    factor = 0.0
    while factor < 0.2:  # keep a non-empty intersection
        shift = rng.normal(size=3) * 0.1
        deltas = (_potential_gradients(tet) / 4.0) @ shift
        lower = np.maximum(deltas, 0.0)
        factor = 1.0 - lower.sum()
    exact_volume = _six_volume(tet) / 6.0 * factor**3
    exact_centroid = (lower + factor / 4.0) @ tet
    volume, centroid = tet_intersection_volume_centroid(tet, tet + shift)
    assert abs(volume - exact_volume) <= CLIP_TOLERANCE * _six_volume(tet)
    assert np.all(np.abs(centroid - exact_centroid) <= CLIP_TOLERANCE * 10.0)


def test_intersection_with_half_edge_translate_matches_monte_carlo():
    rng = np.random.default_rng(6)
    tet_a = _random_tet(rng)
    tet_b = tet_a + 0.5 * (tet_a[2] - tet_a[1])
    volume, centroid = tet_intersection_volume_centroid(tet_a, tet_b)
    points = _uniform_in_simplex(rng, tet_a, MC_SAMPLES)
    inside = (_barycentric(tet_b, points).min(axis=1) >= 0.0).astype(float)
    volume_a = _six_volume(tet_a) / 6.0
    mc_volume, mc_error = _mc_mean_and_error(inside[:, None], volume_a)
    assert abs(volume - mc_volume[0]) <= MC_SIGMAS * mc_error[0]
    mc_moment, moment_error = _mc_mean_and_error(points * inside[:, None], volume_a)
    assert np.all(np.abs(volume * centroid - mc_moment) <= MC_SIGMAS * moment_error)
    # Half an edge shrinks a simplex by 1/2, so the exact volume is V/8.
    assert abs(volume - volume_a / 8.0) <= CLIP_TOLERANCE * volume_a


@pytest.mark.parametrize("seed", range(10, 16))
def test_intersection_is_symmetric(seed):
    tet_a, tet_b = _overlapping_tet_pair(seed)
    volume_ab, centroid_ab = tet_intersection_volume_centroid(tet_a, tet_b)
    volume_ba, centroid_ba = tet_intersection_volume_centroid(tet_b, tet_a)
    scale = min(_six_volume(tet_a), _six_volume(tet_b)) / 6.0
    assert volume_ab > 0.0
    assert abs(volume_ab - volume_ba) <= CLIP_TOLERANCE * scale
    # centroid * volume is the quantity clipped; divide the round-off by the intersection volume
    assert np.all(np.abs(centroid_ab - centroid_ba) * volume_ab <= CLIP_TOLERANCE * scale)


def test_clipping_by_a_containing_tet_gives_the_tet():
    tet = _random_tet(np.random.default_rng(7), size=0.5)
    container = np.array([[-3.0, -3.0, -3.0], [9.0, -3.0, -3.0], [-3.0, 9.0, -3.0],
                          [-3.0, -3.0, 9.0]])
    volume, centroid = tet_intersection_volume_centroid(tet, container)
    exact = _six_volume(tet) / 6.0
    assert abs(volume - exact) <= CLIP_TOLERANCE * exact
    assert np.all(np.abs(centroid - tet.mean(axis=0)) <= CLIP_TOLERANCE)
    volume_swapped, _ = tet_intersection_volume_centroid(container, tet)
    assert abs(volume_swapped - exact) <= CLIP_TOLERANCE * exact


# ------------------------------------------------------------------------------------------
# body-body contact
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("seed", [20, 21, 22])
def test_body_contact_is_antisymmetric(seed):
    rng = np.random.default_rng(seed)
    nodes_a, tets_a = _random_mesh(rng, 25, offset=(0.0, 0.0, 0.0))
    nodes_b, tets_b = _random_mesh(rng, 25, offset=rng.uniform(0.3, 0.6, 3))
    force_ab, moment_ab = reference_body_contact(nodes_a, tets_a, nodes_b, tets_b, penalty=PENALTY)
    force_ba, moment_ba = reference_body_contact(nodes_b, tets_b, nodes_a, tets_a, penalty=PENALTY)
    magnitude = np.linalg.norm(force_ab)
    extent = np.abs(np.vstack([nodes_a, nodes_b])).max()
    assert magnitude > 0.0
    assert np.linalg.norm(force_ab + force_ba) <= ANTISYMMETRY_TOLERANCE * magnitude
    assert (np.linalg.norm(moment_ab + moment_ba)
            <= ANTISYMMETRY_TOLERANCE * (np.linalg.norm(moment_ab) + extent * magnitude))


def test_body_contact_translation_keeps_force_and_shifts_moment():
    rng = np.random.default_rng(30)
    nodes_a, tets_a = _random_mesh(rng, 25, offset=(0.0, 0.0, 0.0))
    nodes_b, tets_b = _random_mesh(rng, 25, offset=(0.5, 0.2, 0.4))
    shift = np.array([3.7, -1.2, 5.1])
    force, moment = reference_body_contact(nodes_a, tets_a, nodes_b, tets_b, penalty=PENALTY)
    moved_force, moved_moment = reference_body_contact(nodes_a + shift, tets_a, nodes_b + shift,
                                                       tets_b, penalty=PENALTY)
    magnitude = np.linalg.norm(force)
    assert np.linalg.norm(moved_force - force) <= TRANSLATION_TOLERANCE * magnitude
    # sum of (x + d) × f = M + d × F
    expected = moment + np.cross(shift, force)
    scale = np.linalg.norm(moment) + np.linalg.norm(shift) * magnitude + magnitude
    assert np.linalg.norm(moved_moment - expected) <= TRANSLATION_TOLERANCE * scale


def test_body_contact_of_separated_bodies_is_zero():
    rng = np.random.default_rng(31)
    nodes_a, tets_a = _random_mesh(rng, 15, offset=(0.0, 0.0, 0.0))
    nodes_b, tets_b = _random_mesh(rng, 15, offset=(1.5, 0.0, 0.0))
    force, moment = reference_body_contact(nodes_a, tets_a, nodes_b, tets_b, penalty=PENALTY)
    assert np.all(force == 0.0) and np.all(moment == 0.0)


def _mc_volume_force_and_moment(rng, tet_c, tet_t):
    """Independent estimate of ∫_{c∩t} (grad phi_c - grad phi_t) dV and ∫ x × (...) dV."""
    points = _uniform_in_simplex(rng, tet_c, MC_SAMPLES)
    lambda_c = _barycentric(tet_c, points)
    lambda_t = _barycentric(tet_t, points)
    inside = lambda_t.min(axis=1) >= 0.0
    # sub-tet k is where lambda_k is the smallest barycentric coordinate
    integrand = (_potential_gradients(tet_c)[lambda_c.argmin(axis=1)]
                 - _potential_gradients(tet_t)[lambda_t.argmin(axis=1)]) * inside[:, None]
    values = np.hstack([integrand, np.cross(points, integrand)])
    return _mc_mean_and_error(values, _six_volume(tet_c) / 6.0)


@pytest.mark.parametrize("seed", [40, 41])
def test_body_contact_of_two_tets_matches_monte_carlo(seed):
    tet_c, tet_t = _overlapping_tet_pair(seed)
    force, moment = reference_body_contact(tet_c, ONE_TET, tet_t, ONE_TET, penalty=PENALTY)
    estimate, error = _mc_volume_force_and_moment(np.random.default_rng(seed), tet_c, tet_t)
    reference = np.concatenate([force, moment]) / PENALTY
    assert np.all(np.abs(reference - estimate) <= MC_SIGMAS * error)


@pytest.mark.parametrize("seed", [50, 51])
def test_body_contact_volume_form_equals_boundary_form(seed):
    """Divergence theorem: ∫_{c∩t} grad(phi_c - phi_t) dV = ∮ (phi_c - phi_t) n dΓ.

    phi_c vanishes on ∂c and phi_t on ∂t, so the boundary form is
    -∫_{∂c ∩ t} phi_t n_c dΓ + ∫_{∂t ∩ c} phi_c n_t dΓ (n outward), and for the moment
    ∫ x × grad f dV = ∮ f x × n dΓ. Both are sampled on the eight faces.
    """
    tet_c, tet_t = _overlapping_tet_pair(seed)
    force, moment = reference_body_contact(tet_c, ONE_TET, tet_t, ONE_TET, penalty=PENALTY)
    rng = np.random.default_rng(seed)
    estimate = np.zeros(6)
    variance = np.zeros(6)
    for owner, other, sign in ((tet_c, tet_t, -1.0), (tet_t, tet_c, 1.0)):
        for opposite in range(4):
            face = np.delete(owner, opposite, axis=0)
            normal = np.cross(face[1] - face[0], face[2] - face[0])
            area = 0.5 * np.linalg.norm(normal)
            normal /= np.linalg.norm(normal)
            if np.dot(normal, owner[opposite] - face[0]) > 0.0:
                normal = -normal
            points = _uniform_in_simplex(rng, face, MC_SAMPLES // 8)
            phi_other = np.maximum(4.0 * _barycentric(other, points).min(axis=1), 0.0)
            values = sign * phi_other[:, None] * np.hstack(
                [np.broadcast_to(normal, points.shape), np.cross(points, normal)])
            mean, error = _mc_mean_and_error(values, area)
            estimate += mean
            variance += error**2
    reference = np.concatenate([force, moment]) / PENALTY
    assert np.any(np.abs(reference) > 0.0)
    assert np.all(np.abs(reference - estimate) <= MC_SIGMAS * np.sqrt(variance))


def test_brute_force_pairs_match_box_test():
    rng = np.random.default_rng(60)
    nodes_a, tets_a = _random_mesh(rng, 20, offset=(0.0, 0.0, 0.0))
    nodes_b, tets_b = _random_mesh(rng, 20, offset=(0.6, 0.3, 0.0))
    pairs = brute_force_overlapping_tet_pairs(nodes_a, tets_a, nodes_b, tets_b)
    low_a, high_a = nodes_a[tets_a].min(axis=1), nodes_a[tets_a].max(axis=1)
    low_b, high_b = nodes_b[tets_b].min(axis=1), nodes_b[tets_b].max(axis=1)
    overlap = np.all((low_a[:, None] <= high_b[None]) & (low_b[None] <= high_a[:, None]), axis=2)
    assert pairs.shape[1] == 2 and pairs.shape[0] > 0
    assert np.array_equal(pairs, np.argwhere(overlap))


def test_inverted_tet_raises_mesh_error():
    with pytest.raises(MeshError, match="tet 0"):
        reference_body_contact(UNIT_TET, ONE_TET[:, [0, 2, 1, 3]], UNIT_TET, ONE_TET,
                               penalty=PENALTY)


# ------------------------------------------------------------------------------------------
# wall contact
# ------------------------------------------------------------------------------------------
def test_wall_contact_of_sunk_tet_matches_monte_carlo():
    rng = np.random.default_rng(70)
    rotation = _rotation(rng)
    normal = rotation @ [0.0, 0.0, 1.0]
    point = np.array([0.3, -0.2, 0.1])
    depth, wall_potential_depth = 0.15, 0.4
    # face 0-1-2 in the plane z = 0 of the local frame, apex above, then pushed in by depth
    local = np.array([[0.0, 0.0, 0.0], [0.8, 0.1, 0.0], [0.2, 0.7, 0.0], [0.3, 0.2, 0.6]])
    tet = (local - [0.0, 0.0, depth]) @ rotation.T + point
    force, moment = reference_wall_contact(tet, ONE_TET, point=point, normal=normal,
                                           wall_potential_depth=wall_potential_depth,
                                           penalty=PENALTY)
    points = _uniform_in_simplex(rng, tet, MC_SAMPLES)
    inside = (points - point) @ normal < 0.0
    gradients = _potential_gradients(tet)[_barycentric(tet, points).argmin(axis=1)]
    integrand = (gradients + normal / wall_potential_depth) * inside[:, None]
    estimate, error = _mc_mean_and_error(np.hstack([integrand, np.cross(points, integrand)]),
                                         _six_volume(tet) / 6.0)
    reference = np.concatenate([force, moment]) / PENALTY
    assert np.linalg.norm(force) > 0.0
    assert np.all(np.abs(reference - estimate) <= MC_SIGMAS * error)


def test_wall_contact_of_sunk_cube_is_along_normal_and_matches_section_integral():
    """For a sunk body, F = p n (∫_{section} phi dA + V_sunk / h_W) (divergence theorem)."""
    rng = np.random.default_rng(71)
    depth, wall_potential_depth, side = 0.1, 0.25, 1.0
    nodes, tets = _cube_tets(low=(0.0, 0.0, -depth), size=side)
    normal = np.array([0.0, 0.0, 1.0])
    force, _ = reference_wall_contact(nodes, tets, point=np.zeros(3), normal=normal,
                                      wall_potential_depth=wall_potential_depth, penalty=PENALTY)
    # exactly along n up to round-off, since each ∫ grad phi_c over c ∩ wall is along n
    assert np.linalg.norm(force[:2]) <= CLIP_TOLERANCE * abs(force[2])
    samples = np.column_stack([rng.uniform(0.0, side, (MC_SAMPLES, 2)), np.zeros(MC_SAMPLES)])
    phi = np.zeros(MC_SAMPLES)
    for tet in tets:
        phi = np.maximum(phi, 4.0 * _barycentric(nodes[tet], samples).min(axis=1))
    section, error = _mc_mean_and_error(phi[:, None], side**2)
    expected = section[0] + side**2 * depth / wall_potential_depth
    assert abs(force[2] / PENALTY - expected) <= MC_SIGMAS * error[0]


def test_wall_contact_of_body_above_or_touching_plane_is_exactly_zero():
    rng = np.random.default_rng(72)
    nodes, tets = _random_mesh(rng, 20, offset=(0.0, 0.0, 0.01))
    force, moment = reference_wall_contact(nodes, tets, point=np.zeros(3), normal=[0.0, 0.0, 1.0],
                                           wall_potential_depth=0.1, penalty=PENALTY)
    assert np.all(force == 0.0) and np.all(moment == 0.0)
    cube_nodes, cube_tets = _cube_tets(low=(0.0, 0.0, 0.0), size=1.0)
    force, moment = reference_wall_contact(cube_nodes, cube_tets, point=np.zeros(3),
                                           normal=[0.0, 0.0, 1.0], wall_potential_depth=0.1,
                                           penalty=PENALTY)
    assert np.all(force == 0.0) and np.all(moment == 0.0)
