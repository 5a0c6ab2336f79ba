"""The pack a placement writes (``pack.toml``, ``shapes/``, ``contact_history.csv``): the last
run's bodies at their poses, the slope's walls, the run settings a later ``riprap run`` starts
from (a strip's sides included), for units and for rock armour alike."""
from __future__ import annotations

import os
from pathlib import Path

from riprap.case.load import parse_case
from riprap.io.case_text import read_case_text
from riprap.io.pack import PackBody, write_pack

__all__ = ["write_placed_pack", "write_checked_pack"]


def write_checked_pack(directory, **pack) -> Path:
    """:func:`riprap.io.pack.write_pack`, then the written ``pack.toml`` read back through the case
    parser: a value the schema rejects is an error that names the file and line now, instead of a
    surprise at the next ``riprap run``. Keywords as ``write_pack``'s."""
    path = write_pack(directory, **pack)
    parse_case(read_case_text(path), source=os.fspath(path), base_dir=Path(directory).resolve())
    return path


def write_placed_pack(case, sim, materials, slope, out: Path, *, comment: str,
                      contact_history) -> Path:
    """Write the pack of placement run ``sim`` (every body, its shape and material) into
    ``out``; ``contact_history``: the contacts it starts from."""
    solver = sim.solver
    names = {index: name for name, index in sim.shape_names.items()}
    shapes = {names[k]: shape.mesh for k, shape in enumerate(solver.shapes)}
    material_names = [m.name for m in solver.materials]
    omegas = solver.angular_velocities
    bodies = [PackBody(shape=names[int(solver.shape_index[b])],
                       material=material_names[int(solver.material_index_of_body[b])],
                       position=tuple(solver.positions[b]), orientation=tuple(solver.quaternions[b]),
                       velocity=tuple(solver.velocities[b]), angular_velocity=tuple(omegas[b]),
                       fixed=bool(solver.fixed[b]))
              for b in range(solver.n_bodies)]
    return write_checked_pack(
        out, shapes=shapes, materials=materials.all(), bodies=bodies,
        walls=slope.walls(face_material=materials.face.name,
                          side_material=materials.side_wall.name),
        simulation={"end_time": case.simulation.end_time,
                    "time_step": case.simulation.time_step,
                    "time_step_safety": case.simulation.time_step_safety,
                    "gravity": list(case.simulation.gravity),
                    # a strip's pack runs on the strip (dry, or in its fluid)
                    **({"periodic_y_low": 0.0, "periodic_y_high": slope.width}
                       if slope.periodic else {})},
        comment=comment, contact_history=contact_history,
        friction_pairs=materials.friction_pairs)
