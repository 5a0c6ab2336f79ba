"""A restart does not depend on the history of numba's on-disk cache.

Reported: ``riprap run CASE --restart checkpoint.npz`` ended in a segmentation fault when the cache
had been written by an earlier, different run (``riprap demo``), while with a fresh cache it was
bit-exact; a restart calls the cached ``stepper.advance`` first. Here, as a user would: the
checkpoint and the unbroken run are made in this process, then a separate process fills an empty
cache folder with the demo's kernels, and a third, fresh process restarts from that cache. It must
finish (exit 0) and end bit for bit where the unbroken run ends.

The cache is also stamped with one hash of all kernel sources (``riprap._jit``), so a kernel
compiled against another version of a kernel it calls is never loaded; the last test checks that
riprap's kernels use that stamp.
"""
import os
import subprocess
import sys

import numpy as np
import pytest

from riprap.case.build import build_simulation
from riprap.case.load import load_case
from riprap.io.checkpoint import load_checkpoint

CASE = """format_version = 1
[simulation]
end_time = {end_time}
output_interval = 0.05
[[materials]]
name = "rock"
density = 2650.0
friction_coefficient = 0.6
restitution = 0.4
contact_penalty = 1.0e7
[[shapes]]
name = "ell"
type = "l_shape"
length = 0.2
width = 0.08
thickness = 0.05
[[shapes]]
name = "rock"
type = "random_rock"
size = 0.1
elongation = 1.5
seed = 11
[[bodies]]
shape = "ell"
material = "rock"
position = [-0.2, 0.0, 0.15]
orientation = [0.7, 0.7, 0.0, 0.1]
[[bodies]]
shape = "rock"
material = "rock"
position = [0.15, 0.0, 0.12]
velocity = [-0.5, 0.0, 0.0]
[[walls]]
type = "box"
material = "rock"
min = [-0.5, -0.5, 0.0]
max = [0.5, 0.5, 1.0]
"""


def _run(path, out, restart=None):
    sim = build_simulation(load_case(path), output_directory=out, progress=False)
    sim.picture = False
    sim.run(restart_from=restart)
    return load_checkpoint(out / "checkpoint.npz")[0]


@pytest.mark.slow
def test_restart_in_a_fresh_process_after_another_run_filled_the_cache(tmp_path):
    half, full = tmp_path / "half.toml", tmp_path / "full.toml"
    half.write_text(CASE.format(end_time=0.15))
    full.write_text(CASE.format(end_time=0.3))
    _run(half, tmp_path / "restarted")
    unbroken = _run(full, tmp_path / "unbroken")

    environment = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba-cache"),
                   "RIPRAP_SMOKE": ""}
    demo = subprocess.run([sys.executable, "-m", "riprap", "demo", "--out", str(tmp_path / "demo"),
                           "--quiet"], env={**environment, "RIPRAP_SMOKE": "1"},
                          capture_output=True, text=True, timeout=900)
    assert demo.returncode == 0, demo.stderr
    assert any((tmp_path / "numba-cache").rglob("*.nbi")), "the demo filled the cache"
    restart = subprocess.run([sys.executable, "-m", "riprap", "run", str(full), "--out",
                              str(tmp_path / "restarted"), "--restart",
                              str(tmp_path / "restarted" / "checkpoint.npz"), "--quiet"],
                             env=environment, capture_output=True, text=True, timeout=900)
    assert restart.returncode == 0, restart.stderr
    restarted = load_checkpoint(tmp_path / "restarted" / "checkpoint.npz")[0]
    for name in ("positions", "quaternions", "velocities", "angular_momenta"):
        assert np.array_equal(restarted[name], unbroken[name]), name


def test_riprap_kernels_are_cached_under_one_stamp_of_all_kernel_sources(tmp_path):
    from riprap._jit import kernel
    from riprap._jit import kernel_source_hash
    from riprap.solid.kernels import integrate

    locator = integrate.kick._cache._impl._locator
    assert type(locator).__name__.startswith("Riprap")
    stamp = locator.get_source_stamp()
    assert stamp == type(locator)(integrate.kick.py_func, integrate.__file__).get_source_stamp()

    # The stamp follows every kernel file: change one, and the hash changes.
    package = tmp_path / "package" / "kernels"
    package.mkdir(parents=True)
    (package / "a.py").write_text("x = 1\n")
    before = kernel_source_hash(str(tmp_path / "package"))
    (package / "a.py").write_text("x = 2\n")
    assert kernel_source_hash(str(tmp_path / "package")) != before
    assert callable(kernel)
