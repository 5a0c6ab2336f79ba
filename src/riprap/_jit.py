"""The one place where numba options are set.

``kernel`` compiles a function for the CPU with an on-disk cache, so a second run of riprap does not
pay the compile time again. ``parallel_kernel`` adds ``parallel=True`` and is used only where a bench
in ``bench/`` shows that threads pay. ``fastmath`` stays off: contact forces are compared with a
reference evaluation to 1e-9 and must not depend on reassociation.

The cache is stamped with one hash of all kernel sources, not numba's per-file time stamps, so
that a kernel compiled against an older version of another kernel file is never loaded.

Set ``NUMBA_DISABLE_JIT=1`` to run every kernel as plain Python (slow) for tracebacks and debugging.
"""
import hashlib
import os

# OpenMP worker threads that spin while waiting steal the only other core of a small machine from
# whatever else runs (or from the main thread): measured 70x slowdowns on a loaded 2-core box with
# GNU OpenMP's default spin (300,000 polls). Sleeping at once costs a wake-up per parallel region
# instead: about 70 microseconds here, a third of a fracturing unit's step, which runs three
# regions back to back. A short spin (10,000 polls, tens of microseconds) catches the next region
# of the same step and gives the core back soon after the step ends (bench/fracture.py: joint
# kernel 0.27 -> 0.20 ms). Must be set before numba starts its thread pool; a user's own setting
# wins.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
os.environ.setdefault("GOMP_SPINCOUNT", "10000")

import numba  # noqa: E402


def kernel_source_hash(package_dir: str, extra_files=(), salt: str = "") -> str:
    """SHA-256 of every ``.py`` file in a ``kernels`` folder under ``package_dir``, of
    ``extra_files`` and of ``salt``, in a fixed order: the stamp of numba's on-disk cache.

    It reads riprap's own source files, the one file reading outside ``riprap/io/`` (an exemption
    named in ``tests/architecture/test_layers.py``): ``_jit`` stands on the ground floor, under
    ``io``, and every kernel module imports it."""
    digest = hashlib.sha256(salt.encode())
    paths = []
    for root, folders, files in os.walk(package_dir):
        folders.sort()
        if os.path.basename(root) == "kernels":
            paths += [os.path.join(root, name) for name in sorted(files) if name.endswith(".py")]
    for path in sorted(paths) + [os.path.abspath(p) for p in extra_files]:
        with open(path, "rb") as stream:
            digest.update(os.path.relpath(path, package_dir).encode() + b"\0" + stream.read())
    return digest.hexdigest()


def _use_source_stamped_cache() -> None:
    """Put riprap's own cache locators (numba's three file-backed ones, stamped with one hash of
    all kernel sources) in front of numba's; functions outside riprap keep numba's behaviour. numba's locator list is not
    public API: where it has moved, numba's own per-file stamps stay in use."""
    try:
        from numba.core import caching

        bases = (caching.UserProvidedCacheLocator, caching.InTreeCacheLocator,
                 caching.UserWideCacheLocator)
        existing = list(caching.CacheImpl._locator_classes)
    except AttributeError:
        return
    package_dir = os.path.dirname(os.path.abspath(__file__))
    # numba judges a cached function fresh by its own file's time stamp and size only, but a
    # cached kernel carries compiled copies of the kernels it calls from other files: after one
    # of those changed, a stale copy would run with today's data layout. One hash of all kernel
    # sources (and of this file and numba's version) as every riprap entry's stamp makes any
    # change recompile them all.
    stamp = kernel_source_hash(package_dir, extra_files=[__file__], salt=numba.__version__)

    def stamped(base):
        class RiprapLocator(base):
            @classmethod
            def from_function(cls, py_func, py_file):
                if not os.path.abspath(py_file).startswith(package_dir + os.sep):
                    return None
                return super().from_function(py_func, py_file)

            def get_source_stamp(self):
                return stamp

        RiprapLocator.__name__ = f"Riprap{base.__name__}"
        return RiprapLocator

    if not any(getattr(cls, "__name__", "").startswith("Riprap") for cls in existing):
        caching.CacheImpl._locator_classes = [stamped(base) for base in bases] + existing


_use_source_stamped_cache()

kernel = numba.njit(cache=True, fastmath=False, error_model="numpy")


def _refcount_free_options() -> dict:
    """numba's ``_nrt=False`` where this numba has it (a private option, so looked for first).
    A compiled function takes a reference to each array argument on entry and drops it on every
    exit; numba's pass that removes such pairs gives up on functions with loops and several
    exits, so a small geometric helper called per contact piece paid two atomic operations per
    array per call (a quarter of the rigid contact's time, contended between the threads)."""
    from numba.core.cpu import CPUTargetOptions

    return {"_nrt": False} if hasattr(CPUTargetOptions, "_nrt") else {}


# Leaf helpers called per contact piece or pair: they read and write the arrays they are given
# and allocate none, so they need no reference counts. (Where numba lacks the option they are
# ordinary kernels: slower, the same results.)
leaf_kernel = numba.njit(cache=True, fastmath=False, error_model="numpy",
                         **_refcount_free_options())
parallel_kernel = numba.njit(cache=True, fastmath=False, parallel=True, error_model="numpy")
# Small per-element or per-node bodies called from both a parallel and a serial loop: inlined
# into each caller at numba's IR level, since an LLVM call per element measured 1.6x slower
# (finite-strain tets). Compiled only as part of their callers, which are cached.
inline_kernel = numba.njit(fastmath=False, error_model="numpy", inline="always")
prange = numba.prange
