"""A deformable body: explicit finite-strain dynamics of one tetrahedral mesh (the seed's Y3D-D).

State: node positions and velocities (the velocities live at half steps, as the central-difference
scheme wants). Loads: gravity, nodal forces, and mass-proportional damping ``mass_damping`` (1/s,
zero for physics runs; a settling aid for reaching a static state). Supports: any node component
may be held at a prescribed velocity (zero for a fixed support).

The time step is chosen by the caller or by :meth:`DeformableBody.stable_time_step`; a step above
the stable one is refused with both figures, never hidden by scaling masses.
"""
from __future__ import annotations

import math

import numpy as np

from riprap.deformable.elements import build_element_set
from riprap.deformable.kernels import finite_strain
from riprap.deformable.kernels.bundles import ContactState, ElementState, JointData, NodeState
from riprap.deformable.material import ElasticMaterial
from riprap.errors import CaseFileError, InstabilityError
from riprap.schema import default_of

#: The step used by default is this fraction of the stable step.
TIME_STEP_SAFETY = 0.9

# The contact arguments of a run without contact (see finite_strain.advance_steps).
NO_CONTACT = ContactState(
    wall_triangles=np.zeros((0, 3), dtype=np.int64), wall_tets=np.zeros((0, 4), dtype=np.int64),
    triangles=np.zeros((0, 3), dtype=np.int64), contact_tets=np.zeros((0, 4), dtype=np.int64),
    wall_depths=np.zeros(0), pairs=np.zeros((0, 2), dtype=np.int64), penalty=0.0,
    walls=np.zeros((0, 7)), listed_positions=np.zeros((0, 3)), skin=1.0, totals=np.zeros(1),
    triangle_friction=np.zeros(0), tet_friction=np.zeros(0), tangential_ratio=0.0,
    tet_stiffness=np.zeros(0), pair_springs=np.zeros((0, 3)),
    wall_triangle_springs=np.zeros((0, 0, 3)), wall_tet_springs=np.zeros((0, 0, 3)),
    triangle_damping=np.zeros(0), tet_damping=np.zeros(0))
NO_TET4_GRADIENTS = np.zeros((0, 4, 3))


def no_joints() -> tuple:
    """The joint arguments of a run without joints (see finite_strain.advance_steps)."""
    return JointData(nodes=np.zeros((0, 6), dtype=np.int32), sizes=np.zeros(0),
                     properties=np.zeros((1, 9)), material=np.zeros(0, dtype=np.int64),
                     damage=np.zeros((0, 3)), broken=np.zeros(0, dtype=np.bool_),
                     buffer=np.zeros((1, 3)), slot_rows=np.zeros((0, 3), dtype=np.int32),
                     released=np.zeros(0, dtype=np.bool_), work=np.zeros(1),
                     anchors=np.zeros((0, 3, 2)))

# Bodies with fewer integration points than this step on one thread: starting the threads of a
# parallel loop (twice a step) cost more than the work for the 480-tet cantilever of the tests
# (147 against 32 microseconds a step on this 2-core machine).
PARALLEL_POINTS = 8000


