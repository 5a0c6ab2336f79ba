"""Writers: one per output family, each on its own schedule (:mod:`riprap.schedules`), driven by
the run loop (:meth:`riprap.simulation.Simulation.run`); a user's own writer is attached with
:meth:`riprap.simulation.Simulation.add_writer`.

- :class:`RigidBodiesWriter`: ``bodies.pvd``, ``contacts.pvd``, ``final_state.png`` (dry runs);
- :class:`GaugesWriter`: ``gauges.csv``, ``waves_report.json``, ``gauges.png`` (flumes);
- :class:`BodyForcesWriter`: ``body_forces.csv`` (bodies in a flow);
- :class:`StressesWriter`: ``units.csv``, ``fragments.csv`` and the stress pictures (deformable);
- :class:`ModelFrames`: the frames the models still write themselves (the fluid's ``.vti`` and
  free-surface pictures, the bodies in a flow, the deformable bodies' stresses and cracks).
"""
from riprap.outputs.base import ModelFrames, Writer
from riprap.outputs.bodies import RigidBodiesWriter
from riprap.outputs.body_forces import BodyForcesWriter
from riprap.outputs.gauges import GaugesWriter
from riprap.outputs.stresses import StressesWriter

__all__ = ["Writer", "ModelFrames", "RigidBodiesWriter", "BodyForcesWriter", "GaugesWriter",
           "StressesWriter"]
