"""How much work a run asks for, estimated before it starts, so that a size or parameter that
would make billions of steps or cells is refused with the figure instead of hanging without a word.

The rates are this code's measured speeds on a 2-core machine (``bench/README.md``): rigid runs
3e4-6e4 body-steps/s, the fluid solver about 2e6 cell-updates/s and about 250 bytes of memory per
fluid cell (all arrays and the multigrid levels). An estimate above the refusal limit is an error
(:class:`WorkTooLargeError`); above the warning limit a :class:`RiprapWarning` tells the user what
they are about to wait for.
"""
from __future__ import annotations

import os
import warnings

from riprap.errors import RiprapError, plain_numbers

#: Measured speed of a rigid run (body-steps per second), the low end of bench/README.md.
RIGID_BODY_STEPS_PER_SECOND = 3.0e4
#: Measured speed of deformable bodies (element-steps per second), the low end: five Core-Loc-like
#: units sliding in contact in water (examples/05 deformable); 1e7-3e7 without contact.
DEFORMABLE_ELEMENT_STEPS_PER_SECOND = 2.0e6
#: Memory of one fluid cell (bytes): velocities, fraction, pressure, work arrays, multigrid.
FLUID_BYTES_PER_CELL = 250.0
#: A run estimated to take longer than this (s of wall-clock time) is refused: 30 days.
REFUSE_WALL_SECONDS = 30 * 86400.0
#: ... and one estimated to take longer than this gets a warning: 12 hours.
WARN_WALL_SECONDS = 12 * 3600.0
#: More steps than this is refused whatever the rate: the clock's round-off and the output count
#: stop meaning anything long before.
REFUSE_STEPS = 1.0e10
#: A fluid grid needing more than this fraction of the machine's memory is refused.
MEMORY_FRACTION = 0.8
#: Most ParaView frames a run may write: a million, each a file per body set and one of the fluid
#: (at the default 0.05 s, 14 hours of simulated time: a storm of thousands of waves fits).
MAX_FRAMES = 1_000_000
#: Most periodic checkpoints a run may write: each writes the whole state (and a fluid run takes
#: a step to land on it), so more spend the run writing; one a minute of simulated time over a
#: week-long storm is 10,080.
MAX_CHECKPOINTS = 10_000


class WorkTooLargeError(RiprapError):
    """A run, grid or mesh would need an absurd amount of time or memory."""


class RiprapWarning(UserWarning):
    """Something the user should know before waiting for the result."""


def warning_line(message, category) -> str | None:
    """A warning as riprap says it, one line: ``riprap: warning: ...`` for riprap's own, the
    category named for another library's; None for numpy's RuntimeWarnings (riprap checks that
    the state stays finite and names the body and time when it does not)."""
    if issubclass(category, RiprapWarning):
        return f"riprap: warning: {plain_numbers(str(message))}"
    if issubclass(category, RuntimeWarning):
        return None
    return f"riprap: warning ({category.__name__}): {message}"


def _duration(seconds: float) -> str:
    for unit, size in (("years", 365.25 * 86400), ("days", 86400.0), ("hours", 3600.0),
                       ("minutes", 60.0)):
        if seconds >= size:
            return f"{seconds / size:.3g} {unit}"
    return f"{seconds:.3g} s"


def check_rigid_run(*, end_time: float, time_step: float, moving_bodies: int,
                    start_time: float = 0.0, setting_the_step=None,
                    end_key: str = "end_time") -> None:
    """Refuse (or warn about) a rigid run of ``(end_time - start_time) / time_step`` steps;
    ``setting_the_step()``, if given, names the body whose mass and stiffness chose the step
    (asked only when refusing)."""
    steps = max(end_time - start_time, 0.0) / time_step
    seconds = steps * max(moving_bodies, 1) / RIGID_BODY_STEPS_PER_SECOND
    figure = (f"{steps:.3g} steps of {time_step:.3g} s for {end_time - start_time:.3g} s of "
              f"simulated time with {moving_bodies} moving bodies: about {_duration(seconds)} at "
              f"{RIGID_BODY_STEPS_PER_SECOND:.0e} body-steps/s")
    if steps > REFUSE_STEPS or seconds > REFUSE_WALL_SECONDS:
        body = setting_the_step() if setting_the_step is not None else ""
        which = f" ({body})" if body else ""
        raise WorkTooLargeError(
            f"the run would take {figure}. The time step comes from the smallest, lightest "
            f"body{which} and the contact stiffness: check the sizes (in metres), densities and "
            f"contact_penalty, or shorten {end_key}")
    if seconds > WARN_WALL_SECONDS:
        warnings.warn(f"this run will take {figure}", RiprapWarning, stacklevel=3)


