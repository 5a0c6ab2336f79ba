"""A floating cube (half water's density, ``riprap.benchmarks.floating_box``) released 2 cm above its
floating position: the mean draught over the last second against Archimedes', the heave left, and
last ``METRIC floating_box_draught_error <percent> percent`` (issue 13 asks 2 %).

    python bench/floating_box.py [cells across the tank] [seconds] [start above the level, m]
"""
import sys

from riprap.benchmarks.floating_box import run_floating_box


def main(cells=32, seconds=3.0, start_above=0.02):
    cells, seconds, start_above = int(cells), float(seconds), float(start_above)
    run = run_floating_box(cells, seconds, start_above)
    last = run.times > seconds - 1.0
    draught = run.draught(seconds - 1.0)
    error = 100.0 * (draught - run.archimedes_draught) / run.archimedes_draught
    print(f"{cells}^3 cells ({run.cells_across_cube:.0f} across the cube), {len(run.times)} steps in "
          f"{run.wall_time:.0f} s; water volume error {run.water_volume_error:.2e}")
    print(f"over the last second: centre {run.heights[last].min():.4f}..{run.heights[last].max():.4f} m; "
          f"free surface {run.level:.4f} m; draught {draught:.4f} m vs Archimedes "
          f"{run.archimedes_draught:.4f} m ({error:+.2f} %)")
    print(f"METRIC floating_box_draught_error {abs(error):.2f} percent")


if __name__ == "__main__":
    main(*sys.argv[1:])
