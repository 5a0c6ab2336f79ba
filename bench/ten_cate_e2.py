"""ten Cate et al. (2002) case E2, end to end, at one or more resolutions (cells per diameter):
wall time, steps, and the errors of the peak speed, the plateau velocity (L2) and the time of bottom
contact against the digitised record (shared/validation/ten_cate_E2*.csv).

    python bench/ten_cate_e2.py 6 9        # cells per diameter
"""
import csv
import sys
from pathlib import Path

import numpy as np

from riprap.benchmarks.ten_cate import compare_with_experiment, run_ten_cate_e2

VALIDATION = Path(__file__).resolve().parents[2] / "shared" / "validation"


def read_record(name, quantity):
    rows = [(float(r["t_s"]), float(r["value"])) for r in csv.DictReader(open(VALIDATION / name))
            if r["quantity"] == quantity]
    return np.array(sorted(rows))


def main(resolutions):
    velocity = read_record("ten_cate_E2.csv", "u_z_m_per_s")
    gap = read_record("ten_cate_E2_basilisk.csv", "gap_over_D")
    last = None
    for n in resolutions:
        run = run_ten_cate_e2(n)
        errors = compare_with_experiment(run, velocity, gap)
        print(f"D/h = {run.cells_per_diameter:.2f}: {run.steps} steps in {run.wall_time:.1f} s; "
              f"peak {errors['peak_speed_m_per_s']:.4f} m/s vs {errors['record_peak_speed_m_per_s']:.4f} "
              f"({100 * errors['peak_speed_error']:+.1f} %), plateau L2 "
              f"{100 * errors['plateau_velocity_l2']:.1f} %, contact at {errors['contact_time_s']:.3f} s "
              f"vs {errors['record_contact_time_s']:.3f} s ({errors['contact_time_error']:+.3f} s); "
              f"speed by gap L2 {100 * errors['velocity_by_gap_l2']:.1f} %, steady fall (7 D to 2 D) "
              f"{errors['steady_speed_m_per_s']:.4f} vs {errors['record_steady_speed_m_per_s']:.4f} m/s "
              f"({100 * errors['steady_speed_error']:+.1f} %)")
        last = (run, errors)
    run, errors = last
    print(f"METRIC ten_cate_e2_peak_speed_error {100 * abs(errors['peak_speed_error']):.2f} percent")


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [6])
