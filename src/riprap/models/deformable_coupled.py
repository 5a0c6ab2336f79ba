"""Deformable bodies in the flow as a model of the run loop: the coupled run's fluid steps
(:class:`riprap.models.fluid.CoupledModel`), with the deformable run's stresses
(:class:`riprap.models.deformable.DeformableModel`): ``bodies.pvd`` carries the stress fields,
``units.csv`` the largest tensile stress of every unit (looked for every 50 of the bodies' steps
and after every fluid step), and
``peak_stress.png``/``final_stress.png`` show them."""
from __future__ import annotations

import numpy as np

from riprap.models.deformable import RECORD_EVERY_STEPS
from riprap.models.fluid import CoupledModel, FluidModel
from riprap.outputs.stresses import DeformableFramesWriter, StressesWriter

__all__ = ["DeformableCoupledModel"]


class DeformableCoupledModel(CoupledModel):
    """A :class:`riprap.coupling.deformable_coupled.DeformableCoupledSolver` stepped by the
    fluid's steps; ``stresses`` (a DeformableModel of the same system) keeps the stress records
    and writes the bodies' outputs."""

    kind = "riprap deformable coupled run"
    name = "deformable_coupled"

    def __init__(self, coupled, stresses):
        super().__init__(coupled)
        self.stresses = stresses
        self.deformable_steps = 0
        # the largest tensile stresses are looked for every RECORD_EVERY_STEPS of the bodies'
        # steps, as in a dry run (an impact lasts a fraction of a fluid step), and at the end of
        # every fluid step
        coupled.on_steps = stresses.record_stresses
        coupled.steps_between_calls = RECORD_EVERY_STEPS

    @property
    def system(self):
        return self.stresses.system

    def prepare(self, *, restarted: bool) -> None:
        # no stress record at the start: the bodies are put in the water unloaded, a state the
        # run never has once the water's pressure is on them (records follow every fluid step)
        if self.stresses.rigid is not None:
            self.stresses.place_rigid()       # the rigid bodies' surfaces, where they start
        if not restarted:
            self.stresses.check_start_overlaps()

    def advance(self, until: float) -> None:
        super().advance(until)
        self.deformable_steps += self.solver.last_substeps
        if self.system.step_count % RECORD_EVERY_STEPS:     # else on_steps has just looked
            self.stresses.record_stresses()

    # ------------------------------------------------------------------ state
    def state_arrays(self) -> dict:
        arrays = super().state_arrays()
        records = self.stresses.records
        arrays.update({"record_stress": records.stress.copy(), "record_element": records.element.copy(),
                       "record_point": records.point.copy(), "record_time": records.time.copy()})
        return arrays

    def load_state_arrays(self, arrays: dict) -> None:
        super().load_state_arrays(arrays)
        records = self.stresses.records
        records.stress[:] = arrays["record_stress"]
        records.element[:] = arrays["record_element"]
        records.point[:] = arrays["record_point"]
        records.time[:] = arrays["record_time"]

    def checkpoint_content(self, state: dict) -> tuple[dict, dict]:
        arrays, metadata = super().checkpoint_content(state)
        arrays["reference_nodes"] = np.concatenate([b.elements.reference_nodes
                                                    for b in self.system.bodies])
        metadata["body_names"] = self.stresses.body_names
        metadata["rigid_bodies"] = self.solids.n_rigid
        return arrays, metadata

    def check_checkpoint(self, path, arrays: dict, metadata: dict) -> None:
        super().check_checkpoint(path, arrays, metadata)
        self.stresses.check_checkpoint(path, arrays, {"bodies": metadata.get("body_names"),
                                                      "rigid_bodies": metadata.get("rigid_bodies", 0)})

    # ------------------------------------------------------------------ outputs
    def default_writers(self, *, paraview: bool, picture: bool) -> list:
        return (super().default_writers(paraview=paraview, picture=picture)
                + [StressesWriter(self.stresses, picture=picture)])

    def _bodies_writer(self, paraview: bool):
        # the deformable bodies' frames carry the stresses, in the series run.pvd opens with the
        # fluid's (rigid bodies have their own series, there too)
        return DeformableFramesWriter(self.stresses, paraview=paraview, cracks=False, key="bodies")

    def body_force_rows(self) -> list[str]:
        """As a coupled run's, with each body's number in the case (the coupling puts the rigid
        bodies first)."""
        deformable, rigid = self.stresses.case_numbers
        numbers = list(rigid[:self.solids.n_rigid]) + list(deformable)
        rows = super().body_force_rows()
        return [f"{numbers[int(row.split(',', 1)[0])]},{row.split(',', 1)[1]}" for row in rows]

    def progress_text(self) -> str:
        return super().progress_text() + "  " + self.stresses.progress_text().split("  dt")[0]

    def summary_fields(self, wall_time: float, steps: int) -> dict:
        fields = FluidModel.summary_fields(self, wall_time, steps)
        bodies = self.solids
        fields.update({"bodies": bodies.n_bodies, "solid_substeps": self.substeps,
                       "time_step": self.system.time_step,
                       "max_speed": float(np.linalg.norm(self.system.velocities, axis=1).max(initial=0.0)),
                       "element_steps_per_second": (self.deformable_steps * len(self.system.elements)
                                                    / max(wall_time, 1e-9)),
                       "max_tensile_stress": float(self.stresses.records.stress.max())})
        return fields

    def failure_advice(self, good: dict) -> str:
        return (super().failure_advice(good) + " For the deformable bodies: " +
                self.stresses.failure_advice(good))
