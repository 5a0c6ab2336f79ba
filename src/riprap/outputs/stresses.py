"""The stresses of deformable bodies, at the end of a run: ``units.csv`` (per unit the largest
tensile stress of the run, where and when, and its breakage), ``fragments.csv`` (every piece of a
cracking unit), and the pictures ``peak_stress.png``, ``final_stress.png`` and ``fragments.png``.
At every entry: ``bodies.pvd`` (the stresses inside every body), ``cracks.pvd`` (the damaged
joints) and, with rigid bodies too, ``rigid_bodies.pvd`` and ``rigid_contacts.pvd``."""
from __future__ import annotations

import numpy as np

from riprap.deformable.elements import boundary_faces_with_owners
from riprap.io import vtk
from riprap.io.deformable_outputs import write_fragments_csv, write_units_csv
from riprap.io.picture import render_bodies_png
from riprap.outputs.base import Writer

__all__ = ["DeformableFramesWriter", "StressesWriter", "stress_picture", "fragment_picture"]


class DeformableFramesWriter(Writer):
    """Frames of ``stresses`` (a :class:`riprap.models.deformable.DeformableModel`:
    ``frame_fields()``, ``crack_fields()``, ``rigid_frame()``), at its own clock. ``cracks``:
    write ``cracks.pvd`` for cracking bodies; ``key``: summary.json's name of ``bodies.pvd``."""

    name = "deformable_bodies"

    def __init__(self, stresses, *, paraview: bool = True, cracks: bool = True,
                 key: str = "paraview", schedule=None):
        super().__init__(schedule)
        self.stresses = stresses
        self.paraview = paraview
        self.cracks = cracks
        self.key = key
        self.series = self._crack_series = self._rigid_series = self._rigid_contact_series = None

    def open(self, model, directory, *, append):
        if not self.paraview:
            return
        stresses = self.stresses
        self.series = vtk.ParaViewSeries(directory, "bodies", append=append)
        if self.cracks and stresses.system.fracturing_bodies:
            self._crack_series = vtk.ParaViewSeries(directory, "cracks", append=append)
        if stresses.rigid is not None:
            self._rigid_series = vtk.ParaViewSeries(directory, "rigid_bodies", append=append)
            self._rigid_contact_series = vtk.ParaViewSeries(directory, "rigid_contacts",
                                                            append=append)

    def combined_series(self) -> list:
        return [self.series] + ([self._rigid_series] if self._rigid_series is not None else [])

    def write(self, model, entry):
        stresses = self.stresses
        time = stresses.time
        if self.series is not None:
            fields = stresses.frame_fields()
            n = stresses.system.n_deformable_nodes
            self.series.add(time, points=fields["points"][:n], cells=fields["cells"],
                            cell_data=fields["cell_data"],
                            point_data={k: v[:n] for k, v in fields["point_data"].items()})
        if self._crack_series is not None:
            cracks = stresses.crack_fields()
            self._crack_series.add(time, points=cracks["points"], cells=cracks["cells"],
                                   cell_type="triangle", cell_data=cracks["cell_data"])
        if self._rigid_series is not None:
            rigid, contacts = stresses.rigid_frame()
            self._rigid_series.add(time, points=rigid["points"], cells=rigid["cells"],
                                   cell_type="triangle", cell_data=rigid["cell_data"])
            self._rigid_contact_series.add_contacts(time, contacts)

    def close(self, model):
        outputs = {}
        if self.series is not None:
            outputs[self.key] = str(self.series.pvd_path)
        if self._crack_series is not None:
            outputs["cracks"] = str(self._crack_series.pvd_path)
        if self._rigid_series is not None:
            outputs["rigid_bodies"] = str(self._rigid_series.pvd_path)
            outputs["rigid_contacts"] = str(self._rigid_contact_series.pvd_path)
        return outputs


