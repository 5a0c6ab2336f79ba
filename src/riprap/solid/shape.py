"""Rigid shapes: a tetrahedral mesh moved to its principal frame plus everything the contact kernels
need that never changes in that frame.

A rigid body's contact is evaluated in the *boundary form* of Munjiza's potential contact
(see ``kernels/contact.py``): the surface triangles of one body weighted by the tetrahedral
potential of the other. So a shape stores, in its own principal frame,

- the barycentric maps of every tet (``barycentric``: lambda_k = a_k . x + b_k), from which the
  potential phi = 4 min_k lambda_k and its gradient 4 a_k follow;
- its boundary triangles with unit outward normals, grouped in small spatial clusters with bounding
  spheres, so that a pair of bodies only looks at the triangles near the other body;
- a uniform grid over its bounding box listing the tets that touch each cell, and for each cell a
  lower bound of the distance from that cell to the body ("clearance"), which rejects most far
  triangles with one lookup.

All shapes are concatenated into one :class:`ShapeTable` of flat arrays for the kernels.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from riprap.geometry.mass_properties import mass_properties
from riprap.geometry.tetmesh import TetMesh
from riprap.solid.kernels.bundles import ShapeLookup, ShapeMesh, Shapes
from riprap.solid.kernels.geometry_ops import surface_clearance

# The tet lookup grid has cells of 3/4 of a median tet edge (at most this many per axis), so that a
# cell lists few tets and the clearance bound is tight near the surface.
_GRID_MAX_CELLS_PER_AXIS = 64
_GRID_CELL_OVER_EDGE = 0.75
# Boundary triangles per cluster: small enough that a contact touches few clusters, large enough
# that the cluster loop is short.
_TRIANGLES_PER_CLUSTER = 12


@dataclass(frozen=True)
class RigidShape:
    """A shape in its principal frame with precomputed contact data.

    Attributes
    ----------
    name : str
    mesh : TetMesh
        Nodes in the principal frame: centroid at the origin, inertia tensor diagonal.
    volume : float
        m^3.
    unit_principal_moments : (3,) ndarray
        Principal moments of inertia per unit density (m^5); multiply by density for kg m^2.
    frame_rotation : (3, 3) ndarray
        Columns are the principal axes expressed in the frame the mesh was built in: a point ``y`` of
        the principal frame is ``frame_rotation @ y + frame_origin`` in the original frame.
    frame_origin : (3,) ndarray
        Centroid of the mesh in its original frame (m).
    bounding_radius : float
        Largest distance of a node from the centroid (m).
    boundary_subtet_height : float
        Median height of the boundary sub-tetrahedra (centroid of a boundary tet to its boundary
        face), m. Walls use it as the depth over which their potential rises (a wall acts as if
        meshed like the body touching it), and the time step estimate uses a low percentile of it.
    min_subtet_height : float
        Tenth percentile of the boundary sub-tet heights (m), used for the stiffness estimate.
    """

    name: str
    mesh: TetMesh
    volume: float
    unit_principal_moments: np.ndarray
    frame_rotation: np.ndarray
    frame_origin: np.ndarray
    bounding_radius: float
    boundary_subtet_height: float
    min_subtet_height: float
    barycentric: np.ndarray        # (n_tets, 4, 4): row k = (a_k, b_k), lambda_k = a_k.x + b_k
    triangles: np.ndarray          # (n_tri, 3) node indices, outward, ordered by cluster
    triangle_normals: np.ndarray   # (n_tri, 3) unit outward normals
    triangle_centres: np.ndarray   # (n_tri, 3) centres of the bounding spheres
    triangle_radii: np.ndarray     # (n_tri,)
    cluster_start: np.ndarray      # (n_clusters + 1,) triangle ranges
    cluster_centres: np.ndarray    # (n_clusters, 3)
    cluster_radii: np.ndarray      # (n_clusters,)
    tet_boxes: np.ndarray          # (n_tets, 6) lower and upper corners of each tet
    grid_origin: np.ndarray        # (3,) lower corner
    grid_cell_size: float
    grid_dims: np.ndarray          # (3,) int
    cell_start: np.ndarray         # (n_cells + 1,) CSR into cell_tets
    cell_tets: np.ndarray          # tets touching each cell
    cell_clearance: np.ndarray     # (n_cells,) lower bound of distance from the cell to the body, m

    @property
    def n_tets(self) -> int:
        return len(self.mesh.tets)

    def mass(self, density: float) -> float:
        return density * self.volume

    def boundary_triangles_world(self, rotation: np.ndarray, position: np.ndarray) -> np.ndarray:
        """Boundary triangles placed in the world, (n_tri, 3, 3)."""
        nodes = self.mesh.nodes @ rotation.T + position
        return nodes[self.triangles]

    @classmethod
    def from_mesh(cls, mesh: TetMesh, name: str | None = None) -> "RigidShape":
        """Move ``mesh`` to its principal frame and precompute the contact data."""
        mesh.check()
        props = mass_properties(mesh, density=1.0)
        axes = np.array(props.principal_axes, dtype=np.float64)
        if np.linalg.det(axes) < 0:
            axes[:, 2] *= -1.0
        nodes = (mesh.nodes - props.centroid) @ axes
        tets = np.ascontiguousarray(mesh.tets, dtype=np.int64)
        principal = TetMesh(nodes=np.ascontiguousarray(nodes), tets=tets, name=name or mesh.name)
        barycentric = _barycentric_maps(nodes, tets)
        faces = principal.boundary_faces()
        heights = _boundary_subtet_heights(nodes, tets, faces)
        triangles, cluster_start = _cluster_triangles(nodes, faces)
        normals, centres, radii = _triangle_spheres(nodes, triangles)
        cluster_centres, cluster_radii = _cluster_spheres(nodes, triangles, cluster_start)
        grid = _tet_grid(nodes, tets, barycentric, triangles)
        return cls(
            name=name or mesh.name,
            mesh=principal,
            volume=float(props.volume),
            unit_principal_moments=np.asarray(props.principal_moments, dtype=np.float64),
            frame_rotation=axes,
            frame_origin=np.asarray(props.centroid, dtype=np.float64),
            bounding_radius=float(np.max(np.linalg.norm(nodes, axis=1))),
            boundary_subtet_height=float(np.median(heights)),
            min_subtet_height=float(np.percentile(heights, 10.0)),
            barycentric=barycentric,
            triangles=triangles,
            triangle_normals=normals,
            triangle_centres=centres,
            triangle_radii=radii,
            cluster_start=cluster_start,
            cluster_centres=cluster_centres,
            cluster_radii=cluster_radii,
            **grid,
        )


def _barycentric_maps(nodes: np.ndarray, tets: np.ndarray) -> np.ndarray:
    """Affine maps x -> lambda_k(x) for each tet, (n_tets, 4, 4)."""
    x = nodes[tets]                                   # (m, 4, 3)
    homogeneous = np.concatenate([x, np.ones((len(tets), 4, 1))], axis=2)   # rows: (x_k, 1)
    # lambda = inv(H^T) (x, 1): H^T lambda = (x, 1) for the columns being vertex coordinates.
    inverse = np.linalg.inv(np.transpose(homogeneous, (0, 2, 1)))           # (m, 4, 4)
    return np.ascontiguousarray(inverse)


def _boundary_subtet_heights(nodes, tets, faces) -> np.ndarray:
    """Distance from each boundary tet's centroid to its boundary face (m)."""
    key = {tuple(sorted(f)): None for f in faces.tolist()}
    centroids = nodes[tets].mean(axis=1)
    heights = []
    for t, tet in enumerate(tets.tolist()):
        for k in range(4):
            face = tuple(sorted(tet[:k] + tet[k + 1:]))
            if face in key:
                a, b, c = nodes[list(face)]
                n = np.cross(b - a, c - a)
                heights.append(abs(np.dot(centroids[t] - a, n)) / np.linalg.norm(n))
    return np.asarray(heights)


