"""The armour units' contacts frame by frame, from a run's ``bodies.pvd`` (the per-body
``coordination_number``, ``max_contact_force`` and ``factor_of_safety_sliding`` every frame carries,
dry or in water): how the layer's contacts change under wave load, for the report."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from riprap.io.analysis_input import read_frame_mesh, read_pvd_frames

__all__ = ["read_unit_contacts_per_frame", "FRAME_CONTACT_FIELDS"]

#: The cell fields of a bodies frame read, in the order of the arrays returned.
FRAME_CONTACT_FIELDS = ("coordination_number", "max_contact_force", "factor_of_safety_sliding")


def read_unit_contacts_per_frame(run_folder, unit_bodies, *, until: float = np.inf) -> dict | None:
    """``{"time_s": (frames,), field: (frames, units) for FRAME_CONTACT_FIELDS}`` of the frames of
    ``run_folder``'s ``bodies.pvd`` up to time ``until``, or None when its frames do not carry
    those fields (a coupled run written before issue 35). A frame that cannot be read is a
    CaseFileError naming it (riprap.io.analysis_input)."""
    run_folder = Path(run_folder)
    units = np.asarray(unit_bodies, dtype=np.int64)
    times, values = [], {name: [] for name in FRAME_CONTACT_FIELDS}
    for index, (time, name) in enumerate(read_pvd_frames(run_folder / "bodies.pvd")):
        if time > until:
            break
        mesh = read_frame_mesh(run_folder / name, f"frame {index} of bodies.pvd (t = {time:g} s)")
        data = mesh.cell_data_dict
        if any(field not in data or "triangle" not in data[field]
               for field in FRAME_CONTACT_FIELDS + ("body_id",)):
            return None
        owners = np.asarray(data["body_id"]["triangle"], dtype=np.int64).reshape(-1)
        bodies, first = np.unique(owners, return_index=True)
        where = np.searchsorted(bodies, units)
        if where.size and (where.max() >= bodies.size or not np.array_equal(bodies[where], units)):
            return None             # not every unit in the frame: not this layer's run
        times.append(time)
        for field in FRAME_CONTACT_FIELDS:
            column = np.asarray(data[field]["triangle"], dtype=float).reshape(-1)
            values[field].append(column[first[where]])
    if not times:
        return None
    return {"time_s": np.array(times), **{name: np.array(rows) for name, rows in values.items()}}
