"""The fluid's obstacles as fixed bodies, so that the bodies of a coupled run meet them.

A ``[[obstacles]]`` box is a set of inactive cells for the fluid (``FluidSolver.add_obstacle_box``);
bodies only meet bodies and walls. Each box is therefore added to the bodies as a fixed box body
of exactly the cells the fluid leaves out (the box snapped to the cell faces), so that water and
bodies see the same solid. The fluid already holds these cells still, so the exchange leaves the
obstacle bodies out (``CoupledSolver(obstacle_bodies=...)``).
"""
from __future__ import annotations

import numpy as np

from riprap.errors import OverlapError
from riprap.geometry.shapes import box

__all__ = ["add_obstacle_bodies", "name_obstacles_in_overlap"]

#: Obstacle tetrahedra no larger than this share of the smallest moving body's nominal diameter
#: (contact of a body with a face is resolved on the face's boundary sub-tetrahedra).
_MESH_OVER_BODY = 1.0


def add_obstacle_bodies(simulation, boxes, material: str | None = None) -> list[int]:
    """Add one fixed box body per ``(lower, upper)`` in ``boxes`` to ``simulation`` (a
    :class:`riprap.simulation.Simulation` whose solver is not prepared yet); returns their body
    indices, in the order of ``boxes``. ``material``: default the first material."""
    solver = simulation.solver
    if not boxes:
        return []
    material = material or solver.materials[0].name
    moving = solver.moving_shapes()
    nominal = min((shape.volume ** (1.0 / 3.0) for shape in moving), default=np.inf)
    indices = []
    for number, (lower, upper) in enumerate(boxes):
        lower, upper = np.asarray(lower, dtype=np.float64), np.asarray(upper, dtype=np.float64)
        lengths = upper - lower
        mesh_size = float(min(lengths.min(), _MESH_OVER_BODY * nominal))
        name = f"obstacle {number + 1}"
        simulation.add_shape(name, box(lengths=tuple(lengths), mesh_size=mesh_size))
        indices.append(simulation.add_body(shape=name, material=material,
                                           position=tuple((lower + upper) / 2), fixed=True))
    return indices


def name_obstacles_in_overlap(error: OverlapError, obstacle_bodies, boxes) -> OverlapError:
    """The start-overlap error with the obstacle bodies named as the case's [[obstacles]] entries."""
    lines = [f"  body {body} is [[obstacles]] entry {number + 1} "
             f"({np.round(lower, 4).tolist()} .. {np.round(upper, 4).tolist()} m, as the fluid's cells "
             "fill it)"
             for number, (body, (lower, upper)) in enumerate(zip(obstacle_bodies, boxes))
             if f"body {body}" in str(error)]
    if not lines:
        return error
    return OverlapError(f"{error}\n" + "\n".join(lines)
                        + "\nA body may not start inside a fixed obstacle: move it out.")
