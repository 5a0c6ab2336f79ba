"""Speed of the rigid FEMDEM engine in a dense heap of random convex rocks.

N random convex rocks (nominal diameter 0.3 m, 300-600 tetrahedra each, ten distinct shapes that
the bodies cycle through, random uniform orientations) are poured into a walled box whose footprint
grows with N so that the heap is about five rock diameters deep for every N. Once the heap is
dense, a fixed window of steps is timed on 1 and 2 threads (and on all cores where there are more),
each time from the same saved state. Printed per N and thread count:

- body-steps per second: N x steps / wall time;
- contact evaluations per second: candidate pairs evaluated per step (body-body and body-wall
  pairs whose boxes overlap, each one a full potential-contact evaluation) x steps / wall time;
- touching contacts per second: the same with the pairs that actually touch;
- contacts per body in the timed window (coordination: 2 x body-body + body-wall contacts, over N).

Then the per-step cost per body of the largest N over that of the smallest (1.0 means the cost
per step grows exactly linearly with N), the numba compile time (measured in a subprocess with an
empty numba cache), the wall time of the whole bench, and last the line
``METRIC body_steps_per_s <value> 1/s`` for the largest N (1000 by default) on all cores.

Pouring a heap takes thousands of steps (about ten minutes for N = 200 on this machine), so each
heap is built once, with stronger gravity, damping and a larger time step to compact it quickly,
then relaxed under normal gravity and saved to ``bench/.cache/heap_n<N>_<version>.npz``; later runs
load it. Heaps of more than LARGEST_DIRECT_POUR bodies (N = 1000) are assembled from 2 x 2 copies of
a poured heap of N / 4 bodies in a box half as wide, then relaxed (``--direct-pour`` pours them
instead). The timed window always uses the default time step and ``local_damping`` 0.3. Run::

    python bench/rigid_deposition.py                      # N = 200 and 1000
    python bench/rigid_deposition.py --bodies 200 --steps 200 --repeats 1
    python bench/rigid_deposition.py --rebuild-heap       # pour again

Timed windows take the best of ``--repeats`` runs (other work on the machine only slows a run
down); the load average is printed before each window so that a contended figure can be spotted.
"""
from __future__ import annotations

import argparse
import hashlib
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numba
import numpy as np
from scipy.spatial.transform import Rotation

from riprap.errors import InstabilityError, RiprapError
from riprap.geometry import shapes
from riprap.io.checkpoint import load_checkpoint, save_checkpoint
from riprap.solid import walls
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape
from riprap.solid.solver import SolidSolver

# Bump when anything that changes the poured heap changes (shapes, box, pour schedule, contact law),
# so that a stale cache file is not reused. The rock meshes and the layout of the saved state are
# checked automatically.
HEAP_VERSION = "v3"
CACHE_FOLDER = Path(__file__).resolve().parent / ".cache"

GRAVITY = 9.81                  # m/s^2
ROCK_SIZE = 0.3                 # nominal diameter, m
ROCK_DENSITY = 2650.0           # kg/m^3
N_ROCK_SHAPES = 10
# The issue asks for 300-600 tetrahedra per rock; candidate rocks outside that range are skipped.
MIN_TETS, MAX_TETS = 300, 600
CONTACT_PENALTY = 1.0e7         # Pa
FRICTION_COEFFICIENT = 0.6
RESTITUTION = 0.3
LOCAL_DAMPING = 0.3             # damping of the timed window

# Box footprint: the heap should end about HEAP_DEPTH_IN_ROCKS rock diameters deep at an assumed
# solid fraction of a loose rock heap (riprap layers are typically 0.5-0.6 solid).
HEAP_DEPTH_IN_ROCKS = 5.0
ASSUMED_SOLID_FRACTION = 0.55
# Gap between bounding spheres (horizontally) and bounding boxes (vertically) in the start lattice,
# as a fraction of the rock size: no two rocks touch at the start.
LATTICE_GAP = 0.03

