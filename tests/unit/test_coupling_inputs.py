"""CoupledSolver refuses bodies it cannot take, naming the body, and clips only bodies that moved."""
import numpy as np
import pytest

from riprap import FluidGrid, FluidSolver
from riprap.coupling.coupled import MINIMUM_CELLS_ACROSS, RECLIP_DISTANCE, CoupledSolver
from riprap.errors import CaseFileError
from riprap.geometry import shapes
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver


def _setup(cells, side, position, *, fixed=False, second=None):
    grid = FluidGrid(lower=(0.0, 0.0, 0.0), upper=(0.4, 0.4, 0.4), cells=(cells,) * 3)
    fluid = FluidSolver(grid, surface_tension=0.0)
    fluid.set_still_water_level(0.3)
    solids = SolidSolver()
    shape = solids.add_shape(RigidShape.from_mesh(shapes.cube(side=side, mesh_size=side / 2)))
    solids.add_material(Material(name="concrete", density=2400.0, contact_penalty=1e7))
    solids.add_body(shape=shape, material="concrete", position=position, fixed=fixed)
    if second is not None:
        solids.add_body(shape=shape, material="concrete", position=second)
    return fluid, solids


def test_a_body_outside_the_fluid_box_is_named():
    fluid, solids = _setup(16, 0.1, (0.2, 0.2, 0.2), second=(0.38, 0.2, 0.2))
    with pytest.raises(CaseFileError, match="body 1 reaches .* outside the fluid box"):
        CoupledSolver(fluid, solids)


def test_a_moving_body_too_small_for_the_cells_says_what_is_needed():
    fluid, solids = _setup(8, 0.1, (0.2, 0.2, 0.2))       # 0.05 m cells, a 0.1 m cube: 2 across
    with pytest.raises(CaseFileError, match=r"body 0 is 2 cells across .* at least 3"):
        CoupledSolver(fluid, solids)
    assert MINIMUM_CELLS_ACROSS == 3.0


def test_fixed_bodies_are_clipped_once():
    fluid, solids = _setup(16, 0.1, (0.2, 0.2, 0.1), fixed=True, second=(0.2, 0.2, 0.25))
    coupled = CoupledSolver(fluid, solids)
    assert coupled.last_clipped_bodies == 2        # both, to find the fixed one's deep cells
    coupled.step()
    assert coupled.last_clipped_bodies == 0        # nothing moved since
    coupled.step()
    assert coupled.last_clipped_bodies == 1        # only the moving cube


def test_a_body_is_clipped_again_only_once_it_has_moved_a_thousandth_of_a_cell():
    """RECLIP_DISTANCE: a nudge of 0.5e-3 h keeps the body's block (its volumes are those of the
    last clipping), 1.5e-3 h in all clips it again; the clipping pose rides in the checkpoint, so
    a restored solver clips where the original had (restart bit for bit)."""
    fluid, solids = _setup(16, 0.1, (0.2, 0.2, 0.2))
    coupled = CoupledSolver(fluid, solids)
    h = fluid.h
    clipped = coupled._solid_volumes().block(0)[1].copy()
    solids.positions[0, 0] += 0.5 * RECLIP_DISTANCE * h
    again = coupled._solid_volumes().block(0)[1]
    assert coupled.last_clipped_bodies == 0 and np.array_equal(again, clipped)
    arrays = coupled.state_arrays()
    solids.positions[0, 0] += RECLIP_DISTANCE * h
    moved = coupled._solid_volumes().block(0)[1]
    assert coupled.last_clipped_bodies == 1 and not np.array_equal(moved, clipped)

    restored_fluid, restored_solids = _setup(16, 0.1, (0.2, 0.2, 0.2))
    restored = CoupledSolver(restored_fluid, restored_solids)
    restored.load_state_arrays(arrays)
    assert np.array_equal(restored._solid_volumes().block(0)[1], clipped)
