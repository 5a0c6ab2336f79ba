"""A scene: what a run holds before it runs (materials, shapes, rigid bodies, walls, a fluid,
deformable bodies and the contact history of a placed pack). It builds; it does not run (the loop
is :class:`riprap.simulation.Simulation`) and it does not choose the model
(:mod:`riprap.scene.choose_model` does, from what :meth:`Scene.holds`)."""
from __future__ import annotations

import functools

import numpy as np
from scipy.spatial.transform import Rotation

from riprap.coupling.coupled import CoupledSolver, _same_plane
from riprap.deformable.body import DeformableBody
from riprap.deformable.joints import FracturingBody, check_crack_resolution
from riprap.deformable.system import DeformableSystem
from riprap.errors import CaseFileError
from riprap.geometry.mass_properties import mass_properties
from riprap.geometry.tetmesh import TetMesh
from riprap.io.contact_history import ContactHistory
from riprap.schema import default_of
from riprap.solid.kernels.pair_rule import pair_friction
from riprap.solid.materials import FrictionPair, Material, pair_naming
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver
from riprap.solid.walls import Wall
from riprap.parallel.communicator import world

__all__ = ["Scene", "DEFAULT_GRAVITY"]

#: Gravity (m/s^2) when none is given; with a fluid and this default, the fluid's gravity is used.
DEFAULT_GRAVITY = default_of("simulation", "gravity")


