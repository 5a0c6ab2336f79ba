"""The air and water of a run: ``fluid.pvd`` of ``.vti`` files (``water_fraction``, ``pressure``
in Pa, ``velocity`` in m/s at cell centres, ``solid``) and the free-surface pictures
(``free_surface/free_surface_NNNN.png``, NNNN the entry) at every entry; and ``run.pvd``, which
opens the fluid's and the bodies' series together in ParaView."""
from __future__ import annotations

from riprap.io import vtk
from riprap.io.fluid_picture import free_surface_png
from riprap.outputs.base import Writer

__all__ = ["FluidFieldsWriter", "CombinedSeriesWriter"]


class FluidFieldsWriter(Writer):
    """Fields of ``model.fluid`` (a FluidSolver); the bodies drawn in the pictures from
    ``model.body_fraction()`` (None without bodies)."""

    name = "fluid"

    def __init__(self, *, paraview: bool = True, picture: bool = True, schedule=None):
        super().__init__(schedule)
        self.paraview = paraview
        self.picture = picture
        #: ``fluid.pvd`` (None without ParaView frames), for :class:`CombinedSeriesWriter`.
        self.series = None
        self._directory = None

    def open(self, model, directory, *, append):
        self._directory = directory
        if self.paraview:
            self.series = vtk.ParaViewSeries(directory, "fluid", append=append)

    def write(self, model, entry):
        s = model.fluid
        velocity = s.cell_velocity()
        if self.series is not None:
            self.series.add_image(s.time, origin=s.grid.lower, spacing=s.h, cells=s.grid.cells,
                                  cell_data={"water_fraction": s.fraction, "pressure": s.pressure,
                                             "velocity": velocity, "solid": s.solid.astype(float)})
        if self.picture:
            free_surface_png(self._directory / "free_surface" / f"free_surface_{entry:04d}.png",
                             grid=s.grid, fraction=s.fraction, velocity=velocity, solid=s.solid,
                             time=s.time, bodies=model.body_fraction())

    def combined_series(self) -> list:
        return [self.series]

    def close(self, model):
        outputs = {}
        if self.series is not None:
            outputs["paraview"] = str(self.series.pvd_path)
        if self.picture:
            outputs["pictures"] = str(self._directory / "free_surface")
        return outputs


class CombinedSeriesWriter(Writer):
    """``run.pvd``: the series of ``parts`` (writers with ``combined_series()``: their
    ParaView series), rewritten after each entry (put it after its parts, on their schedule).
    Nothing where a part writes no series."""

    name = "run_pvd"

    def __init__(self, parts, schedule=None):
        super().__init__(schedule)
        self.parts = list(parts)
        self._combined = None

    def open(self, model, directory, *, append):
        series = [s for part in self.parts for s in part.combined_series()]
        if series and all(s is not None for s in series):
            self._combined = vtk.CombinedSeries(directory / "run.pvd", series)

    def write(self, model, entry):
        if self._combined is not None:
            self._combined.write()

    def close(self, model):
        return {} if self._combined is None else {"fluid_and_bodies": str(self._combined.path)}
