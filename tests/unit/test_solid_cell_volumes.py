"""Exact solid volumes in fluid cells (riprap.coupling): against analytic box overlaps, an
independent convex-polytope volume (scipy's half-space intersection and convex hull, i.e. Qhull),
conservation of each body's volume, and thread-count independence."""
import numba
import numpy as np
import pytest
from scipy.optimize import linprog
from scipy.spatial import ConvexHull, HalfspaceIntersection

import riprap as rr
from riprap.coupling.kernels.tet_cell_volumes import clip_volume
from riprap.coupling.solid_volumes import body_cell_volumes, rigid_body_cell_volumes
from riprap.errors import CaseFileError
from riprap.fluid.grid import FluidGrid


def _polytope_volume(halfspaces):
    """Volume of {x : A x + b <= 0} (rows [A, b]) by Qhull, 0 if it has no interior."""
    a, b = halfspaces[:, :3], halfspaces[:, 3]
    norms = np.linalg.norm(a, axis=1)
    # Chebyshev centre: an interior point as far from every face as can be
    result = linprog(np.r_[0, 0, 0, -1], A_ub=np.hstack([a, norms[:, None]]), b_ub=-b,
                     bounds=[(None, None)] * 3 + [(0, None)])
    if result.status != 0 or result.x[3] <= 1e-9:
        return 0.0
    return ConvexHull(HalfspaceIntersection(halfspaces, result.x[:3]).intersections).volume


def _box_halfspaces(lower, upper):
    return np.vstack([np.hstack([-np.eye(3), np.asarray(lower)[:, None]]),
                      np.hstack([np.eye(3), -np.asarray(upper)[:, None]])])


def test_clipped_tetrahedron_against_qhull():
    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(200):
        corners = rng.normal(size=(4, 3))
        lower = rng.normal(size=3) * 0.5 - 0.3
        upper = lower + rng.uniform(0.2, 1.5, size=3)
        reference = _polytope_volume(np.vstack([ConvexHull(corners).equations,
                                                _box_halfspaces(lower, upper)]))
        assert clip_volume(corners, lower, upper) == pytest.approx(reference, rel=1e-12, abs=1e-14)
        checked += reference > 0
    assert checked > 50          # the boxes really cut the tetrahedra


def _overlap_1d(a0, a1, b0, b1):
    return np.maximum(np.minimum(a1, b1) - np.maximum(a0, b0), 0.0)


def test_axis_aligned_box_gives_products_of_overlaps():
    h = 0.1
    grid = FluidGrid(lower=(0, 0, 0), upper=(1.0, 0.8, 0.6), cells=(10, 8, 6))
    mesh = rr.shapes.box(lengths=(0.33, 0.27, 0.21))
    lower = np.array([0.217, 0.131, 0.052])
    nodes = mesh.nodes - mesh.nodes.min(axis=0) + lower
    upper = lower + nodes.max(axis=0) - nodes.min(axis=0)
    volumes = body_cell_volumes(grid, nodes, mesh.tets, [0, len(mesh.tets)])
    faces = [np.arange(n + 1) * h for n in grid.cells]
    exact = (_overlap_1d(faces[0][:-1], faces[0][1:], lower[0], upper[0])[:, None, None]
             * _overlap_1d(faces[1][:-1], faces[1][1:], lower[1], upper[1])[None, :, None]
             * _overlap_1d(faces[2][:-1], faces[2][1:], lower[2], upper[2])[None, None, :])
    assert np.abs(volumes.solid_volume() - exact).max() < 1e-12 * h ** 3
    assert volumes.body_volume(0) == pytest.approx(0.33 * 0.27 * 0.21, rel=1e-12)


def test_rotated_box_cell_by_cell_against_qhull():
    h = 0.05
    grid = FluidGrid(lower=(-0.3, -0.3, -0.3), upper=(0.3, 0.3, 0.3), cells=(12, 12, 12))
    mesh = rr.shapes.box(lengths=(0.31, 0.17, 0.23))
    angle = 0.7
    axis = np.array([1.0, 2.0, 0.5]) / np.linalg.norm([1.0, 2.0, 0.5])
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    rotation = np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k
    nodes = mesh.nodes @ rotation.T + np.array([0.013, -0.021, 0.007])
    volumes = body_cell_volumes(grid, nodes, mesh.tets, [0, len(mesh.tets)])
    hull = ConvexHull(nodes).equations
    (i0, j0, k0), block = volumes.block(0)
    compared = 0
    for (a, b, c), value in np.ndenumerate(block):
        lower = np.array(grid.lower) + h * np.array([i0 + a, j0 + b, k0 + c])
        reference = _polytope_volume(np.vstack([hull, _box_halfspaces(lower, lower + h)]))
        assert value == pytest.approx(reference, rel=1e-9, abs=1e-12 * h ** 3)
        compared += 0 < reference < h ** 3 * (1 - 1e-9)
    assert compared > 100        # cells the surface cuts, not only full or empty ones
    assert volumes.body_volume(0) == pytest.approx(0.31 * 0.17 * 0.23, rel=1e-12)


