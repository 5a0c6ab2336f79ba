"""The named bundles of arrays the rigid kernels take, instead of long positional lists.

numba compiles a ``namedtuple`` of arrays as a struct: reading a field is a compile-time offset,
the same code as a separate argument. Kernels read the fields they need once, at their top and
outside their loops, so the loops compile as before.

Reference counts: a compiled function that takes an array takes a reference to it on entry and
drops it on exit (two atomic operations, shared by the threads). A bundle costs that for every
array it holds, so the kernels called once per pair take the smallest bundle that serves them
(:class:`ShapeMesh`, :class:`PairWork`), and those called per piece are ``leaf_kernel``s, which
take no references at all.
"""
from collections import namedtuple

#: The rigid shapes' meshes, all shapes concatenated (``solid/shape.py`` ``ShapeTable``): per-shape
#: ``node_offset``, ``tet_offset``, ``triangle_offset`` (n_shapes + 1,) into ``nodes`` (m, body
#: frame), ``tets``, ``barycentric`` (n_tets, 4, 4: lambda_k = b[k, :3] . y + b[k, 3]),
#: ``triangles`` (boundary, local node indices) and ``triangle_normals`` (unit, outward).
ShapeMesh = namedtuple("ShapeMesh", ["node_offset", "nodes", "tet_offset", "tets", "barycentric",
                                     "triangle_offset", "triangles", "triangle_normals"])

#: What finds the pieces that can touch, per shape or concatenated: boundary triangles' centres
#: and radii, their clusters (``cluster_offset`` per shape, ``cluster_begin``/``cluster_end`` local
#: triangles, centres, radii), the tet lookup grid (``grid_origin`` (n, 3), ``grid_cell_size``,
#: ``grid_dims`` (n, 3), ``cell_offset``/``cell_start_offset``/``cell_tets_offset`` per shape into
#: ``cell_clearance``, ``cell_start``, ``cell_tets``), the body boxes (``local_box_min``/``max``
#: (n, 3)), the depth over which a wall's potential rises (``wall_potential_depth``, m), the tet
#: boxes (n_tets, 6: min xyz, max xyz) and the bounding radius of each shape (m).
ShapeLookup = namedtuple("ShapeLookup", [
    "triangle_centres", "triangle_radii", "cluster_offset", "cluster_begin", "cluster_end",
    "cluster_centres", "cluster_radii", "grid_origin", "grid_cell_size", "grid_dims", "cell_offset",
    "cell_start_offset", "cell_start", "cell_tets_offset", "cell_tets", "cell_clearance",
    "local_box_min", "local_box_max", "wall_potential_depth", "tet_boxes", "bounding_radius"])

#: All rigid shapes: their meshes and their lookup structures.
Shapes = namedtuple("Shapes", ["mesh", "lookup"])

#: The bodies' fixed properties, per body: mass (kg), inverse mass (0 for fixed bodies), inverse
#: principal moments (n, 3), fixed flag, shape and material index.
Bodies = namedtuple("Bodies", ["masses", "inverse_masses", "inverse_principal_inertia", "fixed",
                               "shape_index", "material_index"])

#: The bodies' state (world frame, SI): positions (n, 3), orientation quaternions (n, 4; w, x, y,
#: z), velocities (n, 3), angular momenta (n, 3), and the forces and torques (n, 3) of the last
#: evaluation. Advanced in place.
Motion = namedtuple("Motion", ["positions", "quaternions", "velocities", "angular_momenta",
                               "forces", "torques"])

#: The half-space walls: a point on each (n_walls, 3), its unit normal pointing out of the wall,
#: its material index.
Walls = namedtuple("Walls", ["points", "normals", "materials"])

#: The contact law of every pair of materials (n_materials, n_materials), from
#: ``solid/materials.py`` ``pair_tables``: penalty (Pa), friction coefficient, normal damping
#: ratio, tangential-to-normal stiffness ratio.
PairLaws = namedtuple("PairLaws", ["penalty", "friction", "damping_ratio", "tangential_ratio"])

#: The rigid system the steps advance: its bodies' fixed properties (:class:`Bodies`), the shapes
#: (:class:`Shapes`), the walls (:class:`Walls`) and the pair contact laws (:class:`PairLaws`).
RigidSystem = namedtuple("RigidSystem", ["bodies", "shapes", "walls", "laws"])

#: The contacts' spring state, sorted by pair key (``interactions.py``): keys (n,) and springs
#: (n, HISTORY_WIDTH).
History = namedtuple("History", ["keys", "springs"])

#: Everything outside the bodies that a step needs: gravity (3,) m/s^2, the external loads (n, 6)
#: held on each free body (force, torque; a fluid's), the broad-phase margin (m), the time step
#: (s), the local damping factor, the piece lists' skin (m), and the periodic directions: per
#: axis the lower end of the strip (m) and its period (m; 0: not periodic) (``periodic.py``).
StepSettings = namedtuple("StepSettings", ["gravity", "external_loads", "margin", "step",
                                           "local_damping", "skin", "period_lower", "period"])

#: The (triangle, tet) piece lists kept from the last step (``interactions.evaluate_candidates``):
#: sorted pair keys (n,), the relative pose each list was made at (n, 12), its rows [start, split,
#: end) (n, 3) in ``pieces`` (m, 2).
PieceCache = namedtuple("PieceCache", ["keys", "poses", "bounds", "pieces"])

#: What the candidate pairs' evaluation writes: ``results`` (n_candidates, C_SIZE), the fresh piece
#: lists (``fresh`` (n_batches * capacity, 2), ``capacity`` rows per batch) and, per body pair,
#: where its list for the next step lives (``source``, SOURCE_*), its rows (``bounds``) and the
#: pose it was listed at (``poses``).
CandidateOutputs = namedtuple("CandidateOutputs", ["results", "fresh", "capacity", "source",
                                                   "bounds", "poses"])

#: One candidate pair in the contact law: its row in the results, the two bodies (j = -1 for a
#: wall), its history key, the inverse mass of j (0 for a wall), the two material indices.
Candidate = namedtuple("Candidate", ["row", "i", "j", "key", "inverse_mass_j", "material_i",
                                     "material_j"])

#: One thread's work arrays for a pair's integration (``contact.make_scratch``).
PairWork = namedtuple("PairWork", ["signed", "moments", "vertices", "lam", "normal", "polygons",
                                   "res"])

#: One thread's work arrays (``contact.make_scratch``): three clipping polygons, the pair's
#: integration work (:class:`PairWork`), the piece search's work (centre, candidate tets, the
#: tet stamps and their counter, the triangle's box and its cell range), four tet-node depths and
#: the piece list buffer.
Scratch = namedtuple("Scratch", ["polygon", "work_a", "work_b", "work", "centre", "candidates",
                                 "stamp", "counter", "tri_lo", "tri_hi", "i_lo", "i_hi", "depths",
                                 "pieces"])
