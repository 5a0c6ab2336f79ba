"""Contact-only bodies and their filter zone (issue 51, item 4; ``riprap.coupling.filter_layer``):
fixed rocks smaller than ``[fluid] contact_only_below_cells`` are met by the free bodies and not
by the flow, which sees a porous zone in their place (the case's, or one fitted to them); a ball
sinks onto such a bed and rests on it; bad thresholds and filter zones over the free bodies are
refused naming the key or the zone, before anything is written."""
import csv
import re
import warnings

import numpy as np
import pytest

from riprap.case.build_fluid import build_fluid_run
from riprap.case.load import load_case
from riprap.cli import main
from riprap.coupling.filter_layer import FILTER_POROSITY, UNRESOLVED_BELOW_CELLS
from riprap.errors import CaseFileError
from riprap.fluid.porous import DEFAULT_LINEAR, DEFAULT_QUADRATIC
from riprap.work_estimate import RiprapWarning

ROCK_RADIUS, ROCK_SPACING, ROCKS_PER_SIDE = 0.008, 0.02, 9
ROCK_HEIGHT = ROCK_RADIUS + 0.0005          # their centres (clear of the floor: inside the box)
BALL_RADIUS = 0.03
CELL = 0.0125
#: Where the ball rests on four rocks of the bed (their centres ROCK_SPACING apart).
RESTING_HEIGHT = ROCK_HEIGHT + np.sqrt((BALL_RADIUS + ROCK_RADIUS) ** 2
                                       - 2 * (ROCK_SPACING / 2) ** 2)
#: The ball's height on the floor, without the rocks.
ON_THE_FLOOR = BALL_RADIUS


def _rocks() -> str:
    return "".join(f'[[bodies]]\nshape = "rock"\nmaterial = "stone"\nfixed = true\n'
                   f"position = [{0.02 + i * ROCK_SPACING:.4f}, {0.02 + j * ROCK_SPACING:.4f}, "
                   f"{ROCK_HEIGHT}]\n"
                   for i in range(ROCKS_PER_SIDE) for j in range(ROCKS_PER_SIDE))


#: A bed of 81 fixed rocks of 1.03 cells (nominal diameter) on the floor of a water box of
#: 0.0125 m cells, and a free ball of 3.9 cells above it.
BED = """format_version = 1
[simulation]
end_time = {end_time}
output_interval = 0.1
[fluid]
lower = [0.0, 0.0, 0.0]
upper = [0.2, 0.2, 0.2]
cells = [16, 16, 16]
surface_tension = 0.0
{key}
[[water_regions]]
type = "level"
level = 0.15
[[materials]]
name = "stone"
density = 2000.0
contact_penalty = 1.0e7
restitution = 0.1
[[shapes]]
name = "ball"
type = "sphere"
radius = 0.03
mesh_size = 0.01
[[shapes]]
name = "rock"
type = "sphere"
radius = 0.008
mesh_size = 0.004
[[bodies]]
shape = "ball"
material = "stone"
position = [0.1, 0.1, 0.1]
""" + _rocks()

#: A [[porous_zones]] entry over the rocks only (up to 2 mm above their tops).
ZONE_OVER_THE_ROCKS = """[[porous_zones]]
type = "box"
porosity = 0.45
stone_diameter = 0.013
lower = [0.0, 0.0, 0.0]
upper = [0.2, 0.2, 0.018]
"""


def bed_case(threshold=2.0, end_time=0.01, extra=""):
    """The bed's case text with ``[fluid] contact_only_below_cells = threshold`` (None: no key)."""
    key = "" if threshold is None else f"contact_only_below_cells = {threshold}"
    return BED.format(end_time=end_time, key=key) + extra


def _load(tmp_path, text):
    path = tmp_path / "case.toml"
    path.write_text(text)
    return load_case(path)