def test_bodies_partly_outside_and_thread_count():
    grid = FluidGrid(lower=(0, 0, 0), upper=(0.4, 0.4, 0.4), cells=(8, 8, 8))
    rocks = [rr.shapes.random_rock(size=0.15, seed=s) for s in range(4)]
    centres = np.array([[0.2, 0.2, 0.2], [0.02, 0.2, 0.3], [0.38, 0.41, 0.1], [0.9, 0.9, 0.9]])
    nodes, tets, start = [], [], [0]
    for rock, centre in zip(rocks, centres):
        tets.append(rock.tets + sum(len(n) for n in nodes))
        nodes.append(rock.nodes - rock.nodes.mean(axis=0) + centre)
        start.append(start[-1] + len(rock.tets))
    nodes, tets = np.concatenate(nodes), np.concatenate(tets)
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        single = body_cell_volumes(grid, nodes, tets, start)
    finally:
        numba.set_num_threads(threads)
    volumes = body_cell_volumes(grid, nodes, tets, start)
    assert np.array_equal(single.values, volumes.values)
    # wholly inside: every bit counted; partly outside: less; outside: nothing
    assert volumes.body_volume(0) == pytest.approx(rocks[0].volumes().sum(), rel=1e-12)
    assert 0 < volumes.body_volume(1) < rocks[1].volumes().sum()
    assert 0 < volumes.body_volume(2) < rocks[2].volumes().sum()
    assert volumes.body_volume(3) == 0.0
    fraction = volumes.solid_fraction()
    assert fraction.min() >= 0 and fraction.max() <= 1
    # the part of body 1 inside the grid: its volume on the side x >= 0 (one clip of every tet)
    first = nodes[tets[start[1]:start[2]]]
    inside = sum(clip_volume(t, np.array([0.0, -1, -1]), np.array([1.0, 1, 1])) for t in first)
    assert volumes.body_volume(1) == pytest.approx(inside, rel=1e-12)


def test_rigid_bodies_of_a_solver():
    solver = rr.SolidSolver(gravity=(0, 0, 0))
    rock = rr.RigidShape.from_mesh(rr.shapes.random_rock(size=0.2, seed=5), name="rock")
    solver.add_shape(rock)
    solver.add_material(rr.Material(name="rock"))
    orientation = np.array([0.9, 0.1, -0.3, 0.2])
    solver.add_body(shape=0, material="rock", position=(0.31, 0.27, 0.22),
                    orientation=orientation / np.linalg.norm(orientation))
    grid = FluidGrid(lower=(0, 0, 0), upper=(0.6, 0.6, 0.6), cells=(24, 24, 24))
    volumes = rigid_body_cell_volumes(grid, solver)
    assert volumes.body_volume(0) == pytest.approx(rock.volume, rel=1e-12)
    # the solid's centre of volume from the cells lies at the body's centroid within a cell
    solid = volumes.solid_volume()
    centres = [grid.centres(a) for a in range(3)]
    centroid = [np.sum(solid * np.expand_dims(centres[a], [b for b in range(3) if b != a]))
                / solid.sum() for a in range(3)]
    assert np.allclose(centroid, solver.positions[0], atol=grid.cell_size / 2)


def test_bad_input_is_named():
    grid = FluidGrid(lower=(0, 0, 0), upper=(1, 1, 1), cells=(4, 4, 4))
    nodes = np.array([[0.1, 0.1, 0.1], [0.5, 0.1, 0.1], [0.1, 0.5, 0.1], [0.1, 0.1, np.nan]])
    with pytest.raises(CaseFileError, match="node 3 .body 0. is not finite"):
        body_cell_volumes(grid, nodes, [[0, 1, 2, 3]], [0, 1])
    with pytest.raises(CaseFileError, match="tets refer to nodes"):
        body_cell_volumes(grid, nodes[:3], [[0, 1, 2, 3]], [0, 1])


