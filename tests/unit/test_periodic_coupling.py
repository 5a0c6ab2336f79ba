"""Bodies in the flow of a periodic strip (issue 53): a body across the strip's side is clipped in
both images, its faces' arms are taken to the image nearest it, and the strip's sides are no walls.

What is checked, and against what: nothing in a periodic strip marks where its side lies, so a
cube placed across the side must move as the same cube in the middle of the strip (the whole
state shifted by whole cells): sinking through water and resting on a fixed block, its velocity,
spin and fluid load equal the middle one's to 1e-9 of their size (the clipping's coordinates differ
by round-off); the solid volume the fluid sees is the cube's whole volume, and the bodies get no
walls at the strip's sides. A fluid with walls refuses bodies made periodic, and deformable bodies
are refused on a strip.
"""
import numpy as np
import pytest

from riprap import FluidGrid, FluidSolver
from riprap.coupling.coupled import CoupledSolver
from riprap.errors import CaseFileError
from riprap.geometry import shapes
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

STRIP = {"y_low": "periodic", "y_high": "periodic"}
H = 0.025                      # cells (m)
WIDTH = 16 * H                 # the strip


def _cube_in_strip(y, *, boundaries=STRIP, base=True):
    grid = FluidGrid(lower=(0.0, 0.0, 0.0), upper=(0.3, WIDTH, 0.3), cells=(12, 16, 12),
                     boundaries=boundaries)
    fluid = FluidSolver(grid, surface_tension=0.0)
    fluid.set_still_water_level(0.25)
    solids = SolidSolver()
    cube = solids.add_shape(RigidShape.from_mesh(shapes.cube(side=0.1, mesh_size=0.05)))
    solids.add_material(Material(name="concrete", density=2400.0, contact_penalty=1e7))
    solids.add_body(shape=cube, material="concrete", position=(0.15, y, 0.12))
    if base:     # a fixed block under it, across the strip's side too
        block = solids.add_shape(RigidShape.from_mesh(shapes.box(lengths=(0.14, 0.14, 0.05),
                                                                 mesh_size=0.05)))
        solids.add_body(shape=block, material="concrete", position=(0.15, y, 0.035), fixed=True)
    return CoupledSolver(fluid, solids)


def test_a_cube_across_the_side_moves_as_one_in_the_middle():
    """A cube 4 cells wide (and the fixed block under it) in the middle of the strip and shifted
    by 8 cells, so that the strip's side cuts them through: 40 coupled steps of 2 ms (it sinks
    onto the block and settles), the cube's velocity and spin, its fluid load and the fluid's
    velocities (rolled by 8 cells) equal to 1e-9 of their size; the cube's volume is all in the
    grid both times; no wall at the strip's sides."""
    middle = _cube_in_strip(WIDTH / 2)
    across = _cube_in_strip(WIDTH / 2 + 8 * H - WIDTH)      # its centre at y = 0 (wrapped)
    assert not any(abs(wall.normal[1]) > 0 for wall in across.solids.walls)
    volume = 0.1 ** 3
    assert across._solid_volumes().body_volume(0) == pytest.approx(volume, rel=1e-12)
    assert across.body_fraction().sum() * H ** 3 == pytest.approx(
        middle.body_fraction().sum() * H ** 3, rel=1e-12)
    for _ in range(40):
        middle.step(2e-3)
        across.step(2e-3)
    speed = np.abs(middle.solids.velocities[0]).max()
    assert speed > 1e-3                                   # it moved
    assert np.abs(across.solids.velocities[0] - middle.solids.velocities[0]).max() < 1e-9 * speed
    spin_middle = middle.solids.angular_velocities[0]
    spin_across = across.solids.angular_velocities[0]
    assert np.abs(spin_across - spin_middle).max() < 1e-9 * max(speed / 0.05, 1e-12)
    load = np.abs(middle.fluid_loads[0]).max()
    assert np.abs(across.fluid_loads[0] - middle.fluid_loads[0]).max() < 1e-9 * load
    for name in ("u", "w", "fraction"):
        rolled = np.roll(getattr(middle.fluid, name), -8, axis=1)
        scale = max(np.abs(rolled).max(), 1e-12)
        assert np.abs(getattr(across.fluid, name) - rolled).max() < 1e-9 * max(scale, 1.0), name


