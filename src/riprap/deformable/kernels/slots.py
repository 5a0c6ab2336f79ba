"""Sums over node-to-slot lists: the forces that elements or joints put on a node, kept per
element or joint (so that their loops run in parallel without atomics) and summed per node."""
from riprap._jit import inline_kernel


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
def table_slot_sum(node, flat, table, overflow_offsets, overflow_slots):
    """``slot_sum`` for lists kept as a table three wide: the sum of ``flat[slot]`` over
    ``table[node]`` (padded with the index of a row of zeros) and over the node's rest,
    ``overflow_slots[overflow_offsets[node]:overflow_offsets[node + 1]]``. (A loop whose length
    changes from node to node costs a mispredicted branch per node: the joints' slots of an
    exploded mesh are 2 or 3 a node, at random. Written out, and without a branch on the
    table's width: either made the node update 4 % slower with joints, the one-thread update
    without them twice as slow.)"""
    s0, s1, s2 = table[node, 0], table[node, 1], table[node, 2]
    fx = flat[s0, 0] + flat[s1, 0] + flat[s2, 0]
    fy = flat[s0, 1] + flat[s1, 1] + flat[s2, 1]
    fz = flat[s0, 2] + flat[s1, 2] + flat[s2, 2]
    # (slot_sum's loop written again: calling it here measured 5 % slower)
    for s in range(overflow_offsets[node], overflow_offsets[node + 1]):
        slot = overflow_slots[s]
        fx += flat[slot, 0]
        fy += flat[slot, 1]
        fz += flat[slot, 2]
    return fx, fy, fz
