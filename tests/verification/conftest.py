"""Shared fixtures of the verification tests: small solver set-ups and contact timing.

The verification cases hold one to a dozen bodies. For so few candidate pairs the thread launch of
the parallel pair loop (``interactions.evaluate_candidates``) costs far more than the pair work, and
on a 2-core machine shared with other jobs a parallel region can wait a whole scheduler slice for
its second thread (measured here while other jobs ran: 3000 steps of a box resting on a plane took
1.0 s on one thread and 72 s on two). The results do not depend on the thread count (every pair
writes its own row), so the verification tests run numba on one thread and restore the previous
setting afterwards.
"""
import numba
import pytest

from riprap.solid import walls
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver


@pytest.fixture(autouse=True, scope="module")
def _one_numba_thread():
    previous = numba.get_num_threads()
    numba.set_num_threads(1)
    yield
    numba.set_num_threads(previous)


def _material(*, name="m", density=2650.0, friction_coefficient=0.0, restitution=1.0,
              contact_penalty=1.0e8, tangential_stiffness_ratio=2.0 / 7.0):
    return Material(name=name, density=density, friction_coefficient=friction_coefficient,
                    restitution=restitution, contact_penalty=contact_penalty,
                    tangential_stiffness_ratio=tangential_stiffness_ratio)


@pytest.fixture
def body_on_plane():
    """Factory: a solver with one free body above the plane z = 0 (or no plane).

    ``body_on_plane(mesh, position=..., velocity=..., gravity=..., plane=True, time_step_factor=1,
    time_step=None, **material)`` returns the finalized solver; ``time_step_factor`` scales the
    automatic step, ``time_step`` (s) replaces it.
    """

    def build(mesh, *, position, velocity=(0.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 0.0),
              orientation=(1.0, 0.0, 0.0, 0.0), gravity=(0.0, 0.0, 0.0), plane=True,
              time_step_factor=1.0, time_step=None, local_damping=0.0, shape=None, **material):
        solver = SolidSolver(gravity=gravity, local_damping=local_damping)
        k = solver.add_shape(shape if shape is not None else RigidShape.from_mesh(mesh))
        m = solver.add_material(_material(**material))
        if plane:
            solver.add_walls(walls.plane(point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0), material="m"))
        solver.add_body(shape=k, material=m, position=position, orientation=orientation,
                        velocity=velocity, angular_velocity=angular_velocity)
        solver.time_step = (time_step if time_step is not None
                            else time_step_factor * solver.stable_time_step())
        solver.finalize()
        return solver

    return build


@pytest.fixture
def run_through_contact():
    """Function: step a solver one step at a time until a contact has started and ended.

    ``run_through_contact(solver, max_steps)`` returns the number of steps during which at least
    one contact was active (the contact duration is that times the time step). Fails the test if no
    contact starts or if it does not end within ``max_steps``.
    """

    def run(solver, max_steps):
        first = last = None
        for n in range(1, max_steps + 1):
            solver.step()
            if len(solver.contacts):
                first = n if first is None else first
                last = n
            elif first is not None:
                return last - first + 1
        pytest.fail(f"contact {'never started' if first is None else 'did not end'} within "
                    f"{max_steps} steps (time step {solver.time_step:.3e} s)")

    return run


@pytest.fixture(scope="session")
def small_placement(tmp_path_factory):
    """``examples/coreloc_small.toml`` placed in full once per session: (summary, output folder)."""
    from pathlib import Path

    from riprap.workflows.place import run_placement
    from riprap.case.load import load_case

    example = Path(__file__).resolve().parents[2] / "examples" / "coreloc_small.toml"
    folder = tmp_path_factory.mktemp("coreloc_small")
    previous = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        summary = run_placement(load_case(example), output_directory=folder, progress=False)
    finally:
        numba.set_num_threads(previous)
    return summary, folder
