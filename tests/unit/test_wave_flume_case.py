"""A flume in a case file (``[waves]``, ``[[gauges]]``): it runs, writes its gauges and report,
restarts with the gauge records continued bit for bit, and bad flume input is refused naming the
file and the key."""
import dataclasses
import json

import numpy as np
import pytest

from riprap.case.build_fluid import build_fluid_run
from riprap.case.load import parse_case
from riprap.errors import CaseFileError

# A short, coarse flume (a linear wave of 4 cm, T = 1 s, d = 0.3 m: L = 1.40 m; 2 cm cells).
CASE = """
format_version = 1
[simulation]
end_time = {end_time}
output_interval = 0.2
[fluid]
lower = [0.0, 0.0, 0.0]
upper = [{length}, 0.02, 0.44]
cells = [{cells}, 1, 22]
surface_tension = 0.0
x_low = "free_slip"
x_high = "free_slip"
[[water_regions]]
type = "level"
level = 0.3
[waves]
type = "{kind}"
still_water_level = 0.3
height = 0.04
period = 1.0
{extra}
[[gauges]]
type = "surface"
name = "a"
position = [{gauge_x}, 0.01, 0.0]
[[gauges]]
type = "surface"
name = "b"
position = [2.0, 0.01, 0.0]
[[gauges]]
type = "velocity"
name = "u"
position = [1.8, 0.01, 0.15]
[[gauges]]
type = "overtopping"
name = "over"
position = [1.5, 0.01, 0.0]
[[gauges]]
type = "overtopping"
name = "above"
position = [1.5, 0.01, {above_z}]
[[gauges]]
type = "run_up"
name = "up"
position = [1.0, 0.01, 0.0]
to_x = 2.0
"""


def _case(end_time=0.4, length=5.6, kind="linear", extra="", gauge_x=1.8, above_z=0.42):
    text = CASE.format(end_time=end_time, length=length, cells=round(length / 0.02), kind=kind,
                       extra=extra, gauge_x=gauge_x, above_z=above_z)
    return parse_case(text, source="flume.toml")


def _run(tmp_path, name, end_time, restart=None, extra=""):
    run = build_fluid_run(_case(end_time, extra=extra), output_directory=tmp_path / name,
                          progress=False)
    return run, run.run(restart_from=restart)


def test_flume_writes_gauges_and_report_and_restarts_bit_for_bit(tmp_path):
    whole, _ = _run(tmp_path, "whole", 0.4)
    _run(tmp_path, "first", 0.2)
    second, _ = _run(tmp_path, "first", 0.4, restart=tmp_path / "first" / "checkpoint.npz")
    assert np.array_equal(second.fluid.fraction, whole.fluid.fraction)
    assert np.array_equal(second.fluid.gauges.values, whole.fluid.gauges.values)
    assert np.array_equal(second.fluid.gauges.times, whole.fluid.gauges.times)
    table = np.loadtxt(tmp_path / "first" / "gauges.csv", delimiter=",", skiprows=1)
    header = (tmp_path / "first" / "gauges.csv").read_text().splitlines()[0]
    assert header == ("time_s,a_eta_m,b_eta_m,u_u_m_s,u_v_m_s,u_w_m_s,over_q_m3_s_m,"
                      "over_volume_m3_m,above_q_m3_s_m,above_volume_m3_m,up_level_m")
    assert table.shape == (whole.fluid.step_count, 11)
    assert abs(table[-1, 7]) > 0.0          # the generation zone pushes water through x = 1.5
    # ... but none of it above z = 0.42 m (the still water at 0.3 m, waves of 4 cm): a gauge on
    # a crest counts only what goes over it
    assert np.all(table[:, 8:10] == 0.0)
    assert np.allclose(table[:, 1:], whole.fluid.gauges.values, rtol=1e-8, atol=1e-12)
    # the zone makes a wave from the start (ramped): gauge a, inside the generation zone's reach,
    # has moved; the report says the record is too short to analyse yet
    report = json.loads((tmp_path / "first" / "waves_report.json").read_text())
    assert report["target"]["period_s"] == 1.0
    assert "note" in report["gauges"]["a"]
    assert "over" in report["overtopping"] and "up" in report["run_up"]
    assert (tmp_path / "first" / "gauges.png").exists()


@pytest.mark.parametrize("change, message", [
    (dict(length=3.0), "fill the whole flume"),
    (dict(extra="generation_zone = 0.3"), "generation zone is 0.3 m long"),
    (dict(extra="absorption_zone = 0.5"), "needed to absorb"),
    (dict(gauge_x=9.0), "flume.toml \\[\\[gauges\\]\\]: gauge 'a'"),
    (dict(above_z=4.2), "gauge 'above' at \\[1.5, 0.01, 4.2\\] m is outside the fluid box"),
    (dict(extra='generation = "boundary"\ngeneration_zone = 1.4'), "which has no zone"),
    (dict(extra='generation = "boundary"\nabsorption_zone = 0.5'), "needed to absorb"),
    (dict(extra='generation = "bounday"'), "generation"),
])
def test_bad_flumes_are_refused_naming_the_file(change, message):
    with pytest.raises(CaseFileError, match=message):
        build_fluid_run(_case(**change), progress=False)


