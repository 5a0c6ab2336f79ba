"""``riprap check``: every check that ``riprap run`` or ``riprap place`` makes before it simulates,
without simulating: the schema and the rules joining keys (on loading), meshes and mesh files,
grid files, the contact history of a pack, the fluid grid and its water, the time step and the
work it implies, overlapping and coincident bodies, and the output folder. What only a run can
tell is listed as not checked, never passed over in silence.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from riprap.case.build import build_friction_pairs, build_material, build_simulation
from riprap.case.build_fluid import build_fluid_run
from riprap.workflows.series import check_series
from riprap.case.load import Case
from riprap.errors import CaseFileError
from riprap.io.output_folder import check_output_folder
from riprap.solid.materials import PairFriction, friction_by_pair
from riprap.workflows.place import PLACEMENT_NOT_CHECKED, placement_materials, prepare_placement
from riprap.workflows.place_stones import prepare_stone_placement

__all__ = ["CheckReport", "check_case", "friction_in_use"]


@dataclass
class CheckReport:
    """What ``check_case`` found: a one-line description of the case, what was checked and what
    cannot be known without running it."""

    description: str
    checked: list[str] = field(default_factory=list)
    not_checked: list[str] = field(default_factory=list)
    #: The friction coefficient of each pair of materials that can meet, and where it came from
    #: (riprap.solid.materials.PairFriction).
    friction: list = field(default_factory=list)
    #: The contact-only bodies and the filter zones the flow sees in their place
    #: (riprap.coupling.filter_layer.FilterLayer), or None.
    filter_layer: object = None


def check_case(case: Case, *, output_directory=None, restart=None) -> CheckReport:
    """Run every pre-simulation check of ``case``; raises the error the run would raise.
    ``restart``: a checkpoint to check a restart from (``riprap run --restart``)."""
    out = output_directory or case.output.directory
    if restart is not None and case.is_placement:
        raise CaseFileError(f"{case.source}: a placement does not restart (--restart {restart}); "
                            "run 'riprap place' again")
    sim = None
    if case.is_placement and case.armour_stone is not None:
        inputs = prepare_stone_placement(case, placement_materials(case))
        grading = inputs.grading
        report = CheckReport(
            f"a rock armour placement for riprap place: {inputs.design.layers} layer(s) of "
            f"stones of D_n50 = {grading.dn50:.3g} m on a 1:{case.slope.cotangent:g} slope",
            checked=["tables and keys",
                     f"the grading ({'class ' + grading.standard_class.name if grading.standard_class else 'custom'}"
                     f": M50 {grading.m50:.4g} kg, M85/M15 {grading.m85_over_m15:.3g})",
                     f"{len(inputs.stones)} stone shapes, {len(inputs.rocks)} rock shapes",
                     f"the grid: {inputs.stone_count} stones ({inputs.design.stones_per_area:.4g} "
                     f"per m^2: k_t {inputs.design.layer_thickness_coefficient:g}, design "
                     f"porosity {inputs.design.porosity:g})",
                     f"the underlayer's start lattice ({inputs.rock_count} rocks)",
                     f"the filter rule (D_n50 ratio {grading.dn50 / case.underlayer.dn50:.2f})"],
            not_checked=list(PLACEMENT_NOT_CHECKED))
    elif case.is_placement:
        inputs = prepare_placement(case)
        report = CheckReport(
            f"an armour placement for riprap place: {case.armour.unit} units on a "
            f"1:{case.slope.cotangent:g} slope",
            checked=["tables and keys", f"unit mesh ({len(inputs.unit.mesh.tets)} tetrahedra)",
                     f"{len(inputs.rocks)} rock shapes",
                     f"the underlayer's start lattice ({inputs.rock_count} rocks)",
                     f"the filter rule (Dn / Dn50 = "
                     f"{inputs.unit.nominal_diameter / case.underlayer.dn50:.2f})"],
            not_checked=list(PLACEMENT_NOT_CHECKED))
        if inputs.grid is not None:
            report.checked.append(f"grid file ({len(inputs.grid.positions)} units)")
        else:
            report.checked.append("design grid: units per row across the section, rows on the "
                                  "face, units inside the side walls")
    elif case.is_series:
        if restart is not None:
            raise CaseFileError(f"{case.source}: a test series resumes from its steps' checkpoints "
                                "when run again into the same folder; drop --restart")
        report = CheckReport(f"a test series of {len(case.series_steps)} steps on "
                             f"{case.body_count} bodies",
                             checked=["tables and keys", *check_series(case, out)],
                             not_checked=["whether the flow stays stable (the time step adapts "
                                          "to it)"])
    elif case.is_fluid:
        run = sim = build_fluid_run(case, output_directory=out, progress=False)
        cells = "x".join(map(str, case.fluid.cells))
        bodies = f" with {case.body_count} bodies in it" if run.coupled else ""
        report = CheckReport(
            f"air and water on {cells} cells{bodies}",
            checked=["tables and keys", "fluid grid and memory",
                     f"water regions ({run.fluid.water_volume():.4g} m^3 of water)"],
            not_checked=["whether the flow stays stable (the time step adapts to it)"])
        if run.coupled:
            report.checked.append("bodies: meshes, overlaps, inside the fluid box, cells across")
            report.checked.append(_bodies_step(run))
            report.filter_layer = run.filter_layer
            if run.filter_layer is not None and len(run.filter_layer.bodies):
                report.checked.append("contact-only bodies and their filter zones: covered, "
                                      "clear of the free bodies")
    else:
        sim = build_simulation(case, output_directory=out, progress=False)
        sim.prepare()
        checked = ["tables and keys", f"{len(case.shapes)} shape meshes", _bodies_step(sim),
                   "overlapping and coincident bodies at the start"]
        if case.simulation.contact_history:
            checked.append(f"contact history ({len(sim.accepted_overlaps)} resting contacts)")
        deformable = len(sim.deformable_bodies)
        rigid = sim.solver.n_bodies
        bodies = (f"{deformable} deformable and {rigid} rigid bodies" if deformable and rigid
                  else f"{deformable} deformable bodies" if deformable else f"{rigid} bodies")
        report = CheckReport(bodies, checked=checked,
                             not_checked=["whether the contacts that form later stay stable at "
                                          "this time step (a run stops with a checkpoint if not)"])
    if restart is not None:
        sim.check_restart(restart)
        report.checked.append(f"restart from {restart}: a checkpoint of this case (only what may "
                              "change on a restart has changed)")
    report.checked.append(check_output_folder(out))
    report.friction = friction_in_use(case)
    return report


def friction_in_use(case: Case) -> list[PairFriction]:
    """The friction coefficient of each pair of materials that can meet in the runs of ``case``
    (a free body with any body or wall; a placement's rocks and units with what they settle on),
    from its ``[[friction]]`` entry or the smaller of the two materials' own."""
    if case.is_placement:
        materials = placement_materials(case)
        return friction_by_pair(materials.all(), materials.friction_pairs, materials.in_contact())
    moving = [b.material for b in case.bodies if not b.fixed] + [g.material for g in case.body_grids]
    still = [b.material for b in case.bodies if b.fixed] + [w.material for w in case.walls]
    if case.obstacles and case.body_count:
        still.append(case.materials[0].name)        # obstacles meet bodies with the first material
    pairs = [(a, b) for a in dict.fromkeys(moving) for b in dict.fromkeys(moving + still)]
    return friction_by_pair([build_material(spec) for spec in case.materials],
                            build_friction_pairs(case), pairs)


def _bodies_step(sim) -> str:
    """The bodies' time step and the work it implies, as the run estimated it when its model was
    built (the run refuses an absurd one there, so reaching this line means it passed)."""
    model = sim.model
    system = getattr(model, "system", None)
    if system is not None:              # deformable bodies, dry or in the flow
        step, what = system.time_step, f"{len(system.elements)} elements"
        text = f"deformable bodies' stable time step {step:.3e} s"
        if sim.solver.n_bodies:
            what += f" and {sim.solver.n_bodies} rigid bodies"
    else:
        step, what = sim.solver.time_step, f"{sim.solver.n_bodies} bodies"
        text = f"time step {step:.3e} s"
    if sim.fluid is not None:
        # the fluid's own step follows its Courant number; the bodies' is a sub-step inside it
        coupled = getattr(model, "solver", None)
        if getattr(coupled, "adaptive_substep", False):
            return (f"{text} to start the contact sub-steps of each fluid step (adaptive: they "
                    f"follow the contacts' measured stability, up to {coupled.substep_ceiling:.3e} "
                    f"s) for {what}")
        return f"{text} (a sub-step of each fluid step) for {what}"
    return f"{text} and the work of {sim.end_time / step:.3g} steps of {what}"
