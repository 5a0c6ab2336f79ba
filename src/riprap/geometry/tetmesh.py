"""Tetrahedral meshes of rigid or deformable bodies.

A :class:`TetMesh` is the geometry of one body in its own frame: node coordinates in metres and
four node indices per tetrahedron, every tetrahedron positively oriented. The boundary (the faces
used by exactly one tetrahedron, oriented outward) is what contact sees; :meth:`TetMesh.check`
rejects meshes that would break contact or mass properties, and says which tetrahedra or edges are
at fault.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError, MeshError

# A tetrahedron whose volume is below this fraction of (bounding-box diagonal)^3 is degenerate: at
# 1e-12 its heights are ~1e-8 of the body size or smaller, which no mesher produces on purpose and
# which would make the contact stiffness, and so the stable time step, absurd.
DEGENERATE_VOLUME_FRACTION = 1e-12

# The volume of the tetrahedra and the volume their boundary encloses (divergence theorem) agree
# to round-off in a valid mesh; a relative difference above this means overlaps or gaps.
_VOLUME_ROUND_OFF = 1e-9

# Pieces of a mesh (tetrahedra joined by no face to the rest), and tetrahedra of each, tested for
# lying inside the rest: a valid body has one piece, so a few tested show an overlap.
_MAX_PIECES_TESTED = 20

# How many offending tetrahedra or edges an error message lists before it says "and N more".
_MAX_LISTED = 5

# Outward faces of a positively oriented tetrahedron (0, 1, 2, 3): face k is opposite node k and is
# ordered so that (x1 - x0) x (x2 - x0) points away from node k.
_OUTWARD_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]], dtype=np.int64)


def _signed_volumes(nodes: np.ndarray, tets: np.ndarray) -> np.ndarray:
    corners = nodes[tets]
    edges = corners[:, 1:, :] - corners[:, :1, :]
    return np.linalg.det(edges) / 6.0


def _listing(items: list[str], total: int) -> str:
    text = ", ".join(items)
    if total > len(items):
        text += f" and {total - len(items)} more"
    return text


@dataclass(frozen=True, eq=False)
class TetMesh:
    """A tetrahedral mesh of one body in its own frame.

    Parameters
    ----------
    nodes : numpy.ndarray, shape (n_nodes, 3)
        Node coordinates in metres (float64).
    tets : numpy.ndarray, shape (n_tets, 4)
        Node indices of each tetrahedron (int64), positively oriented:
        ``det[x1 - x0, x2 - x0, x3 - x0] > 0``. Use :meth:`from_arrays` with
        ``fix_orientation=True`` for meshes whose orientation convention is unknown.
    name : str
        Name used in error messages (a file name, a shape name).

    Notes
    -----
    The arrays are copied to contiguous float64/int64 and made read-only, so a mesh can be shared
    between bodies. Equality is identity (``eq=False``): comparing arrays element-wise is left to
    the caller. Construction checks only the array shapes; call :meth:`check` for the full
    validity checks.

    Examples
    --------
    >>> import numpy as np
    >>> mesh = TetMesh(nodes=np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]),
    ...                tets=np.array([[0, 1, 2, 3]]), name="corner")
    >>> float(mesh.volumes()[0])
    0.16666666666666666
    >>> mesh.boundary_faces().shape
    (4, 3)
    """

    nodes: np.ndarray
    tets: np.ndarray
    name: str = "mesh"

    def __post_init__(self) -> None:
        nodes = np.array(self.nodes, dtype=np.float64, order="C", copy=True)
        tets = np.array(self.tets, order="C", copy=True)
        if nodes.ndim != 2 or nodes.shape[1] != 3:
            raise MeshError(
                f"mesh '{self.name}': nodes must have shape (n_nodes, 3), got {nodes.shape}"
            )
        if tets.ndim != 2 or tets.shape[1] != 4:
            raise MeshError(
                f"mesh '{self.name}': tets must have shape (n_tets, 4), got {tets.shape}"
            )
        if tets.size and not np.issubdtype(tets.dtype, np.integer):
            raise MeshError(
                f"mesh '{self.name}': tets must hold integer node indices, got dtype {tets.dtype}"
            )
        tets = tets.astype(np.int64)
        if tets.size and (tets.min() < 0 or tets.max() >= len(nodes)):
            bad = np.flatnonzero(((tets < 0) | (tets >= len(nodes))).any(axis=1))
            raise MeshError(
                f"mesh '{self.name}': tets {bad[:_MAX_LISTED].tolist()} refer to node indices "
                f"outside 0..{len(nodes) - 1}; node indices are zero-based"
            )
        nodes.setflags(write=False)
        tets.setflags(write=False)
        object.__setattr__(self, "nodes", nodes)
        object.__setattr__(self, "tets", tets)

    @classmethod
    def from_arrays(
        cls,
        nodes: np.ndarray,
        tets: np.ndarray,
        name: str = "mesh",
        fix_orientation: bool = False,
    ) -> TetMesh:
        """Build a mesh from arrays, optionally re-orienting negatively oriented tetrahedra.

        Parameters
        ----------
        nodes : numpy.ndarray, shape (n_nodes, 3)
            Node coordinates in metres.
        tets : numpy.ndarray, shape (n_tets, 4)
            Node indices of each tetrahedron.
        name : str
            Name used in error messages.
        fix_orientation : bool
            If True, swap the last two node indices of every tetrahedron with negative volume
            (meshers differ in their orientation convention). If False, leave them for
            :meth:`check` to reject.

        Returns
        -------
        TetMesh
        """
        nodes = np.asarray(nodes, dtype=np.float64)
        tets = np.array(tets, dtype=np.int64, copy=True)
        if fix_orientation and tets.ndim == 2 and tets.shape[1] == 4 and len(tets):
            mesh = cls(nodes=nodes, tets=tets, name=name)
            negative = mesh.volumes() < 0.0
            tets[negative] = tets[negative][:, [0, 1, 3, 2]]
        return cls(nodes=nodes, tets=tets, name=name)

    @property
    def n_nodes(self) -> int:
        """Number of nodes."""
        return int(self.nodes.shape[0])

    @property
    def n_tets(self) -> int:
        """Number of tetrahedra."""
        return int(self.tets.shape[0])

    def volumes(self) -> np.ndarray:
        """Signed volume of each tetrahedron.

        Returns
        -------
        numpy.ndarray, shape (n_tets,)
            ``det[x1 - x0, x2 - x0, x3 - x0] / 6`` in m^3; positive for a valid mesh.
        """
        return _signed_volumes(self.nodes, self.tets)

    def boundary_faces(self) -> np.ndarray:
        """Faces used by exactly one tetrahedron, oriented outward.

        Returns
        -------
        numpy.ndarray, shape (n_faces, 3)
            Node indices of each boundary face, ordered so that ``(x1 - x0) x (x2 - x0)`` points
            out of the body (for positively oriented tetrahedra).
        """
        faces, counts, first = self._face_table()
        return faces[first[counts == 1]]

    def boundary_tet_indices(self) -> np.ndarray:
        """Indices of the tetrahedra that own at least one boundary face.

        Returns
        -------
        numpy.ndarray, shape (n_boundary_tets,)
            Sorted, unique tetrahedron indices (int64).
        """
        _, counts, first = self._face_table()
        return np.unique(first[counts == 1] // 4)

    def _face_table(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """All 4 n_tets oriented faces, the use count of each distinct face and a representative.

        Face ``f`` of tetrahedron ``t`` is row ``4 t + f`` of the returned faces.
        """
        faces = self.tets[:, _OUTWARD_FACES].reshape(-1, 3)
        keys = np.sort(faces, axis=1)
        _, first, counts = np.unique(keys, axis=0, return_index=True, return_counts=True)
        return faces, counts, first

    def check(self) -> None:
        """Check that the mesh is a valid solid; raise :class:`MeshError` otherwise.

        Checks, in order: at least one tetrahedron; finite coordinates; every tetrahedron
        positively oriented ("inverted" otherwise); no degenerate tetrahedron (volume below
        ``DEGENERATE_VOLUME_FRACTION`` x bounding-box diagonal^3); no tetrahedron repeated (the
        same four nodes twice); no face shared by more than two tetrahedra; a boundary that is a closed 2-manifold (every boundary edge used by exactly two
        boundary faces). Unused nodes are allowed.

        Raises
        ------
        MeshError
            Naming the mesh, the offending tetrahedra or edges, and the likely fix.
        """
        name = self.name
        if self.n_tets == 0:
            raise MeshError(f"mesh '{name}' has no tetrahedra; a body needs a volume mesh")
        bad_nodes = np.flatnonzero(~np.isfinite(self.nodes).all(axis=1))
        if bad_nodes.size:
            listed = [f"{i} {self.nodes[i].tolist()}" for i in bad_nodes[:_MAX_LISTED]]
            raise MeshError(
                f"mesh '{name}' has non-finite node coordinates: nodes "
                f"{_listing(listed, bad_nodes.size)}; fix the mesh file or the generator"
            )
        volumes = self.volumes()
        inverted = np.flatnonzero(volumes <= 0.0)
        if inverted.size:
            listed = [f"{i} (volume {volumes[i]:.3e} m^3)" for i in inverted[:_MAX_LISTED]]
            raise MeshError(
                f"mesh '{name}' has {inverted.size} inverted tetrahedra (non-positive volume): "
                f"tets {_listing(listed, inverted.size)}; reverse two node indices of each (e.g. "
                f"swap the last two), or build the mesh with "
                f"TetMesh.from_arrays(..., fix_orientation=True)"
            )
        used = self.nodes[np.unique(self.tets)]
        diagonal = float(np.linalg.norm(used.max(axis=0) - used.min(axis=0)))
        threshold = DEGENERATE_VOLUME_FRACTION * diagonal**3
        degenerate = np.flatnonzero(volumes < threshold)
        if degenerate.size:
            listed = [f"{i} (volume {volumes[i]:.3e} m^3)" for i in degenerate[:_MAX_LISTED]]
            raise MeshError(
                f"mesh '{name}' has {degenerate.size} degenerate tetrahedra (volume below "
                f"{threshold:.3e} m^3 = {DEGENERATE_VOLUME_FRACTION:g} x bounding-box diagonal^3): "
                f"tets {_listing(listed, degenerate.size)}; remesh with mesh optimisation or "
                f"remove these tetrahedra"
            )
        self._check_repeated_tets()
        faces, counts, first = self._face_table()
        overused = np.flatnonzero(counts > 2)
        if overused.size:
            keys = np.sort(faces, axis=1)
            listed = []
            for k in overused[:_MAX_LISTED]:
                owners = np.flatnonzero((keys == keys[first[k]]).all(axis=1)) // 4
                listed.append(f"{faces[first[k]].tolist()} (tets {owners.tolist()})")
            raise MeshError(
                f"mesh '{name}' has {overused.size} faces shared by more than two tetrahedra "
                f"(overlapping elements): faces {_listing(listed, overused.size)}; remove the "
                f"overlapping tetrahedra or remesh the body"
            )
        boundary = faces[first[counts == 1]]
        self._check_closed_boundary(boundary)
        self._check_no_overlapping_tets(faces, volumes, boundary)

    def _check_repeated_tets(self) -> None:
        # A repeated tetrahedron (same four nodes, any order) counts its volume and mass twice and
        # hides its faces from the boundary; the face counts alone do not always reveal it.
        keys = np.sort(self.tets, axis=1)
        _, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
        inverse = inverse.reshape(-1)
        repeated = np.flatnonzero(counts > 1)
        if repeated.size:
            listed = []
            for k in repeated[:_MAX_LISTED]:
                copies = np.flatnonzero(inverse == k)
                listed.append(f"{self.tets[copies[0]].tolist()} (tets {copies.tolist()})")
            raise MeshError(
                f"mesh '{self.name}' has {repeated.size} repeated tetrahedra (the same four nodes "
                f"more than once): {_listing(listed, repeated.size)}; remove the duplicates"
            )

    def _check_no_overlapping_tets(self, faces: np.ndarray, volumes: np.ndarray,
                                   boundary: np.ndarray) -> None:
        """Tetrahedra that overlap count their volume (and mass) twice. Three tests: the two
        tetrahedra on an interior face lie on opposite sides of it; the tetrahedra fill exactly
        the volume their boundary encloses (divergence theorem, to round-off); a piece of the
        mesh joined to the rest by no face does not lie inside the rest."""
        keys = np.sort(faces, axis=1)
        n = int(self.tets.max()) + 1
        if n < 2**21:        # one int64 per face: sorting it is ten times faster than rows
            codes = (keys[:, 0] * n + keys[:, 1]) * n + keys[:, 2]
        else:
            codes = np.unique(keys, axis=0, return_inverse=True)[1].reshape(-1)
        order = np.argsort(codes, kind="stable")
        runs = np.flatnonzero(np.diff(codes[order]) == 0)         # two faces with one key
        face_a, face_b = order[runs], order[runs + 1]
        # The node order of a face against its sorted order: opposite sides reverse it.
        parity = ((faces[:, 0] > faces[:, 1]).astype(int) + (faces[:, 0] > faces[:, 2])
                  + (faces[:, 1] > faces[:, 2])) % 2
        same_side = np.flatnonzero(parity[face_a] == parity[face_b])
        if same_side.size:
            listed = [f"{(face_a[k] // 4)} and {(face_b[k] // 4)} on face {keys[face_a[k]].tolist()}"
                      for k in same_side[:_MAX_LISTED]]
            raise MeshError(
                f"mesh '{self.name}' has {same_side.size} pairs of overlapping tetrahedra (both on "
                f"the same side of the face they share): tets {_listing(listed, same_side.size)}; "
                "remove the extra tetrahedra or remesh the body")
        centre = self.nodes[np.unique(self.tets)].mean(axis=0)
        corners = self.nodes[boundary] - centre
        enclosed = float(np.einsum("ij,ij->i", corners[:, 0],
                                   np.cross(corners[:, 1], corners[:, 2])).sum()) / 6.0
        total = float(volumes.sum())
        if abs(total - enclosed) > _VOLUME_ROUND_OFF * total:
            raise MeshError(
                f"mesh '{self.name}': its tetrahedra fill {total:.6g} m^3 but its boundary encloses "
                f"{enclosed:.6g} m^3 ({100 * (total - enclosed) / enclosed:+.3g} %): tetrahedra "
                "overlap or leave gaps; remesh the body")
        self._check_pieces_apart(face_a // 4, face_b // 4)

    def _check_pieces_apart(self, tet_a: np.ndarray, tet_b: np.ndarray) -> None:
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        n = self.n_tets
        graph = coo_matrix((np.ones(len(tet_a)), (tet_a, tet_b)), shape=(n, n))
        count, piece = connected_components(graph, directed=False)
        if count == 1:
            return
        sizes = np.bincount(piece, minlength=count)
        corners = self.nodes[self.tets]                            # (n, 4, 3)
        # Barycentric coordinates of a point in every tet: solve with the inverse edge matrices.
        edges = (corners[:, 1:] - corners[:, :1]).transpose(0, 2, 1)
        inverses = np.linalg.inv(edges)
        for label in np.argsort(sizes)[:-1][:_MAX_PIECES_TESTED]:   # all but the largest piece
            members = np.flatnonzero(piece == label)[:_MAX_PIECES_TESTED]
            others = np.flatnonzero(piece != label)
            for tet in members:
                point = corners[tet].mean(axis=0)
                local = np.einsum("nij,nj->ni", inverses[others], point - corners[others, 0])
                weights = np.concatenate([1.0 - local.sum(axis=1)[:, None], local], axis=1)
                inside = np.flatnonzero((weights > 1e-9).all(axis=1))
                if inside.size:
                    raise MeshError(
                        f"mesh '{self.name}': tetrahedron {tet} (in a piece of {sizes[label]} "
                        f"joined to the rest by no face) lies inside tetrahedron "
                        f"{others[inside[0]]}: overlapping elements count their volume and mass "
                        "twice; remove the extra tetrahedra or remesh the body")

    def _check_closed_boundary(self, boundary: np.ndarray) -> None:
        edges = np.sort(boundary[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
        unique_edges, edge_counts = np.unique(edges, axis=0, return_counts=True)
        bad = np.flatnonzero(edge_counts != 2)
        if bad.size:
            listed = [
                f"{unique_edges[k].tolist()} (used by {edge_counts[k]} boundary faces)"
                for k in bad[:_MAX_LISTED]
            ]
            raise MeshError(
                f"mesh '{self.name}': the boundary is not a closed 2-manifold; boundary edges "
                f"{_listing(listed, bad.size)} should each be used by exactly two boundary faces; "
                f"the mesh has a crack, a hanging face or bodies touching along an edge, remesh it"
            )

    def transformed(self, rotation: np.ndarray, translation: np.ndarray) -> TetMesh:
        """The mesh moved rigidly: ``x -> rotation @ x + translation``.

        Parameters
        ----------
        rotation : numpy.ndarray, shape (3, 3)
            Proper rotation matrix (orthonormal, determinant +1); a reflection would invert every
            tetrahedron and is refused.
        translation : numpy.ndarray, shape (3,)
            Translation in metres.

        Returns
        -------
        TetMesh
            Same tetrahedra and name, moved nodes.
        """
        rotation = np.asarray(rotation, dtype=np.float64)
        translation = np.asarray(translation, dtype=np.float64)
        if rotation.shape != (3, 3) or translation.shape != (3,):
            raise CaseFileError(
                f"mesh '{self.name}'.transformed: rotation must have shape (3, 3) and translation "
                f"(3,), got {rotation.shape} and {translation.shape}"
            )
        # 1e-9 leaves room for rotations assembled from float64 quaternions or products of many.
        orthogonality_error = np.abs(rotation.T @ rotation - np.eye(3)).max()
        if orthogonality_error > 1e-9 or np.linalg.det(rotation) <= 0.0:
            raise CaseFileError(
                f"mesh '{self.name}'.transformed: rotation is not a proper rotation matrix "
                f"(|R^T R - I| = {orthogonality_error:.2e}, det = {np.linalg.det(rotation):.6f}); "
                f"pass an orthonormal matrix with determinant +1"
            )
        nodes = self.nodes @ rotation.T + translation
        return TetMesh(nodes=nodes, tets=self.tets, name=self.name)
