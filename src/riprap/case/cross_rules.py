"""Rules that join several keys or tables of a case file.

The schema (:mod:`riprap.schema`) judges each key alone; these rules judge keys together, so
that ``riprap check`` refuses every combination that ``riprap run`` or ``riprap place`` would
refuse or, worse, silently ignore. Each rule adds a problem at the line of the key that has to
change, through ``add(path, message, value)`` of the case loader.
"""
from __future__ import annotations

from collections.abc import Callable

from riprap.work_estimate import schedule_problems

# The validated tables: name -> dict of values (defaults filled, _INVALID where a value was
# refused), a list of such dicts for arrays, or None for an absent optional table.
Tables = dict

#: Keys of [placement] that describe a design grid; a grid file replaces all of them.
DESIGN_GRID_KEYS = ("rows", "units_per_row", "units_per_alternate_row",
                    "packing_density_coefficient", "first_row_s", "drop_height")
#: Tables only ``riprap place`` reads.
PLACEMENT_TABLES = ("slope", "underlayer", "armour", "placement", "armour_stone")
#: The tables of a placement of units, and of one of rock armour.
UNIT_PLACEMENT_TABLES = ("slope", "underlayer", "armour", "placement")
STONE_PLACEMENT_TABLES = ("slope", "underlayer", "armour_stone")


def check_cross_rules(tables: Tables, add: Callable, invalid: object) -> None:
    """Add a problem for every broken rule; values equal to ``invalid`` were already reported."""
    def ok(*values):
        return all(value is not invalid for value in values)

    simulation = tables.get("simulation")
    if simulation and ok(simulation["time_step"], simulation["end_time"]):
        if simulation["time_step"] > simulation["end_time"]:
            add(("simulation", "time_step"),
                f"longer than end_time = {simulation['end_time']:g} s: the run would make no "
                "step; 0 chooses the step automatically", simulation["time_step"])
    if simulation and ok(simulation["end_time"], simulation["output_interval"],
                         simulation["checkpoint_interval"]):
        # a placement's runs last their settle_time (the longer one counts), a run its end_time
        ends = [(tables[name]["settle_time"], f"{name}.settle_time")
                for name in ("underlayer", "placement", "armour_stone")
                if tables.get(name) is not None and ok(tables[name]["settle_time"])]
        end_time, end_key = max(ends) if ends else (simulation["end_time"], "end_time")
        for key, value, message in schedule_problems(
                end_time=end_time, output_interval=simulation["output_interval"],
                checkpoint_interval=simulation["checkpoint_interval"], end_key=end_key):
            add(("simulation", key), message, value)
        output = tables.get("output")
        interval = output.get("body_forces_interval") if output else None
        if interval is not None and ok(interval) and interval > 0:
            # the body forces' own schedule has the frames' limit
            for _, value, message in schedule_problems(end_time=end_time, output_interval=interval,
                                                       checkpoint_interval=0.0, end_key=end_key):
                add(("output", "body_forces_interval"),
                    message.replace("set output_interval", "set body_forces_interval"), value)

    output = tables.get("output")
    interval = output.get("body_forces_interval") if output else None
    if interval is not None and ok(interval) and interval > 0 and tables.get("fluid") is None:
        add(("output", "body_forces_interval"), "body_forces.csv holds the flow's forces on the "
            "bodies: a run without a [fluid] table writes none; drop the key or set it to 0",
            interval)

    for name in ("waves", "gauges", "porous_zones"):
        if tables.get(name) and tables.get("fluid") is None:
            header = "[waves]" if name == "waves" else f"[[{name}]]"
            add((name,), f"{header} belongs to a flume: it needs a [fluid] table (the air and water "
                "the waves run in)")

    _check_series(tables, add, ok)

    given_placement = [name for name in PLACEMENT_TABLES if tables.get(name) is not None]
    has_bodies = bool(tables.get("bodies")) or bool(tables.get("body_grids"))
    if given_placement:
        stones = tables.get("armour_stone") is not None
        if stones and (tables.get("armour") is not None or tables.get("placement") is not None):
            add(("armour_stone",), "rock armour ([armour_stone]) or armour units ([armour] and "
                "[placement]), not both: one layer is placed per case")
        needed = STONE_PLACEMENT_TABLES if stones else UNIT_PLACEMENT_TABLES
        missing = [f"[{name}]" for name in needed if tables.get(name) is None]
        if missing:
            add((given_placement[0],),
                "an armour placement (riprap place) needs "
                + (", ".join(f"[{name}]" for name in needed))
                + f"; missing: {', '.join(missing)}")
        if tables.get("fluid") is not None:
            add(("fluid",), "a case is either an armour placement ([slope], [underlayer], [armour], "
                "[placement]; riprap place) or a fluid run ([fluid]; riprap run), not both: place "
                "the layer first, then run its pack")
        if tables.get("deformable") is not None:
            add(("deformable",), "riprap place drops rigid rocks and units and would ignore "
                "[deformable]; remove it, and add it to the case that runs the placed pack "
                "(pack = \"pack.toml\")")
        if has_bodies:
            where = "bodies" if tables.get("bodies") else "body_grids"
            add((where,), "riprap place makes its own bodies (rocks and units) and would ignore "
                "these; remove them, or run them as a separate case")
        _check_placement(tables, add, ok)


