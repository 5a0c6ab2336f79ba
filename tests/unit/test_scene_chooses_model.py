"""The loop only runs (issue 36): a scene builds, a table of builders chooses the one model that
serves what the scene holds, and a model written outside riprap runs in the loop unchanged."""
from itertools import combinations

import numpy as np
import pytest

from riprap.errors import RiprapError
from riprap.models.base import Model
from riprap.scene import Scene
from riprap.models.settings import ModelSettings
from riprap.scene.choose_model import (MODEL_BUILDERS, ModelBuilder, build_model, register_model,
                                      scenes)
from riprap.simulation import Simulation

HELD = ("rigid bodies", "deformable bodies", "fluid", "coupled solver")


def _scenes():
    for size in range(len(HELD) + 1):
        for held in combinations(HELD, size):
            if not {"fluid", "coupled solver"} <= set(held):    # one flow at most
                yield frozenset(held)


@pytest.mark.parametrize("held", list(_scenes()),
                         ids=lambda held: "+".join(sorted(held)) or "empty")
def test_exactly_one_model_serves_every_scene(held):
    assert len([builder for builder in MODEL_BUILDERS if held in builder.serves]) == 1


@pytest.mark.parametrize("held, name", [
    (set(), "rigid"), ({"rigid bodies"}, "rigid"), ({"fluid"}, "fluid"),
    ({"fluid", "rigid bodies"}, "coupled"), ({"coupled solver", "rigid bodies"}, "coupled"),
    ({"deformable bodies", "rigid bodies"}, "deformable"),
    ({"deformable bodies", "fluid"}, "deformable_coupled")])
def test_the_model_each_scene_gets(held, name):
    [builder] = [builder for builder in MODEL_BUILDERS if frozenset(held) in builder.serves]
    assert builder.name == name


class _Falling(Model):
    """A point falling from rest, advanced exactly: a model riprap does not know."""

    kind = "test falling point"
    name = "falling"

    def __init__(self, step: float = 0.01):
        self.clock = np.array([0.0, 0.0, step])

    @property
    def time(self):
        return float(self.clock[0])

    @property
    def step_count(self):
        return int(self.clock[1])

    def reached(self, time):
        return self.time >= time - 1e-12

    def advance(self, until):
        steps = max(1, round((until - self.time) / self.clock[2]))
        self.clock[:2] += (steps * self.clock[2], steps)

    def last_time_step(self):
        return float(self.clock[2])

    def state_arrays(self):
        return {"clock": self.clock.copy()}

    def load_state_arrays(self, arrays):
        self.clock[:] = arrays["clock"]

    def summary_fields(self, wall_time, steps):
        return {"max_speed": 9.81 * self.time}


def test_a_model_written_outside_riprap_runs_in_the_loop(tmp_path):
    sim = Simulation(_Falling(), end_time=0.1, output_interval=0.05, progress=False,
                     output_directory=tmp_path)
    summary = sim.run()
    assert summary.model == "falling" and summary.end_reason == "end_time"
    assert summary.simulated_time == pytest.approx(0.1) and summary.frames == 3
    assert summary.max_speed == pytest.approx(0.981)


def test_a_registered_builder_serves_its_scenes_and_no_two_serve_one():
    class PointScene(Scene):
        def holds(self):
            return frozenset({"points"})

    built = []
    builder = ModelBuilder("falling", scenes(("points",)),
                           lambda scene, settings, restarted: built.append(settings) or _Falling())
    register_model(builder)
    try:
        model = build_model(PointScene(), ModelSettings(end_time=1.0), restarted=False)
        assert isinstance(model, _Falling) and built[0].end_time == 1.0
        with pytest.raises(RiprapError, match="served by 'falling' already"):
            register_model(ModelBuilder("twin", scenes(("points",)), builder.build))
    finally:
        MODEL_BUILDERS.remove(builder)
    with pytest.raises(RiprapError, match="served by none"):
        build_model(PointScene(), ModelSettings(end_time=1.0), restarted=False)


def test_a_scene_built_apart_runs_as_the_simulation_built_it():
    scene = Scene(gravity=(0.0, 0.0, -1.0))
    sim = Simulation(scene, end_time=1.0, progress=False)
    assert sim.solver is scene.solver and sim.scene is scene
    assert sim.model.name == "rigid" and sim.model.settings.end_time == 1.0
