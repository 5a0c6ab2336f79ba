"""Deposit an underlayer of rocks and an armour layer of units on a slope until they rest (POSITIT).

Two stages, each one rigid FEMDEM run (:class:`riprap.simulation.Simulation`):

1. :func:`build_underlayer`: graded rocks start on a loose lattice above the face (no two bounding
   spheres touch) and fall onto it; each rock is held fixed where it first touches the face or a
   rock already held (a compacted bed: loose rocks on a face near their angle of repose would roll
   down to the toe instead).
2. :func:`place_units`: units start at the grid's centroids (a user file or a design grid) with
   user, random (uniform on rotations) or limited random orientations and an optional initial
   velocity, are lowered straight down until they touch (``release="on_contact"``, as a crane
   sets them down) or let fall from there (``"free_fall"``) onto the fixed underlayer, and run
   until every unit rests (``rest_speed`` and ``rest_kinetic_energy``) or ``max_time`` passes.

A unit that starts overlapping another unit, a rock or a wall is an error naming the unit and the
grid line it came from; with a generated grid, units are lifted until they are clear instead.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from riprap.schema import MAXIMUM_BODY_COUNT, default_of
from riprap.errors import CaseFileError, OverlapError
from riprap.limits import START_OVERLAP_FRACTION as _START_OVERLAP_FRACTION
from riprap.placement import layer_metrics
from riprap.placement.lowering import Surface, VerticalLowering
from riprap.simulation import Simulation
from riprap.solid.materials import Material
from riprap.solid.shape import RigidShape

# Gap between the bounding spheres of neighbouring rocks in the start lattice, over their diameter.
_ROCK_LATTICE_GAP = 0.05
# A unit is lifted by this fraction of its height at a time while it overlaps something.
_LIFT_STEP = 0.25
_MAX_LIFTS = 40
# Generated units reaching through a side wall are moved inside, this fraction of their width
# clear of it.
_SIDE_WALL_GAP = 0.01
# Units lowered onto the layer are released this fraction of D_n above what they touch.
_RELEASE_GAP = 0.002


#: Name of the armour unit's shape in the placement runs (and in the pack they write).
UNIT_SHAPE_NAME = "armour_unit"


@dataclass(frozen=True)
class PlacementMaterials:
    """Contact materials of the four kinds of surfaces, and the friction coefficients of named
    pairs of them (``[[friction]]``: unit on rock, unit on the glass side walls, ...)."""

    unit: Material
    rock: Material
    face: Material          # the slope face and the bed (the core's surface)
    side_wall: Material
    friction_pairs: tuple = ()      # riprap.solid.materials.FrictionPair

    def all(self) -> list[Material]:
        """Each material once (two roles may share one)."""
        unique = {}
        for m in (self.unit, self.rock, self.face, self.side_wall):
            unique.setdefault(m.name, m)
        return list(unique.values())

    def add_to(self, sim: Simulation) -> None:
        """Add every material and friction pair to a placement run."""
        for m in self.all():
            sim.add_material(m)
        for pair in self.friction_pairs:
            sim.add_friction_pair(pair)

    def in_contact(self) -> list[tuple[str, str]]:
        """The pairs of materials that meet in the placement runs: rocks settling on the face,
        between the side walls and on each other, then units on the rocks, the face, the side
        walls and each other."""
        pairs = []
        for moving in (self.rock, self.unit):
            pairs += [(moving.name, other.name) for other in (self.rock, self.face, self.side_wall)]
        return pairs + [(self.unit.name, self.unit.name)]


@dataclass
class Underlayer:
    """Rocks resting on the face, held fixed for the armour placement."""

    shapes: list[RigidShape]
    shape_of_rock: np.ndarray        # (n,) index into shapes
    positions: np.ndarray            # (n, 3) centroids, m
    quaternions: np.ndarray          # (n, 4) principal frames (w, x, y, z)
    nominal_diameters: np.ndarray    # (n,) m
    top_level: float                 # top of the underlayer above the face, m
    summary: dict = field(default_factory=dict)

    def node_sets(self) -> list[np.ndarray]:
        out = []
        for k in range(len(self.positions)):
            rotation = Rotation.from_quat(np.roll(self.quaternions[k], -1)).as_matrix()
            out.append(self.shapes[self.shape_of_rock[k]].mesh.nodes @ rotation.T + self.positions[k])
        return out


@dataclass
class PlacementResult:
    """The armour layer at the end of the placement run."""

    simulation: Simulation
    unit_bodies: np.ndarray          # body index of each unit
    grid_lines: np.ndarray | None    # grid-file line of each unit (None for a generated grid)
    summary: dict
    rows: np.ndarray | None = None   # placement row of each unit


def _run_settings(kwargs: dict) -> dict:
    keys = ("end_time", "time_step", "time_step_safety", "output_interval", "checkpoint_interval",
            "local_damping", "rest_speed", "rest_kinetic_energy", "output_directory", "paraview",
            "picture", "progress", "gravity", "adaptive_time_step")
    return {k: v for k, v in kwargs.items() if k in keys}


def build_underlayer(slope, rocks, *, materials: PlacementMaterials, s_range,
                     layers: int = default_of("underlayer", "layers"),
                     seed: int = default_of("underlayer", "seed"), **run) -> Underlayer:
    """Drop graded rocks on the face between ``s_range`` = (s_low, s_high) (m along the face).

    ``rocks``: sequence of objects with ``mesh`` (TetMesh), ``nominal_diameter`` and
    ``probability`` (a rock library, :func:`riprap.geometry.rock_grading.rock_library`).
    ``run``: :class:`Simulation` settings (``end_time`` is the longest settling time).
    """
    rng = np.random.default_rng(seed)
    shapes = rock_shapes(rocks)
    probability = np.array([r.probability for r in rocks], dtype=float)
    probability /= probability.sum()
    points = rock_lattice(slope, shapes, s_range, layers)
    sim = Simulation(**_run_settings(run))
    materials.add_to(sim)
    for s in shapes:
        sim.add_shape(s.name, s)
    sim.add_walls(slope.walls(face_material=materials.face.name,
                              side_material=materials.side_wall.name))
    _strip(sim, slope)
    choice = rng.choice(len(shapes), size=len(points), p=probability)
    orientations = Rotation.random(len(points), random_state=rng.integers(2**31)).as_quat()
    world = slope.to_world(points[:, 0], points[:, 1], points[:, 2])
    for k in range(len(points)):
        x, y, z, w = orientations[k]
        sim.add_body(shape=shapes[choice[k]].name, material=materials.rock.name, position=world[k],
                     orientation=(w, x, y, z))
    summary = sim.run(after_chunk=_stick_to_face)
    solver = sim.solver
    underlayer = Underlayer(shapes=shapes, shape_of_rock=choice.astype(np.int64),
                            positions=solver.positions.copy(), quaternions=solver.quaternions.copy(),
                            nominal_diameters=np.array([rocks[c].nominal_diameter for c in choice]),
                            top_level=0.0, summary=summary.as_dict())
    underlayer.top_level = layer_metrics.underlayer_top(slope, underlayer.node_sets())
    return underlayer


def _strip(sim: Simulation, slope) -> None:
    """A periodic strip's sides for the bodies: they wrap and meet across them."""
    if slope.periodic:
        sim.solver.set_periodic(1, 0.0, slope.width)


