"""``riprap place``: build an armour layer from a case with ``[slope]``, ``[underlayer]``,
``[armour]`` and ``[placement]`` tables, and write the pack, pictures and summary.

Output folder:

- ``underlayer/``: the rock deposition run (ParaView series, picture, its own summary);
- ``deposition/``: the unit deposition run (``bodies.pvd``, ``contacts.pvd``, ``final_state.png``);
- ``pack.toml`` and ``shapes/``: the final layer as a case file, readable by ``riprap run``;
- ``summary.json``: units placed and at rest, packing density coefficient, porosity and layer
  thickness against the design values, largest overlap over D_n.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from riprap.analysis.layer_state import LayerDescription
from riprap.case.body_start import check_grid_starts
from riprap.case.build import SMOKE_END_TIME, build_friction_pairs, build_material, smoke_mode
from riprap.errors import CaseFileError
from riprap.geometry.armour_units import armour_unit
from riprap.geometry.rock_grading import RockGrading, rock_library
from riprap.io.grid_file import read_grid_file
from riprap.io.layer_file import CONTACTS_FILE_NAME, write_contact_table, write_layer_file
from riprap.io.output_folder import prepare_output_folder
from riprap.io.summary import write_json
from riprap.placement import (PlacementMaterials, Slope, build_underlayer, design_grid,
                              place_units, unit_orientations)
from riprap.placement.checks import check_filter_rule, check_row_fits
from riprap.placement.place import (UNIT_SHAPE_NAME, check_generated_positions,
                                    check_start_positions, free_body_time_step, rock_lattice,
                                    rock_shapes)
from riprap.schema import MAXIMUM_BODY_COUNT
from riprap.solid.shape import RigidShape
from riprap.work_estimate import RiprapWarning, check_rigid_run
from riprap.workflows.place_stones import run_stone_placement
from riprap.workflows.placed_pack import write_checked_pack, write_placed_pack


def _material(case, name):
    for spec in case.materials:
        if spec.name == name:
            return build_material(spec)
    raise CaseFileError(f"{case.source}: no material named {name!r}")


def placement_materials(case) -> PlacementMaterials:
    """The four roles' materials and the ``[[friction]]`` pairs between them (a pair naming a
    material no role has meets nothing in a placement)."""
    units = case.armour_stone if case.armour_stone is not None else case.armour
    roles = dict(unit=_material(case, units.material),
                 rock=_material(case, case.underlayer.material),
                 face=_material(case, case.slope.face_material),
                 side_wall=_material(case, case.slope.side_wall_material))
    names = {material.name for material in roles.values()}
    return PlacementMaterials(**roles, friction_pairs=tuple(
        pair for pair in build_friction_pairs(case) if set(pair.materials) <= names))


def _require_tables(case) -> None:
    needed = (("slope", "underlayer", "armour_stone") if case.armour_stone is not None
              else ("slope", "underlayer", "armour", "placement"))
    missing = [f"[{name}]" for name in needed if getattr(case, name) is None]
    if missing:
        raise CaseFileError(f"{case.source}: riprap place needs the tables {', '.join(missing)} "
                            "(see docs/case-file.md)")


def _armour_unit(case):
    spec = case.armour
    given = {name: value for name, value in (("height", spec.height),
                                              ("nominal_diameter", spec.nominal_diameter),
                                              ("mass", spec.mass)) if value > 0}
    if len(given) != 1:
        raise CaseFileError(f"{case.source}: [armour] needs exactly one of height, nominal_diameter "
                            f"and mass (> 0), got {', '.join(given) or 'none'}")
    density = _material(case, spec.material).density
    return armour_unit(spec.unit, density=density, mesh_size=spec.mesh_size or None, **given)


def _settings(case, end_time, output_directory, progress) -> dict:
    sim = case.simulation
    return dict(end_time=min(end_time, SMOKE_END_TIME) if smoke_mode() else end_time,
                time_step=sim.time_step, time_step_safety=sim.time_step_safety,
                gravity=sim.gravity, output_interval=sim.output_interval,
                local_damping=case.placement.local_damping,
                rest_speed=case.placement.rest_speed,
                rest_kinetic_energy=case.placement.rest_kinetic_energy,
                output_directory=output_directory, paraview=case.output.paraview,
                picture=case.output.picture, progress=progress,
                # Settling runs: the time step follows the contacts present (see Simulation).
                adaptive_time_step=True)


@dataclass
class PlacementInputs:
    """Everything ``riprap place`` builds and checks before it simulates anything."""

    slope: Slope
    materials: PlacementMaterials
    unit: object            # riprap.geometry.armour_units.ArmourUnit
    rocks: list             # the rock library (riprap.geometry.rock_grading)
    grid: object = None     # riprap.io.grid_file.GridFile, when [placement] grid_file is given
    rock_count: int = 0     # rocks in the underlayer's start lattice


#: What ``riprap check`` cannot know of a placement case without running it.
PLACEMENT_NOT_CHECKED = ("whether the rocks and units come to rest, and where (only the "
                         "deposition runs tell)",)


def prepare_placement(case) -> PlacementInputs:
    """Build the slope, materials, unit mesh and rock shapes of ``case`` and read its grid file:
    every check ``riprap place`` makes before the deposition runs (``riprap check`` runs this)."""
    _require_tables(case)
    sl, ul, pl = case.slope, case.underlayer, case.placement
    slope = Slope(cotangent=sl.cotangent, width=sl.width, length=sl.length, toe_x=sl.toe_x,
                  toe_level=sl.toe_level, toe_stop_distance=sl.toe_stop_distance,
                  periodic=sl.sides == "periodic")
    materials = placement_materials(case)
    grid = None
    if pl.grid_file:
        grid = read_grid_file(case.base_dir / pl.grid_file)
        check_grid_starts(grid)
    unit = _armour_unit(case)
    check_filter_rule(nominal_diameter=unit.nominal_diameter, dn50=ul.dn50, unit=case.armour.unit,
                      where=case.source)
    if grid is not None:
        check_start_positions(slope, unit, grid.positions, _unit_orientations(case, slope, grid),
                              grid_lines=grid.lines, release=pl.release)
    else:
        _check_design_grid(case, slope, unit)
    rocks = rock_library(RockGrading(dn50=ul.dn50, dn85_over_dn15=ul.dn85_over_dn15),
                         n_shapes=ul.rock_shapes, n_size_classes=ul.size_classes, seed=ul.seed)
    # the underlayer's start lattice, as build_underlayer lays it (it refuses a band holding no
    # rock, or too many)
    shapes = rock_shapes(rocks)
    try:
        lattice = rock_lattice(slope, shapes, (ul.from_s, ul.to_s or slope.length), ul.layers)
    except CaseFileError as error:
        raise CaseFileError(f"{case.source}: {error}") from None
    units = len(grid.positions) if grid is not None else _unit_count(pl)
    _check_work(case, materials, shapes, unit, rocks=len(lattice), units=units)
    return PlacementInputs(slope=slope, materials=materials, unit=unit, rocks=rocks, grid=grid,
                           rock_count=len(lattice))


def _check_work(case, materials, rock_shapes, unit, *, rocks: int, units: int) -> None:
    """The work estimates the two runs make when they start (the rocks settling, then every unit
    moving on the fixed rocks), made now with the same time steps, so that a run of months is
    refused before the underlayer is built."""
    for table, shapes, material, moving in (
            ("underlayer", rock_shapes, materials.rock.name, rocks),
            ("placement", [RigidShape.from_mesh(unit.mesh, name=UNIT_SHAPE_NAME)],
             materials.unit.name, units)):
        settings = _settings(case, getattr(case, table).settle_time, case.output.directory, False)
        step, setting = free_body_time_step(shapes, materials, material, **settings)
        check_rigid_run(end_time=settings["end_time"], time_step=step, moving_bodies=moving,
                        setting_the_step=setting, end_key=f"[{table}] settle_time")


def _unit_count(pl) -> int:
    """Units of a design grid: rows alternate units_per_row and units_per_alternate_row."""
    alternate = pl.units_per_alternate_row or pl.units_per_row
    return (pl.rows + 1) // 2 * pl.units_per_row + pl.rows // 2 * alternate


def _check_design_grid(case, slope, unit) -> None:
    """The checks ``place_units`` makes of a design grid, before the underlayer run: rows of
    units that fit across the section, rows that stay on the face, no more units than a case may
    have bodies, and no unit wider than the flume (its orientation as the run draws it)."""
    pl = case.placement
    for key in ("units_per_row", "units_per_alternate_row"):
        if getattr(pl, key) > 0:
            check_row_fits(units_per_row=getattr(pl, key), nominal_diameter=unit.nominal_diameter,
                           width=slope.width, where=case.source, key=key)
    units = _unit_count(pl)
    if units > MAXIMUM_BODY_COUNT:
        raise CaseFileError(f"{case.source}: [placement] rows = {pl.rows} of units_per_row = "
                            f"{pl.units_per_row} make {units:,} units, more than the "
                            f"{MAXIMUM_BODY_COUNT:,} bodies a case may have")
    # the centroids' height above the face is the underlayer's business; 0 here changes
    # neither the rows along the face nor the units' widths
    try:
        generated = _design_grid(case, slope, unit, centroid_height=0.0)
        check_generated_positions(slope, unit, generated.positions,
                                  _orientations(case, slope, len(generated.positions), None))
    except CaseFileError as error:
        raise CaseFileError(f"{case.source}: [placement] {error}") from None


def _design_grid(case, slope, unit, *, centroid_height: float):
    """The design grid of ``[placement]``: staggered rows of unit centroids ``centroid_height``
    (m) above the face, each unit starting its drop height above its centroid."""
    pl = case.placement
    counts = (pl.units_per_row, pl.units_per_alternate_row or pl.units_per_row)
    packing = pl.packing_density_coefficient or unit.design.packing_density_coefficient
    return design_grid(slope, nominal_diameter=unit.nominal_diameter, rows=pl.rows,
                       units_per_row=counts, packing_density_coefficient=packing,
                       first_row_s=pl.first_row_s or 0.5 * unit.height,
                       centroid_height=centroid_height,
                       drop_height=(pl.drop_height or unit.height
                                    if pl.release == "free_fall" else 0.0))


def _orientations(case, slope, count: int, user):
    """The orientations of ``count`` units as the placement draws them (seeded: the same in
    ``riprap check`` and ``riprap place``)."""
    pl = case.placement
    return unit_orientations(count, mode=pl.orientation, slope=slope, seed=pl.seed,
                             max_tilt_deg=pl.max_tilt_deg, max_spin_deg=pl.max_spin_deg,
                             user=user)


def _unit_orientations(case, slope, grid):
    """The orientations of the units of a grid file, as the placement will use them."""
    return _orientations(case, slope, len(grid.positions), grid.orientations)


def run_placement(case, *, output_directory=None, progress: bool = True) -> dict:
    """Build the underlayer and the armour layer of ``case``; returns the summary (also written
    as ``summary.json``)."""
    if case.armour_stone is not None:
        _require_tables(case)
        return run_stone_placement(case, placement_materials(case),
                                   output_directory=output_directory, progress=progress)
    inputs = prepare_placement(case)
    out = prepare_output_folder(output_directory or case.output.directory)
    ul, pl = case.underlayer, case.placement
    slope, materials, unit = inputs.slope, inputs.materials, inputs.unit
    underlayer = build_underlayer(
        slope, inputs.rocks, materials=materials, s_range=(ul.from_s, ul.to_s or slope.length),
        layers=ul.layers, seed=ul.seed,
        **_settings(case, ul.settle_time, out / "underlayer", progress))
    if inputs.grid is not None:
        grid = inputs.grid
        positions, velocities, lines = grid.positions, grid.velocities, grid.lines
        user = grid.orientations
        lift = False
        rows = None
    else:
        if pl.rows < 1 or pl.units_per_row < 1:
            raise CaseFileError(f"{case.source}: [placement] without grid_file needs rows and "
                                "units_per_row (a design grid)")
        # Design centroids half a design layer thickness above the underlayer top.
        centroid_height = (underlayer.top_level
                           + 0.5 * unit.design.layer_thickness_coefficient * unit.nominal_diameter)
        generated = _design_grid(case, slope, unit, centroid_height=centroid_height)
        positions, velocities, lines, user, lift = generated.positions, None, None, None, True
        rows = generated.rows
    # Where each unit was meant to go: the grid point of its centroid (a free-fall drop height
    # is not part of the design).
    design_positions = np.array(positions, dtype=float)
    if not pl.grid_file and pl.release == "free_fall":
        design_positions[:, 2] -= pl.drop_height or unit.height
    orientations = _orientations(case, slope, len(positions), user)
    result = place_units(slope, unit, underlayer, positions=positions, orientations=orientations,
                         materials=materials, velocities=velocities, grid_lines=lines,
                         lift_overlapping=lift, initial_velocity=pl.initial_velocity,
                         deposition=pl.deposition, rows=rows, release=pl.release,
                         **_settings(case, pl.settle_time, out / "deposition", progress))
    summary = dict(result.summary)
    stacked = summary["units_not_on_underlayer"]
    if stacked and not smoke_mode():
        warnings.warn(f"{len(stacked)} of {summary['units_placed']} units rest on other units, "
                      f"not on the underlayer (units {_listed(stacked)}; summary.json "
                      "units_not_on_underlayer): the layer is stacked, not one layer on the rocks; "
                      "check the unit size against the section and the underlayer",
                      RiprapWarning, stacklevel=2)
    summary["smoke"] = smoke_mode()
    if summary["smoke"]:
        summary["smoke_note"] = (f"RIPRAP_SMOKE=1 cut every deposition run to {SMOKE_END_TIME} s: "
                                 "the units had no time to settle, so the layer figures describe "
                                 "a cut run, not a layer")
    layer = _layer_description(unit, slope, underlayer, result, design_positions)
    summary["outputs"] = _write_outputs(case, result, materials, slope, out, layer)
    summary["underlayer_run"] = underlayer.summary
    write_json(out / "summary.json", summary)
    return summary


def _listed(numbers, most: int = 10) -> str:
    shown = ", ".join(str(n) for n in numbers[:most])
    return shown + (f" and {len(numbers) - most} more" if len(numbers) > most else "")


def _layer_description(unit, slope, underlayer, result, design_positions):
    """What ``riprap analyse`` needs to know of the layer (written as ``layer.json``)."""
    sim = result.simulation
    unit_shape = sim.solver.shapes[sim.shape_names[UNIT_SHAPE_NAME]]
    return LayerDescription.for_unit(unit, unit_shape, slope=slope,
                                     underlayer_top=underlayer.top_level,
                                     unit_bodies=result.unit_bodies, rows=result.rows,
                                     design_positions=design_positions)


def _write_outputs(case, result, materials, slope, out: Path, layer) -> dict:
    sim = result.simulation
    solver = sim.solver
    pack = write_placed_pack(case, sim, materials, slope, out,
                             comment=f"armour layer placed by riprap place from {case.source}",
                             contact_history=sim.contact_history())
    outputs = {"pack": str(pack), "paraview": str(out / "deposition" / "bodies.pvd"),
               "layer": str(write_layer_file(out, layer)),
               "contacts": str(write_contact_table(out / CONTACTS_FILE_NAME, solver.contacts))}
    if case.output.picture:
        outputs["picture"] = str(_write_layer_picture(out / "final_layer.png", sim, slope,
                                                      n_units=len(result.unit_bodies)))
    return outputs


# Seen from above the sea side of the slope, looking at the face, like the 3D views of
# ``riprap analyse`` (riprap/io/analysis_figures.py).
_LAYER_VIEW = (30, -125)


def _write_layer_picture(path: Path, sim, slope, *, n_units: int) -> Path:
    """The placed layer: units in colour, the fixed underlayer rocks in grey, the slope face as
    a translucent plane, with units and rocks counted separately in the title."""
    face = slope.to_world([0.0, slope.length, slope.length, 0.0],
                          [0.0, 0.0, slope.width, slope.width], [0.0, 0.0, 0.0, 0.0])
    n_rocks = sim.solver.n_bodies - n_units
    title = (f"{n_units} armour units and {n_rocks} underlayer rocks (grey) on the "
             f"1:{slope.cotangent:g} slope face, t = {sim.solver.time:.3f} s")
    return sim.write_picture(path, show_fixed=True, planes=[face], view=_LAYER_VIEW, title=title)


__all__ = ["run_placement", "prepare_placement", "placement_materials", "write_checked_pack"]
