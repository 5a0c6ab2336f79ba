"""Run under ``mpiexec -n N``: the slab pressure solve against one process's ``PressureSolver`` on
1000:1 problems (3D with drops and bubbles, 2D, a closed tank, listed cells); prints one line per
problem and exits 1 if a slab's pressure differs from the one process's in any bit."""
import sys
from pathlib import Path

import numpy as np

from riprap.fluid.pressure import PressureSolver
from riprap.fluid.slab_pressure import DISTRIBUTED_LEVELS, SlabPressureSolver
from riprap.parallel.communicator import world
from riprap.parallel.slabs import cut_slabs

# the one-process solver's tests' 1000:1 problems
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "unit"))
from test_fluid_pressure import blob_density, face_coefficients  # noqa: E402

def check(name, shape, seed, open_top=True, listed=False, comm=None):
    density = blob_density(shape, seed)
    beta = face_coefficients(density, open_top=open_top)
    rng = np.random.default_rng(seed + 1)
    rhs = rng.standard_normal(shape)
    guess = rng.standard_normal(shape) * 10.0
    listed_global = None
    if listed:
        block = np.zeros(shape, dtype=bool)
        block[shape[0] // 3: 2 * shape[0] // 3 + 1, :, shape[2] // 3: shape[2] // 2] = True
        listed_global = block
    serial = PressureSolver(shape, 0.05, tolerance=1e-9)
    expected, report = serial.solve(*beta, rhs, p_initial=guess,
                                    listed_cells=None if listed_global is None
                                    else np.flatnonzero(listed_global))
    cut = cut_slabs(shape[0], comm.size, alignment=2 ** DISTRIBUTED_LEVELS,
                    thinnest=2 ** DISTRIBUTED_LEVELS)
    first, stop = cut.first(comm.rank), cut.stop(comm.rank)
    low = 1 if comm.rank > 0 else 0
    high = 1 if comm.rank < comm.size - 1 else 0
    cells = slice(first - low, stop + high)
    faces = slice(first - low, stop + high + 1)
    solver = SlabPressureSolver(shape, 0.05, cut, comm, tolerance=1e-9)
    local_listed = None
    if listed_global is not None:
        mine = np.zeros_like(listed_global[cells])
        mine[low:low + stop - first] = listed_global[first:stop]
        local_listed = np.flatnonzero(mine)
    got, got_report = solver.solve(beta[0][faces], beta[1][cells], beta[2][cells], rhs[cells],
                                   p_initial=guess[cells], listed_cells=local_listed)
    same = np.array_equal(got[low:low + stop - first], expected[first:stop])
    ghosts_same = np.array_equal(got, expected[cells])
    ok = comm.sum_int(0 if (same and ghosts_same) else 1) == 0
    if comm.rank == 0:
        print(f"{name}: {report.iterations} iterations on one process, "
              f"{got_report.iterations} over {comm.size}; slabs {cut.starts}; "
              f"{'bit for bit' if ok else 'DIFFERENT'}", flush=True)
    return ok and got_report.iterations == report.iterations


def main():
    comm = world()
    results = [
        check("3D drops and bubbles", (37, 11, 19), 3, comm=comm),
        check("3D with listed cells", (40, 9, 17), 5, listed=True, comm=comm),
        check("2D x-z", (96, 1, 40), 7, comm=comm),
        check("closed tank", (33, 6, 14), 11, open_top=False, comm=comm),
    ]
    sys.exit(0 if all(results) else 1)


if __name__ == "__main__":
    main()