# Pour: compaction under COMPACTION_GRAVITY_FACTOR x g with stronger damping and a larger time step
# (POUR_TIME_STEP_SAFETY instead of the default 0.2 of the estimated critical step, which is
# conservative for these contacts; a pour that goes unstable is retried with a smaller step; the
# step count of the slowest part of the bench drops fourfold) until the heap is still and
# dense, then relaxation under normal gravity until it is still again (dropping from 5 g to 1 g
# releases the stored contact energy and the heap rebounds a little).
COMPACTION_GRAVITY_FACTOR = 5.0
POUR_DAMPING = 0.4
POUR_TIME_STEP_SAFETY = 0.8
# A pour that goes unstable is started again with this fraction of its time step.
POUR_RETRY_STEP_FACTOR = 0.5
SMALLEST_POUR_SAFETY = 0.05
POUR_CHUNK_STEPS = 250
MIN_COMPACTION_STEPS = 2000
MAX_COMPACTION_STEPS = 30000
MIN_RELAX_STEPS = 500
MAX_RELAX_STEPS = 5000
# A phase ends when the kinetic-energy rms speed sqrt(2 KE / M) drops below this (m/s) and every
# body has on average at least MIN_CONTACTS_PER_BODY touching contacts.
STILL_RMS_SPEED = 0.05
MIN_CONTACTS_PER_BODY = 2.0
# Heaps of more than this many bodies are not poured but assembled from 2 x 2 copies of a poured
# heap of a quarter of the bodies (whose box is exactly half as wide), then relaxed: pouring 1000
# rocks directly costs about four times as long as the rest of the bench. --direct-pour turns
# this off.
LARGEST_DIRECT_POUR = 300

# The timed window is run in chunks of this many steps so that candidate and contact counts can be
# averaged over the window (the per-call overhead is a few microseconds against milliseconds).
TIMING_CHUNK_STEPS = 50


# ---------------------------------------------------------------------------------------- set-up
def build_rock_shapes(count: int = N_ROCK_SHAPES) -> list[RigidShape]:
    """``count`` distinct random rocks of nominal diameter ROCK_SIZE with 300-600 tetrahedra each.

    Elongation 1.0-1.4 and flatness 0.75-1.0 are spread over the set; a candidate meshed outside the
    tetrahedron range is replaced by the next seed.
    """
    rocks: list[RigidShape] = []
    seed = 0
    while len(rocks) < count:
        k = len(rocks)
        elongation = 1.0 + 0.4 * ((0.37 * k) % 1.0)
        flatness = 1.0 - 0.25 * ((0.61 * k) % 1.0)
        mesh = shapes.random_rock(size=ROCK_SIZE, elongation=elongation, flatness=flatness,
                                  seed=1000 + seed)
        seed += 1
        if MIN_TETS <= len(mesh.tets) <= MAX_TETS:
            rocks.append(RigidShape.from_mesh(mesh))
        if seed > 20 * count:
            raise RiprapError("could not mesh enough random rocks with 300-600 tetrahedra; "
                              "check riprap.geometry.shapes.random_rock's default mesh size")
    return rocks


def shape_fingerprint(rocks: list[RigidShape]) -> str:
    """Hash of the rock meshes, stored with the heap so a changed mesher invalidates the cache."""
    digest = hashlib.sha1()
    for rock in rocks:
        digest.update(np.round(rock.mesh.nodes, 9).tobytes())
        digest.update(np.asarray(rock.mesh.tets, dtype=np.int64).tobytes())
    return digest.hexdigest()[:16]


def box_side(n_bodies: int, rocks: list[RigidShape]) -> float:
    """Side of the square box footprint (m) for a heap HEAP_DEPTH_IN_ROCKS rocks deep."""
    mean_volume = float(np.mean([r.volume for r in rocks]))
    area = n_bodies * mean_volume / (ASSUMED_SOLID_FRACTION * HEAP_DEPTH_IN_ROCKS * ROCK_SIZE)
    return float(np.sqrt(area))


