"""Fracture of deformable bodies: joint (cohesive) elements between the tets of a split mesh.

The mesh is split where it may crack (``explode_mesh``: each side of a joint its own copy of the
face's nodes) and a joint holds each pair of faces that were shared; the joints' law is Munjiza's
combined single and smeared crack model (``riprap/deformable/kernels/joints.py``). A
:class:`FracturingBody` is a :class:`DeformableBody` on the split mesh whose steps add the joints'
forces (inside the compiled step); in a :class:`riprap.deformable.system.DeformableSystem` its
fragments are bodies of their own for the contact.

Why the softening length is G / (f * 0.3863) and not Y3D's 3 G / f: the area under Hordijk's curve
z(D) over D in [0, 1] is 0.3863 (``SOFTENING_AREA``), so a crack that opens from the strength to
z = 0 over a length o_t dissipates f_t o_t 0.3863 per unit area; Y3D's o_t = 3 G_f / f_t gives
1.16 G_f. With o_t = G_f / (0.3863 f_t) it is G_f exactly (checked in
``tests/verification/test_fracture_mode_one.py``).

Limits: 4-node tets only; a broken joint keeps its faces from passing through each other by the
compressive penalty (with the joint's friction) until they no longer face each other, then lets
go for good; single-tet chips crushed off under a rock leave fast (docs/fracture.md, Limits).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components, reverse_cuthill_mckee

from riprap.deformable.body import DeformableBody, stable_step_for
from riprap.deformable.kernels import joints as joint_kernels
from riprap.errors import CaseFileError
from riprap.schema import default_of

__all__ = ["JointMaterial", "ExplodedMesh", "explode_mesh", "FracturingBody", "SOFTENING_AREA"]


def _softening_area(samples: int = 200_001) -> float:
    damage = np.linspace(0.0, 1.0, samples)
    a, b, c = joint_kernels.SOFTENING_A, joint_kernels.SOFTENING_B, joint_kernels.SOFTENING_C
    z = ((1.0 - (a + b - 1.0) / (a + b) * np.exp(damage * (a + c * b) / ((a + b) * (1.0 - a - b))))
         * (a * (1.0 - damage) + b * (1.0 - damage) ** c))
    return float(np.sum(0.5 * (z[1:] + z[:-1]) * np.diff(damage)))


#: The area under the softening curve z(D), D in [0, 1] (0.3863).
SOFTENING_AREA = _softening_area()


@dataclass(frozen=True)
class JointMaterial:
    """Strength and toughness of the joints between a body's tets (SI units).

    tensile_strength : float
        f_t (Pa): the normal stress at which a joint starts to crack (concrete: 2-5 MPa).
    cohesion : float
        c (Pa): the shear strength without normal stress (concrete: about 2 f_t).
    friction_angle : float
        phi (degrees): the shear strength grows by tan(phi) times the compressive normal stress.
    fracture_energy_mode_i, fracture_energy_mode_ii : float
        G_I, G_II (J/m^2): energy a crack dissipates per unit area in opening and in sliding
        (concrete: about 100 and 1000 J/m^2).
    joint_penalty : float
        p (Pa): a joint's stiffness per unit area is p / h (h its size), so p = 10 E makes it a
        tenth as compliant as the elements beside it; stiffer joints shorten the time step.
    """

    tensile_strength: float
    cohesion: float
    friction_angle: float
    fracture_energy_mode_i: float
    fracture_energy_mode_ii: float
    joint_penalty: float

    def __post_init__(self):
        for name in ("tensile_strength", "cohesion", "fracture_energy_mode_i",
                     "fracture_energy_mode_ii", "joint_penalty"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise CaseFileError(f"joints: {name} = {value!r} must be > 0")
        if not (math.isfinite(self.friction_angle) and 0.0 <= self.friction_angle < 90.0):
            raise CaseFileError(f"joints: friction_angle = {self.friction_angle!r} must be in "
                                "[0, 90) degrees")

    def kernel_row(self) -> np.ndarray:
        """(f_t, c, tan phi, p, f_t area / G_I, area / G_II, 2 / p, 1 / (2 f_t), 1 / (2 c)) as
        the kernel reads them (area: ``SOFTENING_AREA``; the inverses taken here, once)."""
        f_t, c, p = self.tensile_strength, self.cohesion, self.joint_penalty
        return np.array([f_t, c, math.tan(math.radians(self.friction_angle)), p,
                         f_t * SOFTENING_AREA / self.fracture_energy_mode_i,
                         SOFTENING_AREA / self.fracture_energy_mode_ii,
                         2.0 / p, 0.5 / f_t, 0.5 / c])


_TET_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])   # outward, opposite corner k


class ExplodedMesh(NamedTuple):
    """A mesh split along its joints (``explode_mesh``)."""

    #: (k, 3) node coordinates: one copy of an original node per group of its tets that no
    #: joint separates.
    nodes: np.ndarray
    #: (m, 4) tets in those nodes, in the original order and orientation.
    tets: np.ndarray
    #: (n, 6) joint j holds face A (nodes ``joints[j, :3]``) to face B (``joints[j, 3:]``, paired
    #: in order); (x1 - x0) x (x2 - x0) of face A points out of its tet.
    joints: np.ndarray
    #: (n, 2) the tets of faces A and B.
    joint_tets: np.ndarray
    #: (m, 4) the joint on tet t's face k (opposite its corner k), -1 on the mesh's surface, -2 on
    #: a face shared with a tet it stays glued to (no joint between them).
    face_joint: np.ndarray
    #: (k,) the original node of every node.
    original_node: np.ndarray
    #: (g, 2) pairs of tets that share a face without a joint: they never part.
    glued_tets: np.ndarray


def explode_mesh(nodes, tets, cracking=None) -> ExplodedMesh:
    """Split a mesh along the faces where it may crack: a joint between every two tets that share
    a face and are both ``cracking`` (a mask over the tets; default all). Each side of a joint
    gets its own copy of the face's nodes; tets that share a face without a joint keep sharing
    their nodes (with joints everywhere, every tet has its own four)."""
    nodes = np.asarray(nodes, dtype=np.float64)
    tets = np.asarray(tets, dtype=np.int64)
    m = len(tets)
    cracking = np.ones(m, dtype=bool) if cracking is None else np.asarray(cracking, dtype=bool)
    first, second = _shared_faces(tets)
    # joints in the order of their first tet: a block of tets and the block of joints at the
    # same place in their lists then mostly share their nodes (one thread's cache)
    by_tet = np.argsort(first, kind="stable")
    first, second = first[by_tet], second[by_tet]
    tet_a, face_a = first // 4, first % 4
    tet_b, face_b = second // 4, second % 4
    corners_a = _TET_FACES[face_a]                                      # local corners in A, (n, 3)
    global_ids = tets[tet_a[:, None], corners_a]                        # outward from A
    # B's local corner holding each of those global nodes
    match = tets[tet_b][:, None, :] == global_ids[:, :, None]           # (n, 3, 4)
    corners_b = np.argmax(match, axis=2)
    jointed = cracking[tet_a] & cracking[tet_b]
    # a node's copies: its (tet, corner) incidences joined across the faces without a joint
    glued_a = (4 * tet_a[:, None] + corners_a)[~jointed].ravel()
    glued_b = (4 * tet_b[:, None] + corners_b)[~jointed].ravel()
    incidences = 4 * m
    same_node = coo_matrix((np.ones(glued_a.size), (glued_a, glued_b)),
                           shape=(incidences, incidences))
    _, copy_of = connected_components(same_node, directed=False)
    new_tets = copy_of.reshape(m, 4).astype(np.int64)
    original_node = np.zeros(int(copy_of.max()) + 1 if m else 0, dtype=np.int64)
    original_node[copy_of] = tets.reshape(-1)
    joints = np.concatenate([new_tets[tet_a[:, None], corners_a],
                             new_tets[tet_b[:, None], corners_b]], axis=1)[jointed]
    face_joint = np.full((m, 4), -1, dtype=np.int64)
    face_joint[tet_a[~jointed], face_a[~jointed]] = -2
    face_joint[tet_b[~jointed], face_b[~jointed]] = -2
    n_joints = int(jointed.sum())
    face_joint[tet_a[jointed], face_a[jointed]] = np.arange(n_joints)
    face_joint[tet_b[jointed], face_b[jointed]] = np.arange(n_joints)
    return ExplodedMesh(nodes[original_node], new_tets, joints.astype(np.int64),
                        np.stack([tet_a, tet_b], axis=1)[jointed], face_joint, original_node,
                        np.stack([tet_a, tet_b], axis=1)[~jointed])


def _shared_faces(tets):
    """The faces two tets share, as flat (tet * 4 + face) indices (first, second), first < second
    (face k opposite corner k)."""
    keys = np.sort(tets[:, _TET_FACES].reshape(-1, 3), axis=1)
    order = np.lexsort(keys.T[::-1])
    sorted_keys = keys[order]
    same = np.all(sorted_keys[1:] == sorted_keys[:-1], axis=1)
    return order[:-1][same], order[1:][same]


def locality_order(tets) -> np.ndarray:
    """An order of the tets in which neighbours (tets that share a face) are near each other:
    reverse Cuthill-McKee on the face graph. A split mesh numbers its nodes after its tets, and
    each joint reads the nodes of two neighbours: in the mesher's order they were a median 476
    tets apart in the unit-breakage example (and 60 % of the joints were on another thread than
    their tets), after it a few tens."""
    tets = np.asarray(tets, dtype=np.int64)
    m = len(tets)
    if m < 3:
        return np.arange(m)
    first, second = _shared_faces(tets)
    graph = coo_matrix((np.ones(first.size), (first // 4, second // 4)), shape=(m, m)).tocsr()
    return np.asarray(reverse_cuthill_mckee(graph + graph.T, symmetric_mode=True), dtype=np.int64)


#: A crack needs at least this many tets across a body's thinnest extent to find its own path.
MIN_TETS_ACROSS = 3.0


def check_crack_resolution(nodes, tets, name: str) -> None:
    """Refuse a mesh too coarse to show a crack: fewer than ``MIN_TETS_ACROSS`` mean tet edges
    across the body's thinnest extent (along its principal axes). Raises CaseFileError saying
    what is needed."""
    nodes = np.asarray(nodes, dtype=np.float64)
    tets = np.asarray(tets, dtype=np.int64)
    corners = nodes[tets]
    edges = corners[:, [1, 2, 3, 2, 3, 3]] - corners[:, [0, 0, 0, 1, 1, 2]]
    mean_edge = float(np.linalg.norm(edges, axis=2).mean())
    centred = nodes - nodes.mean(axis=0)
    _, _, axes = np.linalg.svd(centred, full_matrices=False)
    extents = np.ptp(centred @ axes.T, axis=0)
    thinnest = float(extents.min())
    if thinnest < MIN_TETS_ACROSS * mean_edge:
        raise CaseFileError(
            f"deformable body '{name}': its mesh is too coarse to show a crack: "
            f"{thinnest / mean_edge:.1f} tet edges (mean {mean_edge:.3g} m) across its thinnest "
            f"extent of {thinnest:.3g} m, where a crack needs at least {MIN_TETS_ACROSS:g}; mesh it "
            f"finer (a shape's mesh_size of at most {thinnest / MIN_TETS_ACROSS:.3g} m)")


def slot_joint_rows(tets, joints, joint_tets, face_joint) -> np.ndarray:
    """(4 m, 3) int32 (half the bytes of int64 for the node update to read): for each
    (tet, corner) slot 4 t + c, the rows of a (6 n + 1, 3) joint force buffer
    (``kernels/joints.joint_forces``: row 6 j + k for joint j's vertex k, 0-2 on face A, 3-5 on
    face B) that hold the forces on that corner from the joints on the tet's three faces
    there (column f - (f > c) for face f, the face opposite corner f); row 6 n, kept zero, where
    a face has no joint."""
    tets = np.asarray(tets, dtype=np.int64)
    joints = np.asarray(joints, dtype=np.int64)
    n = len(joints)
    table = np.full((4 * len(tets), 3), 6 * n, dtype=np.int32)
    for side in (0, 1):
        tet = joint_tets[:, side]
        face = np.argmax(face_joint[tet] == np.arange(n)[:, None], axis=1)
        # the tet's corner at each of the side's three vertices
        corner = np.argmax(tets[tet][:, None, :] == joints[:, 3 * side:3 * side + 3, None],
                           axis=2)
        for k in range(3):
            column = face - (face > corner[:, k])
            table[4 * tet + corner[:, k], column] = 6 * np.arange(n) + 3 * side + k
    return table


class FracturingBody(DeformableBody):
    """A deformable body that cracks: the mesh ``nodes``, ``tets`` split by joints of
    ``joint_material`` between every two tets that share a face and are both ``cracking`` (a mask
    over the tets, default all; ``explode_mesh``).

    Other parameters as :class:`DeformableBody` (4-node tets only).
    """

    def __init__(self, nodes, tets, material, joint_material: JointMaterial, *,
                 name: str = "body", gravity=(0.0, 0.0, 0.0),
                 mass_damping: float = default_of("deformable", "mass_damping"),
                 cracking=None):
        if not isinstance(joint_material, JointMaterial):
            raise CaseFileError(f"deformable body '{name}': joint_material must be a JointMaterial")
        # (the body's tets are numbered afresh, neighbours near each other: ``locality_order``)
        order = locality_order(tets)
        tets = np.asarray(tets, dtype=np.int64)[order]
        if cracking is not None:
            cracking = np.asarray(cracking, dtype=bool)[order]
        split = explode_mesh(nodes, tets, cracking)
        if cracking is not None and len(split.joints) == 0:
            raise CaseFileError(
                f"deformable body '{name}': its fracture region holds {int(np.sum(cracking))} of "
                "its tets and no two of them share a face, so it could never crack; move or "
                "widen fracture_region_lower/upper to take in the part that should crack")
        exploded, joints = split.nodes, split.joints
        super().__init__(exploded, split.tets, material, element_type="tet4", name=name,
                         gravity=gravity, mass_damping=mass_damping)
        self.joint_material = joint_material
        #: The mesh before it was exploded (reference nodes and tets).
        self.original_nodes = np.asarray(nodes, dtype=np.float64).copy()
        self.original_tets = np.asarray(tets, dtype=np.int64).copy()
        # 32-bit node numbers: the joints' step reads them every time (bench/fracture.py)
        self.joints = joints.astype(np.int32)
        self.joint_tets = split.joint_tets
        self.original_node = split.original_node
        #: The joint on tet t's face k, -1 on the surface, -2 glued (``ExplodedMesh.face_joint``).
        self.face_joint = split.face_joint
        self.glued_tets = split.glued_tets
        corners = exploded[joints[:, :3]]
        edges = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2)
        #: h of each joint (m): the mean edge of its face.
        self.joint_sizes = edges.mean(axis=1)
        #: Reference area of each joint's face (m^2).
        self.joint_areas = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0],
                                                         corners[:, 2] - corners[:, 0]), axis=1)
        #: Damage D of each joint's three points (0 intact .. 1 no strength left).
        self.joint_damage = np.zeros((len(joints), 3))
        #: Joints with two points at D = 1: they only keep their faces from passing through each
        #: other (while the faces still face each other: slip below the joint's size).
        self.joint_broken = np.zeros(len(joints), dtype=np.bool_)
        #: Broken joints between two fragments: in a DeformableSystem their faces are contact
        #: surfaces too, for every tet but the two the joint holds and their other neighbours.
        self.joint_parted = np.zeros(len(joints), dtype=np.bool_)
        #: Broken joints whose faces slid apart by the joint's size or more: they no longer face
        #: each other, and the joint acts no more (kernels/joints.py, ``_broken_joint``).
        self.joint_released = np.zeros(len(joints), dtype=np.bool_)
        #: Friction anchor of each joint's three points: the slip at which its friction force
        #: is nil, as multiples of the joint's two edges from its first corner (it turns with
        #: the joint).
        self.joint_friction_anchor = np.zeros((len(joints), 3, 2))
        #: Work done by the joints on the nodes so far (J): minus the energy they stored and
        #: dissipated.
        self.joint_work = np.zeros(1)
        self._joint_properties = joint_material.kernel_row()[None, :]
        self._joint_material_index = np.zeros(len(joints), dtype=np.int64)
        self._slot_joint_rows = slot_joint_rows(split.tets, joints, split.joint_tets,
                                                split.face_joint)
        self._joint_buffer = np.zeros((6 * len(joints) + 1, 3))

    # ------------------------------------------------------------------ steps
    def stable_time_step(self) -> float:
        """The elements' stable step with the joints' stiffness added: the largest frequency
        bounded by sqrt(omega_element^2 + omega_joint^2), omega_joint^2 the largest over the
        nodes of the joints' Gershgorin row sum at the node over its mass: (p / h) (2 A / 3) per
        joint (a node's two points, each a third of the area, each shared by its two vertices
        and read from both faces), twice that with friction (its spring, p / h, acts along the
        joint's plane on top of the cohesion's, whose slope is p / h at most)."""
        if self._stable_time_step is None:
            omega_elements = float(self.elements.largest_element_frequencies(self.material).max())
            omega = math.hypot(omega_elements, self.joint_frequency())
            self._stable_time_step = stable_step_for(omega, self.material.viscous_time_constant,
                                                     self.mass_damping)
            self._stiffest_frequency = omega
        return self._stable_time_step

    def joint_frequency(self) -> float:
        """Bound on the largest angular frequency (rad/s) of a node held by its joints alone."""
        if not len(self.joints):
            return 0.0
        stiffness = np.zeros(len(self.masses))
        springs = 2.0 if self.joint_material.friction_angle > 0.0 else 1.0
        per_joint = (springs * self.joint_material.joint_penalty / self.joint_sizes
                     * self.joint_areas * (2.0 / 3.0))
        np.add.at(stiffness, self.joints.reshape(-1), np.repeat(per_joint, 6))
        return float(np.sqrt((stiffness / self.masses).max()))

    def joint_forces(self) -> np.ndarray:
        """The joints' forces on the nodes (n, 3) at the present positions (updates damage)."""
        forces = np.zeros_like(self.positions)
        joint_kernels.joint_forces(self.positions, self.joints, self.joint_sizes,
                                   self._joint_properties, self._joint_material_index,
                                   self.joint_damage, self.joint_broken, self.joint_released,
                                   self.joint_friction_anchor, self._joint_buffer,
                                   np.empty(joint_kernels.JOINT_SCRATCH_SIZE))
        joint_kernels.gather_joint_forces(self._joint_buffer, self._offsets, self._slots,
                                          self._slot_joint_rows, forces)
        return forces

    def _joint_arguments(self):
        return (self.joints, self.joint_sizes, self._joint_properties, self._joint_material_index,
                self.joint_damage, self.joint_broken, self._joint_buffer, self._slot_joint_rows,
                self.joint_released, self.joint_work, self.joint_friction_anchor)

    # ------------------------------------------------------------------ results
    @property
    def broken_area(self) -> float:
        """Reference area (m^2) of the broken joints: the crack surface (one side)."""
        return float(self.joint_areas[self.joint_broken].sum())

    def fragments(self) -> np.ndarray:
        """Fragment number of every tet: tets joined by unbroken joints share one."""
        intact = ~self.joint_broken
        a = np.concatenate([self.joint_tets[intact, 0], self.glued_tets[:, 0]])
        b = np.concatenate([self.joint_tets[intact, 1], self.glued_tets[:, 1]])
        n = self.n_elements
        graph = coo_matrix((np.ones(a.size), (a, b)), shape=(n, n))
        _, labels = connected_components(graph, directed=False)
        return labels

    def fragment_table(self) -> dict:
        """The pieces the body has broken into, each a body of its own, largest first: per
        fragment its tets' count, volume (m^3, reference), mass (kg), mass fraction of the unit,
        centre of mass (m) and velocity (m/s, its momentum over its mass), and ``element_fragment``
        (the fragment of every tet in this numbering). Mass is the tets' own, so the fragments'
        masses add up to the body's exactly."""
        labels = self.fragments()
        n = int(labels.max()) + 1 if len(labels) else 0
        volumes = np.bincount(labels, weights=self.elements.volumes, minlength=n)
        # a node's tets are all of one fragment (tets that share a node without a joint between
        # them are glued): its mass and momentum belong to that fragment
        node_fragment = np.zeros(len(self.masses), dtype=np.int64)
        node_fragment[self.elements.elements.reshape(-1)] = np.repeat(labels, 4)
        masses = np.bincount(node_fragment, weights=self.masses, minlength=n)
        centres = np.stack([np.bincount(node_fragment, weights=self.masses * self.positions[:, d],
                                        minlength=n) for d in range(3)], axis=1) / masses[:, None]
        velocities = np.stack([np.bincount(node_fragment, weights=self.masses * self.velocities[:, d],
                                           minlength=n) for d in range(3)], axis=1) / masses[:, None]
        order = np.argsort(-masses, kind="stable")
        renumber = np.empty(n, dtype=np.int64)
        renumber[order] = np.arange(n)
        return {"elements": np.bincount(labels, minlength=n)[order], "volume": volumes[order],
                "mass": masses[order], "mass_fraction": masses[order] / self.mass,
                "centre": centres[order], "velocity": velocities[order],
                "element_fragment": renumber[labels]}

    def breakage_summary(self) -> dict:
        """Broken area (m^2), number of fragments and the largest fragment's mass fraction."""
        table = self.fragment_table()
        return {"broken_area_m2": self.broken_area, "fragments": int(len(table["mass"])),
                "largest_fragment_mass_fraction": float(table["mass_fraction"][0])}
