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

With B bodies (``--bodies``; each owned by the process whose slab holds its centre, every
process holding a copy of every body: riprap/solid/bodies_over_processes.py):
  coupling work      = k_c (cells holding bodies) (n + 2H) / nx   clipping, face set, sums
  contact sub-steps  = S (a B / P + o B / P + e B
                          + [P > 1] (f + 3 latency log2(P) + (48 B + rows) / bandwidth))
with a the pair work per body and sub-step, o the broad phase among the bodies near a slab and
the sums of its own bodies' forces, per body owned (measured at P = 8 on 3,888 cubes,
bench/substep_parts.py), e the work every process still does for every body (the half kicks
and the drift, the owners, the joined forces put back; bench/substep_parts.py), f the fixed cost
of a split sub-step (its compiled parts entered from Python, the messages' bookkeeping, the
waiting of a sub-step's imbalance), S the sub-steps per fluid step. Each sub-step sends two
messages (the pairs' rows to the other owners, the forces joined: 48 bytes a body) and, when a
body crossed a cut, a third (the springs). a and f are fitted to bench/parallel.py's placed
layer (161 bodies, 69 sub-steps a step: 2.19 ms a sub-step on one process = a B + b B with b
the one process's broad phase, integration and sums, 0.8 us a body at 192 bodies; 1.50 ms on
two = a B / 2 + o B / 2 + e B + f). Taken as it is measured at P = 8, o grows as slabs thin
(the near bodies beside a slab's own grow to several times them when a slab is a few bodies
wide): the model is optimistic there. The cells holding bodies: 850 per body (137,000 for the
layer's 161 at 11 cells across a unit).

    python bench/parallel_model.py [--cells 1000 200 100] [--bodies 3678]
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
BODY_CELL_SECONDS = 0.15 / 137_000   # the coupling's seconds per cell holding bodies, a step
BODY_CELLS = 850                      # cells holding a body, per body (11 cells across a unit)
# bench/substep_parts.py, 2026-11-29 (one thread):
ONE_PROCESS_BODY_SECONDS = 1.6e-6     # broad phase, integration, sums per body, one process
                                      # (3,888 cubes; the broad phase's sort grows with B)
LAYER_ONE_PROCESS_BODY = 0.8e-6       # the same at 192 bodies, for the layer's fit
EVERY_BODY_SECONDS = 0.16e-6          # e, per body and sub-step on every process (3,888)
OWN_BODY_SECONDS = 1.6e-6             # o, per body owned and sub-step (3,888 over 8: the
                                      # near bodies about twice the owned)
LAYER_BODIES = 161
PAIR_SECONDS = 2.19e-3 / LAYER_BODIES - LAYER_ONE_PROCESS_BODY         # a
SPLIT_SUBSTEP_SECONDS = (1.50e-3 - (PAIR_SECONDS + OWN_BODY_SECONDS) * LAYER_BODIES / 2
                         - EVERY_BODY_SECONDS * LAYER_BODIES)           # f, per sub-step
SUBSTEPS = 69                         # contact sub-steps per fluid step (the layer, adaptive)
ROW_BYTES = 28 * 8                    # a pair's row of results, sent when its bodies' owners differ
CROSSING_ROWS = 0.1                   # rows sent per body and sub-step (pairs across a cut)
NETWORKS = {"shared memory (one node)": (0.5e-6, 10e9),
            "InfiniBand HDR": (2e-6, 12.5e9),
            "10 Gb Ethernet": (25e-6, 1.2e9)}


def body_time(cells, bodies, processes, latency, bandwidth):
    """The bodies' part of a step: their coupling on the slab's planes and the contact
    sub-steps."""
    if bodies == 0:
        return 0.0
    nx = cells[0]
    n = nx / processes
    planes = n + (2 * HALO if processes > 1 else 0)
    coupling = BODY_CELL_SECONDS * BODY_CELLS * bodies * min(planes, nx) / nx
    if processes == 1:
        substep = (PAIR_SECONDS + ONE_PROCESS_BODY_SECONDS) * bodies
    else:
        substep = ((PAIR_SECONDS + OWN_BODY_SECONDS) * bodies / processes
                   + EVERY_BODY_SECONDS * bodies + SPLIT_SUBSTEP_SECONDS
                   + 3 * latency * math.log2(processes)
                   + (48 * bodies + ROW_BYTES * CROSSING_ROWS * bodies / processes) / bandwidth)
    return coupling + SUBSTEPS * substep


def step_time(cells, processes, latency, bandwidth, bodies=0):
    nx, ny, nz = cells
    total = nx * ny * nz
    plane = ny * nz
    n = nx / processes
    if processes == 1:
        return C * total + body_time(cells, bodies, 1, latency, bandwidth)
    if n < max(HALO, 4):
        return math.inf
    work = (1 - PRESSURE_SHARE) * C * plane * (n + 2 * HALO)
    work += PRESSURE_SHARE * C * (plane * n * (1 - GATHERED_SHARE) + total * GATHERED_SHARE)
    exchange = 2 * (EXCHANGES * latency + EXCHANGED_PLANES * plane * 8 / bandwidth)
    reduce = REDUCTIONS * latency * math.log2(processes)
    gather = GATHERS * (latency * math.log2(processes) + total / 64 * 8 / bandwidth)
    return work + exchange + reduce + gather + body_time(cells, bodies, processes, latency,
                                                        bandwidth)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cells", type=int, nargs=3, default=[1000, 200, 100])
    parser.add_argument("--bodies", type=int, default=3678,
                        help="bodies (the seed's 242 Core-Locs on 3,436 rocks: 3678)")
    args = parser.parse_args()
    cells = tuple(args.cells)
    for bodies in (0, args.bodies):
        one = step_time(cells, 1, 0, 1, bodies)
        print(f"{cells[0]} x {cells[1]} x {cells[2]} cells, {bodies} bodies: {one:.1f} s per step "
              "on one process")
        for name, (latency, bandwidth) in NETWORKS.items():
            row = []
            for processes in (2, 8, 64, 512):
                t = step_time(cells, processes, latency, bandwidth, bodies)
                row.append(f"P={processes}: " + (
                    "cannot cut" if math.isinf(t)
                    else f"{t:.3f} s, efficiency {one / (processes * t):.2f}"))
            print(f"  {name} ({latency * 1e6:g} us, {bandwidth / 1e9:g} GB/s): " + "; ".join(row))


if __name__ == "__main__":
    main()
