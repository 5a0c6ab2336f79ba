"""Issue 55's rock ladder: a double layer of graded armour stone on a 1:2 slope under rising
seas, on a permeable and on a much less permeable core, S per step beside the three rock
formulas. Untuned: nothing here was fitted to the formulas.

The section (Froude-scaled laboratory flume, fresh water):

- **armour**: stones of D_n50 = 3.5 cm, D_n85/D_n15 = 1.25 (a narrow grading, as Van der Meer's
  tests), 2650 kg/m^3 (Delta = 1.65), two layers placed by ``riprap place`` ("standard":
  stone by stone from the toe up, random orientation, k_t 0.91 and n_v 0.37 as the grid's
  design) on one layer of filter rocks (D_n50 = D_n50 / 2.3, the Rock Manual's filter rule),
  on a periodic strip 4.7 D_n50 wide;
- **core 1 (permeable)**: a porous zone of stones D50 = 1 cm (D_n50 0.84 cm, armour/core 4.2),
  porosity 0.4; **core 2 (much less permeable)**: the same zone of D50 = 1 mm, porosity 0.3
  (armour/core 42): the flow through it is about a hundredth. Both ``part = "core"``, so the
  report's P and the core formulas read them;
- water depth 0.6 m, crest 0.15 m above still water, a boundary wave maker with active
  absorption 2.1 m seaward of the toe, three gauges for the incident waves; cubic cells of
  D_n50 / 3.4 (16 across the strip; the coupling refuses a moving body under 3 cells, and the
  grading's smallest stones are about 0.85 D_n50; the filter rocks, at 1.5 cells, are a fitted
  porous filter for the flow and contact bodies for the stones); 557,888 cells, about 2.5
  times the cube ladder's, so a step costs about 2.5 times as much (some 8 h a step and member
  at that ladder's measured pace: 30 h or more for the ladder, over the issue's 12 h budget);
- **calibrated seas** (``[series] wave_calibration = "without_structure"``).

The ladder: N_s = H_s / (Delta D_n50) = 2.0, 2.5, 3.0, 3.5 at s_op = 0.03 (from S about 1 to
beyond failure by Van der Meer's formula for 50 waves, cumulative), ``--waves`` waves a step
(default 50), seed 0, the two cores as one ``riprap campaign`` (two Dask workers of one thread).

Resumes from ``--out`` (outside git). ``--report`` writes what is done so far (``curve.csv``
with the three formulas' S cumulative over the steps, and the picture) into ``--results``
(default ``bench/results/rock_damage_ladder_<date>``). Last lines ``METRIC
rock_S_step<k>_core<c>`` (c = 1 permeable, 2 less permeable; nan for a step not yet run) and
``METRIC rock_ladder_wall_s``.

    python bench/rock_damage_ladder.py [--out DIR] [--waves N] [--report]
"""
import argparse
import csv
import datetime
import json
import math
import time
from pathlib import Path

DN50 = 0.035               # m
DELTA = 2650.0 / 1000.0 - 1.0
DEPTH = 0.6                # m
FREEBOARD = 0.15           # m
COT = 2.0
CELL = DN50 / 3.4          # m: the smallest stones (about 0.85 D_n50) keep 3 cells, the
                           # coupling's least for a moving body
ACROSS = 16                # cells across the strip (a multiple of 4)
WIDTH = ACROSS * CELL      # m: 4.7 D_n50
STEEPNESS = 0.03
STEPS = (2.0, 2.5, 3.0, 3.5)
CORES = {1: ("permeable", 0.01, 0.4), 2: ("low_permeability", 0.001, 0.3)}

PLACEMENT = f"""format_version = 1

[simulation]
end_time = 1.0
time_step_safety = 0.3
output_interval = 0.1

[[materials]]
name = "armourstone"
density = 2650.0
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
width = {WIDTH:.6f}
length = {(DEPTH + FREEBOARD) * math.hypot(1.0, COT):.4f}
toe_stop_distance = 0.03
face_material = "core"
side_wall_material = "core"
sides = "periodic"

[underlayer]
material = "rock"
dn50 = {DN50 / 2.3:.5f}
dn85_over_dn15 = 1.3
rock_shapes = 4
size_classes = 2
layers = 1
settle_time = 1.0

[armour_stone]
material = "armourstone"
dn50 = {DN50}
dn85_over_dn15 = 1.25
layers = 2
placement = "standard"
stone_shapes = 8
size_classes = 3
settle_time = 1.5

[output]
directory = "pack"
"""