def _cluster_triangles(nodes, faces):
    """Group triangles into compact clusters by recursive bisection of their centres; the
    triangles are reordered so that each cluster is a contiguous range."""
    centres = nodes[faces].mean(axis=1)
    leaves = []
    _bisect(centres, np.arange(len(faces)), leaves)
    order = np.concatenate(leaves)
    triangles = np.ascontiguousarray(faces[order], dtype=np.int64)
    sizes = np.array([len(leaf) for leaf in leaves], dtype=np.int64)
    cluster_start = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    return triangles, cluster_start


def _bisect(points, indices, leaves):
    if len(indices) <= _TRIANGLES_PER_CLUSTER:
        leaves.append(indices)
        return
    p = points[indices]
    axis = int(np.argmax(p.max(axis=0) - p.min(axis=0)))
    sorted_idx = indices[np.argsort(p[:, axis], kind="stable")]
    half = len(sorted_idx) // 2
    _bisect(points, sorted_idx[:half], leaves)
    _bisect(points, sorted_idx[half:], leaves)


def _triangle_spheres(nodes, triangles):
    x = nodes[triangles]
    n = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    normals = n / np.linalg.norm(n, axis=1)[:, None]
    centres = x.mean(axis=1)
    radii = np.max(np.linalg.norm(x - centres[:, None, :], axis=2), axis=1)
    return np.ascontiguousarray(normals), np.ascontiguousarray(centres), np.ascontiguousarray(radii)


