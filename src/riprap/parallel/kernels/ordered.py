"""Sums in one fixed order, so that a run over several processes adds exactly what one adds."""
from riprap._jit import kernel


@kernel
def ordered_total(values):
    """values[0] + values[1] + ... added one by one from 0.0 (the order of the serial solvers'
    per-slab reductions, ``riprap/fluid/kernels/multigrid.py``)."""
    total = 0.0
    for i in range(values.shape[0]):
        total += values[i]
    return total


@kernel
def ordered_largest(values):
    """The largest of values (0.0 if none is larger)."""
    largest = 0.0
    for i in range(values.shape[0]):
        largest = max(largest, values[i])
    return largest
