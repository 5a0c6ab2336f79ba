"""Issue 54's damage curve: single-layer cubes on a periodic strip, calibrated seas, two seeds or
more, untuned. The successor of bench/damage_curve.py (issue 38's first curve, kept as it ran).

The section (Froude-scaled laboratory flume, fresh water), as the first curve but:

- **a periodic strip 5 Dn wide** (0.23 m, ``[slope] sides = "periodic"`` and the fluid's y sides
  periodic: no glass walls, every unit between neighbours, one unit displaced is N_od 0.2);
- **the packing of a single layer of cubes as laboratories place it**: staggered rows of 4 cubes
  at a design packing density coefficient of 0.70, i.e. a layer porosity of 0.30 (Vieira,
  Taveira-Pinto & Rosa-Santos 2020, Ocean Engineering 216, 108042: single-layer cube armour is
  placed in a regular pattern at a porosity of 0.25-0.30), square to the slope within 5 degrees
  of spin and tilt; 21 rows up to the crest;
- **loads and filter of issue 51**: the default cut-face treatment (``auto``: rigid bodies keep
  the fluid's own velocity), and the underlayer rocks (Dn50 = Dn / 2.3 = 2 cm, 1.4 cells) as a
  porous filter for the flow and contact bodies for the cubes (``contact_only_below_cells =
  2``: between the rocks' 1.3-1.5 cells and the cubes' 3.2); friction by the smaller-of-two rule (concrete 0.6, rock 0.6: nothing tuned);
- **calibrated seas** (``[series] wave_calibration = "without_structure"``): every step's sea run
  first without the bodies until its incident Hm0 at the toe is within 3 % of the asked one and
  Tp within 5 %, kept in the campaign folder and used by every seed.

Kept from the first curve: cubes of Dn = 4.6 cm (2300 kg/m^3, Delta = 1.3) on a 1:1.5 slope (Van
der Meer's and Van Gent's cube tests' slope), one layer of underlayer rocks, a porous core
(porosity 0.4, stone 1 cm), water depth 0.5 m, crest freeboard 0.12 m, a boundary wave maker with
active absorption 2.6 m seaward of the toe, three gauges for the incident waves, a run-up gauge
and an overtopping gauge; cubic cells of 1.4375 cm (3.2 across a cube, 16 across the strip).

The ladder: N_s = Hm0 / (Delta Dn) = 2.0, 2.5, 3.0, 3.5, 4.0 at s_op = 0.035 (Tp 1.48-2.09 s),
``--waves`` waves a step (default 50), seeds ``--seeds`` (default 0 1) as one ``riprap campaign``
(two Dask workers of one thread each). Van Gent (2002): start of damage N_s 2.9-3.0, failure
3.5-3.75 (about 1,000 waves a step).

Resumes: started again with the same ``--out`` (outside git), the pack, the calibration, every
finished step and a cut step's checkpoint are kept. ``--report`` writes what is done so far (every
member's finished steps) without running: the CSV with a ``seed`` column, the spread over seeds and
the picture, into ``--results`` (default ``bench/results/cube_damage_ladder_<date>``). Last lines
``METRIC first_displacement_Ns_min``, ``METRIC first_displacement_Ns_max`` (over the seeds; nan
while a seed has no displacement yet) and ``METRIC cube_ladder_wall_s``.

    python bench/cube_damage_ladder.py [--out DIR] [--waves N] [--seeds 0 1] [--report]
"""
import argparse
import csv
import datetime
import json
import math
import time
from pathlib import Path

DN = 0.046                 # m
DELTA = 2300.0 / 1000.0 - 1.0
DEPTH = 0.5                # m
FREEBOARD = 0.12           # m
COT = 1.5
WIDTH = 0.23               # m: the strip, 5 Dn
CELL = WIDTH / 16          # m: 16 cells across (a multiple of 4 for the periodic pressure solve)
STEEPNESS = 0.035
STEPS = (2.0, 2.5, 3.0, 3.5, 4.0)
PACKING = 0.70
UNITS_PER_ROW = 4
ROWS = 21
VAN_GENT_START = (2.9, 3.0)
VAN_GENT_FAILURE = (3.5, 3.75)

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

[slope]
cotangent = {COT}
width = {WIDTH}
length = {(DEPTH + FREEBOARD) * math.hypot(1.0, COT):.4f}
toe_stop_distance = 0.03
face_material = "core"
side_wall_material = "core"
sides = "periodic"

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
mesh_size = {DN / 2}

[placement]
rows = {ROWS}
units_per_row = {UNITS_PER_ROW}
packing_density_coefficient = {PACKING}
release = "on_contact"
orientation = "random_within"
max_tilt_deg = 5.0
max_spin_deg = 5.0
settle_time = 2.0
rest_speed = 0.01

[output]
directory = "pack"
"""


def series_case(steps, waves: int) -> str:
    crest = DEPTH + FREEBOARD
    top_x = crest * COT
    ladder = "".join(f"""