def _cluster_spheres(nodes, triangles, cluster_start):
    n_clusters = len(cluster_start) - 1
    centres = np.zeros((n_clusters, 3))
    radii = np.zeros(n_clusters)
    for c in range(n_clusters):
        pts = nodes[triangles[cluster_start[c]:cluster_start[c + 1]].ravel()]
        centre = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
        centres[c] = centre
        radii[c] = np.max(np.linalg.norm(pts - centre, axis=1))
    return centres, radii


def _tet_grid(nodes, tets, barycentric, triangles):
    """Uniform grid over the shape listing the tets whose boxes touch each cell."""
    x = nodes[tets]
    lo_t, hi_t = x.min(axis=1), x.max(axis=1)
    edge = np.median(np.linalg.norm(x[:, 1] - x[:, 0], axis=1))
    lo, hi = nodes.min(axis=0), nodes.max(axis=0)
    extent = float(np.max(hi - lo))
    cell = max(_GRID_CELL_OVER_EDGE * edge, extent / _GRID_MAX_CELLS_PER_AXIS)
    origin = lo - cell
    dims = np.maximum(np.ceil((hi - origin) / cell).astype(np.int64) + 1, 1)
    i0 = np.clip(np.floor((lo_t - origin) / cell).astype(np.int64), 0, dims - 1)
    i1 = np.clip(np.floor((hi_t - origin) / cell).astype(np.int64), 0, dims - 1)
    owners = [[] for _ in range(int(np.prod(dims)))]
    for t in range(len(tets)):
        for ix in range(i0[t, 0], i1[t, 0] + 1):
            for iy in range(i0[t, 1], i1[t, 1] + 1):
                for iz in range(i0[t, 2], i1[t, 2] + 1):
                    owners[(ix * dims[1] + iy) * dims[2] + iz].append(t)
    counts = np.array([len(o) for o in owners], dtype=np.int64)
    cell_start = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    cell_tets = np.array([t for o in owners for t in o], dtype=np.int64)
    # Exact distance from each cell centre to the body, less half a cell diagonal: a lower bound of
    # the distance from any point of the cell to the body.
    ix, iy, iz = np.meshgrid(*[np.arange(d) for d in dims], indexing="ij")
    centres = origin + (np.stack([ix.ravel(), iy.ravel(), iz.ravel()], axis=1) + 0.5) * cell
    distance = surface_clearance(centres, nodes, triangles, tets, barycentric, cell_start, cell_tets)
    clearance = np.maximum(distance - 0.5 * np.sqrt(3.0) * cell, 0.0)
    return dict(tet_boxes=np.ascontiguousarray(np.concatenate([lo_t, hi_t], axis=1)),
                grid_origin=origin.astype(np.float64), grid_cell_size=float(cell),
                grid_dims=dims.astype(np.int64), cell_start=cell_start, cell_tets=cell_tets,
                cell_clearance=np.ascontiguousarray(clearance))


