"""The one table of every key of a riprap case file (TOML, ``format_version = 1``).

Each :class:`Key` says where the key lives, its kind, unit, default, allowed values and a
one-line meaning. The validator in :mod:`riprap.case.load` and the reference page
``docs/case-file.md`` are both generated from :data:`KEYS` and :data:`TABLES`; nothing about a key
is written down anywhere else. Run ``python -m riprap.schema > docs/case-file.md`` after a
change here (a unit test fails while the page is out of date).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from riprap.work_estimate import MAX_CHECKPOINTS, MAX_FRAMES

__all__ = [
    "FORMAT_VERSION",
    "MINIMUM_QUATERNION_NORM",
    "MINIMUM_DIRECTION_NORM",
    "MINIMUM_BODY_COUNT",
    "MAXIMUM_BODY_COUNT",
    "MAXIMUM_REPORTED_PROBLEMS",
    "REQUIRED",
    "KINDS",
    "Range",
    "Key",
    "Table",
    "TABLES",
    "KEYS",
    "PLAUSIBLE",
    "table",
    "keys_of",
    "key",
    "default_of",
    "describe_expected",
    "format_toml_value",
    "render_markdown",
]

#: The case-file format this version of riprap reads.
FORMAT_VERSION = 1

#: A quaternion shorter than this cannot be normalised reliably into a rotation.
MINIMUM_QUATERNION_NORM = 1e-6

#: A direction (wall normal) shorter than this is treated as the zero vector.
MINIMUM_DIRECTION_NORM = 1e-12

#: A case must create at least this many bodies from ``[[bodies]]`` and ``[[body_grids]]``.
MINIMUM_BODY_COUNT = 1

#: A case may create at most this many bodies: rigid runs step 3e4-6e4 body-steps/s
#: (bench/README.md), so a million bodies take a day for a hundred steps, and their meshes and
#: contact arrays fill the memory long before more is built.
MAXIMUM_BODY_COUNT = 1_000_000

#: At most this many problems are listed in one error message; the rest are counted.
MAXIMUM_REPORTED_PROBLEMS = 20


class _Required:
    """Marker for a key without a default: the case file must give it."""

    def __repr__(self) -> str:
        return "REQUIRED"


#: Default of a key that the case file must give.
REQUIRED = _Required()

#: Value kinds and how they read in the docs and in error messages.
KINDS = {
    "integer": "an integer",
    "number": "a number",
    "boolean": "true or false",
    "string": "a string",
    "vector": "3 numbers [x, y, z]",
    "integer_vector": "3 integers [x, y, z]",
    "quaternion": (
        f"4 numbers [w, x, y, z] (normalised on load; norm >= {MINIMUM_QUATERNION_NORM:g})"
    ),
    "direction": "3 numbers [x, y, z], not all zero (normalised on load)",
    "string_list": "a non-empty list of strings",
    "name_pair": "2 strings [a, b]",
    "body_selection": '"all", or a non-empty list of body indices (integers from 0, in the order '
                      'the case creates its bodies)',
    "path": "a file path (string)",
    "polygon_xz": "a list of at least 3 points [x, z]",
}

_VECTOR_KINDS = frozenset({"vector", "integer_vector", "quaternion", "direction"})


@dataclass(frozen=True)
class Range:
    """An interval of allowed numbers; ``None`` means unbounded on that side.

    For vector kinds the interval applies to each component.
    """

    minimum: float | None = None
    maximum: float | None = None
    minimum_inclusive: bool = True
    maximum_inclusive: bool = True

    def contains(self, value: float) -> bool:
        """Whether ``value`` lies in the interval."""
        if self.minimum is not None:
            if value < self.minimum or (value == self.minimum and not self.minimum_inclusive):
                return False
        if self.maximum is not None:
            if value > self.maximum or (value == self.maximum and not self.maximum_inclusive):
                return False
        return True

    def describe(self) -> str:
        """The interval as an engineer writes it: ``> 0``, ``>= 1``, ``(0, 1]``, ``exactly 1``."""
        low, high = self.minimum, self.maximum
        if low is not None and high is not None:
            if low == high:
                return f"exactly {low:g}"
            left = "[" if self.minimum_inclusive else "("
            right = "]" if self.maximum_inclusive else ")"
            return f"{left}{low:g}, {high:g}{right}"
        if low is not None:
            return f"{'>=' if self.minimum_inclusive else '>'} {low:g}"
        if high is not None:
            return f"{'<=' if self.maximum_inclusive else '<'} {high:g}"
        return "any"


@dataclass(frozen=True)
class Table:
    """A top-level part of the case file.

    Attributes
    ----------
    name : str
        TOML name; ``""`` is the top level itself (keys written before any table header).
    is_array : bool
        True for arrays of tables, written ``[[name]]`` once per entry.
    minimum_count : int
        For arrays, the fewest entries allowed.
    variant_key : str or None
        Name of the key whose value selects extra keys (``type`` for shapes and walls).
    meaning : str
        One line for the docs.
    """

    name: str
    is_array: bool
    minimum_count: int
    variant_key: str | None
    meaning: str

    @property
    def header(self) -> str:
        """How the table is written in TOML: ``[name]``, ``[[name]]``, or ``top level``."""
        if not self.name:
            return "top level"
        return f"[[{self.name}]]" if self.is_array else f"[{self.name}]"


@dataclass(frozen=True)
class Key:
    """One key of the case file.

    Attributes
    ----------
    table : str
        Name of the :class:`Table` holding the key.
    name : str
        TOML key, identical to the Python field or parameter name.
    kind : str
        One of :data:`KINDS`.
    unit : str
        SI unit, ``-`` for dimensionless or not a physical quantity.
    meaning : str
        One line for the docs.
    default : object
        Value used when the key is absent, or :data:`REQUIRED`. Vectors are tuples.
    valid_range : Range or None
        Allowed numbers (each component for vector kinds).
    choices : tuple of str or None
        Allowed strings.
    variant : str or None
        The key exists only when the table's variant key (``type``) has this value.
    references : str or None
        The value (each element for lists) must be the ``name`` of an entry of this table.
    unique : bool
        No two entries of the table may share this value.
    extensions : tuple of str
        Allowed file name endings for ``path`` keys (lower case, with the dot).
    greater_than : str or None
        Name of a vector key of the same entry that this one must exceed in every component.
    plausible : Range or None
        Physically plausible numbers (each component for vector kinds), orders of magnitude
        around real materials, flumes and seas (:data:`PLAUSIBLE`, where each bound's source is
        given): a value outside is refused as a slip (a wrong unit, a stray exponent). 0 passes
        where the key allows it (off, automatic or not given).
    """

    table: str
    name: str
    kind: str
    unit: str
    meaning: str
    default: object = REQUIRED
    valid_range: Range | None = None
    choices: tuple[str, ...] | None = None
    variant: str | None = None
    references: str | None = None
    unique: bool = False
    extensions: tuple[str, ...] = ()
    greater_than: str | None = None
    plausible: Range | None = None

    def implausible(self, value: float) -> bool:
        """Whether ``value`` lies outside the physically plausible range (0 passes where the key
        allows it: off, automatic or not given)."""
        zero_allowed = self.valid_range is not None and self.valid_range.contains(0.0)
        if self.plausible is None or (value == 0 and zero_allowed):
            return False
        return not self.plausible.contains(value)

    @property
    def required(self) -> bool:
        """Whether the case file must give this key."""
        return self.default is REQUIRED

    def allows(self, value: float) -> bool:
        """Whether a number is finite and within :attr:`valid_range` (for the API's own checks of
        a keyword that is this key, so that its range is written here only)."""
        return math.isfinite(value) and (self.valid_range is None
                                         or self.valid_range.contains(value))

    def stated_range(self) -> str:
        """The allowed numbers with the unit, as a message says them: ``in (0, 0.5]``,
        ``>= 0 N/m``, ``> 0 s``."""
        text = self.valid_range.describe() if self.valid_range is not None else "any"
        if text.startswith(("(", "[")):
            text = "in " + text
        return text if self.unit == "-" else f"{text} {self.unit}"

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"schema key {self.table}.{self.name}: unknown kind {self.kind!r}")


_POSITIVE = Range(minimum=0.0, minimum_inclusive=False)
_NON_NEGATIVE = Range(minimum=0.0)
_FRACTION = Range(minimum=0.0, maximum=1.0, minimum_inclusive=False)
_ZERO = (0.0, 0.0, 0.0)
_SHAPE_TYPES = ("sphere", "box", "cube", "random_rock", "tetrapod", "l_shape", "armour_unit",
                "mesh_file")
_WALL_TYPES = ("plane", "box")
#: The regular wave theories of [waves]: each takes height, period and phase.
_REGULAR_WAVES = ("linear", "stokes2", "stream_function")
#: Armour unit kinds of :mod:`riprap.geometry.armour_units` (a test keeps the two lists equal).
UNIT_KINDS = ("core_loc_like", "accropode_like", "xbloc_like", "tetrapod", "cube", "antifer_cube")
_MESH_EXTENSIONS = (".stl", ".obj", ".ply", ".msh", ".vtu")

#: Every table of the case file, in the order the docs list them.
TABLES: tuple[Table, ...] = (
    Table("", False, 1, None, "Keys written before any table header."),
    Table("simulation", False, 1, None, "Clock, time step, gravity, damping and stopping rules."),
    Table("materials", True, 1, None,
          "Contact materials; bodies and walls refer to them by name."),
    Table("friction", True, 0, None,
          "Coulomb friction coefficient of the contacts between two named materials (a material "
          "with itself too), for rigid bodies and walls; each pair once, in either order. A pair "
          "not listed takes the smaller of its two materials' own friction_coefficient. Walls "
          "have materials too (a placement's face_material and side_wall_material). Not for the "
          "materials of deformable bodies (their contact takes the smaller of the two). A case "
          "with `pack` may name the pack's materials; a pack keeps its pairs."),
    Table("shapes", True, 1, "type",
          "Body shapes, meshed into tetrahedra; bodies and grids refer to them by name."),
    Table("bodies", True, 0, None, "Single bodies, each placed by its centroid."),
    Table("body_grids", True, 0, None,
          "Rectangular grids of bodies (counts[0] x counts[1] x counts[2] bodies each)."),
    Table("walls", True, 0, "type",
          "Fixed analytic boundaries; the side the normal points to is free space."),
    Table("slope", False, 0, None,
          "`riprap place` only: the breakwater face, its toe and the flume's side walls. x points "
          "up the slope, y along the breakwater axis, z up."),
    Table("underlayer", False, 0, None,
          "`riprap place` only: graded rocks dropped on the face, then held fixed."),
    Table("armour", False, 0, None, "`riprap place` only: the armour unit placed on the underlayer."),
    Table("armour_stone", False, 0, None,
          "`riprap place` only, instead of [armour] and [placement]: rock armour, graded armour "
          "stones set down stone by stone on a grid across the slope from the toe up, a layer "
          "at a time (docs/rock-armour.md)."),
    Table("placement", False, 0, None,
          "`riprap place` only: where the units start, how they are oriented, when they rest."),
    Table("fluid", False, 0, None,
          "Air and water on a Cartesian grid of cubic cells (`riprap run`): the box, its cells, "
          "its sides, the two fluids and the solver's settings. z is up."),
    Table("water_regions", True, 0, "type",
          "Water at the start: boxes, or everything below a still-water level (`[fluid]` cases)."),
    Table("obstacles", True, 0, "type",
          "Fixed solid boxes in the fluid (every cell whose centre is inside; `[fluid]` cases). "
          "With bodies, each box is also a fixed body of the same cells, so that bodies meet it "
          "(contact, with the first material); a body may not start inside one."),
    Table("waves", False, 0, "type",
          "Waves made in a relaxation zone at the flume's x = lower end and absorbed in one at its "
          "x = upper end (`[fluid]` cases; docs/waves.md). The flume runs along +x over a flat bed "
          "at the fluid box's bottom."),
    Table("gauges", True, 0, "type",
          "Wave gauges (surface elevation) and velocity probes, read after every fluid step and "
          "written to gauges.csv, with the wave analysis in waves_report.json (`[fluid]` cases)."),
    Table("porous_zones", True, 0, "type",
          "Porous media in the flow: a breakwater's core and filter layers (`[fluid]` cases; "
          "Darcy-Forchheimer friction, the water fills only the pores; docs/waves.md, Porous "
          "zones). A later zone replaces an earlier one where they overlap."),
    Table("deformable", False, 0, None,
          "Deformable bodies (`riprap run`): which bodies deform, their elastic material (density, "
          "friction coefficient and restitution are their `[[materials]]` entry's), elements and "
          "contact. The other bodies stay rigid. Explicit finite-strain tetrahedra "
          "(docs/deformable.md); stresses in every frame and units.csv. With `[fluid]` the water "
          "loads their surfaces."),
    Table("series", False, 0, None,
          "A test series (`riprap run` or `riprap series`; docs/campaign.md): the same structure "
          "attacked by the sea states of `[[series_steps]]` one after the other, each step "
          "starting from the bodies' end state of the step before (at rest, contact history "
          "kept) with the water still again, as in a laboratory flume; a survey after every "
          "step and the damage curves at the end. Needs `[fluid]`, irregular `[waves]` and "
          "bodies."),
    Table("series_steps", True, 0, None,
          "The sea states of a `[series]`, in the order they are run, each replacing the "
          "`[waves]` table's significant_height, peak_period, peak_enhancement, seed and "
          "duration; significant heights must rise from step to step."),
    Table("output", False, 1, None, "Where and what riprap writes."),
)

#: Every key of the case file.
KEYS: tuple[Key, ...] = (
    Key("", "format_version", "integer", "-",
        "Version of the case-file format; this riprap reads version 1.",
        valid_range=Range(minimum=FORMAT_VERSION, maximum=FORMAT_VERSION)),
    Key("", "pack", "path", "-",
        "A placed pack (`pack.toml` written by `riprap place`) whose materials, shapes, bodies, "
        "walls and contact history this case takes first; this file adds to them (e.g. [fluid] "
        "and water to put the layer in water). Bodies of this file use its own shapes and "
        "materials.", default="", extensions=(".toml",)),
    # [simulation]
    Key("simulation", "end_time", "number", "s", "Simulated time at which the run stops.",
        valid_range=_POSITIVE),
    Key("simulation", "time_step", "number", "s",
        "Time step; 0 chooses it automatically from the body masses and contact stiffness. A "
        "step at which a contact the bodies can make (a whole face pressed in at the farthest "
        "corner) would pass the stability ratio dt / (2 sqrt(m/k)) = 0.5 is refused.",
        default=0.0, valid_range=_NON_NEGATIVE),
    Key("simulation", "time_step_safety", "number", "-",
        "Fraction of the critical time step used when the time step is automatic.",
        default=0.2, valid_range=_FRACTION),
    Key("simulation", "adaptive_time_step", "boolean", "-",
        "Let the contact step follow the contacts present, by their measured stability ratio "
        "dt / (2 sqrt(m/k)): a dry run grows it below 0.2 and halves it above 0.5; bodies in a "
        "flow take contact sub-steps that grow towards 0.25 and are cut to it at once. Starts "
        "from time_step (or the automatic step); rigid bodies only.", default=False),
    Key("simulation", "gravity", "vector", "m/s^2", "Gravitational acceleration.",
        default=(0.0, 0.0, -9.81)),
    Key("simulation", "output_interval", "number", "s",
        f"Simulated time between two ParaView frames; a run writes at most {MAX_FRAMES:,} "
        "(end_time, or a placement's settle_time, over this).", default=0.05,
        valid_range=_POSITIVE),
    Key("simulation", "checkpoint_interval", "number", "s",
        "Simulated time between checkpoints; 0 writes one only at the end and on failure; at "
        f"most {MAX_CHECKPOINTS:,} in a run.", default=0.0, valid_range=_NON_NEGATIVE),
    Key("simulation", "local_damping", "number", "-",
        "Cundall's non-viscous local damping: numerical damping, not physics; 0 switches it off.",
        default=0.0, valid_range=Range(minimum=0.0, maximum=1.0, maximum_inclusive=False)),
    Key("simulation", "rest_speed", "number", "m/s",
        "If > 0, stop early once every free body is slower than this and its net force under "
        "5 % of its weight; 0 never stops early.",
        default=0.0, valid_range=_NON_NEGATIVE),
    Key("simulation", "seed", "integer", "-",
        "Seed of the random orientations, shape choices and jitter of body grids.",
        default=0, valid_range=_NON_NEGATIVE),
    Key("simulation", "periodic_y_low", "number", "m",
        "The bodies' periodic strip across the flume, its side y = periodic_y_low (with "
        "periodic_y_high): a body leaving at one side comes back at the other and bodies meet "
        "across them (`riprap place` writes it into the pack of a [slope] with sides = "
        "\"periodic\"). Both 0: no strip. With a [fluid] whose y sides are periodic, the strip "
        "is the fluid box's y range and must be that if given.", default=0.0),
    Key("simulation", "periodic_y_high", "number", "m",
        "The strip's other side, y = periodic_y_high > periodic_y_low.", default=0.0),
    Key("simulation", "contact_history", "path", "-",
        "Contacts the bodies start in (written by `riprap place` beside `pack.toml`): their "
        "friction carries over and the overlaps listed there are accepted at the start; "
        "absent: none.", default="", extensions=(".csv",)),
    # [[materials]]
    Key("materials", "name", "string", "-", "Name that bodies and walls use to refer to it.",
        unique=True),
    Key("materials", "density", "number", "kg/m^3", "Mass density.",
        default=2650.0, valid_range=_POSITIVE),
    Key("materials", "friction_coefficient", "number", "-", "Coulomb friction coefficient.",
        default=0.6, valid_range=_NON_NEGATIVE),
    Key("materials", "restitution", "number", "-",
        "Normal coefficient of restitution; sets the contact damping.",
        default=0.5, valid_range=_FRACTION),
    Key("materials", "contact_penalty", "number", "Pa",
        "Penalty of Munjiza's distributed potential contact.",
        default=1.0e9, valid_range=_POSITIVE),
    Key("materials", "tangential_stiffness_ratio", "number", "-",
        "Tangential over normal contact stiffness (2/7 by default).",
        default=2.0 / 7.0, valid_range=_POSITIVE),
    # [[friction]]
    Key("friction", "materials", "name_pair", "-",
        "The two materials in contact (the same name twice: a material on itself).",
        references="materials"),
    # 2 = tan 63 degrees, above any dry contact of concrete, rock, steel or glass (0.2-1.2)
    Key("friction", "friction_coefficient", "number", "-",
        "Coulomb friction coefficient of their contacts (tan of the friction angle).",
        valid_range=Range(minimum=0.0, maximum=2.0)),
    # [[shapes]], keys of every type
    Key("shapes", "name", "string", "-", "Name that bodies and grids use to refer to it.",
        unique=True),
    Key("shapes", "type", "string", "-", "Kind of shape; selects the keys below.",
        choices=_SHAPE_TYPES),
    Key("shapes", "mesh_size", "number", "m",
        "Target tetrahedron edge length; 0 uses the shape's own default.",
        default=0.0, valid_range=_NON_NEGATIVE),
    # [[shapes]] by type
    Key("shapes", "radius", "number", "m", "Sphere radius.",
        valid_range=_POSITIVE, variant="sphere"),
    Key("shapes", "lengths", "vector", "m", "Edge lengths along x, y and z.",
        valid_range=_POSITIVE, variant="box"),
    Key("shapes", "side", "number", "m", "Edge length.", valid_range=_POSITIVE, variant="cube"),
    Key("shapes", "size", "number", "m", "Nominal size (diameter of the generating ellipsoid).",
        valid_range=_POSITIVE, variant="random_rock"),
    Key("shapes", "elongation", "number", "-", "Longest over middle axis of the rock.",
        default=1.0, valid_range=Range(minimum=1.0), variant="random_rock"),
    Key("shapes", "flatness", "number", "-", "Shortest over middle axis of the rock.",
        default=1.0, valid_range=_FRACTION, variant="random_rock"),
    Key("shapes", "seed", "integer", "-", "Seed of the random vertices.",
        default=0, valid_range=_NON_NEGATIVE, variant="random_rock"),
    Key("shapes", "n_vertices", "integer", "-", "Number of vertices of the convex hull.",
        default=24, valid_range=Range(minimum=8), variant="random_rock"),
    Key("shapes", "height", "number", "m", "Overall height of the tetrapod.",
        valid_range=_POSITIVE, variant="tetrapod"),
    Key("shapes", "unit_kind", "string", "-", "Which armour unit (the library of `[armour]`).",
        choices=UNIT_KINDS, variant="armour_unit"),
    Key("shapes", "unit_height", "number", "m", "Height H of the armour unit.",
        valid_range=_POSITIVE, variant="armour_unit"),
    Key("shapes", "length", "number", "m", "Length of each leg of the L.",
        valid_range=_POSITIVE, variant="l_shape"),
    Key("shapes", "width", "number", "m", "Width of the L (extrusion depth).",
        valid_range=_POSITIVE, variant="l_shape"),
    Key("shapes", "thickness", "number", "m", "Thickness of each leg of the L.",
        valid_range=_POSITIVE, variant="l_shape"),
    Key("shapes", "file", "path", "-",
        "Surface or volume mesh, relative to the case file's folder; must exist.",
        extensions=_MESH_EXTENSIONS, variant="mesh_file"),
    Key("shapes", "scale", "number", "-", "Factor applied to the file's coordinates.",
        default=1.0, valid_range=_POSITIVE, variant="mesh_file"),
    # [[bodies]]
    Key("bodies", "shape", "string", "-", "Name of the body's shape.", references="shapes"),
    Key("bodies", "material", "string", "-", "Name of the body's material.",
        references="materials"),
    Key("bodies", "position", "vector", "m", "Position of the body's centroid."),
    Key("bodies", "orientation", "quaternion", "-",
        "Rotation from the shape's own frame as built, as a unit quaternion.",
        default=(1.0, 0.0, 0.0, 0.0)),
    Key("bodies", "velocity", "vector", "m/s", "Initial velocity of the centroid.",
        default=_ZERO),
    Key("bodies", "angular_velocity", "vector", "rad/s",
        "Initial angular velocity, in the world frame.", default=_ZERO),
    Key("bodies", "fixed", "boolean", "-",
        "A fixed body never moves (infinite mass).", default=False),
    # [[body_grids]]
    Key("body_grids", "shapes", "string_list", "-",
        "Names of the shapes placed in the grid.", references="shapes"),
    Key("body_grids", "shape_choice", "string", "-",
        "Assign the shapes to grid points in turn (cycle) or at random (random).",
        default="cycle", choices=("cycle", "random")),
    Key("body_grids", "material", "string", "-", "Name of the material of every body.",
        references="materials"),
    Key("body_grids", "origin", "vector", "m", "Centroid of the first body of the grid."),
    Key("body_grids", "spacing", "vector", "m", "Distance between neighbouring centroids.",
        valid_range=_POSITIVE),
    Key("body_grids", "counts", "integer_vector", "-",
        f"Number of bodies along x, y and z; a case makes at most {MAXIMUM_BODY_COUNT:,} bodies.",
        valid_range=Range(minimum=1)),
    Key("body_grids", "orientation", "string", "-",
        "Orientation of each body: uniform random rotation or the shape's own frame.",
        default="random", choices=("random", "identity")),
    Key("body_grids", "velocity", "vector", "m/s", "Initial velocity of every body.",
        default=_ZERO),
    Key("body_grids", "jitter", "number", "m",
        "Random offset of each centroid, uniform in [-jitter, jitter] per axis.",
        default=0.0, valid_range=_NON_NEGATIVE),
    # [[walls]]
    Key("walls", "type", "string", "-", "Kind of wall; selects the keys below.",
        choices=_WALL_TYPES),
    Key("walls", "material", "string", "-", "Name of the wall's material.",
        references="materials"),
    Key("walls", "point", "vector", "m", "A point on the plane.", variant="plane"),
    Key("walls", "normal", "direction", "-", "Normal of the plane, pointing into the free space.",
        variant="plane"),
    Key("walls", "min", "vector", "m", "Lower corner of the box; the inside is free space.",
        variant="box"),
    Key("walls", "max", "vector", "m", "Upper corner of the box.", variant="box",
        greater_than="min"),
    Key("walls", "open_top", "boolean", "-",
        "Leave out the top plane (5 planes instead of 6).", default=True, variant="box"),
    # [slope]
    Key("slope", "cotangent", "number", "-",
        "cot(alpha) of the face: 1.5 for a 1:1.5 slope.", valid_range=Range(minimum=0.5)),
    Key("slope", "width", "number", "m", "Distance between the flume's side walls.",
        valid_range=_POSITIVE),
    Key("slope", "length", "number", "m", "Length of the face from toe to crest, along the face.",
        valid_range=_POSITIVE),
    Key("slope", "toe_x", "number", "m", "Horizontal position of the toe line.", default=0.0),
    Key("slope", "toe_level", "number", "m", "Level of the toe line and of the bed in front of it.",
        default=0.0),
    Key("slope", "toe_stop_distance", "number", "m",
        "Distance in front of the toe line of a vertical toe stop (the toe structure holding the "
        "lowest row); 0: no stop, units may slide off onto the bed.", default=0.0,
        valid_range=_NON_NEGATIVE),
    Key("slope", "face_material", "string", "-",
        "Material of the face and the bed (the core's surface).", references="materials"),
    Key("slope", "side_wall_material", "string", "-", "Material of the flume's side walls.",
        references="materials"),
    Key("slope", "sides", "string", "-",
        "The flume's sides at y = 0 and y = width: glass walls (side_wall_material), or a "
        "periodic strip standing for a wide flume (the rock lattice and the units' rows continue "
        "across it, units settle against their neighbours' images; the pack runs periodic: "
        "[simulation] periodic_y_low/high, and a [fluid] run needs y_low = y_high = "
        "\"periodic\"). A strip must be at least twice as wide as a unit's bounding diameter.",
        default="walls", choices=("walls", "periodic")),
    # [underlayer]
    Key("underlayer", "material", "string", "-", "Material of the rocks.", references="materials"),
    Key("underlayer", "dn50", "number", "m",
        "Median nominal diameter of the rocks. The filter rule (Rock Manual 2007, ch. 6; CEM part "
        "VI, ch. 5: underlayer stones of W/10 to W/15 of the armour unit's mass W) asks the "
        "armour's Dn / dn50 = 2.15-2.47; riprap warns outside 1.8-3.0 and refuses outside 1.3-4 "
        "(src/riprap/placement/checks.py).",
        valid_range=_POSITIVE),
    Key("underlayer", "dn85_over_dn15", "number", "-",
        "Grading width Dn85 / Dn15 (1 = uniform).", default=1.5, valid_range=Range(minimum=1.0)),
    # Each rock shape is meshed before anything runs (a tenth of a second each): a thousand is
    # already minutes of meshing, far more than a grading needs (6 by default).
    Key("underlayer", "rock_shapes", "integer", "-", "Distinct random rock shapes.", default=6,
        valid_range=Range(minimum=1, maximum=1000)),
    Key("underlayer", "size_classes", "integer", "-",
        "Sizes the grading is represented by (each shape is built at every size); at most "
        "rock_shapes.", default=2, valid_range=Range(minimum=1, maximum=1000)),
    Key("underlayer", "layers", "integer", "-",
        "Rock layers in the start lattice (they settle into a rough bed).", default=2,
        valid_range=Range(minimum=1)),
    Key("underlayer", "from_s", "number", "m", "Lower end of the rock band, along the face.",
        default=0.0),
    Key("underlayer", "to_s", "number", "m",
        "Upper end of the rock band along the face; 0 means the whole face.", default=0.0,
        valid_range=_NON_NEGATIVE),
    Key("underlayer", "settle_time", "number", "s", "Longest simulated time to let the rocks settle.",
        default=2.0, valid_range=_POSITIVE),
    Key("underlayer", "seed", "integer", "-", "Seed of rock shapes, sizes and orientations.",
        default=0, valid_range=_NON_NEGATIVE),
    # [armour]
    Key("armour", "unit", "string", "-", "Kind of armour unit (approximations of the trademarked "
        "shapes, see docs/armour-units.md).", choices=UNIT_KINDS),
    Key("armour", "material", "string", "-", "Material of the units.", references="materials"),
    Key("armour", "height", "number", "m",
        "Unit height H; give exactly one of height, nominal_diameter and mass.", default=0.0,
        valid_range=_NON_NEGATIVE),
    Key("armour", "nominal_diameter", "number", "m", "Nominal diameter Dn = V^(1/3) of a unit.",
        default=0.0, valid_range=_NON_NEGATIVE),
    Key("armour", "mass", "number", "kg", "Mass of a unit (with the material's density).",
        default=0.0, valid_range=_NON_NEGATIVE),
    Key("armour", "mesh_size", "number", "m",
        "Target tetrahedron edge length; 0 uses the unit's own default.", default=0.0,
        valid_range=_NON_NEGATIVE),
    # [armour_stone]
    Key("armour_stone", "material", "string", "-", "Material of the stones.",
        references="materials"),
    Key("armour_stone", "grading", "string", "-",
        "An EN 13383-1 standard grading by name (LMA 5/40, LMA 10/60, LMA 40/200, LMA 15/300, "
        "LMA 60/300, HMA 300/1000, HMA 1000/3000, HMA 3000/6000, HMA 6000/10000, HMA "
        "10000/15000; masses of the prototype, kg), scaled by length_scale; empty: dn50 and "
        "dn85_over_dn15 give the grading.", default=""),
    Key("armour_stone", "dn50", "number", "m",
        "Median nominal diameter D_n50 of the model's stones (without a grading name).",
        default=0.0, valid_range=_NON_NEGATIVE),
    Key("armour_stone", "dn85_over_dn15", "number", "-",
        "Spread D_n85 / D_n15 of the stones (without a grading name; a ratio of diameters).",
        default=1.25, valid_range=Range(minimum=1.0, maximum=5.0)),
    Key("armour_stone", "length_scale", "number", "-",
        "Length scale prototype / model of a named grading (1: the prototype itself); the "
        "stones are scaled keeping H / (Delta D_n), as laboratories scale them.", default=1.0,
        valid_range=Range(minimum=1.0)),
    Key("armour_stone", "prototype_water_density", "number", "kg/m^3",
        "Water density of the prototype (sea water) for the scaling of a named grading.",
        default=1025.0, valid_range=Range(minimum=900.0, maximum=1100.0)),
    Key("armour_stone", "layers", "integer", "-", "Layers of stones (2: a double layer).",
        default=2, valid_range=Range(minimum=1, maximum=2)),
    Key("armour_stone", "placement", "string", "-",
        "standard (each stone set down where it comes, at a random orientation) or dense (each "
        "stone turned to the orientation that sets it deepest into the gaps), the Rock "
        "Manual's two placements.", default="standard", choices=("standard", "dense")),
    Key("armour_stone", "porosity", "number", "-",
        "Design porosity n_v of the layer, which sets the stones per area N_a = n k_t (1 - n_v) "
        "/ D_n50^2 (0.37: Shore Protection Manual 1984, Table 7-13).", default=0.37,
        valid_range=Range(minimum=0.1, maximum=0.6)),
    Key("armour_stone", "stone_shapes", "integer", "-", "Distinct random stone shapes.",
        default=8, valid_range=Range(minimum=1, maximum=64)),
    Key("armour_stone", "size_classes", "integer", "-",
        "Size classes of the grading the shapes stand for (at most stone_shapes).", default=3,
        valid_range=Range(minimum=1, maximum=16)),
    Key("armour_stone", "from_s", "number", "m", "Lower end of the armour along the face.",
        default=0.0, valid_range=_NON_NEGATIVE),
    Key("armour_stone", "to_s", "number", "m",
        "Upper end of the armour along the face; 0: the whole face.", default=0.0,
        valid_range=_NON_NEGATIVE),
    Key("armour_stone", "toe_berm_width", "number", "m",
        "Width of a toe berm of the same stones on the bed in front of the toe, in as many "
        "layers as the slope's (about 3 D_n50: three stones); 0: no berm, the slope's "
        "toe_stop_distance holds the layer. The berm needs [slope] toe_stop_distance at least "
        "this wide (the fixed toe in front of it).", default=0.0, valid_range=_NON_NEGATIVE),
    Key("armour_stone", "settle_time", "number", "s",
        "Longest simulated time to let each layer of stones settle.", default=2.0,
        valid_range=_POSITIVE),
    Key("armour_stone", "seed", "integer", "-", "Seed of stone shapes, choices and orientations.",
        default=0, valid_range=_NON_NEGATIVE),
    # [placement]
    Key("placement", "grid_file", "string", "-",
        "CSV grid of unit centroids (x, y, z; optional qw, qx, qy, qz or roll, pitch, yaw; "
        "vx, vy, vz), relative to the case file; empty: a design grid from the keys below.",
        default=""),
    Key("placement", "rows", "integer", "-", "Rows of units up the face (design grid).",
        default=0, valid_range=_NON_NEGATIVE),
    Key("placement", "units_per_row", "integer", "-",
        "Units in the first and every other row; units_per_row x the unit's Dn must fit across "
        "the section (slope.width).", default=0, valid_range=_NON_NEGATIVE),
    Key("placement", "units_per_alternate_row", "integer", "-",
        "Units in the rows between (staggered, e.g. 11 between rows of 12); 0: the same.",
        default=0, valid_range=_NON_NEGATIVE),
    Key("placement", "packing_density_coefficient", "number", "-",
        "Packing density of the design grid, phi = N Dn^2 / A; 0: the unit's design value. One "
        "layer of units covers the face at most once (cubes face to face: 1), hence at most 1.5.",
        default=0.0, valid_range=Range(minimum=0.0, maximum=1.5)),
    Key("placement", "first_row_s", "number", "m",
        "Position of the first row along the face from the toe; 0: half a unit height.",
        default=0.0, valid_range=_NON_NEGATIVE),
    Key("placement", "release", "string", "-",
        "How units are let go: lowered straight down until they touch the underlayer or a unit "
        "set down before them, then released (as a crane places them), or dropped from their "
        "start positions.", default="on_contact", choices=("on_contact", "free_fall")),
    Key("placement", "drop_height", "number", "m",
        "free_fall from a design grid: how far straight above its design centroid each unit "
        "starts; 0: one unit height.", default=0.0, valid_range=_NON_NEGATIVE),
    Key("placement", "orientation", "string", "-",
        "Unit orientations: uniform random, random within max_tilt_deg of lying on the face, or "
        "from the grid file.", default="random", choices=("random", "random_within", "user")),
    Key("placement", "max_tilt_deg", "number", "deg", "Largest tilt for random_within.",
        default=30.0, valid_range=Range(minimum=0.0, maximum=180.0)),
    Key("placement", "max_spin_deg", "number", "deg",
        "random_within: largest spin about the face normal away from square to the slope (a "
        "unit's sides along and across the slope); 180: any spin. Cubes set square (a few "
        "degrees) fit two to a row where random spins would need 1.4 Dn each.",
        default=180.0, valid_range=Range(minimum=0.0, maximum=180.0)),
    Key("placement", "initial_velocity", "vector", "m/s",
        "Velocity of every unit at the start (deposits faster).", default=_ZERO),
    Key("placement", "deposition", "string", "-",
        "Drop every unit at once, or row by row from the toe up, each row once the rows below rest.",
        default="all_at_once", choices=("all_at_once", "row_by_row")),
    Key("placement", "settle_time", "number", "s",
        "Longest simulated time of the placement run (of each row's run, row by row).",
        default=10.0, valid_range=_POSITIVE),
    Key("placement", "rest_speed", "number", "m/s",
        "Units rest when every one is slower than this (with rotation at its bounding radius) "
        "and its net force is under 5 % of its weight.",
        default=0.02, valid_range=_POSITIVE),
    Key("placement", "rest_kinetic_energy", "number", "J",
        "... and their total kinetic energy is below this; 0: no energy condition.", default=0.0,
        valid_range=_NON_NEGATIVE),
    Key("placement", "local_damping", "number", "-",
        "Settling damping of the deposition runs (numerical, not physics).", default=0.3,
        valid_range=Range(minimum=0.0, maximum=1.0, maximum_inclusive=False)),
    Key("placement", "seed", "integer", "-", "Seed of the random orientations.", default=0,
        valid_range=_NON_NEGATIVE),
    # [fluid]
    Key("fluid", "lower", "vector", "m", "Lower corner of the fluid box."),
    Key("fluid", "upper", "vector", "m", "Upper corner of the fluid box.", greater_than="lower"),
    Key("fluid", "cells", "integer_vector", "-",
        "Cells along x, y, z; cells must be cubes. ny = 1 is a 2D flume (x-z plane).",
        valid_range=Range(minimum=1)),
    Key("fluid", "x_low", "string", "-", "Side x = lower: wall without or with slip.",
        default="no_slip", choices=("no_slip", "free_slip")),
    Key("fluid", "x_high", "string", "-", "Side x = upper.", default="no_slip",
        choices=("no_slip", "free_slip")),
    Key("fluid", "y_low", "string", "-",
        "Side y = lower: a wall, or \"periodic\" with y_high (a strip across the flume that "
        "stands for a wide one: what leaves at one side comes in at the other; ny even, a "
        "multiple of 4 for the pressure's multigrid; the bodies and obstacles see the strip's "
        "images: docs/fluid.md, Periodic strip).", default="no_slip",
        choices=("no_slip", "free_slip", "periodic")),
    Key("fluid", "y_high", "string", "-", "Side y = upper; \"periodic\" with y_low.",
        default="no_slip", choices=("no_slip", "free_slip", "periodic")),
    Key("fluid", "z_low", "string", "-", "The bottom.", default="no_slip",
        choices=("no_slip", "free_slip")),
    Key("fluid", "z_high", "string", "-",
        "The top: open to the atmosphere (pressure 0) or a wall.", default="open",
        choices=("open", "no_slip", "free_slip")),
    Key("fluid", "water_density", "number", "kg/m^3", "Fresh water at 20 C (sea water: 1024.8).",
        default=998.2, valid_range=_POSITIVE),
    Key("fluid", "water_viscosity", "number", "Pa s", "Dynamic viscosity of water at 20 C.",
        default=1.002e-3, valid_range=_POSITIVE),
    Key("fluid", "air_density", "number", "kg/m^3", "Air at 20 C and 1 atm.", default=1.204,
        valid_range=_POSITIVE),
    Key("fluid", "air_viscosity", "number", "Pa s", "Dynamic viscosity of air at 20 C.",
        default=1.825e-5, valid_range=_POSITIVE),
    Key("fluid", "surface_tension", "number", "N/m",
        "Air-water surface tension, clean water at 20 C; 0 leaves it out.", default=0.0728,
        valid_range=_NON_NEGATIVE),
    Key("fluid", "courant_number", "number", "-",
        "Largest max|u| dt / h; the interface advection is bounded up to 0.5.", default=0.3,
        valid_range=Range(minimum=0.0, maximum=0.5, minimum_inclusive=False)),
    Key("fluid", "max_time_step", "number", "s", "Upper bound of the automatic time step.",
        default=0.01, valid_range=_POSITIVE),
    Key("fluid", "limit_air_speed", "boolean", "-",
        "The Courant number taken only where water is, the air away from it capped at the speed "
        "that step carries (breaking waves: the air blown ahead of crests and out of an armour "
        "layer no longer sets the step).", default=False),
    Key("fluid", "pressure_tolerance", "number", "-",
        "Relative residual at which the pressure solve stops.", default=1.0e-8,
        valid_range=Range(minimum=0.0, maximum=1.0e-2, minimum_inclusive=False)),
    Key("fluid", "pressure_volume_tolerance", "number", "-",
        "The pressure solve also stops once no cell's volume changes by more than this fraction "
        "over the step (|div u| dt, the divergence the solve leaves; Basilisk's TOLERANCE); 0 "
        "leaves that test out.", default=0.0,
        valid_range=Range(minimum=0.0, maximum=1.0e-2, maximum_inclusive=False)),
    # The default 0 is "not given" (off); a value given must be > 0 (valid_range).
    Key("fluid", "contact_only_below_cells", "number", "-",
        "Fixed bodies whose nominal diameter V^(1/3) spans fewer cells than this (underlayer "
        "rocks too small for the grid) are contact-only: the free bodies meet them, the flow "
        "does not (not clipped into it, fluid force 0) but sees a porous filter zone in their "
        "place: the case's [[porous_zones]] that hold them, else one riprap fits to them "
        "(porosity 0.4, their Dn50, the default friction; `riprap check` prints it; "
        "docs/waves.md, Filter layers). Between the rocks' size and the free bodies'. Not given "
        "(0): every body is in the flow, and riprap warns of fixed bodies under 4 cells.",
        default=0.0, valid_range=_POSITIVE),
    Key("fluid", "cut_faces", "string", "-",
        "What the water in a cell face a body cuts keeps after a step (docs/coupling.md, Cut "
        "faces and the step). \"auto\" (the default): \"own_velocity\" for rigid bodies, "
        "\"mixture\" for runs with deformable bodies (their coupling has only that). "
        "\"own_velocity\": the water's own velocity, drawn to the body at a rate per second by "
        "the flow through the face and the shear of the body's wall in it, the bodies' faces "
        "counted in their frame: a towed cube's drag changes 4 % for a step 4 times shorter at 3 "
        "cells across (0.91 of the dynamic pressure where Hoerner gives 1.05), ten Cate's "
        "settling sphere within 5 % at 4 cells across. \"mixture\": the face's one velocity of "
        "water and body, taken the body's solid fraction of the way to the body every step, as "
        "riprap did before issue 51: its load on a moving body grows as the step shrinks (the "
        "towed cube's drag 1.47 at 3 cells across, 18 % more at a step 4 times shorter); a run "
        "started with it continues with it only if the case says so.",
        default="auto", choices=("auto", "own_velocity", "mixture")),
    # [[water_regions]]
    Key("water_regions", "type", "string", "-", "Kind of region; selects the keys below.",
        choices=("box", "level")),
    Key("water_regions", "lower", "vector", "m", "Lower corner of the water box.", variant="box"),
    Key("water_regions", "upper", "vector", "m", "Upper corner of the water box.", variant="box",
        greater_than="lower"),
    Key("water_regions", "level", "number", "m", "Still-water level: water everywhere below it.",
        variant="level"),
    # [[obstacles]]
    Key("obstacles", "type", "string", "-", "Kind of obstacle; selects the keys below.",
        choices=("box",)),
    Key("obstacles", "lower", "vector", "m", "Lower corner of the solid box.", variant="box"),
    Key("obstacles", "upper", "vector", "m", "Upper corner of the solid box.", variant="box",
        greater_than="lower"),
    # [waves]
    Key("waves", "type", "string", "-",
        "Wave theory: linear (Airy), stokes2 (Stokes second order), stream_function (fully "
        "nonlinear, Fenton 1988: steep waves, any depth), irregular (JONSWAP sea of linear "
        "components, random phases).",
        choices=("linear", "stokes2", "stream_function", "irregular")),
    Key("waves", "still_water_level", "number", "m",
        "z of the still water surface; the water depth is measured from the box's bottom."),
    Key("waves", "generation", "string", "-",
        "Where the waves are made: relaxation (a zone from x = lower, blended towards the wave) "
        "or boundary (the x = lower boundary imposes the wave's velocity, with active absorption: "
        "no zone, needs an open top).", default="relaxation", choices=("relaxation", "boundary")),
    Key("waves", "active_absorption", "boolean", "-",
        "generation = boundary: the boundary also absorbs the waves that come back to it "
        "(Schaffer & Klopman 2000).", default=True),
    Key("waves", "generation_zone", "number", "m",
        "Length of the generation zone from x = lower; 0: one wave length (generation = "
        "relaxation).", default=0.0, valid_range=_NON_NEGATIVE),
    Key("waves", "absorption_zone", "number", "m",
        "Length of the absorption zone up to x = upper; 0: two wave lengths.", default=0.0,
        valid_range=_NON_NEGATIVE),
    Key("waves", "absorbing_end", "boolean", "-",
        "false: no absorption zone (a structure ends the flume; the generation zone still absorbs "
        "the waves it reflects).", default=True),
    Key("waves", "ramp_periods", "number", "-",
        "Wave periods over which the generated wave grows from still water.", default=2.0,
        valid_range=_NON_NEGATIVE),
    Key("waves", "stop_time", "number", "s",
        "When the wave maker stops (s): the wave fades out over ramp_periods ending then, and the "
        "flume calms (a step of a test series); 0: it makes waves to the end.", default=0.0,
        valid_range=_NON_NEGATIVE),
    *(key
      for variant in _REGULAR_WAVES
      for key in (
          Key("waves", "height", "number", "m", "Wave height H, crest to trough.",
              variant=variant, valid_range=_POSITIVE),
          Key("waves", "period", "number", "s", "Wave period T.", variant=variant,
              valid_range=_POSITIVE),
          Key("waves", "phase", "number", "rad",
              "Phase at the generation zone's inner edge at t = 0.", default=0.0,
              variant=variant))),
    Key("waves", "significant_height", "number", "m", "Spectral significant wave height Hm0.",
        variant="irregular", valid_range=_POSITIVE),
    Key("waves", "peak_period", "number", "s", "Peak period Tp.", variant="irregular",
        valid_range=_POSITIVE),
    Key("waves", "peak_enhancement", "number", "-", "JONSWAP peak enhancement factor gamma.",
        default=3.3, variant="irregular", valid_range=Range(minimum=1.0)),
    Key("waves", "seed", "integer", "-", "Seed of the random phases.", default=0,
        variant="irregular", valid_range=_NON_NEGATIVE),
    Key("waves", "duration", "number", "s",
        "The sea does not repeat within this time (frequency spacing 1/duration); 0: end_time.",
        default=0.0, variant="irregular", valid_range=_NON_NEGATIVE),
    # [[gauges]]
    Key("gauges", "type", "string", "-",
        "surface: elevation above the still water level at (x, y); velocity: (u, v, w) at the "
        "point; overtopping: discharge per metre width through the plane x (the crest's landward "
        "edge) and its volume; run_up: the highest level the water reaches from x to to_x.",
        choices=("surface", "velocity", "overtopping", "run_up")),
    Key("gauges", "name", "string", "-", "Name of the gauge (columns of gauges.csv).",
        unique=True),
    Key("gauges", "position", "vector", "m", "Where the gauge is (a surface gauge uses x and y).",
        variant="surface"),
    Key("gauges", "position", "vector", "m", "The point read.", variant="velocity"),
    Key("gauges", "position", "vector", "m",
        "A point of the plane x = const (the crest's landward edge) at the crest level z (y "
        "unused). The water crossing the plane above the crest's surface there counts: the top "
        "of the obstacles and porous zones beside the plane, found from the geometry, not z; "
        "the flow through a porous crest under its surface does not. z is where the count "
        "starts only where the plane has no obstacle or porous zone, and gives the freeboard Rc "
        "= z - still_water_level of the EurOtop comparison (docs/waves.md).",
        variant="overtopping"),
    Key("gauges", "crest_width", "number", "m",
        "Width G_c of the crest in front of the plane, for EurOtop's crest-width factor C_r = "
        "min(1, 3.06 exp(-1.5 G_c/Hm0)) in a series' comparison; 0: from the top of the placed "
        "layer's face ([slope] of the pack) to the plane, or no factor (C_r = 1) without a "
        "slope. A width under 0.75 Hm0 gives C_r = 1.", default=0.0, variant="overtopping",
        valid_range=_NON_NEGATIVE),
    Key("gauges", "position", "vector", "m",
        "Where the run-up is looked for from (x; y picks the cell row; z unused).",
        variant="run_up"),
    Key("gauges", "to_x", "number", "m", "... up to this x (the top of the slope).",
        variant="run_up"),
    # [[porous_zones]]
    Key("porous_zones", "type", "string", "-",
        "box: an axis-aligned box; polygon: a cross-section in the x-z plane, the same along y.",
        choices=("box", "polygon")),
    Key("porous_zones", "porosity", "number", "-", "Porosity n (volume of pores / total).",
        valid_range=Range(minimum=0.0, maximum=1.0, minimum_inclusive=False,
                          maximum_inclusive=False)),
    Key("porous_zones", "stone_diameter", "number", "m", "Stone diameter D50.",
        valid_range=_POSITIVE),
    Key("porous_zones", "linear_friction", "number", "-",
        "a of the linear (laminar) friction a (1-n)^3/n^3 mu/D50^2.", default=50.0,
        valid_range=_NON_NEGATIVE),
    Key("porous_zones", "quadratic_friction", "number", "-",
        "b of the quadratic (turbulent) friction b (1-n)/n^3 rho/D50 |u|.", default=2.0,
        valid_range=_NON_NEGATIVE),
    Key("porous_zones", "added_mass", "number", "-", "c of the added mass (1 + c)/n.",
        default=0.34, valid_range=_NON_NEGATIVE),
    Key("porous_zones", "part", "string", "-",
        "Which part of the breakwater the zone is: the core (its stone_diameter is the core's "
        "D50 in the rock formulas and the notional permeability; without a core zone the core "
        "is taken as impermeable), a filter, or other.", default="other",
        choices=("core", "filter", "other")),
    Key("porous_zones", "lower", "vector", "m", "Lower corner of the box.", variant="box"),
    Key("porous_zones", "upper", "vector", "m", "Upper corner of the box.", variant="box",
        greater_than="lower"),
    Key("porous_zones", "points", "polygon_xz", "m",
        "Corners [x, z] of the cross-section, in order.", variant="polygon"),
    # [output]
    # [deformable]
    Key("deformable", "bodies", "body_selection", "-", "Which bodies deform.", default="all"),
    Key("deformable", "young_modulus", "number", "Pa", "Young's modulus E (concrete about 30e9).",
        default=30.0e9, valid_range=_POSITIVE),
    Key("deformable", "poisson_ratio", "number", "-", "Poisson's ratio (concrete about 0.2).",
        default=0.2, valid_range=Range(minimum=-1.0, maximum=0.5, minimum_inclusive=False,
                                       maximum_inclusive=False)),
    Key("deformable", "viscosity", "number", "Pa s",
        "eta of the viscous stress 2 eta D (damps the highest element frequencies first).",
        default=0.0, valid_range=_NON_NEGATIVE),
    Key("deformable", "constitutive_model", "string", "-",
        "neo_hookean_seed: the seed paper's eq. 10; neo_hookean and neo_hookean_decoupled: "
        "hyperelastic forms with a stored energy (docs/deformable.md).",
        default="neo_hookean_seed",
        choices=("neo_hookean_seed", "neo_hookean", "neo_hookean_decoupled")),
    Key("deformable", "element_type", "string", "-",
        "tet4: constant-strain tets; tet10: quadratic tets, no locking in bending (contact through "
        "their 8 linear sub-tets). All deformable bodies of a run have the same.", default="tet4",
        choices=("tet4", "tet10")),
    Key("deformable", "tensile_strength", "number", "Pa",
        "Tensile strength the largest principal stresses are compared with in units.csv, and "
        "the joints' with `fracture`; 0: none given.", default=0.0, valid_range=_NON_NEGATIVE),
    Key("deformable", "contact_penalty", "number", "Pa",
        "Penalty of the potential contact between deformable bodies and walls; 0: Young's "
        "modulus.", default=0.0, valid_range=_NON_NEGATIVE),
    Key("deformable", "mass_damping", "number", "1/s",
        "alpha of a force -alpha m v on every node: 0 for physics, a settling aid otherwise.",
        default=0.0, valid_range=_NON_NEGATIVE),
    Key("deformable", "fracture", "boolean", "-",
        "Joints between the tets of the bodies `fracture_bodies` selects: they crack at "
        "`tensile_strength` and break into fragments (docs/fracture.md).", default=False),
    Key("deformable", "fracture_bodies", "body_selection", "-",
        "Which of the deformable bodies crack (case body numbers).", default="all"),
    Key("deformable", "cohesion", "number", "Pa",
        "Shear strength of the joints without normal stress (concrete: about twice the tensile "
        "strength); needed with `fracture`.", default=0.0, valid_range=_NON_NEGATIVE),
    Key("deformable", "friction_angle", "number", "deg",
        "Coulomb friction between the faces of each joint under compression, on top of the "
        "cohesion: the joints' shear strength grows by tan(friction_angle) times the compression, "
        "and the friction part stays once the cohesion has softened.",
        default=30.0, valid_range=Range(minimum=0.0, maximum=90.0, maximum_inclusive=False)),
    Key("deformable", "fracture_energy_mode_i", "number", "J/m^2",
        "Energy a crack dissipates per unit area in opening (concrete: about 100); needed with "
        "`fracture`.", default=0.0, valid_range=_NON_NEGATIVE),
    Key("deformable", "fracture_energy_mode_ii", "number", "J/m^2",
        "Energy a crack dissipates per unit area in sliding (concrete: about 10 times mode I); "
        "needed with `fracture`.", default=0.0, valid_range=_NON_NEGATIVE),
    Key("deformable", "joint_penalty", "number", "Pa",
        "Stiffness of a joint per unit area times its size; 0: ten times `young_modulus` (stiffer "
        "joints shorten the time step).", default=0.0, valid_range=_NON_NEGATIVE),
    Key("deformable", "fracture_region_lower", "vector", "m",
        "Lower corner of the box (at the start) where cracks may run: joints only between tets "
        "whose centroids are inside; default everywhere.", default=(-1.0e9, -1.0e9, -1.0e9)),
    Key("deformable", "fracture_region_upper", "vector", "m",
        "Upper corner of that box.", default=(1.0e9, 1.0e9, 1.0e9),
        greater_than="fracture_region_lower"),
    # [series]
    Key("series", "displacement_threshold", "number", "-",
        "A unit counts as displaced (N_od) once its centroid has moved more than this many "
        "nominal diameters Dn from where the series started (Van der Meer 1988: units moved out "
        "of the layer, about 1 Dn).", default=1.0, valid_range=Range(minimum=0.0, maximum=10.0,
                                                                     minimum_inclusive=False)),
    Key("series", "settle_time", "number", "s",
        "How long each step runs on after its sea ends, for the last waves to reach the "
        "structure and run down; 0: three peak periods plus the travel time from the wave maker "
        "to the structure.", default=0.0, valid_range=_NON_NEGATIVE),
    Key("series", "wave_calibration", "string", "-",
        "The wave maker's calibration before the steps (docs/campaign.md, Calibrated seas): "
        "none (the wave maker makes the asked sea; the toe sees what the flume lets through) "
        "or without_structure (each step's sea is first run in the flume without the bodies, "
        "the incident Hm0 and Tp measured at the toe, and the wave maker's gain corrected "
        "until they are within 3 % and 5 % of the asked ones; kept and reused by every member "
        "and seed).", default="none", choices=("none", "without_structure")),
    Key("series", "wave_calibration_folder", "string", "-",
        "Folder of the wave calibration (relative to the case's folder): a calibration made "
        "once for this flume and these seas, shared by several series; empty: calibration/ "
        "in the series' output folder (a campaign's: calibration_<case name>/ in its folder).",
        default=""),
    # [[series_steps]]
    Key("series_steps", "significant_height", "number", "m",
        "Spectral significant wave height Hm0 of the step's sea.", valid_range=_POSITIVE),
    Key("series_steps", "peak_period", "number", "s",
        "Peak period Tp; 0: from wave_steepness.", default=0.0, valid_range=_NON_NEGATIVE),
    Key("series_steps", "wave_steepness", "number", "-",
        "Deep-water wave steepness s_op = 2 pi Hm0 / (g Tp^2) that sets Tp (a series at constant "
        "steepness); 0: peak_period is given.", default=0.0,
        valid_range=Range(minimum=0.0, maximum=0.142)),
    Key("series_steps", "peak_enhancement", "number", "-", "JONSWAP peak enhancement factor gamma.",
        default=3.3, valid_range=Range(minimum=1.0)),
    Key("series_steps", "waves", "integer", "-",
        "Number of waves of the step: its sea lasts waves x Tm02 (the spectrum's mean "
        "zero-crossing period); 0: duration is given.", default=0, valid_range=_NON_NEGATIVE),
    Key("series_steps", "duration", "number", "s",
        "Length of the step's sea (s); 0: from waves.", default=0.0, valid_range=_NON_NEGATIVE),
    Key("series_steps", "seed", "integer", "-",
        "Seed of the step's random phases; 0: the step's number (1, 2, ...).", default=0,
        valid_range=_NON_NEGATIVE),
    Key("output", "directory", "string", "-",
        "Output folder, relative to the current directory unless the command line overrides it.",
        default="riprap-out"),
    Key("output", "paraview", "boolean", "-", "Write ParaView frames (.pvd + .vtu).",
        default=True),
    Key("output", "picture", "boolean", "-", "Write a PNG picture of the final state.",
        default=True),
    Key("output", "body_forces_interval", "number", "s",
        "Simulated time between the rows of body_forces.csv (bodies in a flow); 0 writes them at "
        f"the frames ([simulation] output_interval); at most {MAX_FRAMES:,} rows per body in a run.",
        default=0.0, valid_range=_NON_NEGATIVE),
)



def _between(low: float, high: float) -> Range:
    return Range(minimum=low, maximum=high)


#: Physically plausible values of the physical keys, (table, key) -> range, applied to every
#: variant of the key. The bounds are generous on purpose, orders of magnitude around real
#: materials, laboratory flumes and prototype seas, so that only a slip is refused (a value in
#: the wrong unit, a stray exponent: a water viscosity of 1e12 Pa s runs for 18 million minutes).
#: Sources: material tables of Eurocode 2 (EN 1992-1-1, table 3.1) and the CRC Handbook of
#: Chemistry and Physics; CIRIA/CUR/CEM The Rock Manual (2007), chapter 3; EurOtop (2018); the
#: Coastal Engineering Manual (EM 1110-2-1100), part II; and the values in riprap's own
#: examples and tests.
PLAUSIBLE: dict[tuple[str, str], Range] = {
    # gravity: the earth's 9.81; a geotechnical centrifuge spins models at up to a few hundred g
    # (simulation._ABSURD_GRAVITY is 1000 m/s^2 too)
    ("simulation", "gravity"): _between(-1000.0, 1000.0),
    # simulated time: a laboratory test of thousands of waves lasts hours, a week-long storm
    # 6e5 s; 1e8 s is three years of sea (an end time of 1e308 is a slip, not a frame count)
    ("simulation", "end_time"): Range(maximum=1.0e8),
    # densities of solids: expanded polystyrene (about 15 kg/m^3) to osmium (22,590)
    ("materials", "density"): _between(10.0, 25000.0),
    # Coulomb friction: ice on ice about 0.02, rock on rock 0.6-0.9, rubber on concrete up to 2
    ("materials", "friction_coefficient"): _between(0.0, 5.0),
    # restitution: nearly plastic impacts (wet clay, about 0.05) to glass beads (0.95); below a
    # thousandth the contact damping is far above critical and only shortens the step
    ("materials", "restitution"): _between(1.0e-3, 1.0),
    # contact penalty: of the order of the Young's modulus of the softer body, gels (1e3 Pa) to
    # ten times diamond's (1.2e12 Pa)
    ("materials", "contact_penalty"): _between(1.0e3, 1.0e13),
    # tangential over normal contact stiffness: 2/7 (Hertz-Mindlin, rigid spheres) to about 1
    ("materials", "tangential_stiffness_ratio"): _between(1.0e-3, 10.0),
    # liquids as "water": petrol (about 700 kg/m^3) to heavy brines and slurries (2000), with
    # room either side; the second fluid ("air") may be a second liquid (examples/03: an oil)
    ("fluid", "water_density"): _between(500.0, 3000.0),
    ("fluid", "air_density"): _between(1.0e-2, 3000.0),
    # dynamic viscosities: air 1.8e-5 Pa s, water 1.0e-3, silicone oils and glycerol 0.1-1.5,
    # honey about 10; 100 Pa s is already a paste
    ("fluid", "water_viscosity"): _between(1.0e-5, 100.0),
    ("fluid", "air_viscosity"): _between(1.0e-6, 100.0),
    # surface tension: organic liquids about 0.02 N/m, water 0.073, mercury 0.49
    ("fluid", "surface_tension"): _between(1.0e-3, 1.0),
    # porous media (Rock Manual, 3.4; van Gent 1995): porosity of packed rock and units 0.25-0.6
    ("porous_zones", "porosity"): _between(0.05, 0.95),
    # stones: coarse sand (1 mm) to the largest quarried blocks (Dn50 about 3 m)
    ("porous_zones", "stone_diameter"): _between(1.0e-3, 10.0),
    # Darcy-Forchheimer coefficients (van Gent 1995; Jensen et al. 2014): a 0-1500, b 0.3-3.6
    # (a ten times wider range each way still catches a stray exponent), c about 0.34
    ("porous_zones", "linear_friction"): _between(0.0, 1.0e5),
    ("porous_zones", "quadratic_friction"): _between(0.0, 100.0),
    ("porous_zones", "added_mass"): _between(0.0, 10.0),
    # waves: laboratory flumes (a centimetre, half a second) to the highest storm waves at sea
    # (about 30 m) and swell periods (25 s), with infragravity periods in room
    ("waves", "height"): _between(1.0e-3, 50.0),
    ("waves", "period"): _between(0.1, 300.0),
    ("waves", "significant_height"): _between(1.0e-3, 50.0),
    ("waves", "peak_period"): _between(0.1, 300.0),
    # JONSWAP peak enhancement: 1 (Pierson-Moskowitz) to about 7 for young swell-free seas
    ("waves", "peak_enhancement"): _between(1.0, 20.0),
    ("series_steps", "significant_height"): _between(1.0e-3, 50.0),
    ("series_steps", "peak_period"): _between(0.1, 300.0),
    ("series_steps", "peak_enhancement"): _between(1.0, 20.0),
    # a step of 10 000 waves is ten storm tests; 1e6 s is eleven days of sea
    ("series_steps", "waves"): _between(1.0, 10000.0),
    ("series_steps", "duration"): _between(1.0, 1.0e6),
    ("series_steps", "wave_steepness"): _between(1.0e-3, 0.142),
    ("series", "displacement_threshold"): _between(1.0e-3, 10.0),
    # crest widths: a narrow laboratory crest (a few cm) to a prototype berm (a hundred m)
    ("gauges", "crest_width"): _between(1.0e-3, 1000.0),
    ("series", "settle_time"): _between(0.0, 1.0e5),
    # elastic material: gels (1e3 Pa) to diamond (1.2e12); concrete about 3e10
    ("deformable", "young_modulus"): _between(1.0e3, 1.0e13),
    # viscous damping of the elements: riprap's examples use 2-300 Pa s; far beyond 1e9 the
    # viscous step limit takes over and nothing moves
    ("deformable", "viscosity"): _between(1.0e-3, 1.0e9),
    # strengths: weak mortars and rock (1e3-1e5 Pa) to high-strength steel (2e9)
    ("deformable", "tensile_strength"): _between(1.0e3, 1.0e10),
    ("deformable", "cohesion"): _between(1.0e3, 1.0e10),
    # penalties: as the Young's modulus, joints ten times stiffer
    ("deformable", "contact_penalty"): _between(1.0e3, 1.0e14),
    ("deformable", "joint_penalty"): _between(1.0e3, 1.0e15),
    # mass damping: the settling aid of examples/08 is 2000 1/s; a 1 m concrete unit's lowest
    # mode is about 1e4 rad/s, so 1e6 1/s already freezes any unit
    ("deformable", "mass_damping"): _between(1.0e-6, 1.0e6),
    # fracture energies: glass (about 10 J/m^2), concrete 100 (mode I) and 1000 (mode II), to
    # tough steels (1e5)
    ("deformable", "fracture_energy_mode_i"): _between(0.1, 1.0e6),
    ("deformable", "fracture_energy_mode_ii"): _between(0.1, 1.0e6),
    # the flume and the face: a narrow laboratory flume (a few cm) to a prototype section
    # (hundreds of m); slopes from 1:0.5 (steep rock) to 1:20 (a beach)
    ("slope", "cotangent"): _between(0.5, 20.0),
    ("slope", "width"): _between(0.02, 1000.0),
    ("slope", "length"): _between(0.02, 1000.0),
    # rock gradings (Rock Manual, 3.4.3): laboratory stones of 1 mm to 10-15 t blocks (Dn50
    # about 1.8 m); a very wide grading has Dn85/Dn15 up to about 3
    ("underlayer", "dn50"): _between(1.0e-3, 5.0),
    ("underlayer", "dn85_over_dn15"): _between(1.0, 5.0),
    # armour units: model units of 2 cm to the largest concrete units (Tetrapods 6 m high, 80 t;
    # Accropode II Dn about 3.5 m)
    ("armour", "height"): _between(0.01, 20.0),
    ("armour", "nominal_diameter"): _between(5.0e-3, 10.0),
    ("armour", "mass"): _between(1.0e-3, 1.0e6),
}

KEYS = tuple(replace(entry, plausible=PLAUSIBLE[(entry.table, entry.name)])
             if (entry.table, entry.name) in PLAUSIBLE else entry for entry in KEYS)


def table(name: str) -> Table:
    """The :class:`Table` called ``name`` (``""`` for the top level)."""
    for candidate in TABLES:
        if candidate.name == name:
            return candidate
    raise KeyError(f"the case schema has no table {name!r}")


def keys_of(table_name: str, *, variant: str | None = None) -> tuple[Key, ...]:
    """Keys of a table: the common ones, plus those of ``variant`` when given."""
    return tuple(
        entry for entry in KEYS
        if entry.table == table_name and (entry.variant is None or entry.variant == variant)
    )


def key(table_name: str, name: str) -> Key:
    """The :class:`Key` ``name`` of table ``table_name`` (any variant)."""
    for entry in KEYS:
        if entry.table == table_name and entry.name == name:
            return entry
    raise KeyError(f"the case schema has no key {name!r} in table {table_name!r}")


def default_of(table_name: str, name: str) -> object:
    """Default value of a key; raises ``KeyError`` for required keys."""
    entry = key(table_name, name)
    if entry.required:
        raise KeyError(f"{table_name}.{name} is required and has no default")
    return entry.default


def format_toml_value(value: object) -> str:
    """Write a value the way it would appear in a TOML file (for docs and error messages)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        if value != 0.0 and (abs(value) >= 1e6 or abs(value) < 1e-4):
            return f"{value:.6g}"
        return repr(value)
    if isinstance(value, str):
        escaped = value.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
        return f'"{escaped}"'
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(format_toml_value(item) for item in value) + "]"
    if isinstance(value, dict):
        inner = ", ".join(f"{name} = {format_toml_value(item)}" for name, item in value.items())
        return "{ " + inner + " }" if inner else "{}"
    if hasattr(value, "isoformat"):
        return value.isoformat()
    return str(value)


