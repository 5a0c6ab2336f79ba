"""A block of a fluid grid's x-planes (``FluidGrid.block``) has the whole grid's coordinates to
the bit, so that water, obstacles and porous zones built on the block are the whole grid's cells
on those planes, bit for bit: what a process of a split run needs to build its block without the
whole grid (issue 39, the memory split)."""
import copy

import numpy as np
import pytest

from riprap.errors import CaseFileError
from riprap.fluid.grid import BlockGrid, FluidGrid
from riprap.fluid.porous import PorousZone
from riprap.fluid.solver import FluidSolver

# the damage curve's flume: a corner and a cell size that do not add up exactly in binary
WHOLE = FluidGrid(lower=(-2.595, -0.0075, 0.0), upper=(1.5, 0.1275, 0.75), cells=(273, 9, 50))
BLOCKS = [(0, 68), (60, 140), (133, 273), (265, 273)]


@pytest.mark.parametrize("first, stop", BLOCKS)
def test_a_block_has_the_whole_grids_coordinates_to_the_bit(first, stop):
    block = WHOLE.block(first, stop)
    assert isinstance(block, BlockGrid) and block.cells == (stop - first, 9, 50)
    assert block.cell_size == WHOLE.cell_size
    np.testing.assert_array_equal(block.centres(0), WHOLE.centres(0)[first:stop])
    np.testing.assert_array_equal(block.faces(0), WHOLE.faces(0)[first:stop + 1])
    for axis in (1, 2):
        np.testing.assert_array_equal(block.centres(axis), WHOLE.centres(axis))
        np.testing.assert_array_equal(block.faces(axis), WHOLE.faces(axis))
    assert block.lower[0] == WHOLE.faces(0)[first] and block.upper[0] == WHOLE.faces(0)[stop]
    point = (float(block.centres(0)[-1]), 0.05, 0.3)
    i, j, k = WHOLE.cell_of(point)
    assert block.cell_of(point) == (i - first, j, k)


def test_a_block_outside_the_grid_and_a_point_outside_the_block_are_refused():
    with pytest.raises(CaseFileError, match="x-planes 10 .. 300 does not lie within"):
        WHOLE.block(10, 300)
    with pytest.raises(CaseFileError, match="x-planes 5 .. 5"):
        WHOLE.block(5, 5)
    with pytest.raises(CaseFileError, match=r"outside the block .* \(x-planes 60 .. 139 of"):
        WHOLE.block(60, 140).cell_of((1.4, 0.05, 0.3))


def _flume(grid):
    fluid = FluidSolver(grid)
    fluid.set_still_water_level(0.5)
    fluid.add_water_box((-0.4, -0.0075, 0.0), (0.3, 0.1275, 0.6371))
    fluid.add_obstacle_box((-0.9031, 0.0, 0.0), (-0.2, 0.1275, 0.0602))
    fluid.add_porous_zones([
        PorousZone(porosity=0.4, stone_diameter=0.01, name="core",
                   polygon=[[-0.6, 0.0], [0.87, 0.6], [1.2, 0.6], [1.2, 0.0]]),
        PorousZone(porosity=0.5, stone_diameter=0.02, name="filter",
                   lower=(-0.71, -0.0075, 0.0), upper=(0.1, 0.1275, 0.1333))])
    return fluid


def test_water_obstacles_and_porous_zones_built_on_a_block_are_the_whole_grids_cells():
    whole = _flume(WHOLE)
    for first, stop in [(0, 40), (60, 140), (133, 273)]:     # (0, 40) misses the zones
        block = _flume(WHOLE.block(first, stop))
        assert block.h == whole.h
        np.testing.assert_array_equal(block.fraction, whole.fraction[first:stop])
        np.testing.assert_array_equal(block.solid, whole.solid[first:stop])
        np.testing.assert_array_equal(block.porous.porosity, whole.porous.porosity[first:stop])


def test_a_block_refuses_what_the_whole_grid_refuses_and_only_that():
    """A zone, obstacle or water box that misses the block but not the whole grid is built
    (nothing on the block); one that misses the whole grid is refused on every block."""
    block = FluidSolver(WHOLE.block(0, 40))
    block.add_obstacle_box((-0.9031, 0.0, 0.0), (-0.2, 0.1275, 0.0602))
    block.add_water_box((-0.4, -0.0075, 0.0), (0.3, 0.1275, 0.6371))
    assert not block.solid.any() and not block.fraction.any()
    with pytest.raises(CaseFileError, match="holds no cell centre"):
        block.add_obstacle_box((2.0, 0.0, 0.0), (3.0, 0.1, 0.1))
    with pytest.raises(CaseFileError, match="lies outside the fluid box .-2.595"):
        block.add_water_box((2.0, 0.0, 0.0), (3.0, 0.1, 0.1))
    with pytest.raises(CaseFileError, match="far: covers no part of the fluid grid"):
        block.add_porous_zones([PorousZone(porosity=0.4, stone_diameter=0.01, name="far",
                                           polygon=[[2.0, 0.0], [3.0, 0.6], [3.0, 0.0]])])


