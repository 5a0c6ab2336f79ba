"""Rigid bodies: ``bodies.pvd`` (their surfaces, with velocity, contact force and contact
statistics per body; in a flow also the fluid's force) and ``contacts.pvd`` (the contacts) at every
entry, and, for a dry run, ``final_state.png`` at the end."""
from __future__ import annotations

from riprap.io import vtk
from riprap.outputs.base import Writer

__all__ = ["RigidBodiesWriter", "BodiesInFlowWriter"]


class RigidBodiesWriter(Writer):
    """Frames from ``model.frame_fields()`` and ``model.solver.contacts``; the picture from
    ``model.picture(path)`` (``paraview`` and ``picture``: ``[output]``'s switches)."""

    name = "bodies"

    def __init__(self, *, paraview: bool = True, picture: bool = True, schedule=None):
        super().__init__(schedule)
        self.paraview = paraview
        self.picture = picture
        self._series = self._contact_series = None
        self._directory = None

    def open(self, model, directory, *, append):
        self._directory = directory
        if self.paraview:
            self._series = vtk.ParaViewSeries(directory, "bodies", append=append)
            self._contact_series = vtk.ParaViewSeries(directory, "contacts", append=append)

    def write(self, model, entry):
        if self._series is None:
            return
        fields = model.frame_fields()
        self._series.add(model.time, points=fields["points"], cells=fields["cells"],
                         cell_type="triangle", cell_data=fields["cell_data"])
        self._contact_series.add_contacts(model.time, model.solver.contacts)

    def close(self, model):
        outputs = {}
        if self._series is not None:
            outputs["paraview"] = str(self._series.pvd_path)
            outputs["contacts"] = str(self._contact_series.pvd_path)
        if self.picture:
            outputs["picture"] = str(model.picture(self._directory / "final_state.png"))
        return outputs


class BodiesInFlowWriter(Writer):
    """The bodies of a run in a flow: frames from ``model.frame_fields()`` (with the fluid's force)
    and the contacts of ``model.solids``, so that ``riprap analyse`` gets coordination numbers,
    contact forces and factors of safety under wave load as it does dry."""

    name = "bodies"

    def __init__(self, *, paraview: bool = True, schedule=None):
        super().__init__(schedule)
        self.paraview = paraview
        self.series = self._contact_series = None
        self._directory = None
        self._append = False

    def open(self, model, directory, *, append):
        self._directory, self._append = directory, append
        if self.paraview:
            self.series = vtk.ParaViewSeries(directory, "bodies", append=append)

    def combined_series(self) -> list:
        return [self.series]

    def write(self, model, entry):
        if self.series is None:
            return
        fields = model.frame_fields()
        self.series.add(model.time, points=fields["points"], cells=fields["cells"],
                        cell_type="triangle", cell_data=fields["cell_data"])
        if self._contact_series is None:
            # opened with the first frame (a restart that writes none keeps the file as it is)
            self._contact_series = vtk.ParaViewSeries(self._directory, "contacts",
                                                      append=self._append)
        self._contact_series.add_contacts(model.time, model.solids.contacts)

    def close(self, model):
        outputs = {}
        if self.series is not None:
            outputs["bodies"] = str(self.series.pvd_path)
        if self._contact_series is not None:
            outputs["contacts"] = str(self._contact_series.pvd_path)
        return outputs