def _check_armour_stone(tables: Tables, add: Callable, ok: Callable) -> None:
    stone = tables.get("armour_stone")
    if not stone:
        return
    named = ok(stone["grading"]) and stone["grading"] not in ("", None)
    if named and ok(stone["dn50"]) and stone["dn50"] > 0:
        add(("armour_stone", "dn50"), "a grading name gives the stones' sizes; give the name or "
            "dn50 (with dn85_over_dn15), not both", stone["dn50"])
    if not named and ok(stone["dn50"]) and stone["dn50"] <= 0:
        add(("armour_stone",), "give a grading (an EN 13383 name such as \"HMA 300/1000\") or "
            "dn50 (> 0, with dn85_over_dn15)")
    if not named and ok(stone["length_scale"]) and stone["length_scale"] != 1.0:
        add(("armour_stone", "length_scale"), "scales a named grading; dn50 is the model's "
            "already", stone["length_scale"])
    if ok(stone["stone_shapes"], stone["size_classes"]) \
            and stone["size_classes"] > stone["stone_shapes"]:
        add(("armour_stone", "size_classes"), f"more than stone_shapes = "
            f"{stone['stone_shapes']}: every size class needs a shape of its own",
            stone["size_classes"])
    slope = tables.get("slope")
    if slope and ok(slope["length"], stone["from_s"], stone["to_s"]):
        high = stone["to_s"] or slope["length"]
        if stone["to_s"] > slope["length"]:
            add(("armour_stone", "to_s"), f"beyond the crest: the face is {slope['length']:g} m "
                "long (slope.length); 0 means the whole face", stone["to_s"])
        elif stone["from_s"] >= high:
            add(("armour_stone", "from_s"), f"not below to_s = {high:g} m: no stone would be "
                "placed", stone["from_s"])


