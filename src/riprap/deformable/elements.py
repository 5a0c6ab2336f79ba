"""Reference geometry of the finite elements of a deformable body: 4-node and 10-node tetrahedra.

For each element: the reference gradients of its shape functions at its integration points, the
reference volume each point stands for, and the lumped nodal masses (eq. 5 of the seed paper: the
mass of each tet shared among its nodes). The 10-node tet (Xiang, Munjiza & Latham 2009) is built
from a 4-node mesh by adding a node at the middle of every edge, in VTK's node order
(corners 0-3, then edges 01, 12, 20, 03, 13, 23), so its edges are straight in the reference state;
it is integrated with the 4-point Gauss rule and its masses are lumped by diagonal scaling
(Hinton, Rock & Zienkiewicz 1976: corners 1/36, edge nodes 4/27 of the element's mass), since
row sums would give the corners negative masses.

The stable step of the central-difference scheme is 2 / omega_max; omega_max is bounded from
above by the largest eigenvalue of any single element (Irons & Treharne 1971), computed here for
every element from its small-strain stiffness and lumped masses, so the bound is set by the
smallest (or worst-shaped) element, as the seed paper says of Y3D-D.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError, MeshError

ELEMENT_TYPES = ("tet4", "tet10")

# Edges of a tetrahedron in VTK_QUADRATIC_TETRA order: node 4 + k sits on edge k.
TET10_EDGES = np.array([[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]], dtype=np.int64)

# The 8 linear sub-tets of a 10-node tet (node numbers as above: 4 = edge 01, 5 = 12, 6 = 20,
# 7 = 03, 8 = 13, 9 = 23): the 4 corner tets and the inner octahedron split along 4-9.
_TET10_SUBTETS = ((0, 4, 6, 7), (4, 1, 5, 8), (6, 5, 2, 9), (7, 8, 9, 3),
                  (4, 9, 5, 8), (4, 9, 8, 7), (4, 9, 7, 6), (4, 9, 6, 5))

# 4-point Gauss rule on a tet, exact for quadratics: barycentric coordinates, equal weights.
_GAUSS_A = 0.5854101966249685
_GAUSS_B = 0.1381966011250105
TET10_POINTS = np.array([[_GAUSS_A, _GAUSS_B, _GAUSS_B, _GAUSS_B],
                         [_GAUSS_B, _GAUSS_A, _GAUSS_B, _GAUSS_B],
                         [_GAUSS_B, _GAUSS_B, _GAUSS_A, _GAUSS_B],
                         [_GAUSS_B, _GAUSS_B, _GAUSS_B, _GAUSS_A]])

# A tet whose volume is below this fraction of its longest edge cubed is degenerate (a regular
# tet has 0.118): its stable time step would be near zero.
DEGENERATE_SHAPE = 1e-6


@dataclass(frozen=True)
class ElementSet:
    """Elements of one deformable body in its reference state.

    Attributes
    ----------
    element_type : str
        "tet4" or "tet10".
    reference_nodes : (n_nodes, 3) float
    elements : (n_elements, 4 or 10) int
    gradients : (n_elements, n_points, nodes per element, 3) float
        Reference gradients of the shape functions at the integration points (1/m).
    weights : (n_elements, n_points) float
        Reference volume of each integration point (m^3).
    tet4_gradients : (n_elements, 4, 3) float or None
        For 4-node tets: the gradients of the one integration point, contiguous.
    corner_tets : (n_elements, 4) int
        The corner nodes (for contact, pictures and the mesh checks).
    """

    element_type: str
    reference_nodes: np.ndarray
    elements: np.ndarray
    gradients: np.ndarray
    weights: np.ndarray
    tet4_gradients: np.ndarray | None
    corner_tets: np.ndarray

    @property
    def volumes(self) -> np.ndarray:
        return self.weights.sum(axis=1)

    def contact_tets(self) -> np.ndarray:
        """4-node tets that contact sees: the elements themselves for 4-node tets; for 10-node
        tets their 8 sub-tets through the mid-edge nodes (4 at the corners, 4 splitting the inner
        octahedron along the 01-23 diagonal), so that the curved faces take part through all six
        of their nodes and the light corner nodes (1/36 of the mass) do not carry the contact
        alone. Positively oriented in the reference state."""
        if self.element_type == "tet4":
            return self.elements
        e = self.elements
        split = np.concatenate([e[:, list(sub)] for sub in _TET10_SUBTETS])
        corners = self.reference_nodes[split]
        negative = np.linalg.det(corners[:, 1:] - corners[:, :1]) < 0
        split[negative] = split[negative][:, [0, 1, 3, 2]]
        return np.ascontiguousarray(split)

    def lumped_masses(self, density: float) -> np.ndarray:
        """Nodal masses (kg) from the reference volumes."""
        element_mass = density * self.volumes
        if self.element_type == "tet4":
            shares = np.full(4, 0.25)
        else:
            shares = np.r_[np.full(4, 1.0 / 36.0), np.full(6, 4.0 / 27.0)]
        masses = np.zeros(len(self.reference_nodes))
        np.add.at(masses, self.elements, element_mass[:, None] * shares[None, :])
        return masses

    def node_to_element_slots(self) -> tuple[np.ndarray, np.ndarray]:
        """(offsets, slots): the flat (element * nodes per element + local) entries acting on each
        node, in CSR form, for the parallel summation of element forces."""
        flat_nodes = self.elements.ravel()
        order = np.argsort(flat_nodes, kind="stable")
        counts = np.bincount(flat_nodes, minlength=len(self.reference_nodes))
        offsets = np.zeros(len(counts) + 1, dtype=np.int64)
        np.cumsum(counts, out=offsets[1:])
        return offsets, order.astype(np.int64)

    def largest_element_frequencies(self, material) -> np.ndarray:
        """Largest angular frequency (rad/s) of every element on its own: the square root of the
        largest eigenvalue of M_e^-1 K_e with the small-strain stiffness and lumped masses."""
        lam, mu = material.lame_lambda, material.shear_modulus
        n_el, n_points, n_local, _ = self.gradients.shape
        elasticity = _isotropic_elasticity(lam, mu)
        if self.element_type == "tet4":
            shares = np.full(4, 0.25)
        else:
            shares = np.r_[np.full(4, 1.0 / 36.0), np.full(6, 4.0 / 27.0)]
        result = np.empty(n_el)
        chunk = max(1, 200_000 // (n_local * n_local))
        for start in range(0, n_el, chunk):
            stop = min(start + chunk, n_el)
            grads = self.gradients[start:stop]
            strain_matrix = _strain_displacement(grads)            # (c, g, 6, 3 n_local)
            stiffness = np.einsum("cgki,kl,cglj,cg->cij", strain_matrix, elasticity, strain_matrix,
                                  self.weights[start:stop], optimize=True)
            mass = material.density * self.volumes[start:stop, None] * shares[None, :]
            inverse_root = 1.0 / np.sqrt(np.repeat(mass, 3, axis=1))
            scaled = stiffness * inverse_root[:, :, None] * inverse_root[:, None, :]
            if not np.isfinite(scaled).all():
                raise CaseFileError(
                    f"[deformable] young_modulus = {material.young_modulus:g} Pa with density = "
                    f"{material.density:g} kg/m^3 overflows the stiffness over the mass of elements "
                    f"of {float(np.cbrt(self.volumes.min())):.3g} m: no element frequency (and so "
                    "no time step) follows; give young_modulus in Pa (concrete about 3e10) and "
                    "density in kg/m^3")
            result[start:stop] = np.sqrt(np.maximum(np.linalg.eigvalsh(scaled)[:, -1], 0.0))
        return result


def _isotropic_elasticity(lam: float, mu: float) -> np.ndarray:
    """6x6 Voigt matrix (xx, yy, zz, xy, yz, zx with engineering shear strains)."""
    matrix = np.zeros((6, 6))
    matrix[:3, :3] = lam
    matrix[np.arange(3), np.arange(3)] += 2.0 * mu
    matrix[np.arange(3, 6), np.arange(3, 6)] = mu
    return matrix


def _strain_displacement(gradients: np.ndarray) -> np.ndarray:
    """Small-strain B matrices (..., 6, 3 n_local) from shape-function gradients (..., n_local, 3)."""
    shape = gradients.shape[:-2]
    n_local = gradients.shape[-2]
    matrix = np.zeros(shape + (6, 3 * n_local))
    gx, gy, gz = gradients[..., 0], gradients[..., 1], gradients[..., 2]
    matrix[..., 0, 0::3] = gx
    matrix[..., 1, 1::3] = gy
    matrix[..., 2, 2::3] = gz
    matrix[..., 3, 0::3] = gy
    matrix[..., 3, 1::3] = gx
    matrix[..., 4, 1::3] = gz
    matrix[..., 4, 2::3] = gy
    matrix[..., 5, 0::3] = gz
    matrix[..., 5, 2::3] = gx
    return matrix


# Faces of a positively oriented tet (0, 1, 2, 3) ordered so that their normal points outward.
_OUTWARD_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]], dtype=np.int64)


# The same faces of a 10-node tet with their mid-edge nodes: corners a, b, c, then the nodes of
# edges ab, bc, ca.
_OUTWARD_FACES_10 = np.array([[1, 2, 3, 5, 9, 8], [0, 3, 2, 7, 9, 6], [0, 1, 3, 4, 8, 7],
                              [0, 2, 1, 6, 5, 4]], dtype=np.int64)


def boundary_face_nodes(elements: np.ndarray) -> np.ndarray:
    """The boundary faces of a body's elements, outward: (n, 3) corner nodes for 4-node tets,
    (n, 6) for 10-node tets (corners a, b, c, then the mid nodes of ab, bc, ca)."""
    corners, _ = boundary_faces_with_owners(elements[:, :4])
    if elements.shape[1] == 4:
        return corners
    faces = elements[:, _OUTWARD_FACES_10].reshape(-1, 6)
    order = {tuple(key): row for row, key in enumerate(np.sort(faces[:, :3], axis=1).tolist())}
    return faces[[order[tuple(key)] for key in np.sort(corners, axis=1).tolist()]]


def boundary_faces_with_owners(tets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(faces (n, 3) outward, owner tet of each): the faces used by exactly one tet."""
    faces = tets[:, _OUTWARD_FACES].reshape(-1, 3)
    owners = np.repeat(np.arange(len(tets)), 4)
    keys = np.sort(faces, axis=1)
    _, first, counts = np.unique(keys, axis=0, return_index=True, return_counts=True)
    single = first[counts == 1]
    return faces[single], owners[single]