def rock_shapes(rocks) -> list[RigidShape]:
    """The rigid shapes of a rock library, named as the underlayer run names them."""
    return [RigidShape.from_mesh(r.mesh, name=f"rock_{k}") for k, r in enumerate(rocks)]


def rock_lattice(slope, shapes, s_range, layers: int) -> np.ndarray:
    """Start points (s, y, h) of the underlayer rocks: ``layers`` staggered layers of a loose
    lattice over the band ``s_range`` (no two bounding spheres touch). Refuses a band that holds
    no rock, or more rocks than a case may have bodies, before building any."""
    radius = max(shape.bounding_radius for shape in shapes)
    spacing = 2.0 * radius * (1.0 + _ROCK_LATTICE_GAP)
    s_low, s_high = (float(v) for v in s_range)
    n_s = int((s_high - s_low) // spacing)
    n_y = int((slope.width - 2.0 * radius) // spacing) + 1
    spacing_y = spacing
    if slope.periodic:
        # the lattice continues across the strip's side: n_y columns fill its width evenly
        n_y = int(slope.width // spacing)
        spacing_y = slope.width / max(n_y, 1)
    if n_s < 1 or n_y < 1:
        raise CaseFileError(f"underlayer: the band s = {s_low:g}..{s_high:g} m of a {slope.width:g} m "
                            f"wide face holds no rock of bounding diameter {2 * radius:.3g} m")
    if n_s * n_y * layers > MAXIMUM_BODY_COUNT:
        raise CaseFileError(
            f"underlayer: {n_s} x {n_y} rocks in each of {layers} layers on the band s = "
            f"{s_low:g}..{s_high:g} m of a {slope.width:g} m wide face is more than the "
            f"{MAXIMUM_BODY_COUNT:,} bodies a case may have; use larger rocks (dn50), a narrower "
            "band (from_s, to_s) or fewer layers")
    y0 = 0.5 * (slope.width - (n_y - 1) * spacing)
    if slope.periodic:
        y0 = 0.5 * spacing_y
    points = []
    for layer in range(layers):
        shift = 0.5 * spacing * (layer % 2)
        shift_y = 0.5 * spacing_y * (layer % 2)
        columns = n_y if slope.periodic else n_y - (layer % 2)
        for i in range(n_s):
            for j in range(columns):
                points.append((s_low + (i + 0.5) * spacing + shift,
                               y0 + j * spacing_y + shift_y,
                               radius * (1.0 + _ROCK_LATTICE_GAP) + layer * spacing))
    points = np.array(points)
    points[:, 1] = slope.wrapped(points[:, 1])
    if slope.toe_stop_distance > 0:
        # Upper layers of the lattice lean out over the toe: keep them behind the toe stop.
        x = slope.to_world(points[:, 0], points[:, 1], points[:, 2])[:, 0]
        points = points[x - radius * (1.0 + _ROCK_LATTICE_GAP) > slope.toe_x - slope.toe_stop_distance]
    return points


def free_body_time_step(shapes, materials: PlacementMaterials, material: str,
                        **run) -> tuple[float, object]:
    """The time step a placement run of free bodies of ``shapes`` (of ``material``) starts
    with: the one its ``Simulation`` chooses from their masses and the contact stiffness (rocks
    held fixed do not count), found without running, for the work estimate before the runs;
    with a function naming the shape that sets it."""
    sim = Simulation(**_run_settings(run))
    materials.add_to(sim)
    for k, shape in enumerate(shapes):
        sim.add_shape(shape.name, shape)
        # far apart: only the masses and stiffness count, not where the bodies are
        sim.add_body(shape=shape.name, material=material,
                     position=(0.0, 0.0, 10.0 * k * (1.0 + shape.bounding_radius)))
    sim.build_without_checks()
    return sim.solver.time_step, lambda: sim.body_setting_the_step(numbered=False)


def _stick_to_face(sim: Simulation) -> bool:
    """Hold every rock that touches the face, the bed or a rock already held: the underlayer is
    built like a compacted bed, each rock staying where it first lands (loose rocks on a face
    near the angle of repose would otherwise roll to the toe). True once every rock is held."""
    solver = sim.solver
    contacts = solver.contacts
    while True:
        fixed = solver.fixed
        body_i, body_j = contacts.body_i, contacts.body_j
        # Walls 0 and 1 are the bed and the face (Slope.walls order).
        on_ground = (body_j == -1) | (body_j == -2)
        j_fixed = np.where(body_j >= 0, fixed[np.maximum(body_j, 0)], False)
        i_fixed = fixed[body_i]
        landing = set(body_i[(on_ground | j_fixed) & ~i_fixed].tolist())
        landing |= set(body_j[(body_j >= 0) & i_fixed & ~j_fixed].tolist())
        if not landing:
            break
        solver.fix_bodies(sorted(landing))
    return bool(solver.fixed.all())


def unit_orientations(count: int, *, mode: str, slope,
                      seed: int = default_of("placement", "seed"),
                      max_tilt_deg: float = default_of("placement", "max_tilt_deg"),
                      max_spin_deg: float = default_of("placement", "max_spin_deg"),
                      user=None) -> np.ndarray:
    """Quaternions (w, x, y, z) rotating the unit as built into the world.

    ``mode``: ``"user"`` (``user`` quaternions), ``"random"`` (uniform on rotations) or
    ``"random_within"`` (the unit's z axis turned to the face normal, then a random spin about it,
    within ``max_spin_deg`` either way of square to the slope, and a tilt up to ``max_tilt_deg``
    about a random horizontal axis).
    """
    rng = np.random.default_rng(seed)
    if mode == "user":
        if user is None:
            raise CaseFileError("orientation = 'user' needs orientations in the grid file "
                                "(columns qw, qx, qy, qz or roll, pitch, yaw)")
        return np.asarray(user, dtype=float)
    if mode == "random":
        q = Rotation.random(count, random_state=rng.integers(2**31)).as_quat()
    elif mode == "random_within":
        if not 0.0 <= max_tilt_deg <= 180.0:
            raise CaseFileError(f"max_tilt_deg = {max_tilt_deg!r} must lie in 0..180 degrees")
        if not 0.0 <= max_spin_deg <= 180.0:
            raise CaseFileError(f"max_spin_deg = {max_spin_deg!r} must lie in 0..180 degrees")
        to_face = Rotation.from_rotvec(np.array([0.0, -slope.angle, 0.0]))
        # one draw per unit either way, so that the tilts after it are those of any spin limit
        spins = (rng.uniform(0.0, 2.0 * np.pi, count) if max_spin_deg >= 180.0 else
                 rng.uniform(-np.radians(max_spin_deg), np.radians(max_spin_deg), count))
        spin = Rotation.from_euler("z", spins[:, None])
        azimuth = rng.uniform(0.0, 2.0 * np.pi, count)
        tilt = np.radians(max_tilt_deg) * np.sqrt(rng.uniform(0.0, 1.0, count))
        axes = np.stack([np.cos(azimuth), np.sin(azimuth), np.zeros(count)], axis=1)
        q = (to_face * Rotation.from_rotvec(axes * tilt[:, None]) * spin).as_quat()
    else:
        raise CaseFileError(f"orientation = {mode!r}: expected 'user', 'random' or 'random_within'")
    return np.concatenate([q[:, 3:], q[:, :3]], axis=1)


def place_units(slope, unit, underlayer: Underlayer, *, positions, orientations, materials,
                velocities=None, grid_lines=None, lift_overlapping: bool = False,
                initial_velocity=default_of("placement", "initial_velocity"),
                deposition: str = default_of("placement", "deposition"), rows=None,
                release: str = default_of("placement", "release"), **run) -> PlacementResult:
    """Deposit the units on the fixed underlayer and run until they rest.

    ``unit``: an :class:`riprap.geometry.armour_units.ArmourUnit` (mesh, height, nominal_diameter,
    volume, design). ``positions`` (n, 3) start centroids, ``orientations`` (n, 4) quaternions of the
    unit as built; ``velocities`` (n, 3) or ``initial_velocity`` for all. ``grid_lines``: the grid
    file line of each unit, named in errors. ``lift_overlapping``: lift units that start overlapping
    (generated grids) instead of refusing them.

    ``deposition``: ``"all_at_once"``, or ``"row_by_row"`` as cranes place them: row k is dropped
    once rows 0..k-1 rest (or their ``end_time`` has passed), onto them. ``rows``: the row of each
    unit; by default units whose start positions lie within half a D_n of each other along the face
    form a row. Each row is one run (its outputs in ``row_NN/`` under ``output_directory``); the
    units already placed carry their state over, except the tangential contact history.

    ``release``: ``"free_fall"`` lets each unit go where it starts; ``"on_contact"`` first lowers it
    straight down (a crane) until it touches the underlayer, the face or a unit set down before it
    (lowest rows first, :mod:`riprap.placement.lowering`), and lets it go there.
    """
    if release not in ("free_fall", "on_contact"):
        raise CaseFileError(f"release = {release!r}: expected 'free_fall' or 'on_contact'")
    positions = np.array(positions, dtype=float)
    orientations = np.asarray(orientations, dtype=float)
    n_units = len(positions)
    if velocities is None:
        velocities = np.tile(np.asarray(initial_velocity, dtype=float), (n_units, 1))
    velocities = np.asarray(velocities, dtype=float)
    unit_shape = RigidShape.from_mesh(unit.mesh, name=UNIT_SHAPE_NAME)
    if lift_overlapping:
        _shift_inside_walls(slope, unit_shape, positions, orientations)
    # Lowered units are first raised clear of the face, so only the side walls bound their start.
    _check_inside(slope, unit_shape, positions, orientations, grid_lines,
                  above_face=release == "free_fall")
    if rows is None:
        rows = layer_metrics.rows_by_position(slope.to_slope(positions)[:, 0], unit.nominal_diameter)
    rows = np.asarray(rows)
    groups = _deposition_groups(deposition, rows)
    state = _UnitState(positions, orientations, velocities)
    placed: list[int] = []
    results = []
    rock_surfaces = (_rock_surfaces(underlayer) if release == "on_contact" else [])
    for stage, group in enumerate(groups):
        if release == "on_contact":
            _lower_onto_layer(slope, unit, unit_shape, rock_surfaces, state, placed, group)
        members = placed + list(group)
        stage_run = dict(run)
        if len(groups) > 1 and "output_directory" in run:
            stage_run["output_directory"] = Path(run["output_directory"]) / f"row_{stage:02d}"
        sim = _start_without_overlaps(slope, unit, unit_shape, underlayer, state, members,
                                      set(group), materials, stage_run, lift_overlapping,
                                      grid_lines, release)
        results.append(sim.run().as_dict())
        state.update_from(sim.solver, len(underlayer.positions), members)
        placed = members
    # Bodies of the last run are underlayer rocks, then the units in deposition order.
    first_unit = len(underlayer.positions)
    unit_bodies = np.empty(n_units, dtype=np.int64)
    unit_bodies[np.asarray(placed)] = np.arange(first_unit, first_unit + n_units)
    summary = placement_summary(slope, unit, unit_shape, underlayer, sim, unit_bodies, rows)
    summary["deposition"] = deposition
    summary["run"] = _combined_runs(results)
    return PlacementResult(simulation=sim, unit_bodies=unit_bodies,
                           grid_lines=None if grid_lines is None else np.asarray(grid_lines),
                           summary=summary, rows=rows)


class _UnitState:
    """Poses and velocities of every unit between deposition stages; a unit deposited already
    carries the solver's principal-frame orientation, a new one its orientation as built."""

    def __init__(self, positions, orientations, velocities):
        self.positions = positions
        self.orientations = orientations.copy()
        self.velocities = velocities.copy()
        self.angular_velocities = np.zeros_like(velocities)
        self.frames = ["shape"] * len(positions)

    def update_from(self, solver, first_unit, members):
        omegas = solver.angular_velocities
        for body, k in enumerate(members, start=first_unit):
            self.positions[k] = solver.positions[body]
            self.orientations[k] = solver.quaternions[body]
            self.velocities[k] = solver.velocities[body]
            self.angular_velocities[k] = omegas[body]
            self.frames[k] = "principal"


def _rock_surfaces(underlayer) -> list[Surface]:
    faces = [shape.mesh.boundary_faces() for shape in underlayer.shapes]
    return [Surface.from_nodes(nodes, faces[underlayer.shape_of_rock[k]])
            for k, nodes in enumerate(underlayer.node_sets())]


def _unit_nodes(unit_shape, state, k) -> np.ndarray:
    if state.frames[k] == "shape":
        return _world_nodes(unit_shape, state.positions[k], state.orientations[k])
    rotation = Rotation.from_quat(np.roll(state.orientations[k], -1)).as_matrix()
    return unit_shape.mesh.nodes @ rotation.T + state.positions[k]


def _lower_onto_layer(slope, unit, unit_shape, rock_surfaces, state, placed, group) -> None:
    """Lower the units of ``group`` (lowest first along the face) straight down onto the rocks and
    the units ``placed`` before them; their start positions give the vertical each one travels."""
    faces = unit_shape.mesh.boundary_faces()
    lowering = VerticalLowering(slope, gap=_RELEASE_GAP * unit.nominal_diameter,
                                period=slope.width if slope.periodic else 0.0)
    lowering.add(*rock_surfaces)
    lowering.add(*(Surface.from_nodes(_unit_nodes(unit_shape, state, k), faces) for k in placed))
    along = slope.to_slope(state.positions[np.asarray(group)])
    for k in np.asarray(group)[np.lexsort((along[:, 1], along[:, 0]))]:
        surface = Surface.from_nodes(_unit_nodes(unit_shape, state, k), faces)
        dz = lowering.lower(surface)
        state.positions[k, 2] += dz
        lowering.add(surface.moved(dz))


def _deposition_groups(deposition, rows) -> list[np.ndarray]:
    """Unit indices of each deposition stage, lowest row first."""
    if deposition == "all_at_once":
        return [np.arange(len(rows))]
    if deposition != "row_by_row":
        raise CaseFileError(f"deposition = {deposition!r}: expected 'all_at_once' or 'row_by_row'")
    return [np.flatnonzero(rows == r) for r in np.unique(rows)]


def _start_without_overlaps(slope, unit, unit_shape, underlayer, state, members, new, materials,
                            run, lift_overlapping, grid_lines, release) -> Simulation:
    """The stage's simulation, with the new units lifted clear (or refused) if they overlap."""
    for attempt in range(_MAX_LIFTS + 1):
        sim = _placement_simulation(slope, unit_shape, underlayer, state, members, materials, run)
        overlapping = [(members[k], None if other is None else members[other], what, depth)
                       for k, other, what, depth in
                       _overlapping_units(sim, len(underlayer.positions), len(members))
                       if members[k] in new]
        if not overlapping:
            return sim
        if not lift_overlapping:
            lines = [f"  unit {k}" + (f" (grid line {grid_lines[k]})" if grid_lines is not None else "")
                     + f" overlaps {what}" for k, _, what, _ in overlapping[:20]]
            raise OverlapError(f"{len(overlapping)} unit(s) start overlapping:\n" + "\n".join(lines)
                               + "\nMove them apart or higher in the grid.")
        # Lift a unit unless what it overlaps is lifted too (then they would move together);
        # lowest units first, so a chain of overlaps is undone from its bottom.
        lifted: set[int] = set()
        for k, other, _, depth in sorted(overlapping, key=lambda item: item[0]):
            if k in lifted or (other is not None and other in lifted):
                continue
            lifted.add(k)
            if release == "on_contact":
                # Lowered onto what it overlaps (two edges crossing that the lowering's sample
                # points missed): a little higher on the same vertical, more each time.
                state.positions[k, 2] += min(2.0 * depth + _RELEASE_GAP * unit.nominal_diameter
                                             * 2.0 ** attempt, _LIFT_STEP * unit.height)
            elif other is None:
                # Off a rock or a wall (the toe stop, the face): straight up.
                state.positions[k, 2] += _LIFT_STEP * unit.height
            else:
                # Off another unit: along the face normal, as a vertical lift would also move
                # the unit up the face, into the next row.
                state.positions[k] += _LIFT_STEP * unit.height * slope.normal
    listing = "; ".join(f"unit {k} overlaps {what}" for k, _, what, _ in overlapping[:5])
    raise OverlapError(f"units still overlap after lifting them {_MAX_LIFTS} times by "
                       f"{_LIFT_STEP:g} unit heights ({listing}): the grid is too dense for this "
                       "unit, or a unit reaches through a wall")


def _combined_runs(results: list[dict]) -> dict:
    """One run record for all stages: times and steps added, the last stage's end state."""
    combined = dict(results[-1])
    for key in ("steps", "wall_time", "simulated_time"):
        combined[key] = sum(r[key] for r in results)
    combined["body_steps_per_second"] = (sum(r["body_steps_per_second"] * r["wall_time"] for r in results)
                                         / max(combined["wall_time"], 1e-9))
    combined["stages"] = len(results)
    return combined


def on_underlayer(slope, underlayer, materials, run, shapes) -> Simulation:
    """A placement run on the fixed ``underlayer``: its materials, the rocks' ``shapes`` and
    those of what is placed on them, the slope's walls (a strip's sides wrapping), every rock
    held fixed (bodies 0 .. n_rocks - 1)."""
    sim = Simulation(**_run_settings(run))
    materials.add_to(sim)
    for s in list(underlayer.shapes) + list(shapes):
        sim.add_shape(s.name, s)
    sim.add_walls(slope.walls(face_material=materials.face.name,
                              side_material=materials.side_wall.name))
    _strip(sim, slope)
    for k in range(len(underlayer.positions)):
        sim.add_body(shape=underlayer.shapes[underlayer.shape_of_rock[k]].name,
                     material=materials.rock.name, position=underlayer.positions[k],
                     orientation=underlayer.quaternions[k], fixed=True, frame="principal")
    return sim


def _placement_simulation(slope, unit_shape, underlayer, state, members, materials,
                          run) -> Simulation:
    sim = on_underlayer(slope, underlayer, materials, run, [unit_shape])
    for k in members:
        # New units: orientations apply to the unit's mesh as built (frame "shape"); units carried
        # over from an earlier stage have the solver's principal-frame orientation.
        sim.add_body(shape=unit_shape.name, material=materials.unit.name,
                     position=state.positions[k], orientation=state.orientations[k],
                     velocity=state.velocities[k], angular_velocity=state.angular_velocities[k],
                     frame=state.frames[k])
    return sim


def _overlapping_units(sim: Simulation, first_unit: int,
                       n_units: int) -> list[tuple[int, int | None, str, float]]:
    """(unit, the other unit or None, what it overlaps, depth) for every unit that starts overlapping
    something; of two overlapping units the later one is listed."""
    sim.build_without_checks()
    solver = sim.solver
    tolerance = _START_OVERLAP_FRACTION * min(s.min_subtet_height for s in solver.shapes)
    found = []
    for i, j, depth in solver.overlaps(tolerance):
        for a, b in ((i, j), (j, i)):
            if a >= first_unit and (b < 0 or b < first_unit or a > b):
                if b < 0:
                    what = f"wall {-1 - b}"
                elif b < first_unit:
                    what = f"underlayer rock {b}"
                else:
                    what = f"unit {b - first_unit}"
                other = b - first_unit if b >= first_unit else None
                found.append((a - first_unit, other, f"{what} (depth {depth:.2e} m)", depth))
                break
    return found


def _world_nodes(unit_shape, position, quaternion) -> np.ndarray:
    """Nodes of a unit placed with ``quaternion`` applied to its mesh as built."""
    frame = Rotation.from_matrix(unit_shape.frame_rotation)
    rotation = Rotation.from_quat([quaternion[1], quaternion[2], quaternion[3], quaternion[0]]) * frame
    return rotation.apply(np.array(unit_shape.mesh.nodes)) + position


def _shift_inside_walls(slope, unit_shape, positions, orientations) -> None:
    """Move generated units that reach through a side wall or the toe stop back inside (in place)."""
    stop_x = slope.toe_x - slope.toe_stop_distance
    for k in range(len(positions)):
        if slope.toe_stop_distance > 0:
            x = _world_nodes(unit_shape, positions[k], orientations[k])[:, 0]
            gap = _SIDE_WALL_GAP * (x.max() - x.min())
            if x.min() < stop_x + gap:
                positions[k, 0] += stop_x + gap - x.min()
        y = slope.to_slope(_world_nodes(unit_shape, positions[k], orientations[k]))[:, 1]
        if slope.periodic:
            # no side walls; a pair of units across the strip's side must touch in one image only
            if 2.0 * unit_shape.bounding_radius * 2.0 > slope.width:
                raise CaseFileError(
                    f"a periodic strip {slope.width:g} m wide is narrower than twice a unit's "
                    f"bounding diameter ({2.0 * unit_shape.bounding_radius:.3f} m): a unit would "
                    "meet its own neighbour's two images; widen the strip")
            continue
        if (1.0 + 2.0 * _SIDE_WALL_GAP) * (y.max() - y.min()) > slope.width:
            raise CaseFileError(f"unit {k} is {y.max() - y.min():.3f} m wide across the flume, more "
                                f"than its width {slope.width:g} m")
        gap = _SIDE_WALL_GAP * (y.max() - y.min())
        if y.min() < gap:
            positions[k, 1] += gap - y.min()
        elif y.max() > slope.width - gap:
            positions[k, 1] -= y.max() - (slope.width - gap)


def check_generated_positions(slope, unit, positions, orientations) -> None:
    """Refuse a generated grid's unit wider than the flume, as ``place_units`` would (on a copy:
    the run moves them itself)."""
    unit_shape = RigidShape.from_mesh(unit.mesh, name=UNIT_SHAPE_NAME)
    _shift_inside_walls(slope, unit_shape, np.array(positions, dtype=float),
                        np.asarray(orientations, dtype=float))


def check_start_positions(slope, unit, positions, orientations, *, grid_lines=None,
                          release: str = default_of("placement", "release")) -> None:
    """Refuse units of a user's grid that start outside the flume (naming unit and grid line),
    before any rock is dropped; ``place_units`` makes the same check."""
    unit_shape = RigidShape.from_mesh(unit.mesh, name=UNIT_SHAPE_NAME)
    _check_inside(slope, unit_shape, np.asarray(positions, dtype=float),
                  np.asarray(orientations, dtype=float), grid_lines,
                  above_face=release == "free_fall")


def _check_inside(slope, unit_shape, positions, orientations, grid_lines, above_face=True) -> None:
    """Every unit must start inside the flume (between the side walls, above the face)."""
    problems = []
    for k in range(len(positions)):
        coords = slope.to_slope(_world_nodes(unit_shape, positions[k], orientations[k]))
        where = f"unit {k}" + (f" (grid line {grid_lines[k]})" if grid_lines is not None else "")
        if not slope.periodic and (coords[:, 1].min() < 0.0 or coords[:, 1].max() > slope.width):
            problems.append(f"  {where} reaches y = {coords[:, 1].min():.3f}..{coords[:, 1].max():.3f} m, "
                            f"outside the side walls at 0 and {slope.width:g} m")
        elif above_face and coords[:, 2].min() < 0.0:
            problems.append(f"  {where} starts {-coords[:, 2].min():.3f} m inside the slope face")
    if problems:
        more = f"\n  ... and {len(problems) - 20} more" if len(problems) > 20 else ""
        raise CaseFileError(f"{len(problems)} unit(s) start outside the container:\n"
                            + "\n".join(problems[:20]) + more)


def _units_not_on_underlayer(solver, unit_bodies, n_rocks: int, side_walls) -> np.ndarray:
    """For each unit, whether it touches no underlayer rock, nor the face, the bed or the toe
    stop: it rests on other units only (stacked on the layer instead of in it), or on nothing."""
    contacts = solver.contacts
    body_i, body_j = np.asarray(contacts.body_i), np.asarray(contacts.body_j)
    on_ground = np.zeros(solver.n_bodies, dtype=bool)
    wall = body_j < 0
    # the side walls (``Slope.side_wall_indices``) carry no unit
    ground_wall = wall & ~np.isin(-1 - body_j, side_walls)
    on_ground[body_i[ground_wall]] = True
    rock_pair = ~wall & ((body_i < n_rocks) | (body_j < n_rocks))
    on_ground[body_i[rock_pair]] = True
    on_ground[body_j[rock_pair]] = True
    return ~on_ground[np.asarray(unit_bodies)]


def placement_summary(slope, unit, unit_shape, underlayer, sim, unit_bodies, unit_rows) -> dict:
    """The layer as designers read it (``layer_metrics``) plus what came to rest; ``unit_rows``:
    the row each unit was placed in."""
    solver = sim.solver
    rotations = solver.rotation_matrices()
    node_sets = [unit_shape.mesh.nodes @ rotations[b].T + solver.positions[b] for b in unit_bodies]
    coords = slope.to_slope(solver.positions[unit_bodies])
    speeds = (np.linalg.norm(solver.velocities[unit_bodies], axis=1)
              + np.linalg.norm(solver.angular_velocities[unit_bodies], axis=1)
              * unit_shape.bounding_radius)
    dn = unit.nominal_diameter
    # Slid past the toe by more than a unit (a unit resting in the toe corner is not), or thrown
    # above the crest.
    rolled_off = (coords[:, 0] < -dn) | (coords[:, 0] > slope.length)
    threshold = sim.rest_speed if sim.rest_speed > 0 else np.inf
    at_rest = (speeds < threshold) & ~rolled_off
    on_face = ~rolled_off
    figures = layer_metrics.layer_figures(
        slope, solver.positions[unit_bodies][on_face], [n for n, ok in zip(node_sets, on_face) if ok],
        rows=np.asarray(unit_rows)[on_face], nominal_diameter=dn, unit_volume=unit.volume,
        underlayer_level=underlayer.top_level)
    not_on_underlayer = _units_not_on_underlayer(solver, unit_bodies, len(underlayer.positions),
                                                 slope.side_wall_indices)
    overlaps = [depth for i, j, depth in solver.overlaps(0.0)
                if i in set(unit_bodies.tolist()) or j in set(unit_bodies.tolist())]
    design = unit.design
    return {
        "unit": unit.kind,
        "unit_height_m": float(unit.height),
        "nominal_diameter_m": float(dn),
        "units_placed": int(len(unit_bodies)),
        "units_at_rest": int(at_rest.sum()),
        "units_rolled_off": [int(k) for k in np.flatnonzero(rolled_off)],
        "units_not_at_rest": [int(k) for k in np.flatnonzero(~at_rest & ~rolled_off)],
        "units_not_on_underlayer": [int(k) for k in np.flatnonzero(not_on_underlayer & ~rolled_off)],
        **figures,
        "design_packing_density_coefficient": float(design.packing_density_coefficient),
        "design_layer_thickness_m": float(design.layers * design.layer_thickness_coefficient * dn),
        "design_porosity": float(design.porosity),
        "max_overlap_over_dn": float(max(overlaps, default=0.0) / dn),
        "underlayer_rocks": int(len(underlayer.positions)),
        "underlayer_top_m": float(underlayer.top_level),
        "slope_angle_deg": slope.angle_deg,
    }