def describe_expected(entry: Key) -> str:
    """What the key accepts, in words: kind, unit, range or choices (for error messages)."""
    parts = [KINDS[entry.kind]]
    if entry.unit != "-":
        parts.append(f"in {entry.unit}")
    text = " ".join(parts)
    if entry.choices is not None:
        text = "one of " + ", ".join(format_toml_value(choice) for choice in entry.choices)
    if entry.valid_range is not None:
        prefix = "each " if entry.kind in _VECTOR_KINDS else ""
        text += f", {prefix}{entry.valid_range.describe()}"
    if entry.extensions:
        text += ", ending in " + " ".join(entry.extensions)
    if entry.greater_than is not None:
        text += f", each component > {entry.greater_than}"
    if entry.references is not None:
        each = "each " if entry.kind in ("string_list", "name_pair") else ""
        text += f", {each}the name of a [[{entry.references}]] entry"
    return text


def _allowed_cell(entry: Key) -> str:
    notes = []
    if entry.choices is not None:
        notes.append("one of " + ", ".join(f"`{format_toml_value(c)}`" for c in entry.choices))
    if entry.valid_range is not None:
        prefix = "each " if entry.kind in _VECTOR_KINDS else ""
        notes.append(prefix + entry.valid_range.describe())
    if entry.references is not None:
        notes.append(f"name of a `[[{entry.references}]]` entry")
    if entry.unique:
        notes.append(f"unique among `[[{entry.table}]]`")
    if entry.extensions:
        notes.append(" ".join(f"`{extension}`" for extension in entry.extensions))
    if entry.greater_than is not None:
        notes.append(f"each component > `{entry.greater_than}`")
    if entry.plausible is not None:
        prefix = "each " if entry.kind in _VECTOR_KINDS else ""
        zero_allowed = entry.valid_range is not None and entry.valid_range.contains(0.0)
        zero = " (or 0)" if zero_allowed and not entry.plausible.contains(0.0) else ""
        notes.append(f"plausible: {prefix}{entry.plausible.describe()}{zero}")
    return "; ".join(notes) if notes else "any"