[[series_steps]]
significant_height = {ns * DELTA * DN:.4f}
wave_steepness = {STEEPNESS}
waves = {waves}
""" for ns in steps)
    nx = round(4.1 / CELL)
    nz = round(0.75 / CELL)
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
lower = [{1.5 - nx * CELL:.6f}, 0.0, 0.0]
upper = [1.5, {WIDTH}, {nz * CELL:.6f}]
cells = [{nx}, 16, {nz}]
y_low = "periodic"
y_high = "periodic"
surface_tension = 0.0
limit_air_speed = true
pressure_volume_tolerance = 1e-3
contact_only_below_cells = 2.0

[[water_regions]]
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
wave_calibration = "without_structure"
{ladder}
[output]
directory = "series"
body_forces_interval = 0.25
"""


def _number(value) -> float:
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) \
        else math.nan


def step_rows(campaign: Path, seeds) -> list[dict]:
    """Every finished step of every member (its survey), one row each, with the seed."""
    rows = []
    for seed in seeds:
        member = campaign / f"series_seed{seed}"
        for folder in sorted(member.glob("step_*")):
            survey = folder / "survey" / "layer_summary.json"
            if not (folder / "summary.json").is_file() or not survey.is_file():
                continue
            layer = json.loads(survey.read_text())
            flume = layer.get("flume_test") or {}
            summary = json.loads((folder / "summary.json").read_text())
            step_text = (folder / "step.toml").read_text()
            number = int(folder.name.split("_")[1])
            asked = STEPS[number - 1] * DELTA * DN if number <= len(STEPS) else math.nan
            per_wave = folder / "survey" / "per_wave.csv"
            waves, q, nod_by_wave = 0, math.nan, []
            if per_wave.is_file():
                with per_wave.open() as handle:
                    table = list(csv.DictReader(handle))
                waves = len(table)
                q = sum(_number(float(r["overtopping_m3_per_m"])) for r in table
                        if r["overtopping_m3_per_m"] not in ("", "nan"))
                nod_by_wave = [float(r["N_od"]) for r in table]
            moves = []
            if (folder / "survey" / "units.csv").is_file():
                with (folder / "survey" / "units.csv").open() as handle:
                    moves = [float(u["displacement_over_dn"]) for u in csv.DictReader(handle)
                             if u.get("displacement_over_dn") not in (None, "", "nan")]
            hm0 = _number(flume.get("Hm0_m"))
            rows.append({
                "seed": seed, "step": number, "asked_Ns": STEPS[number - 1],
                "asked_Hm0_m": asked, "Hm0_m": hm0, "Ns": hm0 / (DELTA * DN),
                "Tp_s": _number(flume.get("incident_Tp_s")), "Tz_s": _number(flume.get("Tz_s")),
                "waves": waves, "units_displaced": len(layer.get("units_displaced", [])),
                "N_od": _number(layer.get("damage_number_nod")),
                "S": _number(layer.get("damage_level_s")),
                "Kr": _number(flume.get("reflection_coefficient")),
                "q_m3_per_m": q,
                "largest_move_Dn": max(moves) if moves else math.nan,
                "moved_0.5_to_1_Dn": sum(1 for m in moves if 0.5 <= m < 1.0),
                "moved_1_to_2_Dn": sum(1 for m in moves if 1.0 <= m < 2.0),
                "moved_over_2_Dn": sum(1 for m in moves if m >= 2.0),
                "N_od_by_wave": " ".join(f"{v:.3g}" for v in nod_by_wave),
                "wall_s": _number(summary.get("wall_time")),
                "simulated_s": _number(summary.get("simulated_time", summary.get("end_time"))),
                "wave_maker_gain": _gain(step_text)})
    return rows


def _gain(step_text: str) -> float:
    marker = "the wave maker calibrated: Hm0 x "
    if marker not in step_text:
        return 1.0
    return float(step_text.split(marker, 1)[1].split(",", 1)[0])


def first_displacements(rows: list[dict], seeds) -> dict:
    """Per seed the N_s (measured) of the first step with a unit beyond 1 Dn, NaN if none yet."""
    first = {}
    for seed in seeds:
        hit = [r for r in rows if r["seed"] == seed and r["units_displaced"] > 0]
        first[seed] = min(hit, key=lambda r: r["step"])["Ns"] if hit else math.nan
    return first


def write_results(rows: list[dict], results: Path, seeds) -> None:
    results.mkdir(parents=True, exist_ok=True)
    if not rows:
        return
    with (results / "curve.csv").open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    spread = []
    for step in sorted({r["step"] for r in rows}):
        these = [r for r in rows if r["step"] == step]
        entry = {"step": step, "seeds": len(these)}
        for name in ("Ns", "N_od", "S", "Kr", "q_m3_per_m"):
            values = [r[name] for r in these if math.isfinite(r[name])]
            entry[f"{name}_mean"] = sum(values) / len(values) if values else math.nan
            entry[f"{name}_min"] = min(values) if values else math.nan
            entry[f"{name}_max"] = max(values) if values else math.nan
        spread.append(entry)
    with (results / "spread.csv").open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(spread[0]))
        writer.writeheader()
        writer.writerows(spread)
    _picture(rows, results / "curve.png", seeds)