def test_bodies_made_periodic_in_a_walled_fluid_are_refused():
    grid = FluidGrid(lower=(0.0, 0.0, 0.0), upper=(0.3, WIDTH, 0.3), cells=(12, 16, 12))
    fluid = FluidSolver(grid, surface_tension=0.0)
    fluid.set_still_water_level(0.25)
    solids = SolidSolver()
    cube = solids.add_shape(RigidShape.from_mesh(shapes.cube(side=0.1, mesh_size=0.05)))
    solids.add_material(Material(name="concrete", density=2400.0, contact_penalty=1e7))
    solids.add_body(shape=cube, material="concrete", position=(0.15, 0.2, 0.12))
    solids.set_periodic(1, 0.0, WIDTH)
    with pytest.raises(CaseFileError, match="make the fluid's y sides periodic"):
        CoupledSolver(fluid, solids)


def test_a_strip_run_restarts_bit_for_bit():
    """A cube across the strip's side sinking onto the block: 8 steps straight, against 4 steps,
    its state taken (``state_arrays``, a checkpoint's) into a new solver built alike, and 4 more:
    the fluid's fields and the bodies' poses and velocities equal bit for bit."""
    straight = _cube_in_strip(0.0)
    for _ in range(8):
        straight.step(2e-3)
    first = _cube_in_strip(0.0)
    for _ in range(4):
        first.step(2e-3)
    state = first.state_arrays()
    second = _cube_in_strip(0.0)
    second.load_state_arrays(state)
    for _ in range(4):
        second.step(2e-3)
    for name in ("fraction", "u", "v", "w", "pressure"):
        assert np.array_equal(getattr(second.fluid, name), getattr(straight.fluid, name)), name
    for name in ("positions", "quaternions", "velocities", "angular_momenta"):
        assert np.array_equal(getattr(second.solids, name), getattr(straight.solids, name)), name


_BODY_IN_STRIP = """format_version = 1
[simulation]
end_time = 0.1
{simulation}
[[materials]]
name = "concrete"
density = 2400.0
[[shapes]]
name = "cube"
type = "cube"
side = 0.1
[[bodies]]
shape = "cube"
material = "concrete"
position = [0.2, 0.05, 0.1]
{rest}
"""
_FLUID = """[fluid]
lower = [0.0, 0.0, 0.0]
upper = [0.4, {width}, 0.3]
cells = [16, {ny}, 12]
y_low = "{sides}"
y_high = "{sides}"
surface_tension = 0.0
[[water_regions]]
type = "level"
level = 0.2
"""
_WALL = """[[walls]]
type = "plane"
material = "concrete"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
"""


@pytest.mark.parametrize("simulation, rest, words", [
    ("", _FLUID.format(width=0.2, ny=8, sides="periodic"), "shorter than twice the bounding"),
    ("periodic_y_low = 0.0\nperiodic_y_high = 0.4", _FLUID.format(width=0.4, ny=16,
                                                                     sides="no_slip"),
     "has walls at its y sides"),
    ("periodic_y_low = 0.0\nperiodic_y_high = 0.35", _FLUID.format(width=0.4, ny=16,
                                                                      sides="periodic"),
     "is not the [fluid] box's y range"),
    ("periodic_y_low = 0.4\nperiodic_y_high = 0.0", "", "must exceed periodic_y_low"),
    ("periodic_y_low = 0.0\nperiodic_y_high = 0.4", _WALL, "faces along y, the periodic"),
])
def test_riprap_check_names_each_refusal_of_bodies_on_a_strip(tmp_path, capsys, simulation,
                                                               rest, words):
    """``riprap check``: a strip narrower than twice a body's bounding diameter, bodies made a
    strip in a walled fluid box or on another width than its strip, a strip whose sides are
    swapped, a wall across a dry strip: exit 2, one line naming why."""
    from riprap.cli import main
    path = tmp_path / "strip.toml"
    path.write_text(_BODY_IN_STRIP.format(simulation=simulation, rest=rest))
    assert main(["check", str(path)]) == 2
    error = capsys.readouterr().err
    assert words in error, error
