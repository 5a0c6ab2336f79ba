"""Speed of the exact solid volumes in fluid cells (riprap.coupling.solid_volumes).

A rubble mound of the paper's size: ``--bodies`` rocks (Dn50 0.19 m, four shapes, random
orientations) on a jittered lattice in a flume 8 m long and 2 m wide, in fluid cells of ``--cell``
m (default Dn50 / 4). Prints tetrahedra, cells reached, seconds per evaluation on 1 and all
threads, and the solid share of the mound's cells. Last line: ``METRIC solid_volume_tets_per_s
<value> 1/s`` on all threads.

    python bench/solid_volumes.py                      # 3,436 rocks, as the paper's underlayer
"""
from __future__ import annotations

import argparse
import os
import time

import numba
import numpy as np

import riprap as rr
from riprap.coupling.solid_volumes import body_cell_volumes, surface_cell_volumes
from riprap.fluid.grid import FluidGrid

DN50 = 0.19


def mound(bodies: int, seed: int = 0):
    """World nodes, tets, tet_start, boundary triangles and triangle_start of ``bodies`` rocks on
    a jittered lattice."""
    rng = np.random.default_rng(seed)
    shapes = [rr.shapes.random_rock(size=DN50, seed=s) for s in range(4)]
    outward = [rr.RigidShape.from_mesh(shape).triangles for shape in shapes]
    triangles, triangle_start = [], [0]
    spacing = 1.15 * DN50
    per_row = int(8.0 / spacing) - 1
    per_column = int(2.0 / spacing) - 1
    nodes, tets, start = [], [], [0]
    count = 0
    for b in range(bodies):
        layer, rest = divmod(b, per_row * per_column)
        row, column = divmod(rest, per_row)
        centre = np.array([(column + 1) * spacing, (row + 1) * spacing, (layer + 0.6) * spacing])
        centre += rng.uniform(-0.05, 0.05, 3) * DN50
        quaternion = rng.normal(size=4)
        quaternion /= np.linalg.norm(quaternion)
        w, x, y, z = quaternion
        rotation = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                             [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                             [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
        shape = shapes[b % len(shapes)]
        local = shape.nodes - shape.nodes.mean(axis=0)
        nodes.append(local @ rotation.T + centre)
        tets.append(shape.tets + count)
        triangles.append(outward[b % len(shapes)] + count)
        count += len(local)
        start.append(start[-1] + len(shape.tets))
        triangle_start.append(triangle_start[-1] + len(triangles[-1]))
    return (np.concatenate(nodes), np.concatenate(tets), np.array(start),
            np.concatenate(triangles), np.array(triangle_start))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--bodies", type=int, default=3436)
    parser.add_argument("--cell", type=float, default=DN50 / 4, help="fluid cell size (m)")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    nodes, tets, start, triangles, triangle_start = mound(args.bodies)
    lower = nodes.min(axis=0) - 0.1
    cells = tuple(int(c) for c in np.ceil((nodes.max(axis=0) + 0.1 - lower) / args.cell))
    grid = FluidGrid(lower=tuple(lower), upper=tuple(lower + np.array(cells) * args.cell),
                     cells=cells)
    threads = numba.get_num_threads()
    print(f"machine: {os.cpu_count()} cores, numba threads {threads}, load {os.getloadavg()[0]:.2f}")
    print(f"{args.bodies:,} rocks, {len(tets):,} tetrahedra; grid {cells[0]} x {cells[1]} x "
          f"{cells[2]} = {grid.n_cells:,} cells of {args.cell:.4g} m")
    body_cell_volumes(grid, nodes, tets, start)           # compile and warm up
    rate = None
    for count in sorted({1, threads}):
        numba.set_num_threads(count)
        best = np.inf
        for _ in range(args.repeat):
            began = time.perf_counter()
            volumes = body_cell_volumes(grid, nodes, tets, start)
            best = min(best, time.perf_counter() - began)
        rate = len(tets) / best
        print(f"  {count} thread(s): {best:.3f} s per evaluation (best of {args.repeat}), "
              f"{rate:.3g} tetrahedra/s")
    numba.set_num_threads(threads)
    # what the coupling uses: the boundary triangles alone (the same volumes to round-off)
    surface_cell_volumes(grid, nodes, triangles, triangle_start)
    best = np.inf
    for _ in range(args.repeat):
        began = time.perf_counter()
        surface = surface_cell_volumes(grid, nodes, triangles, triangle_start)
        best = min(best, time.perf_counter() - began)
    print(f"  from the boundary triangles ({len(triangles):,}), {threads} thread(s): {best:.3f} s "
          f"per evaluation; largest difference from the clipping "
          f"{np.abs(surface.values - volumes.values).max() / args.cell ** 3:.1e} of a cell")
    solid = volumes.solid_volume()
    reached = solid > 0
    corners = nodes[tets]
    mesh_volume = np.abs(np.linalg.det(corners[:, 1:] - corners[:, :1])).sum() / 6
    print(f"cells reached {reached.sum():,}, solid {solid.sum():.6f} m^3 (meshes "
          f"{mesh_volume:.6f}), mean solid share of the cells reached "
          f"{solid[reached].mean() / args.cell ** 3:.3f}")
    print(f"METRIC solid_volume_tets_per_s {rate:.4g} 1/s")


if __name__ == "__main__":
    main()