def check_deformable_run(*, end_time: float, time_step: float, elements: int,
                         rigid_bodies: int = 0) -> None:
    """Refuse (or warn about) ``end_time / time_step`` steps of ``elements`` finite elements
    (and of ``rigid_bodies`` moving rigid bodies stepped with them)."""
    steps = max(end_time, 0.0) / time_step
    seconds = steps * (max(elements, 1) / DEFORMABLE_ELEMENT_STEPS_PER_SECOND
                       + rigid_bodies / RIGID_BODY_STEPS_PER_SECOND)
    rigid = f" and {rigid_bodies} moving rigid bodies" if rigid_bodies else ""
    figure = (f"{steps:.3g} steps of {time_step:.3g} s for {end_time:.3g} s of simulated time with "
              f"{elements} elements{rigid}: about {_duration(seconds)} at "
              f"{DEFORMABLE_ELEMENT_STEPS_PER_SECOND:.0e} element-steps/s")
    if steps > REFUSE_STEPS or seconds > REFUSE_WALL_SECONDS:
        raise WorkTooLargeError(
            f"the run would take {figure}. The deformable bodies' step is their smallest element "
            "over its wave speed sqrt(E / rho): check the sizes (in metres), young_modulus and "
            "mesh_size, or shorten end_time")
    if seconds > WARN_WALL_SECONDS:
        warnings.warn(f"this run will take {figure}", RiprapWarning, stacklevel=3)


def schedule_problems(*, end_time: float, output_interval: float, checkpoint_interval: float,
                      end_key: str = "end_time") -> list[tuple[str, float, str]]:
    """(key of [simulation], its value, what is wrong) for each interval that would write more
    than :data:`MAX_FRAMES` frames or :data:`MAX_CHECKPOINTS` checkpoints up to ``end_time``
    (the key ``end_key`` gives it): the run writes everything its schedule asks for, so such an
    interval would keep it writing (or, far below the time step, counting frames) for ever."""
    problems = []
    for key, interval, most, what in (("output_interval", output_interval, MAX_FRAMES, "frames"),
                                      ("checkpoint_interval", checkpoint_interval, MAX_CHECKPOINTS,
                                       "checkpoints")):
        if interval > 0 and end_time / interval > most:
            problems.append((key, interval, (
                f"{end_time / interval:.3g} {what} in {end_key} = {end_time:g} s, more than the "
                f"{most} a run may write; set {key} >= {end_time / most:.3g} s ({end_key} / "
                f"{most})")))
    return problems


def available_memory_bytes() -> float:
    """Physical memory of this machine (bytes); infinity where it cannot be read."""
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return float("inf")


def check_fluid_grid(cells) -> None:
    """Refuse a fluid grid whose arrays would not fit in memory, before allocating any."""
    count = 1.0
    for n in cells:
        count *= float(n)
    need = count * FLUID_BYTES_PER_CELL
    have = available_memory_bytes()
    if need > MEMORY_FRACTION * have:
        raise WorkTooLargeError(
            f"a fluid grid of {' x '.join(str(int(n)) for n in cells)} = {count:.3g} cells needs about "
            f"{need / 2**30:.3g} GiB of memory ({FLUID_BYTES_PER_CELL:.0f} bytes per cell); this "
            f"machine has {have / 2**30:.3g} GiB. Use fewer, larger cells")


#: The measured pace of a flume run with bodies: examples/10 (226,800 cells of 0.1 m, 2 m of
#: water, 25 free units on 135 fixed rocks) ran 60 s of simulated time in 1,606 s of wall time on
#: 2 cores (bench/flume_test.py, 2026-11-28; 9,266 fluid steps). As wall seconds per cell, per
#: simulated second and per sqrt(g d) / cell size (the fluid's step follows the flow's speed,
#: which scales with the shallow-water wave speed sqrt(g d), over the cell size).
FLUME_WALL_PER_CELL_AND_WAVE_SPEED = 1606.0 / (60.0 * 226_800 * (9.81 * 2.0) ** 0.5 / 0.1)


def flume_run_seconds(*, simulated_time: float, cells: int, cell_size: float, depth: float,
                      gravity: float = 9.81) -> float:
    """Wall seconds a flume run with bodies is likely to take on 2 cores: examples/10's measured
    pace (``FLUME_WALL_PER_CELL_AND_WAVE_SPEED``) scaled by the cells, the simulated time and the
    wave speed sqrt(g ``depth``) over the (smallest) ``cell_size``. Within a factor of 2-3 for a
    case like it; many more bodies, or breaking much harder, take longer."""
    speed = (max(gravity, 0.0) * max(depth, 0.0)) ** 0.5
    return (FLUME_WALL_PER_CELL_AND_WAVE_SPEED * simulated_time * cells * speed
            / max(cell_size, 1e-12))


def duration_words(seconds: float) -> str:
    """A wall-clock duration as a person says it: "40 s", "12 min", "2.5 h", "3 days".

    >>> duration_words(118.8), duration_words(7200.0), duration_words(12.3)
    ('2 min', '2 h', '12 s')
    """
    for size, unit in ((86400.0, "days"), (3600.0, "h"), (60.0, "min")):
        if seconds >= 0.95 * size * (2 if unit == "days" else 1):
            return f"{seconds / size:.2g} {unit}"
    return f"{seconds:.0f} s" if seconds >= 1 else "under 1 s"
