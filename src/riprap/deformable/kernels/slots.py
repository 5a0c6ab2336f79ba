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
