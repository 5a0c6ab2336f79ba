"""``riprap run`` with a stand-in for a blow-up (tests/parallel/test_mpi_runs.py): after its
fifth step, process 1 of a split run finds a non-finite pressure in its slab's cell 2 planes
past its first own plane, y-cell 0, z-cell 5.

    mpiexec -n 2 python tests/parallel/blow_up_run.py run CASE --out DIR
"""
import math
import sys

from riprap.cli import main
from riprap.fluid.solver import FluidSolver

_finish_step = FluidSolver.finish_step


def finish_step(self, u, v, w, pressure, report, dt, courant):
    comm = getattr(self, "comm", None)
    if comm is not None and comm.rank == 1 and self.step_count == 4:
        pressure[self.low + 2, 0, 5] = math.nan
    return _finish_step(self, u, v, w, pressure, report, dt, courant)


FluidSolver.finish_step = finish_step
sys.exit(main(sys.argv[1:]))