class StressesWriter(Writer):
    """Tables and pictures of ``stresses`` (a :class:`riprap.models.deformable.DeformableModel`:
    ``unit_rows()``, ``fragment_rows()``, ``peak_state()``, ``final_state()``), written at the
    end; its entries write nothing (the records follow the bodies' steps, not a schedule)."""

    name = "stresses"

    def __init__(self, stresses, *, picture: bool = True, schedule=None):
        super().__init__(schedule)
        self.stresses = stresses
        self.picture = picture
        self._directory = None

    def open(self, model, directory, *, append):
        self._directory = directory

    def write(self, model, entry):
        pass

    def close(self, model):
        stresses, directory = self.stresses, self._directory
        outputs = {"units": str(write_units_csv(directory / "units.csv", stresses.unit_rows()))}
        if stresses.system.fracturing_bodies:
            outputs["fragments"] = str(write_fragments_csv(directory / "fragments.csv",
                                                           stresses.fragment_rows()))
            if self.picture:
                outputs["fragments_picture"] = str(fragment_picture(directory / "fragments.png",
                                                                    stresses))
        peak = stresses.peak_state()
        if self.picture and peak is not None:
            outputs["picture"] = str(stress_picture(directory / "peak_stress.png", stresses, peak,
                                                    peak=True))
            outputs["final_picture"] = str(stress_picture(directory / "final_stress.png", stresses,
                                                          stresses.final_state(), peak=False))
        return outputs


def stress_picture(path, stresses, snapshot, *, peak: bool):
    """The bodies' surfaces coloured by the largest principal stress of the element under each
    face in ``snapshot`` (time, positions, sigma_1 of every element): the moment the largest
    tensile stress of the run was found (``peak``), or the end of the run."""
    time, positions, sigma_1 = snapshot
    s = stresses.system
    triangles, values = [], []
    for k, body in enumerate(s.bodies):
        faces, owners = boundary_faces_with_owners(body.elements.corner_tets)
        triangles.append(positions[faces + s.node_offsets[k]])
        values.append(sigma_1[owners + s.element_offsets[k]])
    triangles = np.concatenate(triangles)
    values = np.concatenate(values) / 1e6
    low, high = float(values.min()), float(values.max())
    if low < 0.0 < high:
        # tension and compression: white at zero
        colour_map, value_range = "coolwarm", (-max(-low, high), max(-low, high))
    else:
        # one sign throughout (a body squeezed by the water all round): its own range
        colour_map, value_range = "viridis", (low, high if high > low else low + 1e-9)
    if peak:
        worst = int(np.argmax(stresses.records.stress))
        what = ("largest tensile stress of the run" if stresses.records.stress[worst] > 0.0
                else "least compression of the run (no tension)")
        title = (f"t = {time:.4g} s: {what}, {stresses.records.stress[worst] / 1e6:.3g} MPa in "
                 f"{stresses.body_names[worst]}")
    else:
        what = "largest tensile stress" if sigma_1.max() > 0.0 else "all in compression, sigma_1 up to"
        title = f"end of the run, t = {time:.4g} s: {what} {float(sigma_1.max()) / 1e6:.3g} MPa"
    return render_bodies_png(
        path, triangles_world=triangles, body_ids=np.arange(len(triangles)), values=values,
        value_label="largest principal stress sigma_1 (MPa, tension +)", colour_map=colour_map,
        value_range=value_range, title=title)


def fragment_picture(path, stresses):
    """The bodies' surfaces now, the crack faces included, one colour per fragment (the
    rigid bodies grey)."""
    s = stresses.system
    triangles = s.positions[s.triangles]
    # one id per (body, fragment): the contact groups are exactly that
    ids = s.triangle_group
    rigid = np.unique(ids[s.triangle_body >= s.first_rigid_body])
    pieces = int(s.first_rigid_group)
    broken = sum(stresses.system.bodies[k].breakage_summary()["fragments"] - 1
                 for k in s.fracturing_bodies)
    return render_bodies_png(
        path, triangles_world=triangles, body_ids=ids, grey_bodies=rigid,
        title=f"t = {s.time:.4g} s: {pieces} pieces of {len(s.bodies)} deformable "
              f"bod{'y' if len(s.bodies) == 1 else 'ies'} ({broken} broken off), one colour each")