def _markdown_cell(text: str) -> str:
    return text.replace("|", "\\|")


def _markdown_key_table(entries: tuple[Key, ...]) -> list[str]:
    lines = [
        "| key | type | unit | default | allowed | meaning |",
        "|---|---|---|---|---|---|",
    ]
    for entry in entries:
        default = "required" if entry.required else f"`{format_toml_value(entry.default)}`"
        cells = (
            f"`{entry.name}`", KINDS[entry.kind], entry.unit, default, _allowed_cell(entry),
            entry.meaning,
        )
        lines.append("| " + " | ".join(_markdown_cell(cell) for cell in cells) + " |")
    return lines


def render_markdown() -> str:
    """The reference page ``docs/case-file.md``, generated from :data:`TABLES` and :data:`KEYS`.

    Returns
    -------
    str
        Markdown text ending in a newline.
    """
    lines = [
        "# Case file reference",
        "",
        "<!-- Generated by `python -m riprap.schema > docs/case-file.md` from",
        "     src/riprap/schema.py. Do not edit by hand. -->",
        "",
        f"A riprap case is a TOML file with `format_version = {FORMAT_VERSION}`. Units are SI;",
        "`-` marks a dimensionless or non-physical value. Integers are accepted where a number is",
        "expected, `true`/`false` never are. Unknown tables and keys, wrong types, values out of",
        "range, duplicate names and names that refer to nothing are errors: `riprap` reports all",
        f"of them at once (up to {MAXIMUM_REPORTED_PROBLEMS}), each as `file:line: key path = "
        "value: what was expected`,",
        "for example `case.toml:14: bodies[1].position = [0.0, 1.0]: expected 3 numbers [x, y, z] "
        "in m`.",
        "Entries of arrays of tables are counted from 0 in key paths.",
        "",
        "Rules that involve more than one key:",
        "",
        f"- `[[bodies]]` and `[[body_grids]]` together must create at least {MINIMUM_BODY_COUNT} "
        "body, except in a placement case (one with `[placement]`, run by `riprap place`), which "
        "makes its own shapes and bodies from `[slope]`, `[underlayer]`, `[armour]` and "
        "`[placement]`.",
        "- `name` is unique among `[[materials]]` and among `[[shapes]]`; `shape`, `shapes`, "
        "`material` and `[[friction]]` `materials` must name an entry that exists; a pair of "
        "materials appears in `[[friction]]` at most once, in either order.",
        "- Keys listed under a `type` exist only for that type: giving one for another type is an "
        "error, and a required one must be given.",
        "- Relative file paths are relative to the folder of the case file.",
        "- A physical key's value outside its *plausible* range (the allowed column) is refused "
        "as a slip (a wrong unit, a stray exponent): the ranges span orders of magnitude around "
        "real materials, flumes and seas (their sources are in src/riprap/schema.py, "
        "`PLAUSIBLE`). 0 passes where the key allows it (off, automatic or not given).",
        "",
    ]
    for part in TABLES:
        lines.append(f"## {part.header}")
        lines.append("")
        count_note = ""
        if part.is_array:
            count_note = (
                f" At least {part.minimum_count} entry." if part.minimum_count
                else " Optional; any number of entries."
            )
        lines.append(part.meaning + count_note)
        lines.append("")
        lines.extend(_markdown_key_table(keys_of(part.name)))
        lines.append("")
        if part.variant_key is not None:
            for variant in key(part.name, part.variant_key).choices:
                lines.append(f"### {part.header} with {part.variant_key} = \"{variant}\"")
                lines.append("")
                specific = tuple(entry for entry in KEYS
                                 if entry.table == part.name and entry.variant == variant)
                if specific:
                    lines.extend(_markdown_key_table(specific))
                else:
                    lines.append("No further keys.")
                lines.append("")
    return "\n".join(lines).rstrip("\n") + "\n"


if __name__ == "__main__":
    print(render_markdown(), end="")
