"""The data of one frame of rigid bodies (``bodies.pvd``): their surfaces now, with per triangle
the body's velocity, forces and contact statistics, under the names ParaView shows. A dry run, a
run in a flow (with the fluid's force) and the rigid bodies of a deformable run share it."""
from __future__ import annotations

import numpy as np

from riprap.solid.contact_statistics import solver_contact_statistics
from riprap.solid.surfaces import surface_arrays

__all__ = ["rigid_frame_fields"]


def rigid_frame_fields(solver, fluid_force=None) -> dict:
    """``{"points", "cells", "cell_data"}`` of the bodies of ``solver`` (a SolidSolver) now;
    ``fluid_force`` (n_bodies, 3), N, adds the fluid's force on each body."""

    points, triangles, owners = surface_arrays(solver)
    contact = solver.contact_forces()
    statistics = solver_contact_statistics(solver)
    # ParaView colours inf badly; a huge finite number reads as "nothing pushes it sideways".
    safety = np.minimum(statistics["factor_of_safety_sliding"], 1.0e30)
    cell_data = {"body_id": owners, "velocity": solver.velocities[owners],
                 "speed": np.linalg.norm(solver.velocities, axis=1)[owners],
                 "angular_velocity": solver.angular_velocities[owners]}
    if fluid_force is not None:
        cell_data["fluid_force"] = fluid_force[owners]
    cell_data.update({"contact_force": contact[owners],
                      "fixed": solver.fixed[owners].astype(np.int64),
                      "coordination_number": statistics["coordination_number"][owners],
                      "max_contact_force": statistics["max_contact_force"][owners],
                      "factor_of_safety_sliding": safety[owners]})
    return {"points": points, "cells": triangles, "cell_data": cell_data}