def test_the_small_fixed_rocks_are_left_out_of_the_flow_under_a_fitted_filter_zone(tmp_path):
    simulation = build_fluid_run(_load(tmp_path, bed_case()), output_directory=tmp_path / "out",
                                 progress=False)
    rocks = list(range(1, 1 + ROCKS_PER_SIDE ** 2))
    assert simulation.contact_only_bodies == rocks
    layer = simulation.filter_layer
    assert list(layer.bodies) == rocks and layer.covering == []
    assert layer.sizes.max() < 2.0 < 3.5 < np.cbrt(4 / 3 * np.pi) * BALL_RADIUS / CELL
    (zone,) = layer.fitted
    assert (zone.porosity, zone.linear, zone.quadratic) == (FILTER_POROSITY, DEFAULT_LINEAR,
                                                            DEFAULT_QUADRATIC)
    # the rocks' Dn50: a meshed sphere's V^(1/3), a little under the sphere's
    assert zone.stone_diameter == pytest.approx(np.cbrt(4 / 3 * np.pi) * ROCK_RADIUS, rel=0.05)
    # the band from the floor to the rocks' tops, along x
    polygon = np.array(zone.polygon)
    assert polygon[:, 1].min() == pytest.approx(ROCK_HEIGHT - ROCK_RADIUS, abs=1e-3)
    assert polygon[:, 1].max() == pytest.approx(ROCK_HEIGHT + ROCK_RADIUS, abs=1e-3)
    assert polygon[:, 0].min() < 0.02 - 0.9 * ROCK_RADIUS
    assert polygon[:, 0].max() > 0.18 + 0.9 * ROCK_RADIUS
    fluid = simulation.fluid
    assert fluid.porous.zones[0] is zone
    # the bottom row of cells inside the bed (a polygon's cover: 4 x 4 samples a cell)
    assert fluid.porous.porosity[3:-3, :, 0] == pytest.approx(FILTER_POROSITY)
    assert fluid.porous.porosity[:, :, 3:].min() == 1.0
    # the coupling leaves them out: no solid of theirs in any cell, the ball's there
    coupled = simulation.model.solver
    assert set(rocks) <= set(coupled.obstacle_bodies.tolist())
    solid = coupled.body_fraction()
    assert solid[:, :, 0].max() == 0.0
    assert solid[8, 8, 8] == pytest.approx(1.0)


def test_a_case_zone_over_the_rocks_stands_for_them_and_none_is_fitted(tmp_path):
    simulation = build_fluid_run(_load(tmp_path, bed_case(extra=ZONE_OVER_THE_ROCKS)),
                                 output_directory=tmp_path / "out", progress=False)
    layer = simulation.filter_layer
    assert layer.fitted == [] and len(layer.bodies) == ROCKS_PER_SIDE ** 2
    assert layer.covering == [f"{tmp_path / 'case.toml'} [[porous_zones]] entry 1"]
    assert [zone.porosity for zone in simulation.fluid.porous.zones] == [0.45]


def test_without_the_key_small_fixed_bodies_are_named_in_a_warning(tmp_path):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        simulation = build_fluid_run(_load(tmp_path, bed_case(threshold=None)),
                                     output_directory=tmp_path / "out", progress=False)
    texts = [str(w.message) for w in caught if issubclass(w.category, RiprapWarning)]
    assert any(f"81 fixed bodies span fewer than {UNRESOLVED_BELOW_CELLS:g} cells" in text
               and "contact_only_below_cells" in text for text in texts), texts
    assert simulation.contact_only_bodies == [] and simulation.fluid.porous is None


@pytest.mark.parametrize("threshold, extra, phrase", [
    # the ball spans 3.9 cells: a threshold above it takes the units for rocks
    (5.0, "", "[fluid] contact_only_below_cells = 5: every free body spans fewer cells"),
    # a zone up through the ball
    (2.0, ZONE_OVER_THE_ROCKS.replace("0.018]", "0.2]"), "[[porous_zones]] entry 1: this porous "
                                                         "filter zone holds 1.00 of free body 0"),
])
def test_bad_thresholds_and_zones_are_refused_naming_them(tmp_path, threshold, extra, phrase):
    with pytest.raises(CaseFileError) as error:
        build_fluid_run(_load(tmp_path, bed_case(threshold=threshold, extra=extra)),
                        output_directory=tmp_path / "out", progress=False)
    assert phrase in str(error.value)
    assert not (tmp_path / "out").exists()