def test_surface_integration_equals_clipping_tetrahedra():
    """The boundary-only integration (what the coupling uses) against the tet-by-tet clipping,
    cell by cell, for non-convex bodies in random orientations, partly outside the grid."""
    from scipy.spatial.transform import Rotation
    from riprap.coupling.solid_volumes import surface_cell_volumes
    grid = FluidGrid(lower=(0, 0, 0), upper=(0.4, 0.4, 0.3), cells=(16, 16, 12))
    meshes = [rr.shapes.random_rock(size=0.15, seed=3), rr.shapes.l_shape(length=0.16, width=0.1, thickness=0.05),
              rr.shapes.tetrapod(height=0.2), rr.shapes.random_rock(size=0.12, seed=4)]
    rng = np.random.default_rng(11)
    nodes, tets, triangles, tet_start, triangle_start = [], [], [], [0], [0]
    count = 0
    for i, mesh in enumerate(meshes):
        shape = rr.RigidShape.from_mesh(mesh)
        rotation = Rotation.random(random_state=i).as_matrix()
        centre = rng.uniform(0.0, 0.3, 3) if i < 3 else np.array([0.39, 0.01, 0.15])
        nodes.append((mesh.nodes - mesh.nodes.mean(axis=0)) @ rotation.T + centre)
        tets.append(mesh.tets + count)
        triangles.append(shape.triangles + count)
        count += len(mesh.nodes)
        tet_start.append(tet_start[-1] + len(mesh.tets))
        triangle_start.append(triangle_start[-1] + len(shape.triangles))
    nodes = np.concatenate(nodes)
    clipped = body_cell_volumes(grid, nodes, np.concatenate(tets), tet_start)
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        single = surface_cell_volumes(grid, nodes, np.concatenate(triangles), triangle_start)
    finally:
        numba.set_num_threads(threads)
    surface = surface_cell_volumes(grid, nodes, np.concatenate(triangles), triangle_start)
    assert np.array_equal(single.values, surface.values)
    assert np.array_equal(clipped.offset, surface.offset)
    cell = grid.cell_size ** 3
    assert np.abs(clipped.values - surface.values).max() < 1e-12 * cell
    assert (surface.values >= 0).all()
    assert 0 < surface.body_volume(3) < meshes[3].volumes().sum()


def test_half_cell_volumes_of_a_box_are_products_of_overlaps():
    """The halves of every cell along each axis (the faces' control volumes of the coupling) for
    an axis-aligned box body: products of 1D overlaps, and the cells as their sums."""
    from riprap.coupling.solid_volumes import rigid_body_half_cell_volumes

    h = 0.1
    grid = FluidGrid(lower=(0, 0, 0), upper=(1.0, 0.8, 0.6), cells=(10, 8, 6))
    solver = rr.SolidSolver(gravity=(0, 0, 0))
    solver.add_shape(rr.RigidShape.from_mesh(rr.shapes.box(lengths=(0.33, 0.27, 0.21)),
                                             name="box"))
    solver.add_material(rr.Material(name="concrete"))
    centre = np.array([0.217, 0.131, 0.052]) + 0.5 * np.array([0.33, 0.27, 0.21])
    solver.add_body(shape=0, material="concrete", position=centre)
    [(origin, cells, halves)] = rigid_body_half_cell_volumes(grid, solver)
    lower, upper = centre - [0.165, 0.135, 0.105], centre + [0.165, 0.135, 0.105]
    edges = [np.arange(n + 1) * h for n in grid.cells]
    for axis in range(3):
        for side in range(2):
            overlaps = []
            for a in range(3):
                first, last = edges[a][:-1], edges[a][1:]
                if a == axis:   # the lower or the upper half of each cell along this axis
                    first, last = (first, first + h / 2) if side == 0 else (first + h / 2, last)
                overlaps.append(_overlap_1d(first, last, lower[a], upper[a]))
            exact = overlaps[0][:, None, None] * overlaps[1][None, :, None] * overlaps[2][None, None, :]
            bi, bj, bk = cells.shape
            block = exact[origin[0]:origin[0] + bi, origin[1]:origin[1] + bj, origin[2]:origin[2] + bk]
            assert np.abs(halves[..., axis, side] - block).max() < 1e-12 * h ** 3
            assert exact.sum() == pytest.approx(block.sum(), rel=1e-12)   # the block holds it all
        assert np.abs(halves[..., axis, :].sum(axis=-1) - cells).max() < 1e-12 * h ** 3
    assert cells.sum() == pytest.approx(0.33 * 0.27 * 0.21, rel=1e-12)
