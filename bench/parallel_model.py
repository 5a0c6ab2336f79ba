"""A model of a split fluid run's time per step on P processes, to size a cluster job
(docs/parallel.md). Not a measurement: it extrapolates the figures bench/parallel.py measured on
this machine with the assumptions printed.

Per step and process (slabs along x, n = nx / P planes, halo H planes each side):
  non-pressure work  = (1 - s) c ny nz (n + 2H)       the block's step, halos included
  pressure work      = s c ny nz n (1 - r) + s c N r   split levels + the gathered coarse levels
  exchanges          = m_x (latency + bytes_per_plane / bandwidth)
  reductions         = m_r latency log2(P)
  gathers            = m_g (latency log2(P) + (N / 64) 8 bytes / bandwidth)
with c the one-thread seconds per cell-step, s the pressure's share, r the share of the pressure
work on the gathered levels (both measured on one process), m_x, m_r, m_g the messages per step
measured on two processes.

    python bench/parallel_model.py [--cells 1000 200 100]
"""
import argparse
import math

C = 0.819 / 888_800          # s per cell-step, one thread (bench/parallel.py, 1 process)
PRESSURE_SHARE = 0.68         # of a step, one process
GATHERED_SHARE = 0.055        # of the pressure work, on the gathered coarse levels (2-process fit)
HALO = 8
EXCHANGES = 212               # messages per step per process with two neighbours (measured: 212
                              # with one; an interior slab sends the same count to each side)
EXCHANGED_PLANES = 6.24e6 / (44 * 101 * 8)   # fine-plane equivalents per step, measured
REDUCTIONS = 49
GATHERS = 16
NETWORKS = {"shared memory (one node)": (0.5e-6, 10e9),
            "InfiniBand HDR": (2e-6, 12.5e9),
            "10 Gb Ethernet": (25e-6, 1.2e9)}


def step_time(cells, processes, latency, bandwidth):
    nx, ny, nz = cells
    total = nx * ny * nz
    plane = ny * nz
    n = nx / processes
    if processes == 1:
        return C * total
    if n < max(HALO, 4):
        return math.inf
    work = (1 - PRESSURE_SHARE) * C * plane * (n + 2 * HALO)
    work += PRESSURE_SHARE * C * (plane * n * (1 - GATHERED_SHARE) + total * GATHERED_SHARE)
    exchange = 2 * (EXCHANGES * latency + EXCHANGED_PLANES * plane * 8 / bandwidth)
    reduce = REDUCTIONS * latency * math.log2(processes)
    gather = GATHERS * (latency * math.log2(processes) + total / 64 * 8 / bandwidth)
    return work + exchange + reduce + gather


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cells", type=int, nargs=3, default=[1000, 200, 100])
    args = parser.parse_args()
    cells = tuple(args.cells)
    one = step_time(cells, 1, 0, 1)
    print(f"{cells[0]} x {cells[1]} x {cells[2]} cells: {one:.1f} s per step on one process")
    for name, (latency, bandwidth) in NETWORKS.items():
        row = []
        for processes in (2, 8, 64, 512):
            t = step_time(cells, processes, latency, bandwidth)
            row.append(f"P={processes}: " + ("cannot cut" if math.isinf(t)
                                             else f"{t:.3f} s, efficiency {one / (processes * t):.2f}"))
        print(f"{name} ({latency * 1e6:g} us, {bandwidth / 1e9:g} GB/s): " + "; ".join(row))


if __name__ == "__main__":
    main()