def check_reference_tets(nodes: np.ndarray, tets: np.ndarray, body: str) -> np.ndarray:
    """Signed volumes of the tets; raises MeshError naming the body and the first inverted or
    degenerate elements."""
    corners = nodes[tets]
    edges = corners[:, 1:, :] - corners[:, :1, :]
    volumes = np.linalg.det(edges) / 6.0
    all_edges = corners[:, [1, 2, 3, 2, 3, 3], :] - corners[:, [0, 0, 0, 1, 1, 2], :]
    longest = np.sqrt((all_edges ** 2).sum(axis=2)).max(axis=1)
    inverted = np.flatnonzero(volumes <= 0.0)
    if len(inverted):
        listed = ", ".join(f"{e} (volume {volumes[e]:.3g} m^3)" for e in inverted[:5])
        more = f" and {len(inverted) - 5} more" if len(inverted) > 5 else ""
        raise MeshError(f"deformable body '{body}': element(s) {listed}{more} are inverted or flat "
                        "in the reference state; re-mesh or fix the node order")
    shape = volumes / np.maximum(longest, np.finfo(float).tiny) ** 3
    degenerate = np.flatnonzero(shape < DEGENERATE_SHAPE)
    if len(degenerate):
        listed = ", ".join(f"{e} (volume/edge^3 = {shape[e]:.2g})" for e in degenerate[:5])
        more = f" and {len(degenerate) - 5} more" if len(degenerate) > 5 else ""
        raise MeshError(f"deformable body '{body}': element(s) {listed}{more} are degenerate "
                        f"(volume below {DEGENERATE_SHAPE:g} of the longest edge cubed; a regular "
                        "tet has 0.118): their stable time step would be near zero; re-mesh")
    return volumes


