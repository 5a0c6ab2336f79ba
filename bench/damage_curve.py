"""Issue 38's damage curve: a test series on a narrow section of a single layer of concrete cubes
on a porous core at laboratory scale, untuned, from below the start of damage to beyond it.

The section (Froude-scaled laboratory flume, fresh water): cubes of Dn = 4.6 cm (2300 kg/m^3,
Delta = 1.3) placed by ``riprap place`` on a 1:1.5 slope (Van der Meer's 1988 cube tests' slope)
over one layer of fixed underlayer rocks (Dn50 = Dn / 2.3, the filter rule), a porous core
(porosity 0.4, core stone 1 cm), water depth 0.5 m, crest freeboard 0.12 m, section 0.12 m wide
(2.6 Dn: two units a row, 19 rows up to 4 cm below the crest, placed lying on the face,
square to the slope within 5 degrees of spin and 5 of tilt, at a design packing density of
0.65: randomly spun cubes need up to 1.4 Dn each, and at 2.3 Dn and 0.7 riprap place set 9 of
32 units on others; the flume's water reaches half a cell beyond each side wall, as in
examples/10). The flume: boundary wave maker with active absorption 2.6 m seaward of
the toe, three gauges for the incident waves, a run-up gauge on the face and an overtopping
gauge at the crest's landward edge; cells of 1.5 cm (3 across a cube, 7 across the smallest Hm0).

The ladder: N_s = Hm0 / (Delta Dn) = 1.8, 2.4, 3.0, 3.6 at a constant wave steepness s_op = 0.035
(Tp 1.39-1.97 s), ``--waves`` waves each (default 50, the issue's least). Van Gent's (2002)
single-layer cubes start to be damaged at N_s = 2.9-3.0 and fail at 3.5-3.75; Van der Meer's
(1988) double-layer cubes formula is drawn for the waves run. Nothing is fitted: the materials
are those of riprap's examples (friction 0.6), the core that of
examples/10.

The campaign runs in parts: started again with the same ``--out`` it resumes where it stopped
(the placed pack, the finished steps, a cut step from its last checkpoint). Prints each step's
row of the damage curve beside the formulas, where the first displacement happened in N_s, and
last ``METRIC damage_curve_wall_s <seconds> s`` (the wall time of this call; the steps already
done before it are not counted again).

    python bench/damage_curve.py [--out DIR] [--waves N] [--steps 1.8,2.4,3.0,3.6]
        [--first-seed K] [--cut-faces own_velocity] [--filter-below-cells 4]
        [--concrete-on-rock 0.7]

Issue 51's options (their defaults are the curve as first run): ``--first-seed K`` gives the steps
the seeds K, K+1, ... (the series numbers its steps' seeds from 1, so ``--steps 2.4
--first-seed 2`` runs the sea of the ladder's step 2 alone, on the freshly placed layer);
``--cut-faces`` the ``[fluid] cut_faces`` treatment; ``--filter-below-cells`` makes the
underlayer rocks contact-only under a fitted filter zone (``[fluid] contact_only_below_cells``);
``--concrete-on-rock`` a ``[[friction]]`` pair for the cubes on the rocks.
"""
import argparse
import math
import time
from pathlib import Path

from riprap.case.load import load_case
from riprap.workflows.place import run_placement
from riprap.workflows.series import run_series

DN = 0.046                 # m, the cubes' nominal diameter (3.07 cells)
DELTA = 2300.0 / 1000.0 - 1.0
DEPTH = 0.5                # m
FREEBOARD = 0.12           # m
COT = 1.5
WIDTH = 0.12               # m: 8 cells, two cubes a row (2.6 Dn)
STEEPNESS = 0.035
CELL = 0.015               # m

PLACEMENT = f"""format_version = 1

[simulation]
end_time = 1.0
time_step_safety = 0.3
output_interval = 0.1

[[materials]]
name = "concrete"
density = 2300.0
friction_coefficient = 0.6
restitution = 0.3
contact_penalty = 1.0e6

[[materials]]
name = "rock"
density = 2650.0
friction_coefficient = 0.6
restitution = 0.3
contact_penalty = 1.0e6

[[materials]]
name = "core"
density = 2650.0
friction_coefficient = 0.9
restitution = 0.3
contact_penalty = 1.0e6

[[materials]]
name = "glass"
density = 2500.0
friction_coefficient = 0.2
restitution = 0.3
contact_penalty = 1.0e6

[slope]
cotangent = {COT}
width = {WIDTH}
length = {(DEPTH + FREEBOARD) * math.hypot(1.0, COT):.4f}
toe_stop_distance = 0.03
face_material = "core"
side_wall_material = "glass"

[underlayer]
material = "rock"
dn50 = {DN / 2.3:.5f}
dn85_over_dn15 = 1.3
rock_shapes = 4
size_classes = 2
layers = 1
settle_time = 1.0

[armour]
unit = "cube"
material = "concrete"
nominal_diameter = {DN}
mesh_size = {DN / 2}             # a cube's faces are flat: a coarse mesh is exact, and softer

[placement]
rows = 19
units_per_row = 2
packing_density_coefficient = 0.65
release = "on_contact"
orientation = "random_within"
max_tilt_deg = 5.0
max_spin_deg = 5.0
settle_time = 2.0
rest_speed = 0.01

[output]
directory = "pack"
"""


