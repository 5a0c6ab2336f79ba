"""The one place where numba options are set.

``kernel`` compiles a function for the CPU with an on-disk cache, so a second run of riprap does not
pay the compile time again. ``parallel_kernel`` adds ``parallel=True`` and is used only where a bench
in ``bench/`` shows that threads pay. ``fastmath`` stays off: contact forces are compared with a
reference evaluation to 1e-9 and must not depend on reassociation.

Set ``NUMBA_DISABLE_JIT=1`` to run every kernel as plain Python (slow) for tracebacks and debugging.
"""
import os

# OpenMP worker threads that spin while waiting steal the only other core of a small machine from
# whatever else runs (or from the main thread): measured 70x slowdowns on a loaded 2-core box.
# Passive waiting costs a few microseconds per parallel region instead. Must be set before numba
# starts its thread pool; a user's own setting wins.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import numba  # noqa: E402

kernel = numba.njit(cache=True, fastmath=False, error_model="numpy")
parallel_kernel = numba.njit(cache=True, fastmath=False, parallel=True, error_model="numpy")
prange = numba.prange