def series_case(steps, waves: int, core_d50: float, core_porosity: float) -> str:
    crest = DEPTH + FREEBOARD
    top_x = crest * COT
    ladder = "".join(f"""
[[series_steps]]
significant_height = {ns * DELTA * DN50:.4f}
wave_steepness = {STEEPNESS}
waves = {waves}
""" for ns in steps)
    x_low, x_high = -2.1, top_x + 0.3
    nx = round((x_high - x_low) / CELL)
    nz = round((crest + 0.2) / CELL)
    gauges = "\n".join(f'[[gauges]]\ntype = "surface"\nname = "g{k + 1}"\n'
                       f"position = [{x}, {WIDTH / 2:.5f}, 0.0]\n"
                       for k, x in enumerate((-1.5, -1.2, -0.7)))
    return f"""format_version = 1
pack = "pack/pack.toml"

[simulation]
end_time = 60.0
adaptive_time_step = true
output_interval = 5.0
checkpoint_interval = 5.0

[fluid]
lower = [{x_high - nx * CELL:.6f}, 0.0, 0.0]
upper = [{x_high:.6f}, {WIDTH:.6f}, {nz * CELL:.6f}]
cells = [{nx}, {ACROSS}, {nz}]
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
part = "core"
porosity = {core_porosity}
stone_diameter = {core_d50}
points = [[0.04, 0.0], [{top_x - 0.04:.4f}, {crest - 0.02:.4f}], [{x_high:.4f}, {crest - 0.02:.4f}], [{x_high:.4f}, 0.0]]

[waves]
type = "irregular"
still_water_level = {DEPTH}
significant_height = 0.1
peak_period = 1.4
duration = 100.0
generation = "boundary"
absorbing_end = false

{gauges}
[series]
displacement_threshold = 1.0
wave_calibration = "without_structure"
{ladder}
[output]
directory = "series"
body_forces_interval = 0.25
"""


def _number(value) -> float:
    return (float(value) if isinstance(value, (int, float)) and not isinstance(value, bool)
            else math.nan)


def step_rows(campaign: Path) -> list[dict]:
    """Every finished step of both members (its survey), one row each, with the core; the
    formulas' S cumulative over the member's steps (riprap.analysis.series_damage)."""
    from riprap.analysis.series_damage import rock_formula_curves

    rows = []
    for core, (name, d50, _) in CORES.items():
        member = campaign / f"{name}_seed0"
        mine = []
        for folder in sorted(member.glob("step_*")):
            survey = folder / "survey" / "layer_summary.json"
            if not (folder / "summary.json").is_file() or not survey.is_file():
                continue
            layer = json.loads(survey.read_text())
            flume = layer.get("flume_test") or {}
            rock = flume.get("rock") or {}
            number = int(folder.name.split("_")[1])
            summary = json.loads((folder / "summary.json").read_text())
            hm0 = _number(flume.get("Hm0_m"))
            mine.append({
                "core": core, "core_name": name, "core_D50_m": d50, "step": number,
                "asked_Ns": STEPS[number - 1], "Hm0_m": hm0, "Ns": hm0 / (DELTA * DN50),
                "Tm_1_0_s": _number(rock.get("spectral_period_s")),
                "Tp_s": _number(flume.get("incident_Tp_s")),
                "waves": int(flume["waves"]) if math.isfinite(_number(flume.get("waves")))
                else 0,
                "S": _number(layer.get("damage_level_s")),
                "damage_class": rock.get("damage_class", ""),
                "stones_displaced": len(layer.get("units_displaced", [])),
                "N_od": _number(layer.get("damage_number_nod")),
                "P": _number(rock.get("notional_permeability")),
                "Kr": _number(flume.get("reflection_coefficient")),
                "wall_s": _number(summary.get("wall_time"))})
        if mine:
            last = json.loads((sorted(member.glob("step_*"))[len(mine) - 1] / "survey" /
                               "layer_summary.json").read_text())["flume_test"].get("rock", {})
            curves = rock_formula_curves(
                [(r["Hm0_m"], r["Tm_1_0_s"], r["waves"]) for r in mine], slope_cot=COT,
                delta=DELTA, nominal_diameter=_number(last.get("nominal_diameter_m")),
                permeability=_number(last.get("notional_permeability")),
                core_nominal_diameter=_number(last.get("core_dn50_m")))
            for k, row in enumerate(mine):
                for column, values in curves.items():
                    row[column] = values[k]
        rows.extend(mine)
    return rows


