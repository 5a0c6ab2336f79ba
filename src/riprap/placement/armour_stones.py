"""Rock armour placed as a contractor places it: graded armour stones set down one by one on a
grid across the slope, from the toe up, a layer at a time, each layer settled before the next.

The design (:class:`StoneLayerDesign`): n layers (two, the usual rock armour) of stones of median
nominal diameter D_n50, with the layer thickness coefficient k_t of the Rock Manual (0.91 for a
double layer, standard or dense placement; CIRIA, CUR, CETMEF 2007, *The Rock Manual*, p. 126)
and a design porosity n_v (0.37: the Shore Protection Manual's random double layer of rough
quarrystone, 1984, Table 7-13). The stones per area of the face are then N_a = n k_t (1 - n_v) /
D_n50^2 (the Rock Manual's count of a layer; CEM VI-5), and each layer's grid holds k_t (1 - n_v)
/ D_n50^2 stones per area: rows along the face, the next row shifted half a spacing across (a
staggered grid), the second layer's grid shifted half a spacing both ways over the first's.

The placement (:func:`place_armour_stones`): each stone is drawn from the grading's library (by
count, so that the stones have the grading's mass curve), given a random orientation (uniform on
rotations), and lowered straight down onto what is already there (the underlayer rocks, the face,
the stones set before it; :mod:`riprap.placement.lowering`), lowest first along the face, as a
crane sets it down; ``"dense"`` placement tries several orientations for each stone and sets it
in the one that lets it down deepest, as a crane operator turns a stone into the gap before
releasing it. After each layer every stone of it (and of the layers below, free too) runs until
at rest on the fixed underlayer: a stone carries its state into the next layer's run.

What came out is measured as the Rock Manual measures a placed layer: the layer thickness from
the underlayer's top to the stones' tops (along the face normal) and its k_t = t / (n D_n50), the
stones per area N_a D_n50^2 / n, and the bulk porosity 1 - (stone volume) / (area t), over the
face between a D_n50 inside the first and last rows.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from riprap.errors import CaseFileError
from riprap.geometry.armour_stone import grading_statistics
from riprap.io.contact_history import ContactHistory
from riprap.limits import START_OVERLAP_FRACTION
from riprap.placement import layer_metrics
from riprap.placement.lowering import Surface, VerticalLowering
from riprap.placement.place import Underlayer, _rock_surfaces, on_underlayer
from riprap.schema import MAXIMUM_BODY_COUNT
from riprap.simulation import Simulation
from riprap.solid.shape import RigidShape

__all__ = ["StoneLayerDesign", "ArmourStones", "stone_grid", "place_armour_stones",
           "ROCK_LAYER_THICKNESS_COEFFICIENT", "ROCK_DESIGN_POROSITY", "STONE_PLACEMENTS"]

#: k_t of rock armour by (layers, placement) (The Rock Manual 2007, p. 126, as tabulated in
#: Sander-w/breakwater's ``layer_coefficient``; shared/validation/armour_design.md).
ROCK_LAYER_THICKNESS_COEFFICIENT = {(1, "dense"): 0.84, (2, "standard"): 0.91, (2, "dense"): 0.91}
#: Design porosity of a random double layer of rough quarrystone (U.S. Army Corps of Engineers,
#: Shore Protection Manual 1984, Table 7-13: P = 37 %).
ROCK_DESIGN_POROSITY = 0.37
STONE_PLACEMENTS = ("standard", "dense")
#: Orientations tried for each stone in dense placement.
DENSE_ORIENTATION_TRIES = 6
#: Stones are released this fraction of D_n50 above what they land on.
_RELEASE_GAP = 0.002
#: Times a stone that starts overlapping is lifted before the layer is refused.
_MAX_LIFTS = 10


@dataclass(frozen=True)
class StoneLayerDesign:
    """The layer asked for: ``layers`` layers of stones of ``dn50`` (m), ``placement``
    (``"standard"`` or ``"dense"``), design porosity ``porosity``."""

    dn50: float
    layers: int = 2
    placement: str = "standard"
    porosity: float = ROCK_DESIGN_POROSITY
    #: width (m) of a toe berm of the same stones on the bed in front of the toe, in as many
    #: layers as the slope's; 0: none (the slope's toe stop holds the layer)
    toe_berm_width: float = 0.0

    def __post_init__(self):
        if not (math.isfinite(self.dn50) and self.dn50 > 0):
            raise CaseFileError(f"armour stones: dn50 must be a positive length in m, got "
                                f"{self.dn50!r}")
        if not (math.isfinite(self.toe_berm_width) and self.toe_berm_width >= 0):
            raise CaseFileError(f"armour stones: toe_berm_width must be 0 (no berm) or a positive "
                                f"width in m, got {self.toe_berm_width!r}")
        if 0 < self.toe_berm_width < self.dn50:
            raise CaseFileError(f"armour stones: a toe berm {self.toe_berm_width:g} m wide holds "
                                f"no stone of D_n50 = {self.dn50:g} m; give toe_berm_width 0 (no "
                                f"berm) or about {3 * self.dn50:.3g} m (three stones)")
        if self.placement not in STONE_PLACEMENTS:
            raise CaseFileError(f"armour stones: placement = {self.placement!r}: expected one of "
                                f"{', '.join(STONE_PLACEMENTS)}")
        if (self.layers, self.placement) not in ROCK_LAYER_THICKNESS_COEFFICIENT:
            known = ", ".join(f"{n} layer(s) {p}" for n, p in ROCK_LAYER_THICKNESS_COEFFICIENT)
            raise CaseFileError(f"armour stones: {self.layers} layer(s) placed {self.placement} "
                                f"has no layer thickness coefficient in the Rock Manual; known: "
                                f"{known}")
        if not 0.0 < self.porosity < 1.0:
            raise CaseFileError(f"armour stones: porosity must lie between 0 and 1, got "
                                f"{self.porosity!r}")

    @property
    def layer_thickness_coefficient(self) -> float:
        return ROCK_LAYER_THICKNESS_COEFFICIENT[(self.layers, self.placement)]

    @property
    def layer_thickness(self) -> float:
        """t = n k_t D_n50 (m)."""
        return self.layers * self.layer_thickness_coefficient * self.dn50

    @property
    def stones_per_area(self) -> float:
        """N_a = n k_t (1 - n_v) / D_n50^2 (1/m^2)."""
        return self.layers * self.layer_thickness_coefficient * (1.0 - self.porosity) / self.dn50 ** 2

    @property
    def spacing(self) -> float:
        """The grid spacing of one layer (m): a square of it holds one stone."""
        return self.dn50 / math.sqrt(self.layer_thickness_coefficient * (1.0 - self.porosity))


def stone_grid(slope, design: StoneLayerDesign, s_range, layer: int) -> np.ndarray:
    """(s, y) of the stones of ``layer`` (0 first) on the face between ``s_range``: rows along
    the face a spacing apart, alternate rows shifted half a spacing across, the second layer
    shifted half a spacing both ways. On a periodic strip a row holds a whole number of stones
    (the spacing across stretched or shrunk to fill the width) and the rows' spacing along the
    face changes the other way, so that the grid keeps the design's stones per area on any
    width; between walls the rows keep half a spacing from each wall."""
    s_low, s_high = (float(v) for v in s_range)
    spacing = design.spacing
    if slope.periodic:
        across = max(1, round(slope.width / spacing))
        dy = slope.width / across
    else:
        across = int((slope.width - spacing) // spacing) + 1
        dy = spacing
    ds = spacing ** 2 / dy          # one stone per ds x dy: the design's stones per area
    rows = int((s_high - s_low - 0.5 * ds) // ds) + 1
    if across < 1 or rows < 1 or slope.width < design.dn50:
        raise CaseFileError(f"armour stones: the face s = {s_low:g}..{s_high:g} m by "
                            f"{slope.width:g} m holds no row of stones {spacing:.3g} m apart "
                            f"(D_n50 = {design.dn50:g} m)")
    points = []
    for row in range(rows):
        shift = 0.5 * dy * ((row + layer) % 2)
        s = s_low + 0.5 * ds + row * ds + 0.5 * ds * (layer % 2)
        if s > s_high - 0.5 * design.dn50:
            continue            # a stone there would stand out over the top of the face
        y0 = (0.5 * dy if slope.periodic else 0.5 * (slope.width - (across - 1) * dy)) + shift
        for column in range(across):
            y = y0 + column * dy
            if not slope.periodic and y > slope.width - 0.5 * design.dn50:
                continue
            points.append((s, y))
    points.extend(_berm_points(slope, design, layer, across, dy, ds))
    points = np.array(points)
    points[:, 1] = slope.wrapped(points[:, 1])
    return points


def _berm_points(slope, design: StoneLayerDesign, layer: int, across: int, dy: float,
                 ds: float) -> list:
    """(s, y) of a toe berm's stones of ``layer``: rows across the bed ``ds`` apart from the
    toe seaward over ``design.toe_berm_width``, staggered as the face's; s < 0 (along the face's
    line produced below the toe: straight above it lies the bed point the stone is lowered
    onto)."""
    if design.toe_berm_width <= 0:
        return []
    cos = math.cos(slope.angle)
    points, row = [], 0
    while True:
        back = 0.5 * ds + row * ds + 0.5 * ds * (layer % 2)
        if back > design.toe_berm_width - 0.5 * design.dn50:
            break
        shift = 0.5 * dy * ((row + layer + 1) % 2)
        y0 = (0.5 * dy if slope.periodic else 0.5 * (slope.width - (across - 1) * dy)) + shift
        for column in range(across):
            y = y0 + column * dy
            if not slope.periodic and y > slope.width - 0.5 * design.dn50:
                continue
            points.append((-back / cos, y))
        row += 1
    return points


@dataclass
class ArmourStones:
    """The placed stones: their shapes, which shape each stone is, poses and layer."""

    shapes: list                   # RigidShape per library entry
    nominal_diameters: np.ndarray  # (k,) of each library entry, m
    shape_of_stone: np.ndarray     # (n,)
    layer_of_stone: np.ndarray     # (n,) 0 = first layer
    positions: np.ndarray          # (n, 3)
    quaternions: np.ndarray        # (n, 4) (w, x, y, z) principal frame after a run
    frames: list                   # "shape" (as built) or "principal"
    simulation: object = None      # the last run
    contact_history: object = None  # its contacts (springs, resting depths): the next run's start
    resting_history: object = None  # the contacts at the final poses, for the pack
    summary: dict = field(default_factory=dict)
    set_positions: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    # (n, 3): where each stone was set down (its centroid when lowered, before the layer ran)
    rows: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    # (n,): the grid row of each stone in its layer, 0 the lowest (a toe berm's rows first)
    in_berm: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))
    # (n,): set down in the toe berm (on the bed in front of the toe), not on the face

    def node_sets(self) -> list[np.ndarray]:
        """The world nodes of every stone."""
        return [_nodes_of(self, k) for k in range(len(self.positions))]


def _nodes_of(stones: ArmourStones, k: int) -> np.ndarray:
    shape = stones.shapes[stones.shape_of_stone[k]]
    q = stones.quaternions[k]
    rotation = Rotation.from_quat([q[1], q[2], q[3], q[0]])
    if stones.frames[k] == "shape":
        rotation = rotation * Rotation.from_matrix(shape.frame_rotation)
    return rotation.apply(np.array(shape.mesh.nodes)) + stones.positions[k]


def place_armour_stones(slope, library, underlayer: Underlayer, *, materials, design,
                        s_range, seed: int = 0, **run) -> ArmourStones:
    """Set ``design.layers`` layers of stones of ``library`` (a rock library of the armour
    grading: objects with ``mesh``, ``nominal_diameter``, ``probability``) on the fixed
    ``underlayer`` between ``s_range`` (m along the face), layer by layer, and run each layer
    until at rest. ``materials``: :class:`riprap.placement.place.PlacementMaterials` (the stones
    are of its ``unit`` material). ``run``: :class:`Simulation` settings of each layer's run
    (``output_directory``: each layer's run in ``layer_<k>/`` under it)."""
    rng = np.random.default_rng(seed)
    shapes = [RigidShape.from_mesh(r.mesh, name=f"stone_{k}") for k, r in enumerate(library)]
    probability = np.array([r.probability for r in library], dtype=float)
    probability /= probability.sum()
    grids = [stone_grid(slope, design, s_range, layer) for layer in range(design.layers)]
    total = sum(len(g) for g in grids) + len(underlayer.positions)
    if total > MAXIMUM_BODY_COUNT:
        raise CaseFileError(f"armour stones: {total - len(underlayer.positions):,} stones on "
                            f"{len(underlayer.positions):,} rocks are more than the "
                            f"{MAXIMUM_BODY_COUNT:,} bodies a case may have; a narrower or "
                            "shorter face, or larger stones")
    stones = ArmourStones(shapes=shapes,
                          nominal_diameters=np.array([r.nominal_diameter for r in library]),
                          shape_of_stone=np.zeros(0, np.int64), layer_of_stone=np.zeros(0, np.int64),
                          positions=np.zeros((0, 3)), quaternions=np.zeros((0, 4)), frames=[])
    rock_surfaces = _rock_surfaces(underlayer)
    results = []
    for layer, grid in enumerate(grids):
        _set_down_layer(slope, stones, grid, layer, design, rng, probability, rock_surfaces)
        layer_run = dict(run)
        if "output_directory" in run:
            layer_run["output_directory"] = Path(run["output_directory"]) / f"layer_{layer}"
        sim = _clear_start(slope, stones, underlayer, materials, layer_run, design)
        results.append(sim.run().as_dict())
        stones.contact_history = sim.contact_history()
        first = len(underlayer.positions)
        solver = sim.solver
        stones.positions = solver.positions[first:].copy()
        stones.quaternions = solver.quaternions[first:].copy()
        stones.frames = ["principal"] * len(stones.positions)
        stones.simulation = sim
    stones.resting_history = _resting_history(slope, stones, underlayer, materials, run)
    stones.summary = stone_layer_summary(slope, stones, underlayer, design, s_range)
    stones.summary["runs"] = results
    return stones


def _set_down_layer(slope, stones, grid, layer, design, rng, probability, rock_surfaces) -> None:
    """Draw the layer's stones and lower each onto what is there, lowest first along the face."""
    count = len(grid)
    choice = rng.choice(len(stones.shapes), size=count, p=probability)
    tries = DENSE_ORIENTATION_TRIES if design.placement == "dense" else 1
    orientations = Rotation.random(count * tries, random_state=rng.integers(2 ** 31)).as_quat()
    lowering = VerticalLowering(slope, gap=_RELEASE_GAP * design.dn50,
                                period=slope.width if slope.periodic else 0.0)
    lowering.add(*rock_surfaces)
    lowering.add(*(Surface.from_nodes(_nodes_of(stones, k),
                                      stones.shapes[stones.shape_of_stone[k]].mesh.boundary_faces())
                   for k in range(len(stones.positions))))
    start_height = 2.0 * design.layers * design.dn50 + 2.0 * max(
        s.bounding_radius for s in stones.shapes)
    order = np.lexsort((grid[:, 1], grid[:, 0]))
    # the rows of the grid by their s (a row's points share it exactly: stone_grid)
    _, row_of_point = np.unique(grid[:, 0], return_inverse=True)
    positions, quaternions = [], []
    for k in order:
        shape = stones.shapes[choice[k]]
        faces = shape.mesh.boundary_faces()
        # above the grid point, as a crane holds it: lowered straight down onto the face there
        start = slope.to_world(grid[k, 0], grid[k, 1], 0.0) + np.array([0.0, 0.0, start_height])
        best = None
        for t in range(tries):
            x, y, z, w = orientations[k * tries + t]
            rotation = Rotation.from_quat([x, y, z, w]) * Rotation.from_matrix(shape.frame_rotation)
            nodes = rotation.apply(np.array(shape.mesh.nodes)) + start
            if slope.toe_stop_distance > 0:
                # clear of the toe stop (an upright wall the vertical lowering does not see)
                stop = slope.toe_x - slope.toe_stop_distance + _RELEASE_GAP * design.dn50
                nodes[:, 0] += max(0.0, stop - nodes[:, 0].min())
            surface = Surface.from_nodes(nodes, faces)
            dz = lowering.lower(surface)
            depth = slope.to_slope(surface.moved(dz).points)[:, 2].mean()
            if best is None or depth < best[0]:
                best = (depth, dz, (w, x, y, z), surface, nodes[0] - rotation.apply(
                    np.array(shape.mesh.nodes[0])))
        _, dz, quaternion, surface, centre = best
        lowering.add(surface.moved(dz))
        positions.append(centre + np.array([0.0, 0.0, dz]))
        quaternions.append(quaternion)
    stones.shape_of_stone = np.concatenate([stones.shape_of_stone, choice[order]])
    stones.layer_of_stone = np.concatenate([stones.layer_of_stone, np.full(count, layer)])
    stones.positions = np.vstack([stones.positions, np.array(positions)])
    stones.set_positions = np.vstack([stones.set_positions, np.array(positions)])
    stones.rows = np.concatenate([stones.rows, row_of_point[order]]).astype(np.int64)
    stones.in_berm = np.concatenate([stones.in_berm, grid[order, 0] < 0.0])
    stones.quaternions = np.vstack([stones.quaternions, np.array(quaternions)])
    stones.frames = stones.frames + ["shape"] * count


def _resting_history(slope, stones, underlayer, materials, run) -> ContactHistory:
    """The contacts of the placed layer at its final poses, for the pack: the last run's springs,
    each pair's overlap measured again at the poses written (the run's last contact list is a
    step older than its last poses, and a stone still creeping at the rest speed is a few
    micrometres further in), the deeper of a pair's two orders, every touching pair listed
    (the lower body first, walls second), so that ``riprap run`` of the pack accepts what rests
    and refuses only a body moved into another."""
    carried = stones.contact_history
    probe = _layer_simulation(slope, stones, underlayer, materials, run)
    probe.build_without_checks()
    depths: dict = {}
    for i, j, depth in probe.solver.overlaps(0.0):
        pair = (i, j) if j < 0 else (min(i, j), max(i, j))
        depths[pair] = max(depth, depths.get(pair, 0.0))
    listed = list(zip(carried.body_i.tolist(), carried.body_j.tolist()))
    extra = [pair for pair in depths if pair not in set(listed)]
    return ContactHistory(
        np.concatenate([carried.body_i, np.array([p[0] for p in extra], dtype=np.int64)]),
        np.concatenate([carried.body_j, np.array([p[1] for p in extra], dtype=np.int64)]),
        np.vstack([carried.springs, np.zeros((len(extra), 6))]),
        [max(depths.get(pair, 0.0), float(d)) for pair, d in zip(listed, carried.overlap_depths)]
        + [depths[pair] for pair in extra])


def _clear_start(slope, stones, underlayer, materials, run, design) -> Simulation:
    """The layer's run, its stones lifted off what they start overlapping: the lowering samples
    a stone's surface at points, and two edges crossing between the points can leave a stone a
    few micrometres into its neighbour; such a stone is raised by twice that and tried again."""
    first = len(underlayer.positions)
    for attempt in range(_MAX_LIFTS + 1):
        sim = _layer_simulation(slope, stones, underlayer, materials, run)
        sim.build_without_checks()
        solver = sim.solver
        tolerance = START_OVERLAP_FRACTION * min(s.min_subtet_height for s in solver.shapes)
        new = stones.layer_of_stone == stones.layer_of_stone.max()
        lifts, off_walls = {}, set()
        for i, j, depth in solver.overlaps(tolerance):
            # only the layer just set down is lifted (the layers below rest pressed together,
            # as contacts at rest do); of two new stones the later one
            candidates = [b - first for b in (i, j) if b >= first and new[b - first]]
            if candidates:
                stone = max(candidates)
                lifts[stone] = max(lifts.get(stone, 0.0), depth)
                if j < 0:
                    off_walls.add(stone)
        if not lifts:
            resting = {}
            for i, j, depth in solver.overlaps(0.0):
                if not any(b >= first and new[b - first] for b in (i, j)):
                    # either order: the next run lists a pair as the carried contacts list it
                    deepest = max(depth, resting.get((i, j), 0.0))
                    resting[(i, j)] = resting[(j, i)] = deepest
            sim = _layer_simulation(slope, stones, underlayer, materials, run)
            # the layers below rest pressed on each other and on the rocks as they came to rest
            carried = dict(sim.accepted_overlaps)
            sim.accepted_overlaps = {pair: max(depth, carried.get(pair, 0.0))
                                     for pair, depth in {**carried, **resting}.items()}
            return sim
        reach = 2.0 * max(s.bounding_radius for s in stones.shapes)
        moves = np.zeros(len(stones.positions))
        sideways = np.zeros(len(stones.positions), dtype=bool)
        for k in sorted(lifts):
            # its own lift on top of what it is carried up by (a stone below it lifted)
            total = moves[k] + 2.0 * lifts[k] + _RELEASE_GAP * design.dn50 * 2.0 ** attempt
            moves[k] = total
            sideways[k] = k in off_walls
            # the stones set down after this one within reach of it may rest on it (each was
            # lowered onto those before it), and others on them: they go up with it, or each
            # lift would push into the next stone up the face
            group = [k]
            for m in np.flatnonzero(new & (np.arange(len(new)) > k)):
                if np.min(np.linalg.norm(stones.positions[group, :2] - stones.positions[m, :2],
                                         axis=1)) <= reach:
                    group.append(int(m))
            moves[group[1:]] = np.maximum(moves[group[1:]], total)
        stones.positions[:, 2] += moves
        # the toe stop stands upright: a stone pressed into it goes up the slope too
        stones.positions[sideways, 0] += moves[sideways]
    raise CaseFileError(f"armour stones: stones {sorted(lifts)[:10]} still overlap after being "
                        f"lifted {_MAX_LIFTS} times; the grid is too dense for these stones")


def _layer_simulation(slope, stones, underlayer, materials, run) -> Simulation:
    sim = on_underlayer(slope, underlayer, materials, run, stones.shapes)
    for k in range(len(stones.positions)):
        sim.add_body(shape=stones.shapes[stones.shape_of_stone[k]].name,
                     material=materials.unit.name, position=stones.positions[k],
                     orientation=stones.quaternions[k], frame=stones.frames[k])
    if stones.contact_history is not None:
        # the layers below carry their contacts over: their friction, and their resting overlaps
        # accepted at the start (bodies keep their numbers; the new stones come after them)
        sim.set_contact_history(stones.contact_history)
    return sim


def stone_layer_summary(slope, stones: ArmourStones, underlayer: Underlayer,
                        design: StoneLayerDesign, s_range) -> dict:
    """The placed layer beside its design: stones per area, layer thickness and its k_t, bulk
    porosity, over the face between a D_n50 inside the lowest and the highest stone centroids,
    with the placed stones' own D_n50 (as a laboratory measures the stones it placed; the
    grading's is ``design.dn50``)."""
    dn50 = design.dn50
    volumes = np.array([float(stones.shapes[c].mesh.volumes().sum())
                        for c in stones.shape_of_stone])
    # D_n50 of the volumes: any density gives the same (masses and density cancel)
    placed_dn50 = grading_statistics(2650.0 * volumes, density=2650.0).dn50
    face = ~stones.in_berm
    nodes = stones.node_sets()
    measured = {"dn50_m": placed_dn50, **layer_metrics.stone_layer_figures(
        slope, stones.positions[face], [n for n, ok in zip(nodes, face) if ok], volumes[face],
        dn50=placed_dn50, layers=design.layers, underlayer_level=underlayer.top_level)}
    if stones.in_berm.any():
        # the berm's top above the bed: the highest point of each berm stone's nodes above the
        # bed, the upper half's mean (as a staff's foot on the higher stones)
        levels = np.array([nodes[k][:, 2].max() for k in np.flatnonzero(stones.in_berm)])
        levels = levels - slope.toe_level
        upper = levels[levels >= np.median(levels)]
        measured["toe_berm"] = {
            "stones": int(stones.in_berm.sum()),
            "top_above_bed_m": float(upper.mean()),
            "design_top_above_bed_m": design.layer_thickness,
            # berm stones that ended on the face (their centroid half a D_n50 past the toe)
            "stones_off_the_bed": int(sum(
                1 for k in np.flatnonzero(stones.in_berm)
                if stones.positions[k, 0] > slope.toe_x + 0.5 * dn50))}
    return {"design": {"dn50_m": dn50, "layers": design.layers, "placement": design.placement,
                       "toe_berm_width_m": design.toe_berm_width,
                       "layer_thickness_coefficient": design.layer_thickness_coefficient,
                       "porosity": design.porosity, "layer_thickness_m": design.layer_thickness,
                       "stones_per_area": design.stones_per_area,
                       "sources": "k_t: The Rock Manual (2007) p. 126; porosity: Shore "
                                  "Protection Manual (1984) Table 7-13"},
            "measured": measured}
