"""The one place where numba options are set.

``kernel`` compiles a function for the CPU with an on-disk cache, so a second run of riprap does not
pay the compile time again. ``parallel_kernel`` adds ``parallel=True`` and is used only where a bench
in ``bench/`` shows that threads pay. ``fastmath`` stays off: contact forces are compared with a
reference evaluation to 1e-9 and must not depend on reassociation.

Set ``NUMBA_DISABLE_JIT=1`` to run every kernel as plain Python (slow) for tracebacks and debugging.
"""
import numba

kernel = numba.njit(cache=True, fastmath=False, error_model="numpy")
parallel_kernel = numba.njit(cache=True, fastmath=False, parallel=True, error_model="numpy")
prange = numba.prange