def test_a_threshold_over_every_body_is_refused(tmp_path):
    text = bed_case().replace("position = [0.1, 0.1, 0.1]",
                              "position = [0.1, 0.1, 0.1]\nfixed = true")
    with pytest.raises(CaseFileError, match=r"contact_only_below_cells = 5: every one of the 82 "
                                            r"bodies spans fewer cells"):
        build_fluid_run(_load(tmp_path, text.replace("contact_only_below_cells = 2.0",
                                                     "contact_only_below_cells = 5")),
                        output_directory=tmp_path / "out", progress=False)


def test_a_ball_sinks_onto_contact_only_rocks_and_rests_on_them(tmp_path, capsys):
    path = tmp_path / "case.toml"
    path.write_text(bed_case(end_time=0.4))
    out = tmp_path / "run"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    said = capsys.readouterr().out
    assert re.search(r"filter layer: 81 fixed bodies of 1\.0\d cells are contact-only", said), said
    with open(out / "body_forces.csv") as table:
        rows = list(csv.DictReader(table))
    ball = [row for row in rows if row["body"] == "0"][-1]
    # carried by the rocks' contact (on the floor it would be at ON_THE_FLOOR)
    assert float(ball["z_m"]) == pytest.approx(RESTING_HEIGHT, abs=0.003)
    assert float(ball["z_m"]) > ON_THE_FLOOR + 0.008
    assert abs(float(ball["vz_m_per_s"])) < 0.02
    # the rocks carry the ball, and the water gives them no force
    rocks = [row for row in rows if row["body"] != "0" and row["time_s"] == ball["time_s"]]
    assert len(rocks) == ROCKS_PER_SIDE ** 2
    assert sum(abs(float(row["contact_force_z_N"])) for row in rocks) > 0.0
    for part in ("pressure_force", "viscous_force"):
        assert all(float(row[f"{part}_{axis}_N"]) == 0.0 for row in rocks for axis in "xyz")


def test_check_prints_the_fitted_zone_as_a_case_file_entry(tmp_path, capsys):
    path = tmp_path / "case.toml"
    path.write_text(bed_case())
    assert main(["check", str(path)]) == 0
    said = capsys.readouterr().out
    assert "contact-only bodies and their filter zones" in said
    assert "filter layer: the filter zone fitted to the 81 contact-only bodies" in said
    assert '[[porous_zones]]\ntype = "polygon"\nporosity = 0.4' in said


def test_the_key_is_in_a_restart_record_only_when_given(tmp_path):
    """A checkpoint written before the key existed has no record of it: without the key the
    record is as it was (such a checkpoint restarts); given, changing it is refused."""
    from riprap.case.run_record import RunDefinition

    without = RunDefinition.of(_load(tmp_path, bed_case(threshold=None)))
    assert not any("contact_only_below_cells" in key for key in without.values)
    given = RunDefinition.of(_load(tmp_path, bed_case(threshold=2.0)))
    assert given.values["[fluid] contact_only_below_cells"] == "2.0"
    assert given.changes(without.values) == [
        "[fluid] contact_only_below_cells was (not set), is now 2.0"]


def test_rocks_that_make_no_straight_band_are_refused_with_the_recipe(tmp_path):
    """A block of rocks 9 high (not a layer): no band of a few Dn50 fits them."""
    block = "".join(f'[[bodies]]\nshape = "rock"\nmaterial = "stone"\nfixed = true\n'
                    f"position = [{0.02 + i * ROCK_SPACING:.4f}, 0.02, "
                    f"{ROCK_HEIGHT + j * ROCK_SPACING:.4f}]\n"
                    for i in range(ROCKS_PER_SIDE) for j in range(ROCKS_PER_SIDE))
    text = "[[bodies]]".join(bed_case().split("[[bodies]]")[:2])     # the case and its ball
    with pytest.raises(CaseFileError, match=r"do not lie in one straight band .* give "
                                            r"\[\[porous_zones\]\] entries covering them"):
        build_fluid_run(_load(tmp_path, text + block), output_directory=tmp_path / "out",
                        progress=False)
