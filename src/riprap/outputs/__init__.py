"""Writers: one per output family, each on its own schedule (:mod:`riprap.schedules`), driven by
the run loop (:meth:`riprap.simulation.Simulation.run`); a user's own writer is attached with
:meth:`riprap.simulation.Simulation.add_writer`. Each model names its default writers
(``Model.default_writers``) and gives them data; the models write no files.

- :class:`RigidBodiesWriter`: ``bodies.pvd``, ``contacts.pvd``, ``final_state.png`` (dry runs);
- :class:`BodiesInFlowWriter`: ``bodies.pvd`` (with the fluid's force), ``contacts.pvd``;
- :class:`FluidFieldsWriter`: ``fluid.pvd``, ``free_surface/free_surface_NNNN.png``;
- :class:`CombinedSeriesWriter`: ``run.pvd`` (fluid and bodies together);
- :class:`GaugesWriter`: ``gauges.csv``, ``waves_report.json``, ``gauges.png`` (flumes);
- :class:`BodyForcesWriter`: ``body_forces.csv`` (bodies in a flow);
- :class:`SolverLogWriter`: ``solver_log.csv`` (fluid runs: what the solvers did per frame);
- :class:`DeformableFramesWriter`: ``bodies.pvd`` with the stresses, ``cracks.pvd``,
  ``rigid_bodies.pvd``, ``rigid_contacts.pvd`` (deformable bodies);
- :class:`StressesWriter`: ``units.csv``, ``fragments.csv`` and the stress pictures;
- :class:`ModelFrames`: a model of the older interface (``open_outputs``, ``write_frame``,
  ``close_outputs``).
"""
from riprap.outputs.base import ModelFrames, Writer
from riprap.outputs.bodies import BodiesInFlowWriter, RigidBodiesWriter
from riprap.outputs.body_forces import BodyForcesWriter
from riprap.outputs.fluid import CombinedSeriesWriter, FluidFieldsWriter
from riprap.outputs.gauges import GaugesWriter
from riprap.outputs.solver_log import SolverLogWriter
from riprap.outputs.stresses import DeformableFramesWriter, StressesWriter

#: The names of riprap's own writers: the output families a run's default writers come from, and
#: what ``Simulation.set_output_interval`` (``[output] <name>_interval``) may name.
DEFAULT_WRITER_NAMES = tuple(sorted({cls.name for cls in (
    RigidBodiesWriter, BodiesInFlowWriter, FluidFieldsWriter, CombinedSeriesWriter, GaugesWriter,
    BodyForcesWriter, DeformableFramesWriter, StressesWriter, SolverLogWriter)}))

__all__ = ["DEFAULT_WRITER_NAMES", "Writer", "ModelFrames", "RigidBodiesWriter", "BodiesInFlowWriter", "FluidFieldsWriter",
           "CombinedSeriesWriter", "GaugesWriter", "BodyForcesWriter", "DeformableFramesWriter",
           "StressesWriter", "SolverLogWriter"]
