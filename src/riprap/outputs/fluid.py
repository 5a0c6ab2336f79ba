"""The air and water of a run: ``fluid.pvd`` of ``.vti`` files (``water_fraction``, ``pressure``
in Pa, ``velocity`` in m/s at cell centres, ``solid``) and the free-surface pictures
(``free_surface/free_surface_NNNN.png``, NNNN the entry) at every entry; and ``run.pvd``, which
opens the fluid's and the bodies' series together in ParaView.

A run over several processes writes each frame as ParaView's parallel image data: every process
its own x-planes into ``fluid_NNNNNN/piece_PPPP.vti``, process 0 the ``fluid_NNNNNN.pvti`` that
names them, listed in ``fluid.pvd`` (``riprap.io.vti.read_pvti`` joins them back)."""
from __future__ import annotations

from riprap.io import vtk
from riprap.io.fluid_picture import free_surface_png
from riprap.io.vti import write_pvti, write_vti
from riprap.outputs.base import Writer

__all__ = ["FluidFieldsWriter", "CombinedSeriesWriter"]


class FluidFieldsWriter(Writer):
    """Fields of ``model.fluid`` (a FluidSolver); the bodies drawn in the pictures from
    ``model.body_fraction()`` (None without bodies)."""

    name = "fluid"
    #: every process of a run over several calls it (each writes its piece of a frame)
    every_process = True

    def __init__(self, *, paraview: bool = True, picture: bool = True, schedule=None):
        super().__init__(schedule)
        self.paraview = paraview
        self.picture = picture
        #: ``fluid.pvd`` (None without ParaView frames), for :class:`CombinedSeriesWriter`.
        self.series = None
        self._directory = None

    def open(self, model, directory, *, append):
        self._directory = directory
        if self.paraview and _writes_files(model):
            self.series = vtk.ParaViewSeries(directory, "fluid", append=append)

    def write(self, model, entry):
        s = model.fluid
        piece = model.frame_piece() if hasattr(model, "frame_piece") else None
        writes = _writes_files(model)
        fields = _fields(s) if writes and (piece is None or self.picture) else None
        if self.paraview:
            if piece is None:
                self.series.add_image(s.time, origin=s.grid.lower, spacing=s.h,
                                      cells=s.grid.cells, cell_data=fields)
            else:
                self._write_pieces(piece)
        if self.picture and writes:
            free_surface_png(self._directory / "free_surface" / f"free_surface_{entry:04d}.png",
                             grid=s.grid, fraction=s.fraction, velocity=fields["velocity"],
                             solid=s.solid, time=s.time, bodies=model.body_fraction())

    def _write_pieces(self, piece) -> None:
        """Every process its piece of the frame, then process 0 the ``.pvti`` naming them."""
        comm, block, grid = piece.comm, piece.block, piece.whole_grid
        stem = comm.broadcast(self.series.next_frame_stem(block.time) if comm.rank == 0 else None)
        fields = {name: values[piece.planes] for name, values in _fields(block).items()}
        name = f"{stem}/piece_{comm.rank:04d}.vti"
        planes = fields["water_fraction"].shape[0]
        write_vti(self._directory / name, origin=grid.lower, spacing=block.h,
                  cells=(planes,) + tuple(grid.cells[1:]), cell_data=fields,
                  start=(piece.first, 0, 0))
        pieces = comm.all_values((name, piece.first, piece.first + planes))
        if comm.rank == 0:
            components = {key: (3 if value.ndim == 4 else 1) for key, value in fields.items()}
            write_pvti(self._directory / f"{stem}.pvti", origin=grid.lower, spacing=block.h,
                       cells=grid.cells, fields=components, pieces=pieces)
            self.series.list_frame(block.time, f"{stem}.pvti")

    def combined_series(self) -> list:
        return [self.series]

    def close(self, model):
        outputs = {}
        if self.series is not None:
            outputs["paraview"] = str(self.series.pvd_path)
        if self.picture:
            outputs["pictures"] = str(self._directory / "free_surface")
        return outputs


def _fields(s) -> dict:
    """The fields of a frame of the fluid ``s`` (a FluidSolver, or a process's block)."""
    return {"water_fraction": s.fraction, "pressure": s.pressure, "velocity": s.cell_velocity(),
            "solid": s.solid.astype(float)}


def _writes_files(model) -> bool:
    return bool(getattr(model, "writes_files", True))


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