@pytest.mark.parametrize("value, message", [
    ("-0.3", "flume.toml:41: gauges\\[4\\].crest_width = -0.3: out of range; expected a number "
             "in m, >= 0"),
    ("3e6", "gauges\\[4\\].crest_width = 3e\\+06: far outside any physical value"),
    ('"wide"', "gauges\\[4\\].crest_width = \"wide\": expected a number in m"),
])
def test_a_bad_crest_width_is_refused_naming_the_line_and_key(value, message):
    text = CASE.format(end_time=0.4, length=5.6, cells=280, kind="linear", extra="", gauge_x=1.8,
                       above_z=0.42).replace('name = "above"\n',
                                             f'name = "above"\ncrest_width = {value}\n')
    with pytest.raises(CaseFileError, match=message):
        parse_case(text, source="flume.toml")


def test_a_crest_width_is_only_for_an_overtopping_gauge():
    text = CASE.format(end_time=0.4, length=5.6, cells=280, kind="linear", extra="", gauge_x=1.8,
                       above_z=0.42).replace('name = "a"\n', 'name = "a"\ncrest_width = 0.3\n')
    with pytest.raises(CaseFileError, match="'crest_width' is a key of \\[\\[gauges\\]\\] with "
                                            'type = "overtopping", not "surface"'):
        parse_case(text, source="flume.toml")


def test_waves_without_a_fluid_are_refused_at_the_line():
    text = """format_version = 1
[simulation]
end_time = 1.0
[[materials]]
name = "m"
[[shapes]]
name = "s"
type = "sphere"
radius = 0.1
[[bodies]]
shape = "s"
material = "m"
position = [0, 0, 0]
[waves]
type = "linear"
still_water_level = 0.3
height = 0.04
period = 1.0
"""
    with pytest.raises(CaseFileError, match="needs a \\[fluid\\] table"):
        parse_case(text, source="dry.toml")
    with pytest.raises(CaseFileError, match="heigth"):
        _case(extra="heigth = 0.1")


def test_an_irregular_sea_is_built_from_its_spectrum():
    def sea_case(end_time):
        text = CASE.format(end_time=end_time, length=5.6, cells=280, kind="irregular", extra="",
                           gauge_x=1.8, above_z=0.42)
        text = text.replace("height = 0.04\nperiod = 1.0", "significant_height = 0.05\npeak_period = 1.0")
        return parse_case(text, source="sea.toml")

    sea = build_fluid_run(sea_case(20.0), progress=False).fluid.relaxation.wave
    assert sea.duration == 20.0 and sea.frequencies[1] - sea.frequencies[0] == pytest.approx(1 / 20.0)
    with pytest.raises(CaseFileError, match="sea.toml \\[waves\\]: waves: duration 1 s"):
        build_fluid_run(sea_case(1.0), progress=False)


def test_a_boundary_wave_maker_restarts_bit_for_bit_and_brings_water_in(tmp_path):
    """generation = "boundary": the x = lower faces carry the wave's velocity (no zone), the water
    that enters through them is counted, and a restart continues exactly (the boundary velocity
    is a function of the time and the water in the first cells, both in the checkpoint)."""
    extra = 'generation = "boundary"'
    whole, _ = _run(tmp_path, "whole", 0.8, extra=extra)
    _run(tmp_path, "first", 0.4, extra=extra)
    second, _ = _run(tmp_path, "first", 0.8, restart=tmp_path / "first" / "checkpoint.npz",
                     extra=extra)
    fluid = whole.fluid
    assert fluid.relaxation.zones[0].kind == "absorption" and len(fluid.relaxation.zones) == 1
    assert np.array_equal(second.fluid.fraction, fluid.fraction)
    assert np.array_equal(second.fluid.u, fluid.u)
    assert np.array_equal(second.fluid.gauges.values, fluid.gauges.values)
    # the boundary moves water: its face velocity is the wave's under the surface and zero in air
    maker = fluid.wave_maker
    assert np.abs(fluid.u[0]).max() > 1e-3
    above = fluid.grid.centres(2) > 0.3 + 0.04
    assert np.all(fluid.u[0][:, above] == 0.0)
    # ... and the first column's water is what came through it: the fluid's volume changed by the
    # water the boundary let in, not by air turned into water
    assert fluid.water_volume() != fluid.initial_water_volume
    assert abs(fluid.last_report.water_volume_error) < 5e-3
    assert maker.last_correction is not None and maker.last_correction.shape == (1,)


def test_a_boundary_wave_maker_needs_an_open_top_and_open_boundary_cells():
    from riprap.case.build_fluid import build_fluid_solver
    from riprap.waves.boundary_generation import BoundaryWaveMaker

    case = _case(extra='generation = "boundary"')
    closed = dataclasses.replace(case, fluid=dataclasses.replace(case.fluid, z_high="free_slip"))
    with pytest.raises(CaseFileError, match="needs an open top"):
        build_fluid_solver(closed)
    fluid = build_fluid_solver(_case())
    fluid.add_obstacle_box((0.0, 0.0, 0.0), (0.04, 0.02, 0.1))
    with pytest.raises(CaseFileError, match="must be open"):
        BoundaryWaveMaker(fluid.relaxation.wave, 0.3).attach(fluid)
