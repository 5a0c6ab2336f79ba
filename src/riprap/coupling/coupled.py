"""Two-way coupling of rigid bodies and the air-water flow: one step of both.

Method (``docs/coupling.md``): the rigidity-constraint projection of Sharma & Patankar (2005) on
riprap's staggered grid, with exact solid fractions. The whole box is one fluid whose density on a
face holds the fluid's share and the bodies' (by the exact solid fraction of the face's control
volume), each moved by the pressure at its own density; the projection moves body and fluid
inertia together, so no added-mass
instability appears at any density ratio; after it, each body's region is made rigid with the
motion that conserves the momentum and angular momentum of body and fluid together. The force of
the fluid on a body is the momentum this gives it, so the two sides' forces are equal and opposite
by construction. Within a fluid step the bodies take several contact sub-steps with the fluid's
force of the previous step held.

One step of :meth:`CoupledSolver.step`:

1. the solid volume of every body in every cell, at the present poses;
2. the fluid predictor (water, momentum, viscosity, gravity, surface tension);
3. each body's faces take the motion the body would have after falling freely for the step
   (blend by solid fraction); the shares' summed inverse densities go into the projection;
4. each free body's rigid motion from its 6 x 6 momentum system; the fluid's load on every body
   (its own momentum change, or what holding a fixed body still takes); the final blend;
5. the bodies move over the step in contact sub-steps with gravity, contacts and that load held:
   without contacts they end with exactly the motion of step 4. The fluid meets what contacts
   changed at the next step's blend, whose momentum bookkeeping keeps the sum exact.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from riprap.coupling.kernels import rigid_coupling
from riprap.coupling.solid_volumes import (add_block, merge_blocks, rigid_body_half_cell_volumes,
                                           widened_strip)
from riprap.errors import CaseFileError, InstabilityError
from riprap.fluid.kernels.face_speeds import limit_listed_faces, listed_pore_speed
from riprap.fluid.solver import FluidSolver
from riprap.solid.solver import SolidSolver
from riprap.solid.stability import contact_stability_rate, motion_limited_step
from riprap.solid.walls import Wall

#: A cell counts as filled by fixed bodies when they hold all but this share of it.
_FULL_SLACK = 1e-9
#: A cell and its six face neighbours.
_FACE_NEIGHBOURS = np.array([[[0, 0, 0], [0, 1, 0], [0, 0, 0]],
                             [[0, 1, 0], [1, 1, 1], [0, 1, 0]],
                             [[0, 0, 0], [0, 1, 0], [0, 0, 0]]], dtype=bool)

__all__ = ["CoupledSolver", "CoupledStepReport", "fluid_box_walls", "MINIMUM_CELLS_ACROSS",
           "MINIMUM_DENSITY_RATIO", "MAXIMUM_SUBSTEPS"]

#: A free body must be at least this fraction of the water's density. Measured (2026-11-27) on a
#: 0.06 m cube released in still water, 3 cells across, over 0.04 s: at 0.7, 0.5 and 0.3 of the
#: water's density it rises at 0.10, 0.16 and 0.17 g; at 0.2 at 0.08 g; at 0.15 it sinks (0.07 g)
#: and at 0.001 it sinks at 13 g, the fluid's load held over each step then far exceeding what the
#: body's own inertia can carry; at 0.0001 it blows up.
MINIMUM_DENSITY_RATIO = 0.3
#: Contact sub-steps in one fluid step beyond which a run stops: the fluid's load is held over
#: them all, and a body this light or stiff against its fluid step is not resolved by the coupling.
MAXIMUM_SUBSTEPS = 100_000

#: Adaptive contact sub-step (``CoupledSolver(adaptive_substep=True)``): each fluid step the
#: sub-step grows by at most SUBSTEP_GROWTH towards the step at which the contacts present have a
#: measured stability ratio dt / (2 sqrt(m/k)) of SUBSTEP_TARGET_RATIO (1 is the limit of an
#: undamped spring; the rigid model cuts its step above 0.5 and grows it below 0.2), and is cut
#: to it at once when the contacts stiffen; no body moves more than a tenth of its thinnest
#: boundary sub-tet in one (``riprap.solid.stability``); never above SUBSTEP_MAX_OVER_ESTIMATE
#: times the bodies' conservative estimate (a face-to-face contact at the thinnest sub-tet, the
#: automatic step). Measured on examples/10's pack at rest: ratio 0.054 at 1.5e-4 s.
SUBSTEP_TARGET_RATIO = 0.25
SUBSTEP_GROWTH = 1.25
SUBSTEP_MAX_OVER_ESTIMATE = 30.0

#: What the fluid's share of a face a body cuts keeps after a step (docs/coupling.md, Cut faces
#: and the step). "own_velocity" (the default since issue 51): the fluid's own velocity, taken
#: towards the body's at a rate per second (``rigid_coupling.cut_face_grip``: the flow through
#: the face and the shear of the wall that ``rigid_coupling.wall_geometry`` finds in it), and the
#: predictor's change of the bodies' faces counted in the bodies' frame
#: (``_in_the_bodies_frame``): a towed cube's drag at 3 cells per side changes 4 % for a step
#: four times shorter, 0.91 of the dynamic pressure against Hoerner's 1.05. "mixture": the
#: face's one projected velocity, taken a fraction phi of the way to the body's motion every
#: step, whose load on a moving body grows as the step shrinks (the towed cube: C_D 1.47 and
#: 1.73 at Courant numbers 0.2 and 0.05); kept for the deformable bodies' coupling and for runs
#: started with it.
CUT_FACE_TREATMENTS = ("mixture", "own_velocity")
#: With "own_velocity", a face whose fluid share is below this is filled by the bodies in the
#: bodies' frame (``_in_the_bodies_frame``): a share of 1e-15 (phi's round-off) took the
#: bodies' change divided by it, and runs split over processes (whose phi differ in the last
#: bit) parted by 1e-5 of the velocity.
FILLED_SHARE = 1e-6
#: With "own_velocity", on a face no single wall plane describes (a film between two bodies):
#: the viscous renewal rate of its fluid is this times nu / d^2, d = (1 - phi) h the face's
#: open width: the wall shear mu u / (d / 2) on a film of thickness d at its mean velocity u
#: gives 2 nu / d^2 (``rigid_coupling.cut_face_grip``).
VISCOUS_RENEWAL = 2.0
#: A moving body must span at least this many cells (by its nominal diameter, V^(1/3)): at 3
#: the ten Cate sphere (4 cells across its diameter, nominal diameter 3.2 cells) still settles
#: within 9 % of the experiment; below that its forces are noise.
MINIMUM_CELLS_ACROSS = 3.0
#: A body is clipped against the grid again once some point of it may have moved more than this
#: fraction of a cell since it was last clipped. Why not on every move: units resting or rocking
#: in the flow move microns per step, and clipping them again costs more than the rest of the
#: exchange; a lag of at most 1e-3 h changes a face's solid fraction by at most about 1e-3
#: (docs/coupling.md, Speed).
RECLIP_DISTANCE = 1e-3


def _same_plane(a, b, tolerance: float = 1e-9) -> bool:
    """Whether two walls are the same half-space (same outward normal, same plane)."""
    normal_a, normal_b = np.asarray(a.normal, float), np.asarray(b.normal, float)
    if np.linalg.norm(normal_a - normal_b) > tolerance:
        return False
    return abs(float(np.dot(np.asarray(a.point, float) - np.asarray(b.point, float), normal_a))) <= tolerance


def check_substeps(substeps: int, fluid_step: float, contact_step: float) -> None:
    """Stop a coupled run whose fluid step needs more than MAXIMUM_SUBSTEPS contact sub-steps."""
    if substeps > MAXIMUM_SUBSTEPS:
        raise InstabilityError(
            f"the fluid step of {fluid_step:.3g} s needs {substeps:.3g} contact sub-steps of "
            f"{contact_step:.3g} s, more than {MAXIMUM_SUBSTEPS:,}: the bodies are far too light or "
            "stiff for the flow's step; check [[materials]] density and contact_penalty, or lower "
            "[fluid] max_time_step")


def fluid_box_walls(grid, material: str) -> list:
    """The sides of the fluid box as walls for the bodies (an open top is not a wall, nor are a
    periodic strip's y sides)."""
    walls = []
    for axis in range(3):
        for side, (point, sign) in enumerate(((grid.lower, 1.0), (grid.upper, -1.0))):
            if axis == 2 and side == 1 and grid.open_top:
                continue
            if axis == 1 and grid.periodic_y:
                continue
            normal = [0.0, 0.0, 0.0]
            normal[axis] = sign
            walls.append(Wall(point=tuple(point), normal=tuple(normal), material=material))
    return walls


@dataclass
class CoupledStepReport:
    """What one coupled step did (the fluid's report plus the solids')."""

    time: float
    time_step: float
    courant_number: float
    pressure_iterations: int
    water_volume_error: float
    solid_substeps: int
    max_body_speed: float


@dataclass(frozen=True)
class _FaceSet:
    """The faces the bodies touch in one step (``rigid_coupling.touched_faces``): every per-face
    quantity of the coupling is an array over these F faces."""

    axis: np.ndarray          # (F,) 0, 1, 2
    index: np.ndarray         # (F, 3) index in the face array of its axis
    phi: np.ndarray           # (F,) summed body fractions
    capped: np.ndarray        # (F,) min(phi, 1)
    interior: np.ndarray      # (F,) not a wall face
    entries: tuple            # (entry_start (bodies + 1,), entry_face (E,), entry_half (E,))

    def empty(self) -> np.ndarray:
        return np.empty(len(self.axis))

    def zeros(self) -> np.ndarray:
        return np.zeros(len(self.axis))

    def gather(self, arrays, out) -> None:
        rigid_coupling.gather(self.axis, self.index, *arrays, out)

    def scatter(self, values, arrays) -> None:
        rigid_coupling.scatter(self.axis, self.index, values, *arrays)


class CoupledSolver:
    """A :class:`FluidSolver` and a :class:`SolidSolver` that push each other.

    Parameters
    ----------
    fluid : FluidSolver
    solids : SolidSolver
        With its shapes, materials, bodies and walls; its gravity should equal the fluid's.
    solid_time_step : float, optional
        Contact sub-step (s); default the solids' automatic step.
    wall_material : str, optional
        Material of the fluid box's sides as walls for the bodies (every side but an open top);
        default the first material. None: add no walls (the caller's walls bound the bodies).
    check_momentum : bool
        Measure every step how far the exchange is from conserving momentum
        (``last_exchange_balance``; a few whole-grid passes, so off unless asked for).
    obstacle_bodies : sequence of int
        Fixed bodies that stand for the fluid's obstacles (``riprap.coupling.obstacles``): the
        fluid already holds their cells still, so the exchange leaves them out.
    adaptive_substep : bool
        Let the contact sub-step follow the contacts present (``SUBSTEP_TARGET_RATIO``), starting
        from ``solid_time_step``, instead of keeping it.
    """

    def __init__(self, fluid: FluidSolver, solids: SolidSolver, *, solid_time_step: float | None = None,
                 wall_material: str | None = "", check_momentum: bool = False,
                 obstacle_bodies=(), adaptive_substep: bool = False,
                 cut_faces: str = "own_velocity"):
        if not np.allclose(fluid.gravity, solids.gravity):
            raise CaseFileError(f"coupling: the fluid's gravity {fluid.gravity.tolist()} differs from "
                                f"the bodies' {solids.gravity.tolist()}")
        if cut_faces not in CUT_FACE_TREATMENTS:
            raise CaseFileError(f"coupling: cut_faces = {cut_faces!r} must be one of "
                                f"{', '.join(map(repr, CUT_FACE_TREATMENTS))}")
        self.fluid = fluid
        self.solids = solids
        #: What the fluid's share of a cut face keeps after a step (``CUT_FACE_TREATMENTS``).
        self.cut_faces = cut_faces
        self.check_momentum = bool(check_momentum)
        #: Momentum after the last exchange less before less the walls' pressure impulse (N s),
        #: with ``check_momentum``; None otherwise.
        self.last_exchange_balance = None
        if fluid.periodic_y:
            # the bodies live on the fluid's strip: they wrap and meet across its sides too
            strip = fluid.grid.whole_grid
            if solids.periodic is None:
                try:
                    solids.set_periodic(1, strip.lower[1], strip.upper[1])
                except CaseFileError as error:
                    raise CaseFileError(f"coupling: the bodies on the fluid's periodic strip "
                                        f"([fluid] y_low = y_high = \"periodic\", y "
                                        f"{strip.lower[1]:g} .. {strip.upper[1]:g} m): "
                                        f"{error}") from None
            elif solids.periodic != (1, strip.lower[1], strip.upper[1]):
                raise CaseFileError(f"coupling: the bodies are periodic as {solids.periodic}, the "
                                    f"fluid's strip is y {strip.lower[1]:g} .. "
                                    f"{strip.upper[1]:g} m")
        elif solids.periodic is not None:
            raise CaseFileError(f"coupling: the bodies are periodic ({solids.periodic}) in a fluid "
                                "box with walls: make the fluid's y sides periodic too")
        if wall_material is not None:
            # A side that is already a wall (a pack's flume walls, its bed) is not added twice:
            # two coincident walls would push twice.
            solids.add_walls([wall for wall in fluid_box_walls(fluid.grid,
                                                               wall_material or solids.materials[0].name)
                              if not any(_same_plane(wall, other) for other in solids.walls)])
        solids.finalize()
        self.solid_time_step = float(solid_time_step or solids.time_step)
        self.adaptive_substep = bool(adaptive_substep)
        #: The adaptive sub-step's ceiling (s): SUBSTEP_MAX_OVER_ESTIMATE times the bodies'
        #: conservative estimate.
        self.substep_ceiling = (SUBSTEP_MAX_OVER_ESTIMATE * solids.stable_time_step()
                                if self.adaptive_substep else math.inf)
        #: The contacts' measured stability ratio at the last step's sub-step (0: no contact).
        self.last_stability_ratio = 0.0
        # the contacts' stability rate a restart takes from its checkpoint (used once)
        self._restored_contact_rate = None
        n = solids.n_bodies
        #: Force (3) and torque (3) of the fluid on every body over the last step (N, N m).
        self.fluid_loads = np.zeros((n, 6))
        grid = fluid.grid
        self._lower = np.asarray(grid.lower, dtype=np.float64)
        self._cells = np.asarray(grid.cells, dtype=np.int64)
        #: the strip's period along each axis (m; 0: not periodic): the arms of the bodies' faces
        #: are taken to the image nearest each body (``rigid_coupling.BodyFaces``)
        self._period = np.zeros(3)
        if fluid.periodic_y:
            whole = grid.whole_grid
            self._period[1] = whole.upper[1] - whole.lower[1]
        self._densities = self._body_densities()
        self._blocks = None
        self._block_poses = None
        self._restart_block_poses = None
        self._faces = None
        self._listed = None
        self.obstacle_bodies = np.asarray(obstacle_bodies, dtype=np.int64)
        #: The last step's projected (divergence-free) velocity on its faces: (axis, index,
        #: values), or None before the first step.
        self._carried = None
        #: (the face set, the fluid's own velocity less the mixture on each of its faces) after
        #: the last step: on the same faces as ``_carried``
        self._excess = None
        self._wall = None            # (face set, (wall area, distance)): _wall_geometry
        #: Faces between fixed bodies' cells and their deep cells (made obstacle cells of the
        #: fluid): (body, axis, face index, half cell fraction) arrays; None: none.
        self._shut = None
        if len(self.obstacle_bodies) and not solids.fixed[self.obstacle_bodies].all():
            raise CaseFileError("coupling: obstacle bodies must be fixed")
        self.last_clipped_bodies = 0
        # loads for the outputs (``fixed_body_loads``, ``pressure_loads``, ``viscous_loads``)
        self._free_pressure_loads = np.zeros((n, 6))
        self._pending_fixed_loads = None
        self._loads_for_output = (np.zeros((n, 6)), np.zeros((n, 6)))
        # A face's place in the step's face set while it is built (-1: none); kept between steps
        # so that no grid-sized array is made per step.
        self._slots = np.full(rigid_coupling.face_count(grid.cells), -1, dtype=np.int32)
        #: Wall time (s) of the last step's parts beyond the fluid's own: solid volumes (clipping
        #: the moved bodies and listing the faces they touch), the exchange on those faces
        #: (blends, momentum systems, loads), and the bodies' contact sub-steps.
        self.last_solid_volume_seconds = 0.0
        self.last_exchange_seconds = 0.0
        self.last_solid_seconds = 0.0
        self._check_bodies_in_grid()
        self._close_fixed_interiors()

    def drop_grid_arrays(self) -> None:
        """Let go of the arrays over the grid's faces (a whole grid's coupling on a process
        that steps only its block: ``riprap/models/slab_coupled.py``)."""
        self._slots = None

    # ------------------------------------------------------------------ the run loop's view
    # (riprap.models.fluid.CoupledModel drives a CoupledSolver as FluidModel drives a FluidSolver)
    @property
    def time(self) -> float:
        return self.fluid.time

    @property
    def grid(self):
        return self.fluid.grid

    @property
    def last_pressure_seconds(self) -> float:
        return self.fluid.last_pressure_seconds

    @property
    def last_report(self):
        return self.fluid.last_report

    def stable_time_step(self) -> float:
        """The fluid's stable step, held to its Courant number by the field that carries the
        water too (``_carriers``)."""
        step = self.fluid.stable_time_step()
        if self._carried is not None:
            fluid = self.fluid
            axis, index, values = self._carried
            speed = self._largest(float(listed_pore_speed(fluid.fraction, axis, index, values,
                                                          fluid.open_part, fluid.limit_air_speed,
                                                          fluid.periodic_y)))
            if speed > 0.0:
                step = min(step, self.fluid.courant_number * self.fluid.h / speed)
        return step

    def state_arrays(self) -> dict:
        """Fluid and bodies, and the loads held between them: a restart continues bit for bit."""
        arrays = self.fluid.state_arrays()
        for name, value in self.solids.state_arrays().items():
            arrays[f"bodies_{name}"] = value
        arrays["bodies_fluid_loads"] = self.fluid_loads.copy()
        arrays["bodies_external_loads"] = self.solids.external_loads.copy()
        if self._carried is not None:
            for name, value in zip(("axis", "index", "values"), self._carried):
                arrays[f"coupling_carried_{name}"] = value.copy()
            arrays["coupling_carried_excess"] = self._excess[1].copy()
        if self._block_poses is not None:
            arrays["coupling_block_poses"] = self._block_poses.copy()
        arrays["coupling_substep"] = np.array([self.solid_time_step])
        if self.adaptive_substep:
            # the next sub-step follows the contacts of the last force evaluation, which a
            # checkpoint does not hold (the solids make them again only at their next step)
            arrays["coupling_contact_rate"] = np.array([self._contact_rate()])
        return arrays

    def load_state_arrays(self, arrays: dict) -> None:
        self.fluid.load_state_arrays(arrays)
        self.solids.load_state_arrays({name[len("bodies_"):]: value for name, value in arrays.items()
                                       if name.startswith("bodies_")})
        self.fluid_loads = np.array(arrays["bodies_fluid_loads"], dtype=np.float64)
        self.solids.external_loads[:] = arrays["bodies_external_loads"]
        self._blocks = self._block_poses = self._faces = None
        self._restart_block_poses = (np.array(arrays["coupling_block_poses"], dtype=np.float64)
                                     if "coupling_block_poses" in arrays else None)
        self._carried = (tuple(np.array(arrays[f"coupling_carried_{name}"])
                               for name in ("axis", "index", "values"))
                         if "coupling_carried_axis" in arrays else None)
        self._excess = ((None, np.array(arrays["coupling_carried_excess"], dtype=np.float64))
                        if "coupling_carried_excess" in arrays else None)
        if self.adaptive_substep and "coupling_substep" in arrays:
            self.solid_time_step = float(arrays["coupling_substep"][0])
        self._restored_contact_rate = (float(arrays["coupling_contact_rate"][0])
                                       if "coupling_contact_rate" in arrays else None)

    def start_bodies_at_rest_from(self, arrays: dict) -> None:
        """The bodies where another run's left them (``state_arrays`` of its solids), at rest, in
        this run's fluid: their cells are clipped again at the first step."""
        self.solids.start_at_rest_from(arrays)
        self.fluid_loads[:] = 0.0
        self._blocks = self._block_poses = self._faces = self._restart_block_poses = None
        self._restored_contact_rate = None

    def body_fraction(self) -> np.ndarray:
        """Solid fraction of every cell held by the bodies, at their present poses (nx, ny, nz)."""
        return self._solid_volumes().solid_fraction()

    def body_cells_per_x_plane(self) -> np.ndarray:
        """How many cells of the exchange (cells holding some body, not closed) each x-plane of
        the grid has, at the bodies' present poses: the coupling's work per plane."""
        self._clip_moved_bodies()
        cells = tuple(int(n) for n in self._cells)
        flat = [index for index, _ in self._cell_lists if len(index)]
        if not flat:
            return np.zeros(cells[0])
        return np.bincount(np.concatenate(flat) // (cells[1] * cells[2]),
                           minlength=cells[0]).astype(np.float64)

    # ------------------------------------------------------------------ helpers
    def _solid_volumes(self):
        """Every body's cell volumes (``_clip_moved_bodies``, merged)."""
        self._clip_moved_bodies()
        return merge_blocks(self.fluid.grid, self._blocks)

    def _clip_moved_bodies(self) -> None:
        """Bring every body's block and cell list up to date: a body is clipped again only once
        some point of it has moved more than ``RECLIP_DISTANCE`` cells since it was last clipped
        (fixed bodies once), so the cost follows the moving bodies."""
        solids = self.solids
        now = self._clip_reference()
        clipped = 0
        if self._blocks is None:
            # an obstacle body holds no cells of the exchange: the fluid's own obstacle does
            self._blocks = [None] * solids.n_bodies
            self._cell_lists = [(np.zeros(0, dtype=np.int64), np.zeros((0, 6)))] * solids.n_bodies
            for body in self.obstacle_bodies:
                self._blocks[body] = (np.zeros(3, dtype=np.int64), np.zeros((0, 0, 0)),
                                      np.zeros((0, 0, 0, 3, 2)))
            # a restart clips where the run it continues had clipped last, then, as that run
            # would have, again what has moved too far since (bit for bit)
            restart, self._restart_block_poses = self._restart_block_poses, None
            self._block_poses = (now if restart is None else restart).copy()
            everything = np.setdiff1d(np.arange(solids.n_bodies), self.obstacle_bodies)
            clipped += self._clip_again(everything)
        stale = np.flatnonzero(self._moved_since_clipped(now) > RECLIP_DISTANCE * self.fluid.h)
        if len(self.obstacle_bodies):
            stale = np.setdiff1d(stale, self.obstacle_bodies)
        self._take_reference(stale, now)
        clipped += self._clip_again(stale)
        self.last_clipped_bodies = clipped

    def _moved_since_clipped(self, poses) -> np.ndarray:
        """Per body, a bound on how far any point of it has moved since its last clipping (m):
        its centre's displacement plus the rotation angle times its bounding radius."""
        solids = self.solids
        shift = np.linalg.norm(poses[:, :3] - self._block_poses[:, :3], axis=1)
        alignment = np.abs(np.einsum("bi,bi->b", poses[:, 3:], self._block_poses[:, 3:]))
        angle = 2.0 * np.arccos(np.minimum(alignment, 1.0))
        return shift + angle * solids.bounding_radius[solids.shape_index]

    def _clip_again(self, bodies) -> int:
        """Clip ``bodies`` where ``_block_poses`` puts them; their blocks and cell lists anew."""
        if len(bodies):
            for body, block in zip(bodies, self._clip(bodies)):
                self._blocks[body] = block
                self._cell_lists[body] = self._cell_list(block)
            self._faces = None
        return len(bodies)

    # What the bodies are made of and where their surfaces are: the hooks a coupling of other
    # bodies (riprap.coupling.deformable_coupled) replaces.
    def _body_densities(self) -> np.ndarray:
        solids = self.solids
        return np.array([solids.materials[m].density for m in solids.material_index_of_body],
                        dtype=np.float64)

    def _clip_reference(self) -> np.ndarray:
        """Where the bodies are now, as the clipping remembers it: their poses (bodies, 7)."""
        return np.concatenate([self.solids.positions, self.solids.quaternions], axis=1)

    def _take_reference(self, stale, now) -> None:
        """Remember ``now`` for the bodies about to be clipped again."""
        self._block_poses[stale] = now[stale]

    def _clip(self, stale) -> list:
        """Half-cell volume blocks of the ``stale`` bodies where ``_block_poses`` puts them."""
        return self._clip_on(self.fluid.grid, stale)

    def _clip_on(self, grid, stale) -> list:
        """``_clip`` on the cells of ``grid``. On a periodic y the bodies are clipped on the grid
        widened by a body's reach on either side, so that a body across the boundary keeps all
        of itself: its block's y cells then run past 0 or ny, and its users take them modulo ny
        (the strip's other side: both images of the body)."""
        if not grid.periodic_y:
            return rigid_body_half_cell_volumes(grid, self.solids, bodies=stale,
                                                poses=self._block_poses[stale])
        widened, margin = widened_strip(grid, self.solids)
        blocks = rigid_body_half_cell_volumes(widened, self.solids, bodies=stale,
                                              poses=self._block_poses[stale])
        return [(origin - np.array([0, margin, 0]), volumes, halves)
                for origin, volumes, halves in blocks]

    def _cell_list(self, block):
        """(flat grid index of every cell of a body's block that holds solid and is not an
        obstacle cell of the fluid, their half-cell volumes (n, 6)): what the face set reads, so
        that it visits the cells at a body's surface, not its whole bounding block."""
        (i, j, k), volumes, halves = block
        local = np.flatnonzero(volumes)
        if not len(local):
            return np.zeros(0, dtype=np.int64), np.zeros((0, 6))
        p, q, r = np.unravel_index(local, volumes.shape)
        if self.fluid.periodic_y:
            q = (q + j) % int(self._cells[1]) - j        # the strip's other side
        flat = np.ravel_multi_index((p + i, q + j, r + k), tuple(int(n) for n in self._cells))
        keep = ~self.fluid.solid.reshape(-1)[flat]
        return flat[keep], halves.reshape(-1, 6)[local[keep]]

    def _close_fixed_interiors(self) -> None:
        """Make the deep inside of the fixed bodies obstacle cells of the fluid: cells that fixed
        bodies fill, whose six neighbours they fill too. Nothing moves there, yet a core or a
        mound would otherwise put hundreds of thousands of faces into every step's exchange and
        cells into every pressure solve. The cells at their surface stay in the exchange, so the
        water sees the same solid, and the pressure load on a fixed body still sums to the
        pressure on its surface (``rigid_coupling.touched_faces``). Water that the case put
        inside a fixed body is taken out (before the first step, so the water-volume error
        counts from what is left)."""
        from scipy.ndimage import binary_erosion

        fixed = np.setdiff1d(np.flatnonzero(self.solids.fixed), self.obstacle_bodies)
        if not len(fixed):
            return
        volumes = self._solid_volumes()
        cells = tuple(int(n) for n in self._cells)
        filled = np.zeros(cells)
        for body in fixed:
            add_block(filled, *volumes.block(body), self.fluid.periodic_y)
        full = filled >= (1.0 - _FULL_SLACK) * self.fluid.h ** 3
        if self.fluid.periodic_y:     # the strip's sides are each other's neighbours
            padded = np.pad(full, ((0, 0), (1, 1), (0, 0)), mode="wrap")
            deep = binary_erosion(padded, structure=_FACE_NEIGHBOURS, border_value=1)[:, 1:-1]
        else:
            deep = binary_erosion(full, structure=_FACE_NEIGHBOURS, border_value=1)
        if deep.any():
            self.fluid.add_obstacle_mask(deep | self.fluid.solid)
            self._shut_faces_of(fixed, volumes, deep)
            for body in fixed:     # their cell lists without the cells just closed
                self._cell_lists[body] = self._cell_list(self._blocks[body])
            self._faces = None

    def _carriers(self):
        """The fluid's velocity with the last projected field on the faces the bodies touched:
        what carries the water and the mass (None before the first step: the velocity itself)."""
        if self._carried is None:
            return None
        axis, index, values = self._carried
        carriers = (self.fluid.u.copy(), self.fluid.v.copy(), self.fluid.w.copy())
        rigid_coupling.scatter(axis, index, values, *carriers)
        self.fluid.copy_periodic_faces(carriers[1])
        return carriers

    def _shut_faces_of(self, fixed, volumes, deep) -> None:
        """Per fixed body, the faces between its cells and the deep cells (each with the half
        cell fraction every cell beside it gives it), for ``_shut_face_loads``."""
        body_parts, axis_parts, index_parts, weight_parts = [], [], [], []
        cells = self._cells
        for body in fixed:
            (i, j, k), block = volumes.block(body)
            half_fractions = volumes.halves[6 * volumes.offset[body]:6 * volumes.offset[body + 1]]
            half_fractions = half_fractions.reshape(block.shape + (3, 2)) / self.fluid.h ** 3
            filled = np.argwhere(block > 0.0)
            if not len(filled):
                continue
            for axis in range(3):
                for side in (0, 1):
                    where = filled
                    cell = where + (i, j, k)
                    other = cell.copy()
                    other[:, axis] += 1 if side else -1
                    if self.fluid.periodic_y:
                        cell[:, 1] %= cells[1]
                        other[:, 1] %= cells[1]
                    inside = (other[:, axis] >= 0) & (other[:, axis] < cells[axis])
                    cell, other, where = cell[inside], other[inside], where[inside]
                    across = deep[tuple(cell.T)] != deep[tuple(other.T)]
                    face = (cell if side == 0 else other)[across]
                    body_parts.append(np.full(len(face), body))
                    axis_parts.append(np.full(len(face), axis))
                    index_parts.append(face)
                    weight_parts.append(half_fractions[tuple(where[across].T) + (axis, side)])
        self._shut = (np.concatenate(body_parts), np.concatenate(axis_parts),
                      np.concatenate(index_parts), np.concatenate(weight_parts))

    def _shut_face_loads(self, pressure) -> np.ndarray:
        """Force and torque (bodies, 6) of the pressure on the faces that close the deep cells:
        half a cell fraction times (p below - p above) h^2 on each, the deep cell's pressure
        being 0 (the same on every such face, so that a body's sum still telescopes to the
        pressure on its surface)."""
        body, axis, index, weight = self._shut
        low = index.copy()
        low[np.arange(len(low)), axis] -= 1
        force = weight * (pressure[tuple(low.T)] - pressure[tuple(index.T)]) * self.fluid.h ** 2
        centre = np.asarray(self.grid.lower) + (index + 0.5) * self.fluid.h
        centre[np.arange(len(centre)), axis] -= 0.5 * self.fluid.h
        vectors = np.zeros((len(force), 3))
        vectors[np.arange(len(force)), axis] = force
        arms = centre - self.solids.positions[body]
        if self._period[1] > 0.0:        # to the face's image nearest the body
            arms[:, 1] -= self._period[1] * np.floor(arms[:, 1] / self._period[1] + 0.5)
        moments = np.cross(arms, vectors)
        loads = np.zeros((self.solids.n_bodies, 6))
        for a in range(3):
            loads[:, a] = np.bincount(body, vectors[:, a], minlength=len(loads))
            loads[:, 3 + a] = np.bincount(body, moments[:, a], minlength=len(loads))
        return self._totals(loads)[0]

    def _check_bodies_in_grid(self) -> None:
        """Refuse a body that reaches outside the fluid box, or a moving body narrower than
        ``MINIMUM_CELLS_ACROSS`` cells (its drag and buoyancy would be noise)."""
        self._check_rigid_bodies_in_grid(self.solids)

    def _check_rigid_bodies_in_grid(self, solids) -> None:
        grid = self.fluid.grid
        lower, upper = np.asarray(grid.lower), np.asarray(grid.upper)
        rotations = solids.rotation_matrices()
        table = solids.table
        for b in range(solids.n_bodies):
            s = solids.shape_index[b]
            nodes = (table.nodes[table.node_offset[s]:table.node_offset[s + 1]] @ rotations[b].T
                     + solids.positions[b])
            low, high = nodes.min(axis=0), nodes.max(axis=0)
            if grid.periodic_y:       # across the strip's sides is inside it
                low[1], high[1] = lower[1], upper[1]
            if np.any(low < lower - 1e-12) or np.any(high > upper + 1e-12):
                raise CaseFileError(
                    f"coupling: body {b} reaches {low.round(4).tolist()} .. {high.round(4).tolist()} m, "
                    f"outside the fluid box {list(lower)} .. {list(upper)}; move it inside or "
                    "enlarge the box")
            if solids.fixed[b]:
                continue
            across = solids.shapes[s].volume ** (1.0 / 3.0) / grid.cell_size
            if across < MINIMUM_CELLS_ACROSS:
                raise CaseFileError(
                    f"coupling: body {b} is {across:.2g} cells across (nominal diameter "
                    f"{solids.shapes[s].volume ** (1.0 / 3.0):.3g} m, cells {grid.cell_size:.3g} m); "
                    f"a moving body needs at least {MINIMUM_CELLS_ACROSS} cells across: cells of "
                    f"{solids.shapes[s].volume ** (1.0 / 3.0) / MINIMUM_CELLS_ACROSS:.3g} m or smaller")

    def _world_inertia(self):
        s = self.solids
        rotations = s.rotation_matrices()
        return np.einsum("bij,bj,bkj->bik", rotations, s.principal_inertia, rotations)

    def _motions(self, velocities, angular_momenta, inertia):
        omegas = np.linalg.solve(inertia, angular_momenta[..., None])[..., 0]
        motions = np.concatenate([velocities, omegas], axis=1)
        motions[self.solids.fixed] = 0.0
        return motions

    # ------------------------------------------------------------------ the step
    def _face_set(self) -> _FaceSet:
        """The faces the bodies' cells touch at their present poses, with per body its entries;
        the last step's set while no body has been clipped since (its arrays are only read)."""
        self._clip_moved_bodies()
        if self._faces is not None:
            return self._faces
        lists = self._cell_lists
        counts = [len(index) for index, _ in lists]
        cell_start = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        cell_index = np.concatenate([index for index, _ in lists]).astype(np.int64)
        cell_halves = np.concatenate([halves for _, halves in lists]).reshape(-1, 6)
        (axis, index, phi, interior, entry_start, entry_face,
         entry_half) = rigid_coupling.touched_faces(cell_start, cell_index, cell_halves,
                                                    self.fluid.h ** 3, self._cells,
                                                    self._slots, self.fluid.solid.reshape(-1),
                                                    self.fluid.periodic_y)
        self._faces = _FaceSet(axis=axis, index=index, phi=phi, capped=np.minimum(phi, 1.0),
                               interior=interior, entries=(entry_start, entry_face, entry_half))
        return self._faces

    def _free_cells(self, faces, free):
        """The flat indices of the free bodies' cells, kept with the face set they belong to."""
        if self._listed is None or self._listed[0] is not faces:
            lists = [self._cell_lists[b][0] for b in np.flatnonzero(free)]
            # the pressure solver sorts them and drops repeats (cells two bodies share)
            self._listed = (faces, np.concatenate(lists) if lists else None)
        return self._listed[1]

    def step(self, dt: float | None = None) -> CoupledStepReport:
        fluid, solids = self.fluid, self.solids
        dt, courant = fluid.begin_step(self.stable_time_step() if dt is None else dt)
        if fluid.limit_air_speed and self._carried is not None:
            # the carried air beside the bodies is held to the same cap as the fluid's own faces

            axis, index, values = self._carried
            limit_listed_faces(fluid.fraction, axis, index, values, fluid.open_part,
                               fluid.air_speed_limit(dt), fluid.periodic_y)
        free = ~solids.fixed
        inertia = self._world_inertia()
        # Every body is blended in with the motion it would have after falling freely for dt
        # (a fixed one as if it were a body of the fluid's own density, which water at rest
        # balances exactly); the projection then adds what the fluid does to it.
        # The contact forces of the last sub-step count too, so that a body resting on a wall or
        # on other bodies is not blended in falling into them (the fluid, which cannot drain from
        # a gap thinner than a cell, would then carry it instead of the contact).
        dry = np.where(free[:, None], np.concatenate([solids.forces, solids.torques], axis=1)
                       - solids.external_loads, 0.0)
        predicted = self._motions(solids.velocities + dry[:, :3] * (dt / solids.masses[:, None]),
                                  solids.angular_momenta + dry[:, 3:] * dt, inertia)
        predicted[~free, :3] = fluid.gravity * dt

        started = time.perf_counter()
        faces = self._face_set()
        self.last_solid_volume_seconds = time.perf_counter() - started
        started = time.perf_counter()
        # Only the faces the bodies touch are read and written: elsewhere the blends below leave
        # the fluid's own values (phi = 0 there).
        start_velocity, start_density = faces.empty(), faces.empty()
        faces.gather((fluid.u, fluid.v, fluid.w), start_velocity)
        rigid_coupling.face_mean_density(faces.axis, faces.index, faces.interior, fluid.fraction,
                                         fluid.water.density, fluid.air.density, start_density)
        exchange_seconds = time.perf_counter() - started
        u, v, w, fluid_densities = fluid.predict(dt, advecting=self._carriers())
        started = time.perf_counter()
        fluid_part, rho_fluid = faces.empty(), faces.empty()
        faces.gather((u, v, w), fluid_part)
        faces.gather(fluid_densities, rho_fluid)
        # The face holds the mixture (the predictor moves it as a whole, so that a body's own
        # motion is not carried out of it as fluid momentum); the fluid's share has its own
        # velocity, the mixture's plus the excess the last step left it.
        own_velocity = self.cut_faces == "own_velocity"
        fluid_part_own = fluid_part + self._excess_on(faces) if own_velocity else fluid_part
        densities = np.where(free, self._densities, rigid_coupling.FOLLOWS_FLUID)
        centres = solids.positions
        # What the predictor's fluxes (advection, viscous stress, surface tension) moved across
        # each body's surface is the body's: its faces' momentum change there, less gravity.
        # In a porous zone the predictor gave the pore water the zone's factor of gravity (only the
        # fluid's share moves through the pores; the bodies' shares move as themselves).
        porous = self._porous_factors(faces)
        impulses = (rho_fluid * (fluid_part - porous * fluid.gravity[faces.axis] * dt)
                    - start_density * start_velocity)
        if own_velocity:
            impulses, fluid_part_own = self._in_the_bodies_frame(
                faces, centres, np.where(free[:, None], predicted, 0.0), impulses,
                fluid_part_own, rho_fluid, dt)
        zero = faces.zeros()
        # (only the bodies' own part of the matrices is used here: no grip yet)
        _, body_matrices, transferred = self._momentum_systems(
            faces, centres, densities, rho_fluid, zero, [zero],
            [-impulses * np.maximum(faces.capped, 1e-300)], with_matrices=True)
        transferred = transferred[:, 0]
        predicted_dry = predicted.copy()
        for b in range(solids.n_bodies):
            if np.any(transferred[b]):
                predicted[b] += np.linalg.lstsq(body_matrices[b], transferred[b], rcond=None)[0]
        blended_rigid = faces.zeros()
        rigid_coupling.accumulate_rigid(self._body_faces(faces), centres, predicted, faces.phi,
                                        self._ones(faces), blended_rigid)
        fluid_share = 1.0 - faces.capped
        blended = fluid_share * fluid_part_own + blended_rigid
        # The projection moves each share of a face by the pressure at its own density, so the
        # face's volume flux changes by -dt grad p (1 - phi) / rho_fluid + sum phi_b / rho_b: its
        # coefficient is the shares' inverse densities summed, not one over the mixture's
        # density. With the mixture's, air beside a heavy resting body (a sliver of it on a face
        # makes the face three times as dense) is held up by a third of what holds it up and
        # falls, driving spurious currents (docs/coupling.md).
        inverse_solid = faces.zeros()
        # The fluid's share sees the pressure at the density the fluid solver gives it there
        # (FluidSolver.pressure_densities: water and air by where the interface lies).
        rho_pressure = faces.empty()
        faces.gather(fluid.pressure_densities, rho_pressure)
        inverse_fluid = 1.0 / rho_pressure
        rigid_coupling.accumulate_density(*faces.entries, self._inverse_densities(densities),
                                          faces.phi, inverse_fluid, inverse_solid)
        # In a porous zone the fluid's share's coefficient is scaled by the zone's factor
        # n / (1 + c) / (1 + dt K); a body's share is not.
        inverse_mixture = fluid_share * inverse_fluid * porous + inverse_solid
        faces.scatter(blended, (u, v, w))
        fluid.copy_periodic_faces(v)
        # The fluid's pressure densities of this step are not read again (the fluid's share was
        # gathered above): the touched faces take the shares' in place. (The fluid's face
        # coefficients scale porous faces by the zone's factor once more.)
        faces.scatter(porous / inverse_mixture, fluid.pressure_densities)
        exchange_seconds += time.perf_counter() - started
        betas = fluid._face_coefficients(fluid.pressure_densities)
        # The free bodies' cells get extra smoothing in the pressure solve: a heavy body in air
        # is an island of its own pressure modes that the coarse grids miss.
        pressure, report = fluid.project(u, v, w, betas, dt,
                                         listed_cells=self._free_cells(faces, free))

        started = time.perf_counter()
        projected, pressure_force = faces.empty(), faces.empty()
        faces.gather((u, v, w), projected)
        rigid_coupling.face_pressure_force(faces.axis, faces.index, faces.interior, pressure,
                                           fluid.h, pressure_force)
        # The pressure's load rides along as a second right-hand side with no velocity: the
        # momentum -grad p h^3 over the body's share of its faces (buoyancy and form drag).
        pressure_unaccounted = -pressure_force * np.maximum(faces.capped, 1e-300)
        pressure_impulse = (projected - blended) / inverse_mixture
        # The fluid's share of a cut face ends the step with its own velocity: its predicted one
        # plus the pressure's impulse at its own density, not the face's mixture (which holds the
        # bodies' motion by the fraction phi: kept, it pulled the fluid beside every body a
        # fixed fraction of the way to the body each step, a load growing as 1 / dt). It keeps
        # the part (1 - alpha) of that and takes the bodies' motion for the rest
        # (cut_face_grip, a rate per second): what it lost goes to the bodies.
        if own_velocity:
            fluid_own = fluid_part_own + porous * inverse_fluid * pressure_impulse
            grip = self._grip(faces, centres, predicted, fluid_own, rho_fluid, dt)
        else:   # the face's mixture, taken the fraction phi of the way to the bodies each step
            fluid_own, grip = projected, self._ones(faces)
        matrices, _, pressure_rhs = self._momentum_systems(
            faces, centres, densities, rho_fluid, grip, [zero], [pressure_unaccounted],
            with_matrices=True, bodies=free)
        pressure_rhs = pressure_rhs[:, 0]
        # Each part of a face's momentum after the projection goes to whom it belongs: a body's
        # share moves with its own blended motion plus the pressure's change of the face velocity.
        # The pressure's impulse per unit volume on each face, which each share takes in full.
        # -dt grad p per unit volume on each face: each body's share takes it in full, the
        # fluid's share in a porous zone the zone's factor of it
        kept = 1.0 - grip * faces.capped
        fluid_term = fluid_share * (rho_fluid * (fluid_part_own - kept * fluid_own)
                                    + porous * pressure_impulse)
        rhs = self._own_momentum(faces, centres, predicted, densities, rho_fluid, pressure_impulse,
                                 fluid_term, free)
        final = np.zeros((solids.n_bodies, 6))
        in_fluid = self._bodies_with_faces(faces)
        for b in np.flatnonzero(free):
            if in_fluid[b]:
                final[b] = np.linalg.solve(matrices[b], rhs[b])
            else:   # no face in the fluid (thrown out of the box): it flies on by itself
                final[b] = predicted[b]
        # The fluid's load on a free body: its own momentum change (fixed bodies': _output_loads).
        loads = (rhs - np.einsum("bij,bj->bi", body_matrices, predicted_dry)
                 - np.einsum("bij,bj->bi", matrices - body_matrices, final)) / dt
        gripped = faces.zeros()
        rigid_coupling.accumulate_rigid(self._body_faces(faces), centres, final, faces.phi, grip,
                                        gripped)
        fluid_after = kept * fluid_own + gripped
        after = fluid_after
        if own_velocity:    # the face holds the mixture; the "mixture" treatment's grip is 1
            rigid = faces.zeros()
            rigid_coupling.accumulate_rigid(self._body_faces(faces), centres, final, faces.phi,
                                            self._ones(faces), rigid)
            after = fluid_share * fluid_after + rigid
        faces.scatter(after, (u, v, w))
        fluid.copy_periodic_faces(v)
        # The projected field is divergence free; the water and the mass of the next step move
        # with it (FluidSolver.predict's advecting), not with the rigid motion written above.
        self._carried = (faces.axis.copy(), faces.index.copy(), projected.copy())
        self._excess = (faces, fluid_after - after if own_velocity else faces.zeros())
        if self.check_momentum:
            self.last_exchange_balance = self._exchange_balance(
                faces, fluid_share * rho_fluid, fluid_part_own, fluid_after,
                (fluid_share * porous + faces.capped) * pressure_impulse,
                body_matrices, predicted, final, free)
        exchange_seconds += time.perf_counter() - started
        fluid_report = fluid.finish_step(u, v, w, pressure, report, dt, courant)

        # The bodies then move over the step in contact sub-steps with the fluid's load held:
        # without contacts they end with exactly the motion the projection gave them.
        self.fluid_loads = np.where(free[:, None], loads, 0.0)
        self._free_pressure_loads = np.where(free[:, None], pressure_rhs, 0.0)
        self._pending_fixed_loads = (faces, centres.copy(), densities, rho_fluid, grip, predicted,
                                     pressure_impulse, fluid_term, pressure_unaccounted,
                                     body_matrices, predicted_dry, dt, pressure)
        self.last_exchange_seconds = exchange_seconds
        started = time.perf_counter()
        substeps = self._advance_solids(dt)
        self.last_solid_seconds = time.perf_counter() - started
        speeds = np.linalg.norm(solids.velocities[free], axis=1)
        return CoupledStepReport(time=fluid.time, time_step=dt, courant_number=courant,
                                 pressure_iterations=fluid_report.pressure_iterations,
                                 water_volume_error=fluid_report.water_volume_error,
                                 solid_substeps=substeps,
                                 max_body_speed=float(speeds.max(initial=0.0)))

    def _momentum_systems(self, faces, centres, densities, rho_fluid, grip, velocities,
                          unaccounted, with_matrices=False, bodies=None):
        """(M, the body's own part of M, right-hand sides (bodies, r, 6)) of
        ``rigid_coupling.momentum_systems`` for r right-hand sides at once; ``bodies`` (bool per
        body, default all): the bodies summed, the others left 0."""
        n = self.solids.n_bodies
        matrices, body, rhs = np.zeros((n, 6, 6)), np.zeros((n, 6, 6)), np.zeros((n, len(velocities), 6))
        chosen = np.ones(n, dtype=np.bool_) if bodies is None else np.asarray(bodies, dtype=np.bool_)
        rigid_coupling.momentum_systems(self._summed_faces(faces), centres, densities, faces.phi,
                                        grip, rho_fluid, np.array(velocities),
                                        np.array(unaccounted),
                                        with_matrices, chosen, matrices, body, rhs)
        if with_matrices:
            return self._totals(matrices, body, rhs)
        return (matrices, body) + self._totals(rhs)

    def _in_the_bodies_frame(self, faces, centres, motions, impulses, fluid_part_own, rho_fluid,
                             dt):
        """The predictor's momentum change of the bodies' faces as in the bodies' frame.

        The predictor moves each face's mixture as fluid in the grid's frame, so the bodies'
        share of the faces, held at their velocity, is carried along with them: a face ahead of
        a moving body gains the body's velocity from the face behind it as the body arrives. That
        change, dt (V . grad) u with V the bodies' velocity at the face
        (``rigid_coupling.moving_pattern``), is the body moving, not a force: the bodies' share
        of it is taken out of what the predictor gives them, and the fluid's share of the face
        takes it instead, so the exchange still conserves momentum. Without it a towed cube
        felt a thrust of 0.4-0.55 of the dynamic pressure (bench/unit_loads.py). Fixed bodies
        do not move; faces the bodies fill are left out (no fluid share to take it)."""
        fluid = self.fluid
        vectors = np.zeros((len(faces.axis), 3))
        rigid_coupling.body_velocity_vectors(self._body_faces(faces), centres, motions, faces.phi,
                                             vectors)
        pattern = faces.empty()
        rigid_coupling.moving_pattern(faces.axis, faces.index, vectors, fluid.u, fluid.v, fluid.w,
                                      fluid.h, dt, pattern, fluid.periodic_y)
        # (a face the bodies fill has no fluid share to take it: left as it is; nor one they
        # all but fill, whose share would take the bodies' change over the round-off of phi)
        open_share = 1.0 - faces.capped
        pattern = np.where(open_share > FILLED_SHARE, pattern, 0.0)
        moved = faces.capped * pattern / np.maximum(open_share, 1e-300)
        return impulses + rho_fluid * pattern, fluid_part_own - moved

    def _excess_on(self, faces) -> np.ndarray:
        """The fluid's own velocity less the mixture's on each face of the set, as the last step
        left it (0 on faces it did not touch)."""
        if self._excess is None:
            return faces.zeros()
        last, values = self._excess
        if last is faces:
            return values
        axis, index, _ = self._carried
        keys, wanted = self._face_keys(axis, index), self._face_keys(faces.axis, faces.index)
        order = np.argsort(keys, kind="stable")
        at = np.minimum(np.searchsorted(keys, wanted, sorter=order), len(keys) - 1)
        found = order[at] if len(keys) else at
        out = faces.zeros()
        if len(keys):
            hit = keys[found] == wanted
            out[hit] = values[found[hit]]
        return out

    def _face_keys(self, axis, index) -> np.ndarray:
        """One integer per face (axis, i, j, k) of the grid."""
        nx, ny, nz = (int(n) + 1 for n in self.fluid.fraction.shape)
        return ((axis.astype(np.int64) * nx + index[:, 0]) * ny + index[:, 1]) * nz + index[:, 2]

    @staticmethod
    def _ones(faces) -> np.ndarray:
        return np.ones(len(faces.axis))

    def _grip(self, faces, centres, motions, fluid_part, rho_fluid, dt) -> np.ndarray:
        """Each face's grip alpha / phi over this step (``rigid_coupling.cut_face_grip``): how
        far the fluid's share of a cut face goes towards the bodies' motion, at a rate set by
        the flow through the face and viscous diffusion, not once per step."""
        fluid = self.fluid
        rigid = faces.zeros()
        rigid_coupling.accumulate_rigid(self._body_faces(faces), centres, motions, faces.phi,
                                        self._ones(faces), rigid)
        body_velocity = rigid / np.maximum(faces.capped, 1e-300)
        area, distance = self._wall_geometry(faces)
        grip = faces.empty()
        rigid_coupling.cut_face_grip(faces.phi, fluid_part, body_velocity, rho_fluid,
                                     fluid.water.density, fluid.water.dynamic_viscosity,
                                     fluid.air.density, fluid.air.dynamic_viscosity, fluid.h, dt,
                                     VISCOUS_RENEWAL, area, distance, grip)
        return grip

    def _wall_geometry(self, faces):
        """Per cut face, the bodies' wall in its control volume as a plane: its area (h^2) and
        the fluid's mean distance from it (h) (``rigid_coupling.wall_geometry``), kept while
        the face set is (the bodies have not been clipped again)."""
        if self._wall is not None and self._wall[0] is faces:
            return self._wall[1]
        fluid = self.fluid
        dense = (np.zeros_like(fluid.u), np.zeros_like(fluid.v), np.zeros_like(fluid.w))
        faces.scatter(faces.phi, dense)
        entry_start, entry_face, _ = faces.entries
        owner = np.repeat(np.arange(len(entry_start) - 1), np.diff(entry_start))
        pairs = np.unique(entry_face.astype(np.int64) * len(entry_start) + owner)
        bodies_on_face = np.bincount(pairs // len(entry_start), minlength=len(faces.axis))
        area, distance = faces.empty(), faces.empty()
        rigid_coupling.wall_geometry(faces.axis, faces.index, faces.phi, bodies_on_face, *dense,
                                     area, distance, fluid.periodic_y)
        self._wall = (faces, (area, distance))
        return area, distance

    def _body_faces(self, faces) -> rigid_coupling.BodyFaces:
        """The face set as the coupling kernels take it."""
        return rigid_coupling.BodyFaces(*faces.entries, faces.axis, faces.index, self._lower,
                                        self.fluid.h, self._period)

    # The hooks of a coupling over several processes (riprap.coupling.slab_coupled): which faces
    # each body's sums run over, and how the sums of all processes are added.
    def _summed_faces(self, faces) -> rigid_coupling.BodyFaces:
        """The entries each body's momentum sums run over: all of the set's."""
        return self._body_faces(faces)

    def _summed_face_mask(self, faces) -> np.ndarray:
        """Which faces of the set the sums count (bool per face): all."""
        return np.ones(len(faces.axis), dtype=bool)

    def _totals(self, *arrays) -> tuple:
        """Per-body sums over every process's faces: one process's are whole already."""
        return arrays

    def _largest(self, value: float) -> float:
        """The largest of a value over every process's faces."""
        return value

    def _contact_rate(self) -> float:
        """The contacts' stability rate (``contact_stability_rate``) over every process's."""
        return contact_stability_rate(self.solids)

    def _bodies_with_faces(self, faces) -> np.ndarray:
        """Which bodies have any face in the fluid (bool per body)."""
        return np.diff(faces.entries[0]) > 0

    def _porous_factors(self, faces) -> np.ndarray:
        """The fluid's porous factor (``FluidSolver._porous_factors``) on each face of the set;
        1 outside porous zones."""
        fluid = self.fluid
        factors = np.ones(len(faces.axis))
        if fluid._porous_factors is None:
            return factors
        for axis in range(3):
            listed = fluid.porous.faces[axis]
            if listed.size == 0:
                continue
            on_axis = np.flatnonzero(faces.axis == axis)
            shape = (fluid.u, fluid.v, fluid.w)[axis].shape
            flat = np.ravel_multi_index(tuple(faces.index[on_axis].T), shape)
            where = np.searchsorted(listed, flat)
            inside = where < listed.size
            inside[inside] = listed[where[inside]] == flat[inside]
            factors[on_axis[inside]] = fluid._porous_factors[axis][where[inside]]
        return factors

    @staticmethod
    def _inverse_densities(densities) -> np.ndarray:
        """1 / rho_b per body; ``FOLLOWS_FLUID`` stays (the kernels then take the fluid's)."""
        return np.where(densities < 0.0, densities, 1.0 / np.where(densities < 0.0, 1.0, densities))

    def _own_momentum(self, faces, centres, motions, densities, rho_fluid, pressure_impulse,
                      fluid_term, bodies):
        """``rigid_coupling.own_momentum_rhs`` (bodies, 6) for the chosen bodies (bool each)."""
        rhs = np.zeros((self.solids.n_bodies, 6))
        rigid_coupling.own_momentum_rhs(self._summed_faces(faces), centres, motions, densities,
                                        faces.phi, rho_fluid, pressure_impulse, fluid_term,
                                        np.asarray(bodies, dtype=np.bool_), rhs)
        return self._totals(rhs)[0]

    # ------------------------------------------------------------------ loads for the outputs
    # The loads on fixed bodies (and the pressure/viscous split) only go to the outputs: they are
    # summed from the last step's face values when first asked for, not on every step.
    @property
    def fixed_body_loads(self) -> np.ndarray:
        """What holding each fixed body still took over the last step (N, N m); 0 for free ones."""
        return self._output_loads()[0]

    @property
    def pressure_loads(self) -> np.ndarray:
        """The pressure's part of the fluid's load on every body, fixed ones too (minus the
        pressure gradient over the body's share of every face: buoyancy and form drag)."""
        return self._output_loads()[1]

    @property
    def viscous_loads(self) -> np.ndarray:
        """The rest of the fluid's load on every body: viscous stress, with the momentum of the
        no-slip blend and advection (N, N m)."""
        fixed, pressure = self._output_loads()
        return self.fluid_loads + fixed - pressure

    def _output_loads(self):
        if self._pending_fixed_loads is not None:
            (faces, centres, densities, rho_fluid, grip, predicted, pressure_impulse, fluid_term,
             pressure_unaccounted, body_matrices, predicted_dry, dt,
             pressure) = self._pending_fixed_loads
            self._pending_fixed_loads = None
            fixed = self.solids.fixed
            rhs = self._own_momentum(faces, centres, predicted, densities, rho_fluid,
                                     pressure_impulse, fluid_term, fixed)
            _, _, pressure_rhs = self._momentum_systems(
                faces, centres, densities, rho_fluid, grip, [faces.zeros()],
                [pressure_unaccounted], bodies=fixed)
            # a fixed body ends at rest: its load is the momentum its faces were given, less the
            # fall it was blended in with
            loads = (rhs - np.einsum("bij,bj->bi", body_matrices, predicted_dry)) / dt
            pressure_part = pressure_rhs[:, 0]
            if self._shut is not None:
                shut = self._shut_face_loads(pressure)
                loads += shut
                pressure_part = pressure_part + shut
            self._loads_for_output = (np.where(fixed[:, None], loads, 0.0),
                                      np.where(fixed[:, None], pressure_part,
                                               self._free_pressure_loads))
        return self._loads_for_output

    def _exchange_balance(self, faces, fluid_share, before, after, face_impulse,
                          body_matrices, predicted, final, free) -> np.ndarray:
        """Momentum of fluid and free bodies after the exchange, less before, less the pressure's
        impulse (which only the walls do not return): zero to round-off (N s, per axis). Faces the
        bodies do not touch add nothing (there the fluid's share is the whole face, and the blend
        leaves the velocity as it was), so only the touched faces are summed."""
        volume = self.fluid.h ** 3
        balance = np.zeros(3)
        counted = self._summed_face_mask(faces)
        for a in range(3):
            on = faces.interior & (faces.axis == a) & counted
            balance[a] = volume * (np.sum((fluid_share * (after - before))[on])
                                   - np.sum(face_impulse[on]))
        balance = self._totals(balance)[0]
        bodies = np.einsum("bij,bj->bi", body_matrices[free], final[free] - predicted[free])
        return balance + bodies[:, :3].sum(axis=0)

    def _adapt_substep(self) -> None:
        """The next sub-step of an adaptive run (``SUBSTEP_TARGET_RATIO``), from the contacts and
        speeds the last sub-step left."""
        solids = self.solids
        rate = self._restored_contact_rate
        if rate is None:
            rate = self._contact_rate()
        self._restored_contact_rate = None
        target = SUBSTEP_TARGET_RATIO / rate if rate > 0.0 else math.inf
        self.solid_time_step = min(self.solid_time_step * SUBSTEP_GROWTH, target,
                                   motion_limited_step(solids), self.substep_ceiling)

    def _advance_solids(self, dt: float) -> int:
        solids = self.solids
        if self.adaptive_substep:
            self._adapt_substep()
        substeps = max(1, math.ceil(dt / self.solid_time_step - 1e-9))
        check_substeps(substeps, dt, self.solid_time_step)
        solids.set_time_step(dt / substeps)
        # The last sub-step's forces (used by the first half kick) take the new loads too.
        change = self.fluid_loads - solids.external_loads
        solids.forces += change[:, :3]
        solids.torques += change[:, 3:]
        solids.external_loads[:] = self.fluid_loads
        solids.advance(substeps)
        self.last_stability_ratio = solids.time_step * self._contact_rate()
        return substeps