@dataclass
class Scene:
    solver: SolidSolver
    n_bodies: int
    side: float
    lattice_top: float


def build_scene(n_bodies: int, rocks: list[RigidShape], *, gravity_factor: float,
                local_damping: float, seed: int = 7) -> Scene:
    """Rocks on a jittered lattice in an open box; none touches another rock or a wall.

    Columns sit on a square grid whose spacing exceeds the largest bounding diameter, each body
    jittered inside its cell by what its own bounding sphere leaves free; within a column the bodies
    are stacked by their rotated bounding boxes, which is much denser than bounding-sphere spacing.
    """
    solver = SolidSolver(gravity=(0.0, 0.0, -GRAVITY * gravity_factor), local_damping=local_damping)
    keys = [solver.add_shape(rock) for rock in rocks]
    material = solver.add_material(Material(
        name="rock", density=ROCK_DENSITY, friction_coefficient=FRICTION_COEFFICIENT,
        restitution=RESTITUTION, contact_penalty=CONTACT_PENALTY))
    gap = LATTICE_GAP * ROCK_SIZE
    radii = np.array([r.bounding_radius for r in rocks])
    spacing = 2.0 * radii.max() + gap
    side = max(box_side(n_bodies, rocks), spacing)
    per_row = max(1, int(side // spacing))
    margin = 0.5 * (side - per_row * spacing)
    n_columns = per_row * per_row
    rng = np.random.default_rng(seed)
    rotations = Rotation.random(n_bodies, random_state=seed)
    column_top = np.full(n_columns, gap)
    highest = 0.0
    for b in range(n_bodies):
        shape = b % len(rocks)
        column = b % n_columns
        i, j = column % per_row, column // per_row
        free = max(0.0, 0.5 * spacing - radii[shape] - gap)
        x = margin + (i + 0.5) * spacing + rng.uniform(-free, free)
        y = margin + (j + 0.5) * spacing + rng.uniform(-free, free)
        heights = (rocks[shape].mesh.nodes @ rotations[b].as_matrix().T)[:, 2]
        z = column_top[column] - heights.min()
        column_top[column] = z + heights.max() + gap
        highest = max(highest, column_top[column])
        qx, qy, qz, qw = rotations[b].as_quat()
        solver.add_body(shape=keys[shape], material=material, position=(x, y, z),
                        orientation=(qw, qx, qy, qz), frame="principal")
    solver.add_walls(walls.box(min=(0.0, 0.0, 0.0), max=(side, side, 50.0), material="rock"))
    return Scene(solver=solver, n_bodies=n_bodies, side=side, lattice_top=highest)


# ---------------------------------------------------------------------------------- measurements
def contact_counts(solver: SolidSolver) -> tuple[int, int]:
    """(body-body, body-wall) touching contacts of the last force evaluation."""
    body_j = solver.contacts.body_j
    walls_touched = int(np.count_nonzero(body_j < 0))
    return len(body_j) - walls_touched, walls_touched


def contacts_per_body(solver: SolidSolver) -> float:
    """Mean touching contacts per body: each body-body contact counts for both bodies."""
    between, with_walls = contact_counts(solver)
    return (2.0 * between + with_walls) / solver.n_bodies


def rms_speed(solver: SolidSolver) -> float:
    """sqrt(2 KE / total mass), m/s: translation and rotation in one speed."""
    return float(np.sqrt(2.0 * solver.kinetic_energy() / solver.masses.sum()))


def heap_top(solver: SolidSolver, fraction: float = 0.95) -> float:
    """Height (m) below which ``fraction`` of the body centres lie."""
    return float(np.quantile(solver.positions[:, 2], fraction))


def _progress(phase, solver, start, steps):
    print(f"    {phase:<10} step {steps:6d}  wall {time.perf_counter() - start:7.1f} s  "
          f"rms speed {rms_speed(solver):8.4f} m/s  contacts/body {contacts_per_body(solver):5.2f}  "
          f"95% of centres below z = {heap_top(solver):5.2f} m", flush=True)


def _run_until_still(solver, *, phase, start, min_steps, max_steps, wall_limit) -> tuple[int, str]:
    """Advance in chunks until the heap is still and dense, or a cap is hit. (steps, reason)."""
    steps = 0
    reason = "step cap"
    while steps < max_steps:
        solver.advance(POUR_CHUNK_STEPS)
        steps += POUR_CHUNK_STEPS
        if steps % (4 * POUR_CHUNK_STEPS) == 0:
            _progress(phase, solver, start, steps)
        if (steps >= min_steps and rms_speed(solver) < STILL_RMS_SPEED
                and contacts_per_body(solver) >= MIN_CONTACTS_PER_BODY):
            reason = "still and dense"
            break
        if time.perf_counter() - start > wall_limit:
            reason = "wall-time limit"
            break
    _progress(phase, solver, start, steps)
    return steps, reason


def relax(solver: SolidSolver, *, start: float, wall_limit: float) -> dict:
    """Normal gravity with pour damping until the heap is still again."""
    solver.gravity = np.array([0.0, 0.0, -GRAVITY])
    solver.local_damping = POUR_DAMPING
    steps, reason = _run_until_still(solver, phase="relax", start=start, min_steps=MIN_RELAX_STEPS,
                                     max_steps=MAX_RELAX_STEPS, wall_limit=wall_limit)
    return {"relax_steps": steps, "relax_end": reason}


def pour(scene: Scene, *, wall_limit: float, time_step_safety: float = POUR_TIME_STEP_SAFETY) -> dict:
    """Compact the heap under strong gravity, then relax it under normal gravity.

    Each phase stops early at the wall-time limit; the heap is then reported as not settled rather
    than silently used as if it were.
    """
    solver = scene.solver
    start = time.perf_counter()
    solver.time_step = solver.stable_time_step(time_step_safety)
    solver.finalize()
    if len(solver.contacts) > 0:
        raise RiprapError(f"{len(solver.contacts)} contacts in the start lattice of N = "
                          f"{scene.n_bodies}: raise LATTICE_GAP")
    print(f"  pouring N = {scene.n_bodies}: box {scene.side:.2f} m x {scene.side:.2f} m, lattice "
          f"top {scene.lattice_top:.2f} m, time step {solver.time_step:.3e} s, compaction at "
          f"{COMPACTION_GRAVITY_FACTOR:g} g, local damping {POUR_DAMPING:g}", flush=True)
    steps, reason = _run_until_still(solver, phase="compaction", start=start,
                                     min_steps=MIN_COMPACTION_STEPS,
                                     max_steps=MAX_COMPACTION_STEPS, wall_limit=wall_limit)
    record = {"compaction_steps": steps, "compaction_end": reason}
    record.update(relax(solver, start=start, wall_limit=wall_limit))
    record["pour_wall_s"] = time.perf_counter() - start
    record["settled"] = reason == record["relax_end"] == "still and dense"
    return record


def tile_heap(quarter: SolidSolver, side: float) -> dict[str, np.ndarray]:
    """State of 2 x 2 copies of a heap poured in a box of width ``side`` (m).

    Bodies keep their order within each copy, so body k of copy c has the shape of body k of the
    poured heap as long as the poured heap's size is a multiple of N_ROCK_SHAPES. Friction history
    is dropped (the pair numbering changes); the relaxation rebuilds it.
    """
    state = quarter.state_arrays()
    offsets = [(0.0, 0.0), (side, 0.0), (0.0, side), (side, side)]
    tiled = {}
    for name in ("positions", "quaternions", "velocities", "angular_momenta", "forces", "torques"):
        tiled[name] = np.concatenate([state[name]] * 4)
    n = len(state["positions"])
    for c, (dx, dy) in enumerate(offsets):
        tiled["positions"][c * n:(c + 1) * n, 0] += dx
        tiled["positions"][c * n:(c + 1) * n, 1] += dy
    tiled["history_keys"] = np.zeros(0, dtype=np.int64)
    tiled["history_springs"] = np.zeros((0, state["history_springs"].shape[1]))
    tiled["clock"] = state["clock"].copy()
    return tiled


def heap_path(n_bodies: int) -> Path:
    return CACHE_FOLDER / f"heap_n{n_bodies}_{HEAP_VERSION}.npz"


def dense_heap(n_bodies: int, rocks: list[RigidShape], *, rebuild: bool, wall_limit: float,
               direct_pour: bool):
    """The solver at normal gravity and the default time step with the dense heap loaded, and the
    record of how the heap was made (from the cache when it matches)."""
    fingerprint = shape_fingerprint(rocks)
    path = heap_path(n_bodies)
    quarter = n_bodies // 4
    tiled = (not direct_pour and n_bodies > LARGEST_DIRECT_POUR and n_bodies % 4 == 0
             and quarter % len(rocks) == 0)
    scene = build_scene(n_bodies, rocks, gravity_factor=1.0, local_damping=LOCAL_DAMPING)
    default_step = scene.solver.stable_time_step()
    # The width of the friction history changes with the contact law; a state saved by another
    # engine version must not be fed to the kernels.
    history_width = int(scene.solver.state_arrays()["history_springs"].shape[1])
    expected = {"heap_version": HEAP_VERSION, "n_bodies": n_bodies, "shapes": fingerprint,
                "tiled": tiled, "history_width": history_width}
    if path.is_file() and not rebuild:
        arrays, metadata = load_checkpoint(path)
        if all(metadata.get(key) == value for key, value in expected.items()):
            scene.solver.load_state_arrays(arrays)
            scene.solver.time_step = default_step
            print(f"  N = {n_bodies}: heap loaded from {path} ({metadata['how']})")
            return scene, metadata
        print(f"  N = {n_bodies}: {path} is from another bench version or rock set; building again")
    if tiled:
        base, base_record = dense_heap(quarter, rocks, rebuild=rebuild, wall_limit=wall_limit,
                                       direct_pour=True)
        start = time.perf_counter()
        poured = build_scene(n_bodies, rocks, gravity_factor=1.0, local_damping=POUR_DAMPING)
        print(f"  N = {n_bodies}: 2 x 2 copies of the N = {quarter} heap in a {poured.side:.2f} m "
              f"box, relaxing", flush=True)
        poured.solver.load_state_arrays(tile_heap(base.solver, base.side))
        poured.solver.time_step = poured.solver.stable_time_step(POUR_TIME_STEP_SAFETY)
        record = relax(poured.solver, start=start, wall_limit=wall_limit)
        record["pour_wall_s"] = time.perf_counter() - start + base_record["pour_wall_s"]
        record["settled"] = base_record["settled"] and record["relax_end"] == "still and dense"
        record["how"] = (f"2 x 2 copies of a poured N = {quarter} heap, relaxed "
                         f"{record['relax_steps']} steps")
    else:
        safety = POUR_TIME_STEP_SAFETY
        while True:
            poured = build_scene(n_bodies, rocks, gravity_factor=COMPACTION_GRAVITY_FACTOR,
                                 local_damping=POUR_DAMPING)
            try:
                record = pour(poured, wall_limit=wall_limit, time_step_safety=safety)
                break
            except InstabilityError as error:
                if safety < SMALLEST_POUR_SAFETY:
                    raise
                safety *= POUR_RETRY_STEP_FACTOR
                print(f"  pour went unstable ({error}); again with time step safety {safety:g}")
        record["how"] = (f"poured: {record['compaction_steps']} compaction + "
                         f"{record['relax_steps']} relaxation steps")
    settled = "settled" if record["settled"] else "NOT settled"
    record["how"] += f", {record['pour_wall_s']:.0f} s, {settled}"
    metadata = {**expected, **record}
    save_checkpoint(path, arrays=poured.solver.state_arrays(), metadata=metadata)
    print(f"  heap saved to {path}")
    scene.solver.load_state_arrays(poured.solver.state_arrays())
    scene.solver.time_step = default_step
    return scene, metadata


@dataclass
class Window:
    n_bodies: int
    threads: int
    wall: float
    steps: int
    candidates_per_step: float
    touching_per_step: float
    contacts_per_body: float
    load_average: float

    @property
    def body_steps_per_s(self) -> float:
        return self.n_bodies * self.steps / self.wall


def timed_window(scene: Scene, start_state: dict, *, n_steps: int, threads: int) -> Window:
    """Time ``n_steps`` steps from ``start_state`` on ``threads`` threads."""
    solver = scene.solver
    numba.set_num_threads(threads)
    solver.load_state_arrays(start_state)
    load = os.getloadavg()[0]
    candidates = touching = coordination = 0.0
    chunks = 0
    wall = 0.0
    done = 0
    while done < n_steps:
        chunk = min(TIMING_CHUNK_STEPS, n_steps - done)
        tick = time.perf_counter()
        solver.advance(chunk)
        wall += time.perf_counter() - tick
        done += chunk
        candidates += solver._n_candidates
        touching += len(solver.contacts)
        coordination += contacts_per_body(solver)
        chunks += 1
    return Window(n_bodies=scene.n_bodies, threads=threads, wall=wall, steps=n_steps,
                  candidates_per_step=candidates / chunks, touching_per_step=touching / chunks,
                  contacts_per_body=coordination / chunks, load_average=load)


def measure_compile_time() -> float | None:
    """Seconds for the first finalize() + advance(1) in a fresh process with an empty numba cache."""
    with tempfile.TemporaryDirectory(prefix="riprap-numba-cache-") as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        done = subprocess.run([sys.executable, __file__, "--compile-probe"], env=env,
                              capture_output=True, text=True)
    for line in done.stdout.splitlines():
        if line.startswith("COMPILE_SECONDS"):
            return float(line.split()[1])
    print("  compile probe failed:\n" + done.stdout + done.stderr)
    return None


def compile_probe() -> None:
    """Run in the subprocess of measure_compile_time: two rocks resting on a floor."""
    rocks = build_rock_shapes(2)
    scene = build_scene(2, rocks, gravity_factor=1.0, local_damping=LOCAL_DAMPING)
    tick = time.perf_counter()
    scene.solver.finalize()
    scene.solver.advance(1)
    print(f"COMPILE_SECONDS {time.perf_counter() - tick:.3f}")


# -------------------------------------------------------------------------------------- reports
def print_windows(n_bodies: int, windows: list[Window]) -> None:
    print(f"  {'N':>5} {'threads':>7} {'steps':>5} {'wall s':>7} {'body-steps/s':>13} "
          f"{'evaluations/s':>13} {'touching/s':>11} {'cand/step':>9} {'contacts/body':>13} "
          f"{'load':>5}")
    for w in windows:
        print(f"  {n_bodies:5d} {w.threads:7d} {w.steps:5d} {w.wall:7.2f} {w.body_steps_per_s:13.4g} "
              f"{w.candidates_per_step * w.steps / w.wall:13.4g} "
              f"{w.touching_per_step * w.steps / w.wall:11.4g} {w.candidates_per_step:9.0f} "
              f"{w.contacts_per_body:13.2f} {w.load_average:5.2f}")


def best_by_threads(windows: list[Window]) -> dict[int, Window]:
    best: dict[int, Window] = {}
    for w in windows:
        if w.threads not in best or w.wall < best[w.threads].wall:
            best[w.threads] = w
    return best


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--bodies", type=int, nargs="+", default=[200, 1000],
                        help="numbers of rocks (default 200 1000); METRIC uses the largest")
    parser.add_argument("--steps", type=int, default=200, help="steps in each timed window")
    parser.add_argument("--repeats", type=int, default=2, help="timed windows per thread count")
    parser.add_argument("--rebuild-heap", action="store_true", help="pour again, ignoring the cache")
    parser.add_argument("--pour-wall-limit", type=float, default=900.0,
                        help="wall-time limit of each pour phase, s")
    parser.add_argument("--direct-pour", action="store_true",
                        help="pour every heap, also large ones (see LARGEST_DIRECT_POUR)")
    parser.add_argument("--skip-compile-time", action="store_true",
                        help="do not measure the numba compile time")
    parser.add_argument("--compile-probe", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.compile_probe:
        compile_probe()
        return 0

    bench_start = time.perf_counter()
    all_cores = numba.config.NUMBA_NUM_THREADS
    thread_counts = sorted({1, min(2, all_cores), all_cores})
    print(f"rigid_deposition: rocks of {ROCK_SIZE} m, N = {args.bodies}, threads {thread_counts}, "
          f"{args.steps} timed steps x {args.repeats} repeats; load average "
          f"{os.getloadavg()[0]:.2f} on {os.cpu_count()} cores", flush=True)

    compile_seconds = None
    if not args.skip_compile_time:
        compile_seconds = measure_compile_time()
        if compile_seconds is not None:
            print(f"numba compile time (first finalize + advance(1), empty cache): "
                  f"{compile_seconds:.1f} s", flush=True)

    rocks = build_rock_shapes()
    tets = [r.n_tets for r in rocks]
    print(f"{len(rocks)} rock shapes, {min(tets)}-{max(tets)} tetrahedra, bounding radius "
          f"{min(r.bounding_radius for r in rocks):.3f}-{max(r.bounding_radius for r in rocks):.3f} m")

    per_step_per_body: dict[int, dict[int, float]] = {}
    best_all_cores: dict[int, Window] = {}
    for n_bodies in sorted(args.bodies):
        scene, record = dense_heap(n_bodies, rocks, rebuild=args.rebuild_heap,
                                   wall_limit=args.pour_wall_limit, direct_pour=args.direct_pour)
        if not record["settled"]:
            print(f"  WARNING: the N = {n_bodies} heap is not as still/dense as wanted ({record['how']})")
        speeds = np.linalg.norm(scene.solver.velocities, axis=1)
        print(f"  heap at the start of the window: rms speed {rms_speed(scene.solver):.3f} m/s, body "
              f"speeds median {np.median(speeds):.3f} / 99th percentile "
              f"{np.percentile(speeds, 99):.3f} m/s, 95% of centres below z = "
              f"{heap_top(scene.solver):.2f} m", flush=True)
        start_state = scene.solver.state_arrays()
        timed_window(scene, start_state, n_steps=1, threads=all_cores)  # warm-up: loads the cache
        windows = []
        for _ in range(args.repeats):
            for threads in thread_counts:
                windows.append(timed_window(scene, start_state, n_steps=args.steps, threads=threads))
        print_windows(n_bodies, windows)
        best = best_by_threads(windows)
        per_step_per_body[n_bodies] = {t: w.wall / w.steps / n_bodies for t, w in best.items()}
        best_all_cores[n_bodies] = best[all_cores]
        print(f"  N = {n_bodies} best of {args.repeats}: " + ", ".join(
            f"{t} thread(s) {w.body_steps_per_s:.4g} body-steps/s, {w.wall / w.steps * 1e3:.2f} ms/step"
            for t, w in sorted(best.items())), flush=True)

    sizes = sorted(per_step_per_body)
    if len(sizes) > 1:
        small, large = sizes[0], sizes[-1]
        ratios = ", ".join(f"{per_step_per_body[large][t] / per_step_per_body[small][t]:.2f} "
                           f"({t} thread{'s' if t > 1 else ''})" for t in thread_counts)
        print(f"per-step cost ratio N = {large} vs N = {small}, normalised by N (1.00 = linear): "
              f"{ratios}")
    if compile_seconds is not None:
        print(f"numba compile time: {compile_seconds:.1f} s (not included above)")
    print(f"bench wall time: {time.perf_counter() - bench_start:.0f} s")
    largest = sizes[-1]
    print(f"METRIC body_steps_per_s {best_all_cores[largest].body_steps_per_s:.6g} 1/s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
