"""How long ``riprap analyse`` takes on a placed armour layer.

Places ``examples/coreloc_small.toml`` (25 Core-Loc-like units on ~135 rocks) once into
``bench/.cache/coreloc_small`` if that pack is missing (a minute or two), or takes the pack given by
``--pack`` (e.g. the paper's 242-unit layer placed by ``riprap place examples/coreloc_paper_242.toml
--out bench/.cache/paper_242``), then times, ``--repeats`` times:

- reading the pack (case, meshes, layer.json, contacts.csv),
- the analysis itself (per-unit table, factors of safety, layer figures),
- writing the outputs (CSV, ParaView, the pictures and report.html),

and prints the best of each. Last line: ``METRIC analyse_layer_s <value> s`` (the whole
``riprap analyse`` of the pack, best of the repeats).

    python bench/analyse_layer.py
    python bench/analyse_layer.py --pack bench/.cache/paper_242
"""
from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

from riprap.analysis import analyse_layer
from riprap.workflows.layer_input import load_layer_state
from riprap.io.analysis_report import write_analysis

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_PACK = ROOT / "bench" / ".cache" / "coreloc_small"


def _ensure_small_pack() -> Path:
    if not (DEFAULT_PACK / "layer.json").is_file():
        from riprap.workflows.place import run_placement
        from riprap.case.load import load_case

        print(f"placing examples/coreloc_small.toml into {DEFAULT_PACK} (once) ...", flush=True)
        run_placement(load_case(ROOT / "examples" / "coreloc_small.toml"),
                      output_directory=DEFAULT_PACK, progress=False)
    return DEFAULT_PACK


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pack", type=Path, default=None, help="pack folder (default: the small example)")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    pack = args.pack or _ensure_small_pack()
    timings = {"read": [], "analyse": [], "write": [], "total": []}
    for _ in range(args.repeats):
        with tempfile.TemporaryDirectory() as out:
            start = time.perf_counter()
            state = load_layer_state(pack)
            read = time.perf_counter()
            analysis = analyse_layer(state)
            analysed = time.perf_counter()
            write_analysis(out, analysis)
            written = time.perf_counter()
        timings["read"].append(read - start)
        timings["analyse"].append(analysed - read)
        timings["write"].append(written - analysed)
        timings["total"].append(written - start)
    layer = analysis.layer
    print(f"pack {pack}: {layer['units']} units, {layer['underlayer_bodies']} underlayer bodies, "
          f"{layer['contact_force_N']['count']} unit contacts; load {os.getloadavg()[0]:.2f}")
    print(f"coordination {layer['coordination_number_min']}-{layer['coordination_number_max']} "
          f"(mean {layer['coordination_number_mean']:.2f}), largest contact force "
          f"{layer['max_contact_force_N']:.4g} N, packing density "
          f"{layer['packing_density_coefficient']:.3f}, smallest FoS {layer['factor_of_safety_min']:.3f}")
    for name, values in timings.items():
        print(f"{name:8s} best {min(values):7.2f} s   all {', '.join(f'{v:.2f}' for v in values)}")
    print(f"METRIC analyse_layer_s {min(timings['total']):.2f} s")


if __name__ == "__main__":
    main()