def _linear_gradients(nodes: np.ndarray, tets: np.ndarray) -> np.ndarray:
    """Gradients of the four barycentric coordinates of every tet, (n, 4, 3)."""
    corners = nodes[tets]
    edges = corners[:, 1:, :] - corners[:, :1, :]          # rows: x1-x0, x2-x0, x3-x0
    inverse = np.linalg.inv(edges)                          # columns: grad L1, L2, L3
    rest = np.transpose(inverse, (0, 2, 1))
    return np.concatenate([-rest.sum(axis=1, keepdims=True), rest], axis=1)


def build_element_set(nodes: np.ndarray, tets: np.ndarray, element_type: str, body: str) -> ElementSet:
    """Elements of a body from its 4-node mesh (nodes in metres, positively oriented tets)."""
    if element_type not in ELEMENT_TYPES:
        raise MeshError(f"deformable body '{body}': element_type = {element_type!r} is not one of "
                        f"{', '.join(ELEMENT_TYPES)}")
    nodes = np.ascontiguousarray(nodes, dtype=np.float64)
    tets = np.ascontiguousarray(tets, dtype=np.int64)
    volumes = check_reference_tets(nodes, tets, body)
    linear = _linear_gradients(nodes, tets)
    if element_type == "tet4":
        return ElementSet("tet4", nodes, tets, np.ascontiguousarray(linear[:, None, :, :]),
                          volumes[:, None].copy(), np.ascontiguousarray(linear), tets)
    # mid-edge nodes, shared between neighbouring tets
    edge_nodes = tets[:, TET10_EDGES]                       # (n, 6, 2)
    keys = np.sort(edge_nodes.reshape(-1, 2), axis=1)
    unique, inverse = np.unique(keys, axis=0, return_inverse=True)
    midpoints = 0.5 * (nodes[unique[:, 0]] + nodes[unique[:, 1]])
    all_nodes = np.concatenate([nodes, midpoints])
    elements = np.concatenate([tets, len(nodes) + inverse.reshape(-1, 6)], axis=1)
    # grad N at each point: corners (4 L_i - 1) grad L_i, edges 4 (L_i grad L_j + L_j grad L_i)
    n_el = len(tets)
    gradients = np.empty((n_el, 4, 10, 3))
    for g, point in enumerate(TET10_POINTS):
        for i in range(4):
            gradients[:, g, i, :] = (4.0 * point[i] - 1.0) * linear[:, i, :]
        for k, (i, j) in enumerate(TET10_EDGES):
            gradients[:, g, 4 + k, :] = 4.0 * (point[i] * linear[:, j, :] + point[j] * linear[:, i, :])
    weights = np.repeat(volumes[:, None] / 4.0, 4, axis=1)
    return ElementSet("tet10", all_nodes, np.ascontiguousarray(elements), gradients, weights, None, tets)