def series_case(steps: list[float], waves: int, *, first_seed: int = 1,
                cut_faces: str = "mixture", filter_below_cells: float = 0.0,
                concrete_on_rock: float | None = None) -> str:
    crest = DEPTH + FREEBOARD
    top_x = crest * COT
    ladder = "".join(f"""
[[series_steps]]
significant_height = {ns * DELTA * DN:.4f}
wave_steepness = {STEEPNESS}
waves = {waves}
""" + (f"seed = {first_seed + k}\n" if first_seed != 1 else "") for k, ns in enumerate(steps))
    fluid_options = f'cut_faces = "{cut_faces}"\n' if cut_faces != "auto" else ""
    if filter_below_cells > 0:
        fluid_options += f"contact_only_below_cells = {filter_below_cells:g}\n"
    friction = ("" if concrete_on_rock is None else
                f'[[friction]]\nmaterials = ["concrete", "rock"]\n'
                f"friction_coefficient = {concrete_on_rock:g}\n\n")
    length = 4.1
    height = 0.75
    # three gauges for the incident waves, 0.3 and 0.6 m apart (0.07-0.33 of the wave lengths)
    gauges = "\n".join(f'[[gauges]]\ntype = "surface"\nname = "g{k + 1}"\n'
                       f"position = [{x}, {WIDTH / 2}, 0.0]\n"
                       for k, x in enumerate((-2.0, -1.7, -1.1)))
    return f"""format_version = 1
pack = "pack/pack.toml"

[simulation]
end_time = 60.0
adaptive_time_step = true
output_interval = 5.0
checkpoint_interval = 5.0

[fluid]
lower = [{1.5 - round(length / CELL) * CELL:.4f}, {-CELL / 2}, 0.0]
upper = [1.5, {WIDTH + CELL / 2:.4f}, {round(height / CELL) * CELL:.4f}]
cells = [{round(length / CELL)}, {round(WIDTH / CELL) + 1}, {round(height / CELL)}]
surface_tension = 0.0
limit_air_speed = true
pressure_volume_tolerance = 1e-3
{fluid_options}
{friction}[[water_regions]]
type = "level"
level = {DEPTH}

[[porous_zones]]
type = "polygon"
porosity = 0.4
stone_diameter = 0.01
points = [[0.03, 0.0], [{top_x - 0.03:.4f}, {crest - 0.02:.4f}], [1.2, {crest - 0.02:.4f}], [1.2, 0.0]]

[waves]
type = "irregular"
still_water_level = {DEPTH}
significant_height = 0.1
peak_period = 1.4
duration = 100.0
generation = "boundary"
absorbing_end = false

{gauges}
[[gauges]]
type = "run_up"
name = "face"
position = [-0.03, {WIDTH / 2}, 0.0]
to_x = 1.2

[[gauges]]
type = "overtopping"
name = "crest"
position = [1.2, {WIDTH / 2}, {crest:.4f}]

[series]
displacement_threshold = 1.0
{ladder}
[output]
directory = "series"
body_forces_interval = 0.25
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="bench_out/damage_curve")
    parser.add_argument("--waves", type=int, default=50)
    parser.add_argument("--steps", default="1.8,2.4,3.0,3.6",
                        help="stability numbers Hm0 / (Delta Dn) of the steps")
    parser.add_argument("--first-seed", type=int, default=1,
                        help="seed of the first step's sea (the next steps count on from it)")
    parser.add_argument("--cut-faces", default="mixture", choices=("mixture", "own_velocity", "auto"))
    parser.add_argument("--filter-below-cells", type=float, default=0.0)
    parser.add_argument("--concrete-on-rock", type=float, default=None)
    args = parser.parse_args()
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    if not (out / "pack" / "pack.toml").is_file():
        (out / "placement.toml").write_text(PLACEMENT)
        summary = run_placement(load_case(out / "placement.toml"), output_directory=out / "pack",
                                progress=False)
        print(f"placed {summary['units_placed']} cubes on {summary['underlayer_rocks']} rocks, "
              f"packing density {summary.get('packing_density_coefficient', float('nan')):.3f}, "
              f"{time.perf_counter() - started:.0f} s")
    steps = [float(v) for v in args.steps.split(",")]
    (out / "series.toml").write_text(series_case(
        steps, args.waves, first_seed=args.first_seed, cut_faces=args.cut_faces,
        filter_below_cells=args.filter_below_cells, concrete_on_rock=args.concrete_on_rock))
    results = run_series(load_case(out / "series.toml"), output_directory=out / "series",
                         progress=False)
    curve = results["curve"]
    print("step  Hm0_m  N_s    waves  displaced  N_od    S      VdM_cubes_N_od  q_m3/s/m  EurOtop_q"
          "  C_r")
    for k in range(len(curve["step"])):
        print(f"{curve['step'][k]:4d}  {curve['Hm0_m'][k]:.3f}  {curve['stability_number'][k]:.2f}  "
              f"{curve['waves'][k]:5d}  {curve['units_displaced'][k]:9d}  {curve['N_od'][k]:.3f}  "
              f"{curve['S'][k]:.3f}  {curve['van_der_meer_cubes_N_od'][k]:.3f}           "
              f"{curve['q_m3_s_m'][k]:.2e}  {curve['eurotop_q_m3_s_m'][k]:.2e}   "
              f"{curve['eurotop_crest_width_factor'][k]:.3f}")
    formulas = results["formulas"]
    if formulas.get("crest_width_m") is not None:
        print(f"EurOtop_q includes C_r (EurOtop 2018 eq. 6.8), G_c = "
              f"{formulas['crest_width_m']:.3f} m ({formulas['crest_width_source']})")
    first = results["first_displacement"]
    print("first displacement: " + (f"step {first['step']}, N_s = {first['stability_number']:.2f}"
                                     if first else "none")
          + "; Van Gent (2002) single-layer cubes: start N_s = 2.9-3.0, failure 3.5-3.75")
    print(f"report: {results['outputs']['report']}")
    print(f"METRIC damage_curve_wall_s {time.perf_counter() - started:.0f} s")


if __name__ == "__main__":
    main()