@dataclass(frozen=True)
class ShapeTable:
    """All shapes of a simulation concatenated into flat arrays for the kernels.

    Per-shape offsets index the concatenated arrays; node, tet and triangle indices stay local to
    their shape.
    """

    shapes: tuple
    node_offset: np.ndarray
    nodes: np.ndarray
    tet_offset: np.ndarray
    tets: np.ndarray
    barycentric: np.ndarray
    triangle_offset: np.ndarray
    triangles: np.ndarray
    triangle_normals: np.ndarray
    triangle_centres: np.ndarray
    triangle_radii: np.ndarray
    cluster_offset: np.ndarray     # (n_shapes + 1,) into the cluster arrays
    cluster_begin: np.ndarray      # (n_clusters,) first local triangle of each cluster
    cluster_end: np.ndarray        # (n_clusters,) one past the last
    cluster_centres: np.ndarray
    cluster_radii: np.ndarray
    grid_origin: np.ndarray        # (n_shapes, 3)
    grid_cell_size: np.ndarray     # (n_shapes,)
    grid_dims: np.ndarray          # (n_shapes, 3)
    cell_offset: np.ndarray        # into cell_clearance; cell_start has one more entry per shape
    cell_start_offset: np.ndarray
    cell_start: np.ndarray
    cell_tets_offset: np.ndarray
    cell_tets: np.ndarray
    cell_clearance: np.ndarray
    local_box_min: np.ndarray      # (n_shapes, 3)
    local_box_max: np.ndarray
    wall_potential_depth: np.ndarray   # (n_shapes,)
    tet_boxes: np.ndarray          # (n_tets_total, 6)

    @classmethod
    def build(cls, shapes) -> "ShapeTable":
        shapes = tuple(shapes)

        def cat(getter, dtype, width=None):
            parts = [np.asarray(getter(s), dtype=dtype) for s in shapes]
            sizes = np.array([len(p) for p in parts], dtype=np.int64)
            offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
            joined = np.concatenate(parts) if parts else np.zeros((0,) if width is None else (0, width), dtype)
            return offsets, np.ascontiguousarray(joined)

        node_offset, nodes = cat(lambda s: s.mesh.nodes, np.float64)
        tet_offset, tets = cat(lambda s: s.mesh.tets, np.int64)
        _, barycentric = cat(lambda s: s.barycentric, np.float64)
        triangle_offset, triangles = cat(lambda s: s.triangles, np.int64)
        _, normals = cat(lambda s: s.triangle_normals, np.float64)
        _, centres = cat(lambda s: s.triangle_centres, np.float64)
        _, radii = cat(lambda s: s.triangle_radii, np.float64)
        cluster_offset, cluster_centres = cat(lambda s: s.cluster_centres, np.float64)
        _, cluster_radii = cat(lambda s: s.cluster_radii, np.float64)
        _, cluster_begin = cat(lambda s: s.cluster_start[:-1], np.int64)
        _, cluster_end = cat(lambda s: s.cluster_start[1:], np.int64)
        cell_offset, clearance = cat(lambda s: s.cell_clearance, np.float64)
        cell_start_offset, cell_start = cat(lambda s: s.cell_start, np.int64)
        cell_tets_offset, cell_tets = cat(lambda s: s.cell_tets, np.int64)
        _, tet_boxes = cat(lambda s: s.tet_boxes, np.float64)
        return cls(
            shapes=shapes,
            node_offset=node_offset, nodes=nodes, tet_offset=tet_offset, tets=tets,
            barycentric=barycentric, triangle_offset=triangle_offset, triangles=triangles,
            triangle_normals=normals, triangle_centres=centres, triangle_radii=radii,
            cluster_offset=cluster_offset, cluster_begin=cluster_begin, cluster_end=cluster_end,
            cluster_centres=cluster_centres, cluster_radii=cluster_radii,
            grid_origin=np.array([s.grid_origin for s in shapes], dtype=np.float64).reshape(-1, 3),
            grid_cell_size=np.array([s.grid_cell_size for s in shapes], dtype=np.float64),
            grid_dims=np.array([s.grid_dims for s in shapes], dtype=np.int64).reshape(-1, 3),
            cell_offset=cell_offset, cell_start_offset=cell_start_offset, cell_start=cell_start,
            cell_tets_offset=cell_tets_offset, cell_tets=cell_tets, cell_clearance=clearance,
            local_box_min=np.array([s.mesh.nodes.min(axis=0) for s in shapes]).reshape(-1, 3),
            local_box_max=np.array([s.mesh.nodes.max(axis=0) for s in shapes]).reshape(-1, 3),
            wall_potential_depth=np.array([s.boundary_subtet_height for s in shapes], dtype=np.float64),
            tet_boxes=tet_boxes,
        )

    def kernel_arrays(self) -> Shapes:
        """The shapes as the contact kernels take them (``solid/kernels/bundles.py``)."""
        mesh = ShapeMesh(self.node_offset, self.nodes, self.tet_offset, self.tets, self.barycentric,
                         self.triangle_offset, self.triangles, self.triangle_normals)
        lookup = ShapeLookup(
            self.triangle_centres, self.triangle_radii, self.cluster_offset, self.cluster_begin,
            self.cluster_end, self.cluster_centres, self.cluster_radii, self.grid_origin,
            self.grid_cell_size, self.grid_dims, self.cell_offset, self.cell_start_offset,
            self.cell_start, self.cell_tets_offset, self.cell_tets, self.cell_clearance,
            self.local_box_min, self.local_box_max, self.wall_potential_depth, self.tet_boxes,
            np.array([s.bounding_radius for s in self.shapes], dtype=np.float64))
        return Shapes(mesh, lookup)
