"""The wave gauges of a flume: ``gauges.csv`` (every record so far, rewritten whole at every
entry, so a killed run keeps them), and at the end ``waves_report.json`` (the waves measured
against the target) and ``gauges.png``."""
from __future__ import annotations

from riprap.io.gauge_files import gauges_png, write_gauges_csv, write_waves_report
from riprap.outputs.base import Writer

__all__ = ["GaugesWriter"]


class GaugesWriter(Writer):
    """Records from ``model.fluid.gauges`` (a GaugeSet), the report from
    ``model.waves_report()``; nothing for a run without gauges."""

    name = "gauges"

    def __init__(self, *, picture: bool = True, schedule=None):
        super().__init__(schedule)
        self.picture = picture
        self._directory = None

    def open(self, model, directory, *, append):
        self._directory = directory

    def write(self, model, entry):
        if model.fluid.gauges is not None:
            write_gauges_csv(self._directory / "gauges.csv", model.fluid.gauges)

    def close(self, model):
        gauges = model.fluid.gauges
        if gauges is None:
            return {}
        outputs = {"gauges": str(write_gauges_csv(self._directory / "gauges.csv", gauges))}
        report = model.waves_report()
        outputs["waves_report"] = str(write_waves_report(self._directory / "waves_report.json",
                                                         report))
        if self.picture:
            outputs["gauges_picture"] = str(gauges_png(self._directory / "gauges.png", gauges,
                                                       report))
        return outputs
