"""Sums over node-to-slot lists: the forces that elements or joints put on a node, kept per
element or joint (so that their loops run in parallel without atomics) and summed per node."""
import numpy as np

from riprap._jit import inline_kernel, kernel


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
def corner_joint_force(slot, slot_rows, buffer):
    """The joints' force at a tet's corner (``slot`` = 4 tet + corner): the sum of the rows
    ``slot_rows[slot]`` of ``buffer``, one per face at the corner (each the joint's force on its
    vertex there; a face without a joint names the buffer's last row, which stays zero)."""
    r0 = slot_rows[slot, 0]
    r1 = slot_rows[slot, 1]
    r2 = slot_rows[slot, 2]
    return (buffer[r0, 0] + buffer[r1, 0] + buffer[r2, 0],
            buffer[r0, 1] + buffer[r1, 1] + buffer[r2, 1],
            buffer[r0, 2] + buffer[r1, 2] + buffer[r2, 2])


@inline_kernel
def joint_slot_sum(node, flat, buffer, slot_rows, single_slots, offsets, slots):
    """``slot_sum`` of ``flat`` and, over the same (tet, corner) slots, of the joints' forces:
    the rows ``slot_rows[slot]`` of ``buffer`` (``kernels/joints.joint_forces``; 4-node tets).
    Returns both sums (six numbers). A node with only one slot (``single_slots``) reads it
    straight away."""
    single = single_slots[node]
    if single >= 0:
        jx, jy, jz = corner_joint_force(single, slot_rows, buffer)
        return flat[single, 0], flat[single, 1], flat[single, 2], jx, jy, jz
    fx = fy = fz = 0.0
    jx = jy = jz = 0.0
    for s in range(offsets[node], offsets[node + 1]):
        slot = slots[s]
        fx += flat[slot, 0]
        fy += flat[slot, 1]
        fz += flat[slot, 2]
        cx, cy, cz = corner_joint_force(slot, slot_rows, buffer)
        jx += cx
        jy += cy
        jz += cz
    return fx, fy, fz, jx, jy, jz


@kernel
def single_slots_of(offsets, slots):
    """(n,) int32: the one slot of each node that has only one (every node of a mesh split by
    joints everywhere: each tet has its own four), else -1."""
    single = np.full(offsets.shape[0] - 1, -1, dtype=np.int32)
    for node in range(single.shape[0]):
        if offsets[node + 1] - offsets[node] == 1:
            single[node] = slots[offsets[node]]
    return single


@inline_kernel
def node_slot_sum(node, flat, single_slots, offsets, slots):
    """``slot_sum``, read straight from the node's one slot where it has only one
    (``single_slots``): no list to walk (the same sum, bit for bit)."""
    slot = single_slots[node]
    if slot >= 0:
        return flat[slot, 0], flat[slot, 1], flat[slot, 2]
    return slot_sum(node, flat, offsets, slots)