class DeformableBody:
    """One deformable body.

    Parameters
    ----------
    nodes : (n, 3) array
        Reference node coordinates (m).
    tets : (m, 4) array
        Node indices of the 4-node tets, positively oriented.
    material : ElasticMaterial
    element_type : str
        "tet4" (constant strain) or "tet10" (quadratic, mid-edge nodes added here).
    name : str
        Used in messages.
    gravity : 3 floats
        Acceleration of gravity (m/s^2); default none.
    mass_damping : float
        alpha (1/s) of a force -alpha m v on every node; 0 for physics runs.

    Examples
    --------
    >>> from riprap.deformable import ElasticMaterial, DeformableBody, box_mesh
    >>> nodes, tets = box_mesh((0.1, 0.1, 0.1), (2, 2, 2))
    >>> body = DeformableBody(nodes, tets, ElasticMaterial(young_modulus=1e7, density=1000))
    >>> body.step(10)
    >>> float(abs(body.velocities).max())
    0.0
    """

    def __init__(self, nodes, tets, material: ElasticMaterial, *,
                 element_type: str = default_of("deformable", "element_type"),
                 name: str = "body", gravity=(0.0, 0.0, 0.0),
                 mass_damping: float = default_of("deformable", "mass_damping")):
        if not isinstance(material, ElasticMaterial):
            raise CaseFileError(f"deformable body '{name}': material must be an ElasticMaterial")
        if not (mass_damping >= 0 and math.isfinite(mass_damping)):
            raise CaseFileError(f"deformable body '{name}': mass_damping = {mass_damping!r} must be >= 0 1/s")
        self.name = name
        self.material = material
        self.elements = build_element_set(nodes, tets, element_type, name)
        n_nodes = len(self.elements.reference_nodes)
        n_el, n_local = self.elements.elements.shape
        self.masses = self.elements.lumped_masses(material.density)
        self.positions = self.elements.reference_nodes.copy()
        self.velocities = np.zeros((n_nodes, 3))
        self.external_forces = np.zeros((n_nodes, 3))
        self.constrained = np.zeros((n_nodes, 3), dtype=np.bool_)
        self.prescribed_velocities = np.zeros((n_nodes, 3))
        self.gravity = np.asarray(gravity, dtype=np.float64).reshape(3).copy()
        self.mass_damping = float(mass_damping)
        self.time = 0.0
        self.step_count = 0
        self._element_forces = np.zeros((n_el, n_local, 3))
        self.jacobians = np.ones(n_el)
        self._offsets, self._slots = self.elements.node_to_element_slots()
        self.materials = material_table([material])
        self.element_material = np.zeros(n_el, dtype=np.int64)
        self.contact_forces = np.zeros((n_nodes, 3))
        self._no_joints = None
        #: A uniform pressure all round the body that its nodes do not carry (Pa): it neither
        #: moves nor turns a closed body and strains it only isotropically (sigma = -p I, to
        #: first order in p / E), so it is added to the stresses instead. A body in a flow takes
        #: the mean pressure on its surface here (``riprap.coupling.deformable_coupled``).
        self.ambient_pressure = 0.0
        self._stable_time_step = None
        self._time_step = None

    # ------------------------------------------------------------------ sizes and steps
    @property
    def element_type(self) -> str:
        return self.elements.element_type

    @property
    def n_elements(self) -> int:
        return len(self.elements.elements)

    @property
    def mass(self) -> float:
        return float(self.masses.sum())

    def stable_time_step(self) -> float:
        """The largest stable step (s) of the central-difference scheme: 2 / omega_max with
        omega_max bounded by the stiffest element, reduced for the viscous and mass damping."""
        if self._stable_time_step is None:
            omega = float(self.elements.largest_element_frequencies(self.material).max())
            self._stable_time_step = stable_step_for(omega, self.material.viscous_time_constant,
                                                     self.mass_damping)
            self._stiffest_frequency = omega
        return self._stable_time_step

    @property
    def time_step(self) -> float:
        """The step in use (s): TIME_STEP_SAFETY of the stable step unless set."""
        if self._time_step is None:
            self._time_step = TIME_STEP_SAFETY * self.stable_time_step()
        return self._time_step

    @time_step.setter
    def time_step(self, value: float) -> None:
        stable = self.stable_time_step()
        if not (value > 0 and math.isfinite(value)):
            raise CaseFileError(f"deformable body '{self.name}': time_step = {value!r} must be > 0 s")
        if value > stable:
            raise CaseFileError(
                f"deformable body '{self.name}': time_step = {value:.4g} s is above the stable step "
                f"{stable:.4g} s of its stiffest element (largest element frequency "
                f"{self._stiffest_frequency:.4g} rad/s); use a step of at most {stable:.4g} s or "
                "coarser elements (masses are never scaled to hide this)")
        self._time_step = float(value)

    # ------------------------------------------------------------------ supports and loads
    def fix(self, node_ids, components=(0, 1, 2)) -> None:
        """Hold the given components of the given nodes still."""
        self.prescribe_velocity(node_ids, 0.0, components)

    def prescribe_velocity(self, node_ids, velocity, components=(0, 1, 2)) -> None:
        """Move the given components of the given nodes at a prescribed velocity (m/s)."""
        node_ids = np.asarray(node_ids, dtype=np.int64)
        components = list(components)
        velocity = np.broadcast_to(np.asarray(velocity, dtype=np.float64), (len(node_ids), len(components)))
        for column, component in enumerate(components):
            self.constrained[node_ids, component] = True
            self.prescribed_velocities[node_ids, component] = velocity[:, column]
            self.velocities[node_ids, component] = velocity[:, column]

    # ------------------------------------------------------------------ dynamics
    def compute_element_forces(self) -> None:
        """Internal forces of every element at the present state (into the element buffer) and J."""
        arguments = (self.materials, self.element_material)
        if self.elements.element_type == "tet4":
            finite_strain.tet4_element_forces(
                self.positions, self.velocities, self.elements.elements,
                self.elements.tet4_gradients, self.elements.weights[:, 0], *arguments,
                self._element_forces, self.jacobians)
        else:
            finite_strain.general_element_forces(
                self.positions, self.velocities, self.elements.elements, self.elements.gradients,
                self.elements.weights, *arguments, self._element_forces, self.jacobians)

    def internal_forces(self) -> np.ndarray:
        """Nodal internal forces (n, 3) at the present state (N)."""
        self.compute_element_forces()
        forces = np.zeros_like(self.positions)
        np.add.at(forces, self.elements.elements.ravel(), self._element_forces.reshape(-1, 3))
        return forces

    def step(self, n_steps: int = 1) -> None:
        """Advance ``n_steps`` steps of ``time_step``. Raises InstabilityError naming the element
        if one inverts (J <= 0); the state is then that of the start of the failed step."""
        dt = self.time_step
        elements = self.elements
        tet4_gradients = (elements.tet4_gradients if elements.tet4_gradients is not None
                          else NO_TET4_GRADIENTS)
        parallel = self.n_elements * elements.weights.shape[1] >= PARALLEL_POINTS
        nodes = NodeState(self.positions, self.velocities, self.masses, self.external_forces,
                          self.contact_forces, self.constrained, self.prescribed_velocities,
                          self._offsets, self._slots)
        element_state = ElementState(elements.elements, tet4_gradients, elements.gradients,
                                     elements.weights, self.materials, self.element_material,
                                     self._element_forces, self.jacobians)
        done, status, worst, value = finite_strain.advance_steps(
            int(n_steps), parallel, nodes, element_state, self.gravity, self.mass_damping, dt,
            NO_CONTACT, self._joint_arguments())
        self.step_count += int(done)
        self.time += int(done) * dt
        if status == finite_strain.INVERTED:
            self._raise_inverted(int(worst), float(value))

    def _joint_arguments(self):
        """The joint arguments of ``finite_strain.advance_steps`` (none: a body without joints)."""
        if self._no_joints is None:
            self._no_joints = no_joints()
        return self._no_joints

    def _raise_inverted(self, worst: int, value: float, time_step: float | None = None,
                        stable: float | None = None) -> None:
        """``time_step`` and ``stable``: the run's (a system's), where it is not the body's own."""
        time_step = self.time_step if time_step is None else time_step
        stable = self.stable_time_step() if stable is None else stable
        centre = self.positions[self.elements.corner_tets[worst]].mean(axis=0)
        raise InstabilityError(
            f"deformable body '{self.name}': element {worst} inverted (J = {value:.3g}) at "
            f"t = {self.time:.6g} s, near ({centre[0]:.4g}, {centre[1]:.4g}, {centre[2]:.4g}) m; "
            f"time step {time_step:.3g} s (stable {stable:.3g} s): "
            "the loads are too large for the mesh or the step too long")

    # ------------------------------------------------------------------ outputs
    def cauchy_stresses(self) -> np.ndarray:
        """Cauchy stress of every element (n, 3, 3) in Pa (tension positive), the volume-weighted
        mean over its integration points, with -``ambient_pressure`` I added."""
        stresses = np.zeros((self.n_elements, 3, 3))
        finite_strain.cauchy_stresses(self.positions, self.velocities, self.elements.elements,
                                      self.elements.gradients, self.elements.weights,
                                      self.materials, self.element_material, stresses)
        if self.ambient_pressure:
            stresses -= self.ambient_pressure * np.eye(3)
        return stresses

    def kinetic_energy(self, velocities=None) -> float:
        velocities = self.velocities if velocities is None else velocities
        return 0.5 * float(np.sum(self.masses[:, None] * velocities ** 2))

    def stored_energy(self) -> float:
        """Elastic energy stored in the body (J); only the hyperelastic models have one."""
        if self.material.model_code == 0:
            raise CaseFileError(
                f"deformable body '{self.name}': the seed's eq. 10 (neo_hookean_seed) has no "
                "stored-energy function; use constitutive_model = 'neo_hookean' for energy balances")
        energies = np.zeros(self.n_elements)
        finite_strain.stored_energies(self.positions, self.elements.elements,
                                      self.elements.gradients, self.elements.weights,
                                      self.materials, self.element_material, energies)
        return float(energies.sum())


def material_table(materials) -> np.ndarray:
    """Rows (model code, mu, lambda, kappa, eta) of the kernels, one per material."""
    return np.array([[m.model_code, m.shear_modulus, m.lame_lambda, m.bulk_modulus, m.viscosity]
                     for m in materials], dtype=np.float64)


def stable_step_for(omega_max: float, viscous_time_constant: float, mass_damping: float) -> float:
    """Stable step of central differences for a mode of angular frequency ``omega_max`` with
    damping ratio xi = alpha / (2 omega) + beta omega / 2: (2 / omega)(sqrt(1 + xi^2) - xi)
    (Belytschko, Liu & Moran 2000, eq. 6.2.33)."""
    if omega_max <= 0:
        return np.inf
    xi = mass_damping / (2.0 * omega_max) + viscous_time_constant * omega_max / 2.0
    # sqrt(1 + xi^2) - xi written as 1 / (sqrt(1 + xi^2) + xi): no cancellation to 0 (or inf - inf
    # = nan) when the damping is large
    return 2.0 / omega_max / (math.hypot(1.0, xi) + xi)