class Scene:
    """Everything a run holds before it runs, built by ``add_*`` calls (SI units).

    ``gravity`` (3,) m/s^2, left at its default with a ``fluid`` given, the fluid's;
    ``local_damping``: Cundall's non-viscous damping of the rigid bodies in [0, 1); ``fluid``: a
    :class:`riprap.fluid.solver.FluidSolver` (or a ready
    :class:`riprap.coupling.coupled.CoupledSolver`), see :meth:`add_fluid`.
    """

    def __init__(self, *, gravity=DEFAULT_GRAVITY, local_damping: float = 0.0, fluid=None):
        if fluid is not None and tuple(np.asarray(gravity, dtype=float)) == DEFAULT_GRAVITY:
            gravity = fluid.gravity
        #: The rigid bodies, their shapes, materials and walls.
        self.solver = SolidSolver(gravity=gravity, local_damping=local_damping)
        #: Shape name -> index in ``solver.shapes``; ``meshes`` the tet mesh of each shape.
        self.shape_names: dict[str, int] = {}
        self.meshes: list[TetMesh] = []
        #: The walls' box ((lower), (upper)), m, that pictures show; None without one.
        self.container_box = None
        #: The flow the bodies move in (:meth:`add_fluid`), or None for a dry run.
        self.fluid = fluid
        #: Pairs allowed to overlap at the start, up to a depth (m): a pack's resting contacts.
        self.accepted_overlaps: dict[tuple[int, int], float] = {}
        #: Deformable bodies (:meth:`add_deformable_body`) and how they touch.
        self.deformable_bodies = []
        self.deformable_contact_penalty = None
        self.deformable_mass_damping = 0.0
        #: For scenes built from a case: the case's number of each deformable body, and the
        #: resting overlaps (m) of a pack's contacts that involve deformable bodies.
        self.deformable_case_index: list[int] = []
        self.deformable_accepted_depths: dict[tuple[int, int], float] = {}
        #: Fixed bodies the flow does not see (``riprap.coupling.filter_layer``): left out of the
        #: fluid exchange (``CoupledSolver(obstacle_bodies=...)``), met by the other bodies.
        self.contact_only_bodies: list[int] = []
        #: What the water of the faces bodies cut keeps after a step (``[fluid] cut_faces``:
        #: "auto", or one of ``riprap.coupling.coupled.CUT_FACE_TREATMENTS``).
        self.cut_faces = "auto"

    # ------------------------------------------------------------------ what it holds
    def holds(self) -> frozenset[str]:
        """What the scene holds, the key by which a model is chosen: any of "rigid bodies",
        "deformable bodies", "fluid" (a FluidSolver) and "coupled solver" (a CoupledSolver built
        by the caller, which brings its own bodies); and "several processes" when the run was
        started over several (``mpiexec -n N``)."""
        held = set()
        if self.solver.n_bodies > 0:
            held.add("rigid bodies")
        if self.deformable_bodies:
            held.add("deformable bodies")
        if self.fluid is not None:
            held.add("coupled solver" if isinstance(self.fluid, CoupledSolver) else "fluid")
        if world().size > 1:
            held.add("several processes")
        return frozenset(held)

    @property
    def coupled(self) -> bool:
        """Whether bodies move in a fluid."""
        return self.fluid is not None and bool(self.holds() & {"coupled solver", "rigid bodies",
                                                                "deformable bodies"})

    # ------------------------------------------------------------------ building
    def add_material(self, material: Material) -> None:
        self.solver.add_material(material)

    def add_friction_pair(self, pair: FrictionPair) -> None:
        """Give the contacts of two named materials their own friction coefficient (a
        :class:`riprap.solid.materials.FrictionPair`) instead of the smaller of the two; rigid
        bodies and walls only (:meth:`deformable_system` refuses a pair naming a deformable
        body's material)."""
        self.solver.add_friction_pair(pair)

    def add_shape(self, name: str, mesh: TetMesh | RigidShape) -> None:
        """Add a shape by name: a tetrahedral mesh, or a prepared :class:`RigidShape` (whose frame
        as built is then its principal frame)."""
        if name in self.shape_names:
            raise CaseFileError(f"shape '{name}' defined twice")
        shape = mesh if isinstance(mesh, RigidShape) else RigidShape.from_mesh(mesh, name=name)
        self.shape_names[name] = self.solver.add_shape(shape)
        self.meshes.append(shape.mesh if isinstance(mesh, RigidShape) else mesh)

    def shape(self, name: str) -> RigidShape:
        return self.solver.shapes[self.shape_index(name)]

    def shape_index(self, name: str) -> int:
        if name not in self.shape_names:
            raise CaseFileError(f"unknown shape '{name}' (defined: {', '.join(self.shape_names)})")
        return self.shape_names[name]

    def add_body(self, *, shape: str, material: str, position, orientation=(1.0, 0.0, 0.0, 0.0),
                 velocity=(0.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 0.0),
                 fixed: bool = False, frame: str = "shape") -> int:
        """Add a body; ``position`` is its centroid (m), ``orientation`` a quaternion (w, x, y, z)
        applied to the shape as built (``frame="shape"``) or to its principal frame
        (``frame="principal"``, as the solver stores it). Returns the body index."""
        return self.solver.add_body(shape=self.shape_index(shape),
                                    material=self.solver.material_index(material),
                                    position=position, orientation=orientation, velocity=velocity,
                                    angular_velocity=angular_velocity, fixed=fixed, frame=frame)

    def add_deformable_body(self, *, shape: str, material, position,
                            orientation=(1.0, 0.0, 0.0, 0.0), velocity=(0.0, 0.0, 0.0),
                            angular_velocity=(0.0, 0.0, 0.0), element_type: str = "tet4",
                            name: str | None = None, joints=None) -> int:
        """Add a deformable body (:class:`riprap.deformable.DeformableBody`) of a shape's mesh:
        ``material`` an :class:`riprap.deformable.ElasticMaterial`, ``position`` its centroid
        (m), ``orientation`` a quaternion (w, x, y, z) applied to the mesh as built, ``velocity``
        and ``angular_velocity`` its initial rigid motion. ``joints``: a
        :class:`riprap.deformable.joints.JointMaterial` (joints between all its tets), or one with
        a box ((lower), (upper)) in m at the start, joints only between tets whose centroids lie
        in it: the body cracks (:class:`riprap.deformable.joints.FracturingBody`). Returns its
        index among the deformable bodies."""
        mesh = self.meshes[self.shape_index(shape)]
        centroid = np.asarray(mass_properties(mesh).centroid, dtype=np.float64)
        w, x, y, z = (float(v) for v in orientation)
        rotation = Rotation.from_quat([x, y, z, w]).as_matrix()
        nodes = (mesh.nodes - centroid) @ rotation.T + np.asarray(position, dtype=np.float64)
        index = len(self.deformable_bodies)
        name = name or f"{shape}_{index}"
        if joints is None:
            body = DeformableBody(nodes, mesh.tets, material, element_type=element_type, name=name)
        else:
            if element_type != "tet4":
                raise CaseFileError(f"deformable body '{name}': joints need element_type 'tet4', "
                                    f"not {element_type!r}")
            joint_material, region = joints if isinstance(joints, tuple) else (joints, None)
            cracking = None
            if region is not None:
                centres = nodes[mesh.tets].mean(axis=1)
                lower, upper = (np.asarray(corner, dtype=np.float64) for corner in region)
                cracking = np.all((centres >= lower) & (centres <= upper), axis=1)
            check_crack_resolution(nodes, mesh.tets, name)
            body = FracturingBody(nodes, mesh.tets, material, joint_material, name=name,
                                  cracking=cracking)
        offsets = body.positions - np.asarray(position, dtype=np.float64)
        body.velocities[:] = np.asarray(velocity, dtype=np.float64) + np.cross(
            np.asarray(angular_velocity, dtype=np.float64), offsets)
        self.deformable_bodies.append(body)
        return index

    def add_walls(self, walls: list[Wall], *, container_box=None) -> None:
        self.solver.add_walls(walls)
        if container_box is not None:
            self.container_box = container_box

    def add_fluid(self, fluid) -> None:
        """Put the scene in a flow: a :class:`riprap.fluid.solver.FluidSolver` (the bodies, if
        any, are coupled to it when the run starts) or a ready
        :class:`riprap.coupling.coupled.CoupledSolver`."""
        self.fluid = fluid

    # ------------------------------------------------------------------ contacts
    def contact_history(self):
        """The current contacts as a :class:`riprap.io.contact_history.ContactHistory` (spring
        state and overlap depths), to start another run from this state."""
        body_i, body_j, springs = self.solver.contact_history()
        depths = {(i, j): depth for i, j, depth in self.solver.overlaps(0.0)}
        return ContactHistory(body_i, body_j, springs,
                              [depths.get((int(i), int(j)), 0.0) for i, j in zip(body_i, body_j)])

    def set_contact_history(self, history) -> None:
        """Start from the contacts of a placed pack (a
        :class:`riprap.io.contact_history.ContactHistory`): their friction carries over and their
        overlaps, up to the depths recorded, are accepted at the start."""
        self.solver.set_initial_contact_history(history.body_i, history.body_j, history.springs)
        self.accepted_overlaps = history.accepted_depths()

    # ------------------------------------------------------------------ deformable bodies
    def deformable_system(self, gravity, extra_walls=()):
        """The deformable bodies joined in one system, with the rigid solver's bodies (built
        already) as surfaces they touch, its walls, and ``extra_walls`` not already among them
        (with the deformable bodies' smallest friction coefficient)."""
        solver = self.solver
        for body in self.deformable_bodies:
            pair = pair_naming(solver.friction_pairs, body.material.name)
            if pair is not None:
                raise CaseFileError(f"friction pair {pair.materials[0]}-{pair.materials[1]} names "
                                    f"'{body.material.name}', the material of deformable body "
                                    f"'{body.name}': pairs reach the rigid contacts only (a "
                                    "deformable body's contact takes the smaller of the two)")
        rigid_surfaces = []
        for b in range(solver.n_bodies):
            shape = solver.shapes[int(solver.shape_index[b])]
            material = solver.materials[int(solver.material_index_of_body[b])]
            mass = np.inf if solver.fixed[b] else float(solver.masses[b])
            rigid_surfaces.append((shape.mesh.nodes, shape.mesh.tets, material.friction_coefficient,
                                   mass, material.damping_ratio))
        walls = [(wall.point, wall.normal,
                  solver.materials[solver.material_index(wall.material)].friction_coefficient)
                 for wall in solver.walls]
        # a wall added for the deformable bodies meets each of them: the pair rule over them all
        friction = functools.reduce(pair_friction.py_func, (b.material.friction_coefficient
                                                             for b in self.deformable_bodies))
        walls += [(wall.point, wall.normal, friction) for wall in extra_walls
                  if not any(_same_plane(wall, other) for other in solver.walls)]
        return DeformableSystem(self.deformable_bodies, walls=walls,
                                contact_penalty=self.deformable_contact_penalty, gravity=gravity,
                                mass_damping=self.deformable_mass_damping,
                                rigid_surfaces=rigid_surfaces)

    def case_numbers(self):
        """(case number of each deformable body, of each rigid body): their own orders when the
        run was built in Python."""
        deformable = list(self.deformable_case_index) or list(range(len(self.deformable_bodies)))
        taken = set(deformable)
        rigid = [i for i in range(len(deformable) + self.solver.n_bodies) if i not in taken]
        return deformable, rigid