def test_relaxation_zones_prepared_on_a_block_are_the_whole_grids_cut_to_it():
    """The wave-making and absorbing zones prepared on a block's own coordinates give the same
    cells, faces and weights as the whole grid's zones cut to the block
    (``_relaxation_cut``, what the split runs did before); a
    block that holds no part of a zone leaves it out, one that the whole grid misses is refused."""

    from riprap.waves.relaxation import ABSORPTION, GENERATION, RelaxationZone, WaveRelaxation
    from riprap.waves.theory import LinearWave

    zones = [RelaxationZone(GENERATION, -2.595, -1.6), RelaxationZone(ABSORPTION, 0.9, 1.5)]
    wave = LinearWave(height=0.05, period=1.2, depth=0.5)
    whole = WaveRelaxation(wave, 0.5, zones)
    whole._prepare(FluidSolver(WHOLE))
    for first, stop in [(0, 68), (60, 140), (190, 273)]:
        cut = _relaxation_cut(copy.copy(whole), None, first, stop)
        own = WaveRelaxation(wave, 0.5, zones)
        own._prepare(FluidSolver(WHOLE.block(first, stop)))
        assert len(own._cache[0]) == len(cut._cache[0])
        for mine, theirs in zip(own._cache[0], cut._cache[0]):
            assert mine[0] is theirs[0]
            for a, b in zip(mine[1:], theirs[1:]):
                np.testing.assert_array_equal(a, b)
        for a, b in zip(own._cache[1:5], cut._cache[1:5]):
            np.testing.assert_array_equal(a, b)
    with pytest.raises(CaseFileError, match="zone x = 2 .. 3 m holds no cell centre"):
        WaveRelaxation(None, 0.5, [RelaxationZone(ABSORPTION, 2.0, 3.0)])._prepare(
            FluidSolver(WHOLE.block(0, 68)))


def test_porous_zones_built_on_a_block_are_the_whole_grids_cut_to_it():
    """Porous zones built on a block's coordinates: the cells' porosity and every face's
    coefficients inside the block, and the list of porous faces, are those of the whole grid's
    zones cut to the block (``_porous_cut``); only the block's two end x-faces (walls of the
    block, which its halo covers) may differ."""
    whole = _flume(WHOLE).porous
    for first, stop in [(60, 140), (133, 273)]:
        cut = _porous_cut(whole, first, stop)
        own = _flume(WHOLE.block(first, stop)).porous
        np.testing.assert_array_equal(own.porosity, cut.porosity)
        for axis in range(3):
            inner = slice(1, -1) if axis == 0 else slice(None)
            for name in ("face_porosity", "scale", "linear_coefficient", "quadratic_coefficient"):
                np.testing.assert_array_equal(getattr(own, name)[axis][inner],
                                              getattr(cut, name)[axis][inner], err_msg=name)
            np.testing.assert_array_equal(own.faces[axis], cut.faces[axis])


# ---- the whole grid's parts cut to a block's planes: the reference the block's own are held to
# (what the split runs did before session 25: porous zones and relaxation zones built on the
# whole grid, their cells and faces shifted into the block)
def _porous_cut(porous, begin: int, stop: int):
    """``PorousMedium`` of the block's planes begin..stop-1: its arrays cut along x, its list of
    porous faces re-made, the block's two end x-faces left out (they are walls of the block)."""
    names = ("face_porosity", "scale", "linear_coefficient", "quadratic_coefficient")
    cut = {name: [] for name in names + ("faces",)}
    for axis in range(3):
        end = stop + (1 if axis == 0 else 0)
        for name in names:
            cut[name].append(np.ascontiguousarray(getattr(porous, name)[axis][begin:end]))
        mask = np.zeros(porous.face_porosity[axis].shape, dtype=bool)
        mask.reshape(-1)[porous.faces[axis]] = True
        mask = mask[begin:end].copy()
        if axis == 0:
            mask[0] = mask[-1] = False
        cut["faces"].append(np.flatnonzero(mask))
    block = copy.copy(porous)
    block.porosity = np.ascontiguousarray(porous.porosity[begin:stop])
    block._face_arrays, block._cells = cut, None       # (the face arrays PorousMedium makes)
    return block


def _relaxation_cut(relaxation, whole, begin: int, stop: int):
    """``WaveRelaxation`` whose prepared zones are the whole grid's, cut to the block's planes
    (the block's end x-faces left out)."""
    if relaxation._cache is None:
        relaxation._prepare(whole)
    prepared, x_cells, x_faces, z_cells, z_faces, h = relaxation._cache
    block_prepared = []
    for zone, cells, faces, cell_weight, face_weight in prepared:
        keep_cells = (cells >= begin) & (cells < stop)
        keep_faces = (faces > begin) & (faces < stop)
        if not keep_cells.any() and not keep_faces.any():
            continue
        block_prepared.append((zone, cells[keep_cells] - begin, faces[keep_faces] - begin,
                               cell_weight[keep_cells], face_weight[keep_faces]))
    block = copy.copy(relaxation)
    block._cache = (block_prepared, x_cells[begin:stop], x_faces[begin:stop + 1], z_cells,
                    z_faces, h)
    return block
