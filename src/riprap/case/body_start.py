"""Where and how fast the bodies of a case start, checked before any is built: coordinates the
numerics can carry, and start speeds (of the centroid, and of the surface from the spin) that an
armour unit or rock can have. A position near 1e308 m overflows the first distance computed
from it; a spin of 1e308 rad/s makes every later figure infinite.
"""
from __future__ import annotations

import math

import numpy as np

from riprap.errors import CaseFileError
from riprap.geometry.meshing import LARGEST_COORDINATE

__all__ = ["LARGEST_COORDINATE", "START_SPEED_LIMIT", "check_body_starts", "check_coordinates",
           "check_grid_starts", "shape_radius"]


#: Fastest start speed (m/s) of a body's centroid or of its surface from its spin: ten times the
#: fastest water of a breaking storm wave; an armour unit dropped from 50 m reaches 31 m/s.
START_SPEED_LIMIT = 100.0


def check_coordinates(where: str, key: str, values) -> None:
    """Refuse a coordinate beyond ``LARGEST_COORDINATE``; ``where`` names the file and entry."""
    values = np.asarray(values, dtype=float)
    largest = float(np.abs(values).max(initial=0.0))
    if not largest <= LARGEST_COORDINATE:
        raise CaseFileError(f"{where}: {key} = {_listed(values)} m reaches {largest:.3g} m from "
                            f"the origin, beyond {LARGEST_COORDINATE:g} m (the earth's radius is "
                            "6.4e6 m); give coordinates in metres near the model")


def check_body_starts(case, radius_of) -> None:
    """Check every [[bodies]] and [[body_grids]] entry of ``case``: coordinates, start velocity
    and the surface speed of the start spin. ``radius_of(shape)`` is the largest distance (m) of
    the shape's nodes from its centroid."""
    for number, body in enumerate(case.bodies):
        where = f"{case.source} [[bodies]] entry {number + 1} (shape '{body.shape}')"
        check_coordinates(where, "position", body.position)
        _check_speed(where, "velocity", body.velocity)
        spin = math.hypot(*body.angular_velocity)     # no overflow to inf on the way
        radius = radius_of(body.shape)
        surface_speed = spin * radius
        if not surface_speed <= START_SPEED_LIMIT:
            raise CaseFileError(
                f"{where}: angular_velocity = {_listed(body.angular_velocity)} rad/s turns the "
                f"body's surface ({radius:.3g} m from its centroid) at {surface_speed:.3g} m/s, "
                f"faster than {START_SPEED_LIMIT:g} m/s, which no armour unit or rock reaches; "
                f"give at most {START_SPEED_LIMIT / radius:.3g} rad/s")
    for number, grid in enumerate(case.body_grids):
        where = f"{case.source} [[body_grids]] entry {number + 1}"
        check_coordinates(where, "origin", grid.origin)
        last = (np.asarray(grid.origin, dtype=float)
                + np.asarray(grid.spacing, dtype=float) * (np.asarray(grid.counts) - 1))
        with np.errstate(over="ignore", invalid="ignore"):
            reach = np.abs(last) + abs(grid.jitter)
        if not float(reach.max()) <= LARGEST_COORDINATE:
            raise CaseFileError(
                f"{where}: origin, spacing = {_listed(grid.spacing)} m, counts = "
                f"{list(grid.counts)} and jitter = {grid.jitter:g} m put bodies "
                f"{float(reach.max()):.3g} m from the origin, beyond {LARGEST_COORDINATE:g} m; "
                "give spacing and jitter in metres")
        _check_speed(where, "velocity", grid.velocity)


def check_grid_starts(grid) -> None:
    """Check the rows of a placement grid file (``riprap.io.grid_file.GridPoints``): positions
    and start velocities, naming the file and line."""
    for k, line in enumerate(grid.lines):
        where = f"{grid.source}:{int(line)}"
        check_coordinates(where, "x, y, z", grid.positions[k])
        if grid.velocities is not None:
            _check_speed(where, "velocity", grid.velocities[k])


def _check_speed(where: str, key: str, vector) -> None:
    speed = math.hypot(*(float(v) for v in vector))
    if not speed <= START_SPEED_LIMIT:
        raise CaseFileError(f"{where}: {key} = {_listed(vector)} m/s starts the body at "
                            f"{speed:.3g} m/s, faster than {START_SPEED_LIMIT:g} m/s, which no "
                            "armour unit or rock reaches; give the speed in m/s")


def _listed(values) -> str:
    """A vector (or a list of points) as the user typed it: [0, 0, 1e+308], not numpy's repr."""
    values = np.asarray(values, dtype=float)
    if values.ndim == 0:
        return f"{float(values):g}"
    if values.ndim > 1:
        return "[" + ", ".join(_listed(row) for row in values) + "]"
    return "[" + ", ".join(f"{float(v):g}" for v in values.reshape(-1)) + "]"


def shape_radius(mesh) -> float:
    """Largest distance (m) of a mesh's nodes from their mean: the lever of a spin."""
    nodes = np.asarray(mesh.nodes, dtype=float)
    return float(math.sqrt(((nodes - nodes.mean(axis=0)) ** 2).sum(axis=1).max()))
