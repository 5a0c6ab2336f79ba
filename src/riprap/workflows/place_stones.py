"""``riprap place`` of a case with ``[armour_stone]``: rock armour on the underlayer
(docs/rock-armour.md).

The grading: an EN 13383-1 class by name (prototype masses) scaled to the model by
``length_scale`` keeping H / (Delta D_n) (``riprap.geometry.armour_stone``), or the model's own
D_n50 and D_n85 / D_n15. The stones: a library of ``stone_shapes`` random rocks in
``size_classes`` size classes of the grading, drawn by count. The placement:
``riprap.placement.armour_stones`` (a grid from the Rock Manual's k_t and the design porosity,
stones lowered one by one from the toe up, a layer at a time). The summary says the placed
layer beside its design (k_t, N_a, porosity, roughness) and the placed stones' grading beside
the one asked (M50, W85/W15, D_n50; for a named class its EN 13383 requirements).

Output folder: ``underlayer/`` and ``stones/layer_<k>/`` (the runs), ``pack.toml`` and
``shapes/`` (rocks fixed, stones free; ``riprap run`` reads it), ``contacts.csv``,
``final_layer.png``, ``summary.json`` and ``layer.json`` (the stones as the layer's units, of kind
``armour_stone``: ``riprap analyse`` and a test series' survey read it; S from the profiles and
the rock formulas in its stability report).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from riprap.case.build import SMOKE_END_TIME, smoke_mode
from riprap.errors import CaseFileError
from riprap.geometry.armour_stone import ArmourGrading, standard_grading
from riprap.geometry.rock_grading import RockGrading, rock_library
from riprap.analysis.layer_state import LayerDescription
from riprap.io.layer_file import CONTACTS_FILE_NAME, write_contact_table, write_layer_file
from riprap.io.output_folder import prepare_output_folder
from riprap.io.summary import write_json
from riprap.placement import PlacementMaterials, Slope, build_underlayer
from riprap.placement.armour_stones import StoneLayerDesign, place_armour_stones, stone_grid
from riprap.placement.place import rock_lattice, rock_shapes
from riprap.schema import MAXIMUM_BODY_COUNT, default_of
from riprap.workflows.placed_pack import write_placed_pack

__all__ = ["StonePlacementInputs", "prepare_stone_placement", "run_stone_placement",
           "stone_grading"]


@dataclass
class StonePlacementInputs:
    """Everything the placement of rock armour builds and checks before it runs."""

    slope: Slope
    materials: PlacementMaterials
    grading: ArmourGrading
    stones: list            # the stone library
    rocks: list             # the underlayer's rock library
    design: StoneLayerDesign
    s_range: tuple
    rock_count: int
    stone_count: int


def stone_grading(case, density: float) -> ArmourGrading:
    """The grading of the model's stones (of ``density``): a named class scaled to the model,
    or dn50 and dn85_over_dn15 as given."""
    spec = case.armour_stone
    where = f"{case.source} [armour_stone]"
    try:
        if spec.grading:
            grading = standard_grading(spec.grading, density=density)
            if spec.length_scale != 1.0:
                water = (case.fluid.water_density if case.fluid is not None
                         else default_of("fluid", "water_density"))
                grading = grading.to_model(spec.length_scale, model_density=density,
                                           prototype_water_density=spec.prototype_water_density,
                                           model_water_density=water)
            return grading
        return ArmourGrading.from_spread(spec.dn50, spec.dn85_over_dn15, density=density)
    except CaseFileError as error:
        raise CaseFileError(f"{where}: {error}") from None


def prepare_stone_placement(case, materials: PlacementMaterials) -> StonePlacementInputs:
    """Every check of a rock armour placement before it runs (``riprap check`` runs this);
    ``materials``: the placement's (``riprap.workflows.place.placement_materials``: the stones
    are its ``unit``)."""
    sl, ul, spec = case.slope, case.underlayer, case.armour_stone
    slope = Slope(cotangent=sl.cotangent, width=sl.width, length=sl.length, toe_x=sl.toe_x,
                  toe_level=sl.toe_level, toe_stop_distance=sl.toe_stop_distance,
                  periodic=sl.sides == "periodic")
    grading = stone_grading(case, materials.unit.density)
    where = f"{case.source} [armour_stone]"
    ratio = grading.dn50 / ul.dn50
    # the filter rule for rock (The Rock Manual 2007, 5.2.2.10): the underlayer's M50 1/10 to
    # 1/15 of the armour's, D_n50 ratio 2.2 to 2.5; refused outside 1.3 .. 4 as for units
    if not 1.3 <= ratio <= 4.0:
        raise CaseFileError(f"{where}: stones of D_n50 = {grading.dn50:.3g} m on [underlayer] dn50 "
                            f"= {ul.dn50:g} m (ratio {ratio:.2f}): the filter rule puts "
                            "underlayer stones of M50/10 to M50/15 under armour stone, a D_n50 "
                            f"ratio of 2.2 to 2.5; give underlayer dn50 about "
                            f"{grading.dn50 / 2.3:.3g} m")
    try:
        design = StoneLayerDesign(dn50=grading.dn50, layers=spec.layers,
                                  placement=spec.placement, porosity=spec.porosity,
                                  toe_berm_width=spec.toe_berm_width)
        s_range = (spec.from_s, spec.to_s or slope.length)
        count = sum(len(stone_grid(slope, design, s_range, layer)) for layer in range(spec.layers))
    except CaseFileError as error:
        raise CaseFileError(f"{where}: {error}") from None
    if design.toe_berm_width > 0 and slope.toe_stop_distance < design.toe_berm_width:
        raise CaseFileError(f"{where} toe_berm_width = {design.toe_berm_width:g} m: the berm "
                            "lies on the bed between the toe and the fixed toe stop, but [slope] "
                            f"toe_stop_distance = {slope.toe_stop_distance:g} m; give "
                            f"toe_stop_distance {design.toe_berm_width:g} m or more")
    if not slope.periodic and slope.width < 2.0 * design.spacing:
        raise CaseFileError(f"{where}: the section (slope.width = {slope.width:g} m) holds fewer "
                            f"than two stones across ({design.spacing:.3g} m apart, D_n50 = "
                            f"{grading.dn50:.3g} m): widen it, or make it a periodic strip")
    stones = rock_library(grading.as_rock_grading(), n_shapes=spec.stone_shapes,
                          n_size_classes=spec.size_classes, seed=spec.seed)
    rocks = rock_library(RockGrading(dn50=ul.dn50, dn85_over_dn15=ul.dn85_over_dn15),
                         n_shapes=ul.rock_shapes, n_size_classes=ul.size_classes, seed=ul.seed)
    try:
        lattice = rock_lattice(slope, rock_shapes(rocks), (ul.from_s, ul.to_s or slope.length),
                               ul.layers)
    except CaseFileError as error:
        raise CaseFileError(f"{case.source}: {error}") from None
    if len(lattice) + count > MAXIMUM_BODY_COUNT:
        raise CaseFileError(f"{where}: {count:,} stones on {len(lattice):,} rocks are more than "
                            f"the {MAXIMUM_BODY_COUNT:,} bodies a case may have")
    return StonePlacementInputs(slope=slope, materials=materials, grading=grading, stones=stones,
                                rocks=rocks, design=design, s_range=s_range,
                                rock_count=len(lattice), stone_count=count)


def _settings(case, end_time, output_directory, progress) -> dict:
    sim = case.simulation
    return dict(end_time=min(end_time, SMOKE_END_TIME) if smoke_mode() else end_time,
                time_step=sim.time_step, time_step_safety=sim.time_step_safety,
                gravity=sim.gravity, output_interval=sim.output_interval,
                rest_speed=default_of("placement", "rest_speed"),
                output_directory=output_directory, paraview=case.output.paraview,
                picture=False, progress=progress, adaptive_time_step=True)


def run_stone_placement(case, materials: PlacementMaterials, *, output_directory=None,
                        progress: bool = True) -> dict:
    """Place the underlayer and the rock armour of ``case``; returns the summary (also
    ``summary.json``)."""
    inputs = prepare_stone_placement(case, materials)
    out = prepare_output_folder(output_directory or case.output.directory)
    ul, spec = case.underlayer, case.armour_stone
    slope, materials = inputs.slope, inputs.materials
    underlayer = build_underlayer(
        slope, inputs.rocks, materials=materials, s_range=(ul.from_s, ul.to_s or slope.length),
        layers=ul.layers, seed=ul.seed,
        **_settings(case, ul.settle_time, out / "underlayer", progress))
    stones = place_armour_stones(slope, inputs.stones, underlayer, materials=materials,
                                 design=inputs.design, s_range=inputs.s_range, seed=spec.seed,
                                 **_settings(case, spec.settle_time, out / "stones", progress))
    summary = dict(stones.summary)
    runs = summary.pop("runs")
    volumes = np.array([float(stones.shapes[c].mesh.volumes().sum())
                        for c in stones.shape_of_stone])
    masses = volumes * materials.unit.density
    summary["grading"] = _grading_summary(inputs.grading, masses)
    summary["smoke"] = smoke_mode()
    summary["underlayer_rocks"] = int(len(underlayer.positions))
    summary["underlayer_top_m"] = float(underlayer.top_level)
    summary["runs"] = runs
    summary["outputs"] = _write_outputs(case, stones, materials, slope, out)
    layer = LayerDescription.for_stones(
        shape_names=sorted({stones.shapes[c].name for c in stones.shape_of_stone}),
        nominal_diameter=summary["grading"]["placed"]["Dn50_m"], mean_volume=volumes.mean(),
        design=inputs.design, slope=slope, underlayer_top=underlayer.top_level,
        unit_bodies=np.arange(len(underlayer.positions),
                              len(underlayer.positions) + len(stones.positions)),
        rows=stones.rows, design_positions=stones.set_positions, filter_dn50=ul.dn50,
        grading_ratio=summary["grading"]["placed"]["Dn85_over_Dn15"])
    summary["outputs"]["layer"] = str(write_layer_file(out, layer))
    write_json(out / "summary.json", summary)
    return summary


def _grading_summary(grading: ArmourGrading, masses: np.ndarray) -> dict:
    """The placed stones' grading beside the one asked."""
    placed = grading.statistics(masses)
    entry = {"asked": {"M50_kg": grading.m50, "M85_over_M15": grading.m85_over_m15,
                       "Dn50_m": grading.dn50, "Dn85_over_Dn15": grading.dn85_over_dn15,
                       "class": None if grading.standard_class is None
                       else grading.standard_class.name},
             "placed": {"stones": placed.count, "M50_kg": placed.m50,
                        "M85_over_M15": placed.m85_over_m15, "Dn50_m": placed.dn50,
                        "Dn85_over_Dn15": placed.dn85_over_dn15}}
    if grading.standard_class is not None:
        conformity = grading.conformity(masses)
        entry["en13383"] = {"passed": conformity.passed,
                            "failures": [r.description for r in conformity.failures]}
    return entry


def _write_outputs(case, stones, materials, slope, out: Path) -> dict:
    sim = stones.simulation
    solver = sim.solver
    pack = write_placed_pack(case, sim, materials, slope, out,
                             comment=f"rock armour placed by riprap place from {case.source}",
                             contact_history=stones.resting_history)
    outputs = {"pack": str(pack),
               "contacts": str(write_contact_table(out / CONTACTS_FILE_NAME, solver.contacts))}
    if case.output.picture:
        face = slope.to_world([0.0, slope.length, slope.length, 0.0],
                              [0.0, 0.0, slope.width, slope.width], [0.0, 0.0, 0.0, 0.0])
        n_stones = len(stones.positions)
        title = (f"{n_stones} armour stones in {int(stones.layer_of_stone.max()) + 1} layers on "
                 f"{solver.n_bodies - n_stones} underlayer rocks (grey), 1:{slope.cotangent:g}")
        outputs["picture"] = str(sim.write_picture(out / "final_layer.png", show_fixed=True,
                                                   planes=[face], view=(30, -125), title=title))
    return outputs
