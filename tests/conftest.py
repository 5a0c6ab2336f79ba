"""Settings for the whole suite, made before anything imports numpy.

OpenBLAS picks its kernels by CPU (SkylakeX on Intel AVX-512, Zen or Haswell on others), and
the kernels round differently: a shape's principal inertia differs in its last bit, and a smoke
run's summary (tests/regression) drifts from the recorded one after a few hundred steps. Pinned to
the Haswell kernels (AVX2, on every x86-64 machine of the last ten years), the suite gives the
same numbers on every such machine; the processes that tests start inherit the setting. A
setting given from outside is kept."""
import os
import platform
import sys

if platform.machine().lower() in ("x86_64", "amd64") and "OPENBLAS_CORETYPE" not in os.environ:
    if "numpy" in sys.modules:
        raise RuntimeError("tests/conftest.py: numpy was imported before OpenBLAS's kernels "
                           "could be pinned; set OPENBLAS_CORETYPE=Haswell outside")
    os.environ["OPENBLAS_CORETYPE"] = "Haswell"