def write_results(rows: list[dict], results: Path) -> None:
    results.mkdir(parents=True, exist_ok=True)
    if not rows:
        return
    names = list(dict.fromkeys(k for r in rows for k in r))
    with (results / "curve.csv").open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=names)
        writer.writeheader()
        writer.writerows(rows)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
    for panel, (core, (name, d50, _)) in zip(axes, CORES.items()):
        mine = sorted((r for r in rows if r["core"] == core), key=lambda r: r["step"])
        ns = [r["Ns"] for r in mine]
        panel.plot(ns, [r["S"] for r in mine], "o-", color="C0", label="S, riprap")
        for column, style, label in (("van_der_meer_2021_S", "s--", "Van der Meer (2021)"),
                                     ("van_gent_2003_S", "D--", "Van Gent et al. (2003)"),
                                     ("etemad_shahidi_2020_S", "v--",
                                      "Etemad-Shahidi et al. (2020)")):
            panel.plot(ns, [r.get(column, math.nan) for r in mine], style, alpha=0.8,
                       label=label)
        panel.axhline(2.0, color="0.4", linestyle=":", label="start of damage (S 2)")
        panel.axhline(8.0, color="0.4", linestyle="--", label="failure (S 8)")
        panel.set_title(f"core {core}: {name.replace('_', ' ')}, D50 {1000 * d50:g} mm",
                        fontsize=9)
        panel.set_xlabel("N_s = H_s / (Delta D_n50), measured at the toe")
        panel.grid(alpha=0.3)
    axes[0].set_ylabel("damage level S")
    axes[0].legend(fontsize=7)
    figure.suptitle("Rock armour, two layers, 1:2, periodic strip 4.7 D_n50, calibrated seas "
                    "(riprap, untuned); formulas cumulative over the steps", fontsize=10)
    figure.tight_layout()
    figure.savefig(results / "curve.png", dpi=110)
    plt.close(figure)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="/work/runs/rock_damage_ladder")
    parser.add_argument("--waves", type=int, default=50)
    parser.add_argument("--results", default=None)
    parser.add_argument("--report", action="store_true",
                        help="write what is done so far; run nothing")
    parser.add_argument("--place-only", action="store_true",
                        help="place the layer and write the cases; run no series")
    args = parser.parse_args()
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    results = Path(args.results or Path(__file__).parent / "results" /
                   f"rock_damage_ladder_{datetime.date.today().isoformat()}")
    started = time.perf_counter()
    if not args.report:
        from riprap.case.load import load_case
        from riprap.workflows.campaign import members_of, run_campaign
        from riprap.workflows.place import run_placement

        if not (out / "pack" / "pack.toml").is_file():
            (out / "placement.toml").write_text(PLACEMENT)
            summary = run_placement(load_case(out / "placement.toml"),
                                    output_directory=out / "pack", progress=False)
            measured = summary["measured"]
            print(f"placed {measured['stones_placed']} stones on {summary['underlayer_rocks']} "
                  f"rocks: k_t {measured['layer_thickness_coefficient']:.3f}, porosity "
                  f"{measured['porosity']:.3f}, {time.perf_counter() - started:.0f} s",
                  flush=True)
        cases = []
        for core, (name, d50, porosity) in CORES.items():
            (out / f"{name}.toml").write_text(series_case(STEPS, args.waves, d50, porosity))
            cases.append(out / f"{name}.toml")
        if not args.place_only:
            run_campaign(members_of(cases, [0]), out / "campaign", workers=2, threads=1)
    rows = step_rows(out / "campaign")
    write_results(rows, results)
    print("core step asked_Ns  Ns    Tm-1,0  waves  S      class              VdM2021  VG2003  "
          "ES2020")
    for r in rows:
        print(f"{r['core']:4d} {r['step']:4d} {r['asked_Ns']:6.2f} {r['Ns']:5.2f} "
              f"{r['Tm_1_0_s']:6.3f} {r['waves']:5d} {r['S']:6.2f} {r['damage_class']:18s} "
              f"{r.get('van_der_meer_2021_S', math.nan):7.2f} "
              f"{r.get('van_gent_2003_S', math.nan):7.2f} "
              f"{r.get('etemad_shahidi_2020_S', math.nan):7.2f}")
    for core in CORES:
        for step in range(1, len(STEPS) + 1):
            value = next((r["S"] for r in rows if r["core"] == core and r["step"] == step),
                         math.nan)
            print(f"METRIC rock_S_step{step}_core{core} {value:.3f} ratio")
    print(f"METRIC rock_ladder_wall_s {time.perf_counter() - started:.0f} s")


if __name__ == "__main__":
    main()
