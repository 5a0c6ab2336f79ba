"""Sums over node-to-slot lists: the forces that elements or joints put on a node, kept per
element or joint (so that their loops run in parallel without atomics) and summed per node."""
import numpy as np

from riprap._jit import inline_kernel

#: The joint force buffer keeps twelve rows per tet: one per vertex of each face, face by face
#: (row 3 f + position of the corner in face f, faces as ``joints._TET_FACES``), so that a joint
#: writes its side's three rows together. The rows of the three faces at each corner:
CORNER_FACE_ROWS = np.array([[3, 6, 9], [0, 7, 11], [1, 5, 10], [2, 4, 8]], dtype=np.int64)


@inline_kernel
def slot_sum(node, flat, offsets, slots):
    """The sum of ``flat[slot]`` (slot, 3) over the slots of ``node``:
    ``slots[offsets[node]:offsets[node + 1]]``. All three components per slot at once: the slots
    are scattered, a slot's components adjacent."""
    fx = fy = fz = 0.0
    for s in range(offsets[node], offsets[node + 1]):
        slot = slots[s]
        fx += flat[slot, 0]
        fy += flat[slot, 1]
        fz += flat[slot, 2]
    return fx, fy, fz


@inline_kernel
def corner_joint_force(slot, joint_rows):
    """The joints' force at a tet's corner (``slot`` = 4 tet + corner): the sum of the rows of
    the three faces there (``CORNER_FACE_ROWS``) in the tet's twelve rows of ``joint_rows``."""
    base = 12 * (slot >> 2)
    corner = slot & 3
    r0 = base + CORNER_FACE_ROWS[corner, 0]
    r1 = base + CORNER_FACE_ROWS[corner, 1]
    r2 = base + CORNER_FACE_ROWS[corner, 2]
    return (joint_rows[r0, 0] + joint_rows[r1, 0] + joint_rows[r2, 0],
            joint_rows[r0, 1] + joint_rows[r1, 1] + joint_rows[r2, 1],
            joint_rows[r0, 2] + joint_rows[r1, 2] + joint_rows[r2, 2])


@inline_kernel
def joint_slot_sum(node, flat, joint_rows, offsets, slots):
    """``slot_sum`` of ``flat`` and, over the same (tet, corner) slots, of the joints' forces:
    the rows of the three faces at the corner (``CORNER_FACE_ROWS``) in the tet's twelve rows of
    ``joint_rows`` (``kernels/joints.joint_forces``; 4-node tets). Returns both sums (six
    numbers). (The nodes of a mesh split by joints everywhere have one slot each, numbered as
    their tets: their rows are read in the order of the nodes, a tet's block of twelve by its
    four corners one after the other.)"""
    fx = fy = fz = 0.0
    jx = jy = jz = 0.0
    for s in range(offsets[node], offsets[node + 1]):
        slot = slots[s]
        fx += flat[slot, 0]
        fy += flat[slot, 1]
        fz += flat[slot, 2]
        cx, cy, cz = corner_joint_force(slot, joint_rows)
        jx += cx
        jy += cy
        jz += cz
    return fx, fy, fz, jx, jy, jz
