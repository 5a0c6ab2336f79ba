"""Which model runs a scene, and how it is built from it: a table of builders keyed by what the
scene holds (:meth:`riprap.scene.Scene.holds`). The run loop only asks for "the model"; a new
model (a second coupling method, a deformable variant, a model spread over several processes) is
one more entry here, or :func:`register_model` from outside riprap, and no branch in the loop.

Exactly one builder serves a scene: the table's order decides nothing."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from riprap.coupling.coupled import CoupledSolver, _same_plane, fluid_box_walls
from riprap.coupling.deformable_coupled import DeformableBodies, DeformableCoupledSolver
from riprap.coupling.slab_coupled import (SlabCoupledSolver, SlabDeformableCoupledSolver,
                                          coupled_plane_costs)
from riprap.coupling.obstacles import add_obstacle_bodies, name_obstacles_in_overlap
from riprap.errors import CaseFileError, OverlapError, RiprapError
from riprap.fluid.slab_solver import split_fluid
from riprap.models.base import Model
from riprap.models.deformable import DeformableModel
from riprap.models.deformable_coupled import DeformableCoupledModel
from riprap.models.fluid import CoupledModel, FluidModel
from riprap.models.rigid import RigidModel, build_bodies, prepare_bodies
from riprap.models.settings import ModelSettings
from riprap.models.slab_features import add_parts_to_block
from riprap.models.slab_coupled import SlabCoupledModel, SlabDeformableCoupledModel
from riprap.models.slab_fluid import SlabFluidModel
from riprap.models.split_rigid import SplitRigidModel
from riprap.parallel.communicator import world
from riprap.scene.scene import Scene
from riprap.work_estimate import check_deformable_run

__all__ = ["MODEL_BUILDERS", "ModelBuilder", "build_model", "register_model", "scenes"]


@dataclass(frozen=True)
class ModelBuilder:
    """``build(scene, settings, restarted)`` makes the model of every scene whose ``holds()``
    is one of ``serves`` (sets of what a scene holds); ``restarted``: the run continues a
    checkpoint (its start overlaps are its own, not checked again)."""

    name: str
    serves: frozenset
    build: Callable[[Scene, ModelSettings, bool], Model]


def scenes(*contents) -> frozenset:
    """The scenes a builder serves, each given by what it holds: ``scenes((), ("fluid",))``."""
    return frozenset(frozenset(held) for held in contents)


def build_model(scene: Scene, settings: ModelSettings, *, restarted: bool) -> Model:
    """The model of ``scene``, built by the one builder that serves it."""
    held = scene.holds()
    serving = [builder for builder in MODEL_BUILDERS if held in builder.serves]
    if len(serving) != 1:
        names = ", ".join(builder.name for builder in serving) or "none"
        raise RiprapError(f"a scene holding {sorted(held) or 'nothing'} is served by {names}: "
                          "exactly one model builder must serve it")
    return serving[0].build(scene, settings, restarted)


def register_model(builder: ModelBuilder) -> None:
    """Add a model for the scenes ``builder`` serves; refused where another serves one of them
    (replace that builder in :data:`MODEL_BUILDERS` instead)."""
    for other in MODEL_BUILDERS:
        if builder.serves & other.serves:
            taken = sorted(sorted(held) for held in builder.serves & other.serves)
            raise RiprapError(f"model '{builder.name}': the scenes {taken} are served by "
                              f"'{other.name}' already")
    MODEL_BUILDERS.append(builder)


# ---------------------------------------------------------------------- the builders
def rigid_model(scene: Scene, settings: ModelSettings, restarted: bool = False) -> RigidModel:
    """The scene's rigid bodies, their shapes' meshes and names, its accepted start overlaps."""
    return RigidModel(scene.solver, meshes=scene.meshes, shape_names=scene.shape_names,
                      settings=settings, accepted_overlaps=scene.accepted_overlaps,
                      container_box=scene.container_box)


def _fluid_model(scene: Scene, settings: ModelSettings, restarted: bool) -> FluidModel:
    return FluidModel(scene.fluid)


def _coupled_model(scene: Scene, settings: ModelSettings, restarted: bool) -> CoupledModel:
    """The bodies in the flow: a CoupledSolver the caller built (its bodies are the run's), or
    one built here of the scene's fluid and bodies, whose obstacles are fixed bodies too."""
    if "coupled solver" in scene.holds():
        scene.solver = scene.fluid.solids
        return CoupledModel(scene.fluid)
    # The fluid's obstacles are walls for the bodies too: fixed bodies of the same cells.
    boxes = getattr(scene.fluid, "obstacle_boxes", [])
    obstacle_bodies = add_obstacle_bodies(scene, boxes)
    try:
        prepare_bodies(scene.solver, settings, accepted_overlaps=scene.accepted_overlaps,
                       restarted=restarted)
    except OverlapError as error:
        raise name_obstacles_in_overlap(error, obstacle_bodies, boxes) from None
    # Contact-only bodies are left out of the exchange as the obstacles are: the flow holds
    # nothing of them (riprap.coupling.filter_layer: a porous zone stands for them).
    left_out = obstacle_bodies + list(scene.contact_only_bodies)
    return CoupledModel(CoupledSolver(scene.fluid, scene.solver, obstacle_bodies=left_out,
                                      adaptive_substep=settings.adaptive_time_step,
                                      cut_faces=_rigid_cut_faces(scene.cut_faces)))


def _rigid_cut_faces(choice: str) -> str:
    """``[fluid] cut_faces`` for rigid bodies: "auto" is their own velocity (docs/coupling.md,
    Cut faces and the step)."""
    return "own_velocity" if choice == "auto" else choice


def _refuse_adaptive_step(settings: ModelSettings) -> None:
    """Deformable bodies step at their own stable step: an adaptive one is not theirs."""
    if settings.adaptive_time_step:
        raise CaseFileError("[simulation] adaptive_time_step = true: deformable bodies take the "
                            "stable step of their elements; the adaptive contact step is for "
                            "rigid bodies, dry or in a flow. Leave it out (or false) for this case")


def _deformable_model(scene: Scene, settings: ModelSettings, restarted: bool) -> DeformableModel:
    """Deformable bodies, and rigid ones if any: those keep their own solver, stepped with the
    deformable bodies' step, and meet the deformable bodies through their surface layers."""
    _refuse_adaptive_step(settings)
    solver = scene.solver
    rigid = None
    if solver.n_bodies > 0:
        build_bodies(solver, settings)
        rigid = rigid_model(scene, settings)
    system = scene.deformable_system(solver.gravity)
    step = settings.time_step if settings.time_step > 0 else system.time_step
    if solver.n_bodies > 0:
        step = min(step, solver.time_step)
        solver.set_time_step(step)
    system.time_step = step
    check_deformable_run(end_time=settings.end_time, time_step=step, elements=len(system.elements),
                         rigid_bodies=int((~solver.fixed).sum()) if solver.n_bodies else 0)
    return DeformableModel(system, rigid=rigid, case_numbers=scene.case_numbers(),
                           accepted_depths=scene.deformable_accepted_depths)


def _deformable_coupled_model(scene: Scene, settings: ModelSettings,
                              restarted: bool) -> DeformableCoupledModel:
    """Deformable bodies (and rigid ones, if any) in the flow
    (``riprap.coupling.deformable_coupled``); the fluid box's sides (all but an open top) and
    the case's walls bound them."""
    _refuse_adaptive_step(settings)
    solver, fluid = scene.solver, scene.fluid
    if scene.contact_only_bodies:
        raise CaseFileError("contact-only bodies (fixed bodies the flow does not see) are not for "
                            "runs with deformable bodies: their coupling keeps every rigid body "
                            "in the flow")
    if scene.cut_faces == "own_velocity":
        raise CaseFileError(f"[fluid] cut_faces = {scene.cut_faces!r} is for rigid bodies: the "
                            "coupling of deformable bodies keeps the \"mixture\" cut faces")
    if "coupled solver" in scene.holds():
        raise CaseFileError("deformable bodies cannot join a CoupledSolver built by the caller: "
                            "give the Simulation a FluidSolver")
    if solver.n_bodies > 0:
        # the sides of the box are walls for the rigid bodies too (unless already there)
        material = solver.materials[0].name
        solver.add_walls([wall for wall in fluid_box_walls(fluid.grid, material)
                          if not any(_same_plane(wall, other) for other in solver.walls)])
        prepare_bodies(solver, settings, accepted_overlaps=scene.accepted_overlaps,
                       restarted=restarted)
    system = scene.deformable_system(fluid.gravity, extra_walls=fluid_box_walls(fluid.grid, ""))
    if settings.time_step > 0:
        system.time_step = settings.time_step
    check_deformable_run(end_time=settings.end_time, time_step=system.time_step,
                         elements=len(system.elements))
    coupled = DeformableCoupledSolver(fluid, DeformableBodies(
        system, rigid=solver if solver.n_bodies > 0 else None))
    stresses = DeformableModel(system,
                               rigid=rigid_model(scene, settings) if solver.n_bodies > 0 else None,
                               case_numbers=scene.case_numbers(),
                               accepted_depths=scene.deformable_accepted_depths)
    return DeformableCoupledModel(coupled, stresses)


def _slab_fluid_model(scene: Scene, settings: ModelSettings, restarted: bool) -> SlabFluidModel:
    """The fluid alone over the processes of the run: each steps a slab of x-planes."""
    processes = world()
    return SlabFluidModel(split_fluid(scene.fluid, processes, add_parts=add_parts_to_block),
                          scene.fluid)


def _split_rigid_model(scene: Scene, settings: ModelSettings,
                       restarted: bool = False) -> SplitRigidModel:
    """Rigid bodies without a fluid over the processes of the run: the contact pairs shared."""
    return SplitRigidModel(scene.solver, processes=world(), meshes=scene.meshes,
                           shape_names=scene.shape_names, settings=settings,
                           accepted_overlaps=scene.accepted_overlaps,
                           container_box=scene.container_box)


def _slab_coupled_model(scene: Scene, settings: ModelSettings,
                        restarted: bool) -> SlabCoupledModel:
    """Rigid bodies in the flow over the processes of the run: the whole coupling built as on
    one process (walls, checks, the fixed bodies' deep cells closed), then each process's block
    of its fluid, every process stepping every body."""
    whole = _coupled_model(scene, settings, restarted).solver
    block = split_fluid(whole.fluid, world(), add_parts=add_parts_to_block,
                        plane_costs=coupled_plane_costs(whole))
    return SlabCoupledModel(SlabCoupledSolver(block, whole), whole)


def _slab_deformable_coupled_model(scene: Scene, settings: ModelSettings,
                                   restarted: bool) -> SlabDeformableCoupledModel:
    """Deformable bodies (and rigid ones) in the flow over the processes of the run: the whole
    coupling built as on one process, each process's block of its fluid, every process stepping
    every body."""
    whole_model = _deformable_coupled_model(scene, settings, restarted)
    whole = whole_model.solver
    block = split_fluid(whole.fluid, world(), add_parts=add_parts_to_block,
                        plane_costs=coupled_plane_costs(whole))
    return SlabDeformableCoupledModel(SlabDeformableCoupledSolver(block, whole),
                                      whole_model.stresses, whole)


def _not_yet_over_processes(scene: Scene, settings: ModelSettings, restarted: bool) -> Model:
    held = sorted(scene.holds() - {"several processes"})
    raise CaseFileError(
        f"this run holds {', '.join(held) or 'nothing'}: over several processes riprap runs so "
        "far the fluid alone, bodies in a flow (rigid or deformable; porous zones, waves and "
        "gauges included) and rigid bodies alone, not deformable bodies without a fluid; run "
        "this case on one process (without mpiexec)")


#: Every model riprap has, with the scenes it serves (what ``Scene.holds()``: "rigid bodies",
#: "deformable bodies", "fluid", "coupled solver").
MODEL_BUILDERS: list[ModelBuilder] = [
    ModelBuilder("rigid", scenes((), ("rigid bodies",)), rigid_model),
    ModelBuilder("fluid", scenes(("fluid",)), _fluid_model),
    ModelBuilder("coupled", scenes(("fluid", "rigid bodies"), ("coupled solver",),
                                   ("coupled solver", "rigid bodies")), _coupled_model),
    ModelBuilder("deformable",
                 scenes(("deformable bodies",), ("deformable bodies", "rigid bodies")),
                 _deformable_model),
    # (with a CoupledSolver built by the caller: refused, naming why)
    ModelBuilder("deformable_coupled",
                 scenes(("deformable bodies", "fluid"),
                        ("deformable bodies", "fluid", "rigid bodies"),
                        ("deformable bodies", "coupled solver"),
                        ("deformable bodies", "coupled solver", "rigid bodies")),
                 _deformable_coupled_model),
    ModelBuilder("slab_fluid", scenes(("fluid", "several processes")), _slab_fluid_model),
    ModelBuilder("split_rigid", scenes(("rigid bodies", "several processes")),
                 _split_rigid_model),
    ModelBuilder("slab_coupled",
                 scenes(("fluid", "rigid bodies", "several processes"),
                        ("coupled solver", "several processes"),
                        ("coupled solver", "rigid bodies", "several processes")),
                 _slab_coupled_model),
    ModelBuilder("not_yet_over_processes",
                 scenes(("several processes",), ("deformable bodies", "several processes"),
                        ("deformable bodies", "rigid bodies", "several processes")),
                 _not_yet_over_processes),
    # (with a CoupledSolver built by the caller: refused, naming why, as on one process)
    ModelBuilder("slab_deformable_coupled",
                 scenes(("deformable bodies", "fluid", "several processes"),
                        ("deformable bodies", "fluid", "rigid bodies", "several processes"),
                        ("deformable bodies", "coupled solver", "several processes"),
                        ("deformable bodies", "coupled solver", "rigid bodies",
                         "several processes")),
                 _slab_deformable_coupled_model),
]
