"""The named bundles of arrays the deformable kernels take (see ``solid/kernels/bundles.py`` for
why bundles, and why the kernels read their fields once at their top)."""
from collections import namedtuple

#: The nodes of every body (the rigid surfaces' proxy nodes after the deformable ones): positions
#: and velocities (n, 3), lumped masses (kg), the loads held on them and the contact forces of the
#: step (n, 3; N), the held components (n, 3; bool) and their prescribed velocities, and each
#: node's (element, local node) slots (``node_slots[node_offsets[n]:node_offsets[n + 1]]``).
NodeState = namedtuple("NodeState", ["positions", "velocities", "masses", "external_forces",
                                     "contact_forces", "constrained", "prescribed_velocities",
                                     "node_offsets", "node_slots"])

#: The elements: node indices (n, corners), the 4-node tets' shape function gradients ((0, 4, 3)
#: where the elements are not 4-node tets), the gradients and weights at every integration point,
#: the materials' table and each element's row in it, the element forces (written) and the
#: Jacobians J of the last step (written).
ElementState = namedtuple("ElementState", ["elements", "tet4_gradients", "gradients", "weights",
                                           "materials", "element_material", "element_forces",
                                           "jacobians"])

#: The contacts of a system of bodies: the triangles and tets walls act on, all contact triangles
#: and tets, the wall depth per triangle, the candidate (triangle, tet) pairs, the penalty (Pa), the
#: walls (n, 7: point, outward normal, friction coefficient), the positions when the pairs were
#: listed, the skin (m), the totals (n_walls + 1: the normal force of each wall and of the body
#: pairs at the last step; written), the friction coefficient per triangle and per tet, the
#: tangential over normal contact stiffness, the tangential stiffness per tet and m^2 of contact,
#: the tangential springs of the pairs, of the wall triangles and of the wall tets (written), and
#: the normal damping ratio per triangle and per tet.
ContactState = namedtuple("ContactState", [
    "wall_triangles", "wall_tets", "triangles", "contact_tets", "wall_depths", "pairs", "penalty",
    "walls", "listed_positions", "skin", "totals", "triangle_friction", "tet_friction",
    "tangential_ratio", "tet_stiffness", "pair_springs", "wall_triangle_springs",
    "wall_tet_springs", "triangle_damping", "tet_damping"])

#: The contact law of the surfaces: the penalty (Pa), the tangential over normal stiffness of the
#: walls' springs, the friction coefficient and normal damping ratio per triangle and per tet, and
#: the tangential stiffness per tet and m^2 of contact.
SurfaceLaws = namedtuple("SurfaceLaws", ["penalty", "tangential_ratio", "triangle_friction",
                                         "tet_friction", "triangle_damping", "tet_damping",
                                         "tet_stiffness"])

#: The joints between tets of fracturing bodies (``joints.py``): their six nodes, sizes, the joint
#: materials' table, material per joint, damage, broken, the buffer of their forces (a row per
#: joint vertex, and a last row kept zero: ``joints.joint_forces``), each element slot's rows in it
#: (elements.size, 3: one per face at the slot's corner), released (broken joints whose faces slid
#: apart: no force any more), their work done on the nodes so far (1,), by the trapezoidal rule,
#: and the friction anchors of their points (n, 3, 2). No joints: none, and a buffer of no rows.
JointData = namedtuple("JointData", ["nodes", "sizes", "properties", "material", "damage",
                                     "broken", "buffer", "slot_rows", "released", "work",
                                     "anchors"])