def _picture(rows, path: Path, seeds) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from riprap.analysis.design_formulas import van_der_meer_cubes_damage

    figure, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    for band, colour, label in ((VAN_GENT_START, "tab:orange", "Van Gent (2002) start of damage"),
                                (VAN_GENT_FAILURE, "tab:red", "Van Gent (2002) failure")):
        left.axvspan(*band, color=colour, alpha=0.2, label=label)
    ns = [1.8 + 0.05 * k for k in range(50)]
    left.plot(ns, [van_der_meer_cubes_damage(hs=n * DELTA * DN, tm=1.3, waves=50, delta=DELTA,
                                             nominal_diameter=DN) for n in ns],
              "k--", lw=1, label="Van der Meer (1988) double-layer cubes, 50 waves")
    for seed in seeds:
        mine = sorted((r for r in rows if r["seed"] == seed), key=lambda r: r["step"])
        left.plot([r["Ns"] for r in mine], [r["N_od"] for r in mine], "o-", label=f"seed {seed}")
        right.plot([r["Ns"] for r in mine], [r["S"] for r in mine], "o-", label=f"seed {seed}")
    left.set_xlabel("N_s = Hm0 / (Delta Dn), measured at the toe")
    left.set_ylabel("N_od (units beyond 1 Dn per Dn of width)")
    right.set_xlabel("N_s measured at the toe")
    right.set_ylabel("S (eroded area / Dn^2)")
    left.legend(fontsize=7)
    right.legend(fontsize=7)
    figure.suptitle("Single-layer cubes, 1:1.5, periodic strip 5 Dn, calibrated seas (riprap, "
                    "untuned)", fontsize=10)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="/work/runs/cube_damage_ladder")
    parser.add_argument("--waves", type=int, default=50)
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    parser.add_argument("--results", default=None)
    parser.add_argument("--report", action="store_true",
                        help="write what is done so far; run nothing")
    args = parser.parse_args()
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    results = Path(args.results or Path(__file__).parent / "results" /
                   f"cube_damage_ladder_{datetime.date.today().isoformat()}")
    started = time.perf_counter()
    if not args.report:
        from riprap.case.load import load_case
        from riprap.workflows.campaign import members_of, run_campaign
        from riprap.workflows.place import run_placement

        if not (out / "pack" / "pack.toml").is_file():
            (out / "placement.toml").write_text(PLACEMENT)
            summary = run_placement(load_case(out / "placement.toml"),
                                    output_directory=out / "pack", progress=False)
            print(f"placed {summary['units_placed']} cubes on {summary['underlayer_rocks']} "
                  f"rocks, packing density "
                  f"{summary.get('packing_density_coefficient', float('nan')):.3f}, "
                  f"{time.perf_counter() - started:.0f} s", flush=True)
        (out / "series.toml").write_text(series_case(STEPS, args.waves))
        run_campaign(members_of([out / "series.toml"], args.seeds), out / "campaign",
                     workers=min(2, len(args.seeds)), threads=1)
    rows = step_rows(out / "campaign", args.seeds)
    write_results(rows, results, args.seeds)
    print("seed step asked_Ns  Ns    Tp_s   waves displaced N_od   S      Kr    q_m3/m    "
          "largest_Dn gain")
    for r in rows:
        print(f"{r['seed']:4d} {r['step']:4d} {r['asked_Ns']:6.2f} {r['Ns']:5.2f} {r['Tp_s']:6.3f} "
              f"{r['waves']:5d} {r['units_displaced']:9d} {r['N_od']:6.3f} {r['S']:6.3f} "
              f"{r['Kr']:5.3f} {r['q_m3_per_m']:9.2e} {r['largest_move_Dn']:9.3f} "
              f"{r['wave_maker_gain']:.4f}")
    first = first_displacements(rows, args.seeds)
    for seed, ns in first.items():
        print(f"first displacement, seed {seed}: "
              + (f"N_s = {ns:.2f}" if math.isfinite(ns) else "none yet")
              + f"; Van Gent (2002): start {VAN_GENT_START[0]}-{VAN_GENT_START[1]}")
    values = list(first.values())
    done = all(math.isfinite(v) for v in values)
    print(f"METRIC first_displacement_Ns_min {min(values) if done else math.nan:.3f} ratio")
    print(f"METRIC first_displacement_Ns_max {max(values) if done else math.nan:.3f} ratio")
    print(f"METRIC cube_ladder_wall_s {time.perf_counter() - started:.0f} s")


if __name__ == "__main__":
    main()
