"""Run under ``mpiexec -n N``: a fluid case's steps on N processes against one process's; exits 1
if any array of the whole grid (or a gauge's record) differs in any bit, compared every EVERY
steps and after the last. Usage: slab_fluid_check.py CASE STEPS [HALO [EVERY [skewed]]]

``skewed``: the fluid's cut made unequal (the upper half's planes cost three times the lower's),
so that the pressure solve runs on slabs of its own (``riprap/fluid/pressure_window.py``)."""
import sys

import numpy as np

from riprap.case.build_fluid import build_fluid_solver
from riprap.case.load import load_case
from riprap.fluid.slab_solver import HALO_PLANES, split_fluid
from riprap.models.slab_features import add_parts_to_block
from riprap.parallel.communicator import world


def main():
    case_path, steps = sys.argv[1], int(sys.argv[2])
    halo = int(sys.argv[3]) if len(sys.argv) > 3 else HALO_PLANES
    every = int(sys.argv[4]) if len(sys.argv) > 4 else 1
    skewed = len(sys.argv) > 5 and sys.argv[5] == "skewed"
    comm = world()
    case = load_case(case_path)
    serial = build_fluid_solver(case)
    nx = serial.grid.cells[0]
    costs = np.where(np.arange(nx) >= nx // 2, 3.0, 1.0) if skewed else None
    split = split_fluid(build_fluid_solver(case), comm, halo=halo, add_parts=add_parts_to_block,
                        plane_costs=costs)
    if skewed and split.pressure_cut.starts == split.cut.starts:
        print(f"the pressure's cut {split.pressure_cut.starts} is the fluid's: nothing checked")
        sys.exit(1)
    worst = 0
    for step in range(steps):
        serial.step()
        split.step()
        if (step + 1) % every and step + 1 < steps:
            continue
        whole = split.gather_whole(split.state_arrays())
        expected = serial.state_arrays()
        differing = [name for name in ("fraction", "u", "v", "w", "pressure")
                     if not np.array_equal(whole[name], expected[name])]
        clock_same = np.array_equal(whole["clock"], expected["clock"])
        if serial.gauges is not None:
            differing += [] if np.array_equal(split.gauges.whole.values, serial.gauges.values) \
                else ["gauges"]
        if differing or not clock_same:
            if comm.rank == 0:
                planes = {name: np.unique(np.nonzero(whole[name] != expected[name])[0]).tolist()[:10]
                          for name in differing}
                print(f"step {step + 1}: differ in {differing} at x-planes {planes}; clock "
                      f"{'same' if clock_same else 'different'}: {whole['clock']} vs "
                      f"{expected['clock']}", flush=True)
            worst = 1
            break
    if comm.rank == 0 and not worst:
        print(f"{steps} steps on {comm.size} processes (halo {halo}, slabs {split.cut.starts}, "
              f"pressure slabs {split.pressure_cut.starts}): bit for bit", flush=True)
    sys.exit(worst)


if __name__ == "__main__":
    main()