def _check_placement(tables: Tables, add: Callable, ok: Callable) -> None:
    _check_armour_stone(tables, add, ok)
    placement, armour = tables.get("placement"), tables.get("armour")
    slope, underlayer = tables.get("slope"), tables.get("underlayer")
    if placement:
        if placement["grid_file"] not in ("", None) and ok(placement["grid_file"]):
            for name in DESIGN_GRID_KEYS:
                default = 0 if name in ("rows", "units_per_row", "units_per_alternate_row") else 0.0
                if ok(placement[name]) and placement[name] != default:
                    add(("placement", name), "a grid_file gives the unit positions, so this design-"
                        "grid key would be ignored; remove it or the grid_file", placement[name])
        else:
            for name in ("rows", "units_per_row"):
                if ok(placement[name]) and placement[name] < 1:
                    add(("placement", name), "a design grid (no grid_file) needs rows >= 1 and "
                        "units_per_row >= 1", placement[name])
            if placement["orientation"] == "user":
                add(("placement", "orientation"), "'user' orientations come from a grid_file; give "
                    "one, or choose random or random_within", placement["orientation"])
        if placement["release"] == "on_contact" and ok(placement["drop_height"]) \
                and placement["drop_height"] > 0:
            add(("placement", "drop_height"), "only used with release = \"free_fall\"; units "
                "released on contact are lowered until they touch", placement["drop_height"])
    if armour:
        sizes = [name for name in ("height", "nominal_diameter", "mass")
                 if ok(armour[name]) and armour[name] > 0]
        if len(sizes) != 1:
            add(("armour",), "give exactly one of height, nominal_diameter and mass (> 0); got "
                + (", ".join(sizes) or "none"))
    if underlayer and ok(underlayer["rock_shapes"], underlayer["size_classes"]) \
            and underlayer["size_classes"] > underlayer["rock_shapes"]:
        add(("underlayer", "size_classes"), f"more than rock_shapes = "
            f"{underlayer['rock_shapes']}: every size class needs a shape of its own",
            underlayer["size_classes"])
    if slope and underlayer and ok(slope["length"], underlayer["from_s"], underlayer["to_s"]):
        length, low = slope["length"], underlayer["from_s"]
        high = underlayer["to_s"] or length
        if low < 0:
            add(("underlayer", "from_s"), "below the toe (s < 0); the rock band must lie on the "
                f"face, 0 to length = {length:g} m", low)
        if underlayer["to_s"] > length:
            add(("underlayer", "to_s"), f"beyond the crest: the face is {length:g} m long "
                "(slope.length); 0 means the whole face", underlayer["to_s"])
        elif low >= high:
            add(("underlayer", "from_s"), f"not below to_s = {high:g} m: the rock band would be "
                "empty", low)


def _check_series(tables: Tables, add: Callable, ok: Callable) -> None:
    """A test series: a flume with irregular waves, steps that each give one period and one
    length, and significant heights that rise from step to step."""
    series, steps = tables.get("series"), tables.get("series_steps") or []
    if series is None:
        if steps:
            add(("series_steps",), "[[series_steps]] are the sea states of a test series: add a "
                "[series] table, or drop them and give the sea in [waves]")
        return
    if not steps:
        add(("series",), "a test series needs its sea states: add [[series_steps]] entries "
            "(significant_height, peak_period or wave_steepness, waves or duration)")
    waves = tables.get("waves")
    if tables.get("fluid") is None or waves is None:
        add(("series",), "a test series attacks a structure with waves: it needs [fluid] and "
            "[waves] (type = \"irregular\", whose sea the steps replace)")
    elif ok(waves.get("type")) and waves.get("type") != "irregular":
        add(("waves", "type"), "a test series replaces an irregular sea's significant_height and "
            "peak_period step by step: [waves] type must be \"irregular\"", waves.get("type"))
    previous = None
    for number, step in enumerate(steps):
        if step is None:
            continue
        period, steepness = step.get("peak_period"), step.get("wave_steepness")
        if ok(period, steepness) and (period > 0) == (steepness > 0):
            if period > 0:
                add(("series_steps", number, "peak_period"),
                    "give either peak_period or wave_steepness (the other 0)", period)
            else:       # neither given: no value of the user's to show
                add(("series_steps", number),
                    "neither peak_period nor wave_steepness is given: give one of them")
        waves_run, duration = step.get("waves"), step.get("duration")
        if ok(waves_run, duration) and (waves_run > 0) == (duration > 0):
            if waves_run > 0:
                add(("series_steps", number, "waves"),
                    "give either waves (a number of waves) or duration (s), the other 0",
                    waves_run)
            else:
                add(("series_steps", number), "neither waves (a number of waves) nor duration "
                    "(s) is given: give one of them")
        height = step.get("significant_height")
        if not ok(height):
            continue
        if previous is not None and not height > previous[1]:
            add(("series_steps", number, "significant_height"),
                f"does not rise above series_steps[{previous[0]}]'s {previous[1]:g} m (step "
                f"{number + 1} of the series against step {previous[0] + 1}: the steps count "
                "from 1, the entries from 0): a test series runs rising sea states on one "
                "structure (another sea on the same structure is another member of a campaign: "
                "docs/campaign.md)", height)
        previous = (number, height)
