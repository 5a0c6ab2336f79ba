"""Run under ``mpiexec -n N``: the slab pressure solve against one process's ``PressureSolver`` on
1000:1 problems (3D with drops and bubbles, 2D, a closed tank, listed cells); prints one line per
problem and exits 1 if a slab's pressure differs from the one process's in any bit."""
import sys

import numpy as np

from riprap.fluid.pressure import PressureSolver
from riprap.fluid.slab_pressure import DISTRIBUTED_LEVELS, SlabPressureSolver
from riprap.parallel.communicator import world
from riprap.parallel.slabs import cut_slabs

WATER, AIR = 1000.0, 1.2


def face_coefficients(density, open_top=True):
    nx, ny, nz = density.shape
    beta_x = np.zeros((nx + 1, ny, nz))
    beta_y = np.zeros((nx, ny + 1, nz))
    beta_z = np.zeros((nx, ny, nz + 1))
    beta_x[1:-1] = 2.0 / (density[1:] + density[:-1])
    if ny > 1:
        beta_y[:, 1:-1] = 2.0 / (density[:, 1:] + density[:, :-1])
    beta_z[:, :, 1:-1] = 2.0 / (density[:, :, 1:] + density[:, :, :-1])
    if open_top:
        beta_z[:, :, -1] = 1.0 / density[:, :, -1]
    return beta_x, beta_y, beta_z


def blob_density(shape, seed):
    rng = np.random.default_rng(seed)
    nx, ny, nz = shape
    x, y, z = np.meshgrid((np.arange(nx) + 0.5) / nx, (np.arange(ny) + 0.5) / ny,
                          (np.arange(nz) + 0.5) / nz, indexing="ij")
    density = np.where(z < 0.45 + 0.1 * np.sin(7.0 * x) * np.cos(5.0 * y), WATER, AIR)
    for _ in range(12):
        centre = rng.random(3)
        radius = 0.05 + 0.12 * rng.random()
        inside = (x - centre[0]) ** 2 + (y - centre[1]) ** 2 * (ny > 1) + (z - centre[2]) ** 2
        density = np.where(inside < radius ** 2, WATER if rng.random() < 0.5 else AIR, density)
    return density


def check(name, shape, seed, open_top=True, listed=False, comm=None):
    density = blob_density(shape, seed)
    beta = face_coefficients(density, open_top)
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
