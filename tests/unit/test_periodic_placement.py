"""Placement on a periodic strip (issue 53): ``[slope] sides = "periodic"``.

What is checked: `riprap place` on a strip 5 Dn wide of single-layer cubes
(tests/unit/cases/periodic_cube_strip.toml) writes no side walls, a pack whose [simulation] makes
the bodies a strip (periodic_y_low/high) and a layer.json that says so; the rock lattice and the
staggered rows continue across the strip's side (units across it, contacts between units that
meet only across it); every unit comes to rest, and the pack run on continues periodic with no unit
moving more than 1 mm in 0.3 s. A strip narrower than twice a unit's bounding diameter, and rows
of different counts, are refused before anything runs.
"""
import json
from pathlib import Path

import numpy as np
import pytest

from riprap.case.build import build_simulation
from riprap.case.load import load_case, parse_case
from riprap.errors import CaseFileError
from riprap.workflows.place import prepare_placement, run_placement

CASE = Path(__file__).parent / "cases" / "periodic_cube_strip.toml"
WIDTH = 0.23
DN = 0.046


@pytest.fixture(scope="module")
def placed(tmp_path_factory):
    out = tmp_path_factory.mktemp("strip")
    summary = run_placement(load_case(CASE), output_directory=out, progress=False)
    return summary, out


def test_a_strip_places_across_its_sides_and_its_pack_runs_periodic(placed, tmp_path):
    summary, out = placed
    assert summary["units_placed"] == 16 and summary["units_at_rest"] == 16
    pack = load_case(out / "pack.toml")
    assert (pack.simulation.periodic_y_low, pack.simulation.periodic_y_high) == (0.0, WIDTH)
    assert all(abs(wall.parameters["normal"][1]) < 1e-12 for wall in pack.walls)
    assert json.loads((out / "layer.json").read_text())["slope"]["periodic"] is True
    sim = build_simulation(pack, output_directory=tmp_path / "run")
    solver = sim.solver
    assert solver.periodic == (1, 0.0, WIDTH)
    solver.finalize()
    y = solver.positions[:, 1]
    assert y.min() >= 0.0 and y.max() < WIDTH
    fixed = solver.fixed
    # the rock lattice continues across the sides: rocks within a rock's size of both
    assert y[fixed].min() < DN and y[fixed].max() > WIDTH - DN
    units = np.flatnonzero(~fixed)
    # units whose half width reaches across a side, and pairs of units touching only there
    assert np.any((y[units] < 0.5 * DN) | (y[units] > WIDTH - 0.5 * DN))
    contacts = np.loadtxt(out / "contacts.csv", delimiter=",", skiprows=2, ndmin=2)
    pairs = contacts[(contacts[:, 1] >= 0)].astype(int)[:, :2]
    between_units = pairs[~fixed[pairs[:, 0]] & ~fixed[pairs[:, 1]]]
    across = np.abs(y[between_units[:, 0]] - y[between_units[:, 1]]) > 0.5 * WIDTH
    assert across.any()
    start = solver.positions.copy()
    sim.end_time = 0.3
    sim.run()
    moved = solver.positions[units] - start[units]
    moved[:, 1] -= WIDTH * np.round(moved[:, 1] / WIDTH)        # a unit may wrap
    assert np.linalg.norm(moved, axis=1).max() < 1e-3


@pytest.mark.parametrize("changes, words", [
    # two cubes a row on a strip 2.6 Dn wide: a pair would meet in two images
    ((("width = 0.23", "width = 0.12"), ("units_per_row = 4", "units_per_row = 2")),
     "narrower than twice a unit's bounding diameter"),
    ((("units_per_row = 4", "units_per_row = 4\nunits_per_alternate_row = 3"),),
     "every row holds the same number"),
])
def test_a_strip_that_cannot_hold_is_refused_before_it_runs(changes, words):
    text = CASE.read_text()
    for old, new in changes:
        text = text.replace(old, new)
    case = parse_case(text, source="strip.toml", base_dir=CASE.parent)
    with pytest.raises(CaseFileError, match=words):
        prepare_placement(case)


def test_the_survey_of_a_strip_sees_no_damage_in_the_layer_moved_along_it(placed):
    """The placed strip's layer, every body moved 2 profile samples along y (and taken back into
    the strip): the same layer of an infinitely wide flume. Its width-averaged profile is the
    one before, so the eroded area is 0 to round-off (1e-12 m^2; the surfaces across the strip's
    side are laid at their images), and every unit's displacement is the move itself (0.5 Dn,
    not the strip's width, for those that crossed the side): N_od 0."""
    from dataclasses import replace

    from riprap.analysis.layer_analysis import analyse_layer
    from riprap.workflows.layer_input import load_pack_state

    _, out = placed
    state = load_pack_state(out)
    assert state.layer.slope.periodic
    shift = 2 * DN / 4
    moved = state.positions.copy()
    moved[:, 1] = np.mod(moved[:, 1] + shift, WIDTH)
    crossed = moved[:, 1] < state.positions[:, 1]
    assert crossed.any()
    later = replace(state, positions=moved, reference_positions=state.positions,
                    reference_rotations=state.rotations, reference_time=0.0,
                    reference_note="the placed layer")
    analysis = analyse_layer(later)
    assert abs(analysis.layer["eroded_area_m2"]) < 1e-12
    assert np.allclose(analysis.units["displacement_m"], shift, rtol=1e-9)
    assert analysis.layer["damage_number_nod"] == 0.0


def test_a_track_across_the_strip_side_is_unwrapped():
    """A unit's recorded track crossing the side of a 0.23 m strip in steps of 5 mm (wrapped by
    the solver: 2.5 cm in all, 0.54 Dn), and a unit that slid 1.5 Dn down the slope: only the
    second is displaced."""
    from riprap.analysis.per_wave_table import UnitTracks, _unit_columns

    times = np.arange(6, dtype=float)
    crossing = np.column_stack([np.full(6, 0.1), np.mod(0.22 + 0.005 * times, WIDTH),
                                np.full(6, 0.05)])
    sliding = np.column_stack([0.1 - 1.5 * DN * times / 5, np.full(6, 0.1), np.full(6, 0.05)])
    tracks = UnitTracks(unit=np.repeat([0, 1], 6), time=np.tile(times, 2),
                        position=np.vstack([crossing, sliding]), peak_force=np.zeros(12),
                        nominal_diameter=DN, section_width=WIDTH, period_y=WIDTH)
    moved = crossing - crossing[0]
    assert np.abs(moved[:, 1]).max() > WIDTH / 2        # as recorded, it jumped a strip's width

    class _Layout:
        toe_x, armour_x, peak_period, depth = 0.0, 0.0, 1.0, 1.0
    waves = np.array([[0.0, 5.5]])
    table = {"largest_fluid_force_N": np.full(1, np.nan), "force_unit": np.full(1, np.nan)}
    from riprap.analysis import per_wave_table as module
    original = module._shifted
    module._shifted = lambda w, layout, x: (w[:, 0], w[:, 1])
    try:
        _unit_columns(table, waves, _Layout, tracks, 1.0)
    finally:
        module._shifted = original
    assert table["units_displaced"].tolist() == [1.0]


def _unit_contact_forces(out: Path) -> np.ndarray:
    """Per unit of a placed layer, the sum of its contacts' normal force magnitudes over its
    weight (contacts.csv: forces on body_i; every unit-unit contact listed once)."""
    pack = load_case(out / "pack.toml")
    units = [b for b, body in enumerate(pack.bodies) if not body.fixed]
    contacts = np.loadtxt(out / "contacts.csv", delimiter=",", skiprows=2, ndmin=2)
    normal = np.linalg.norm(contacts[:, 5:8], axis=1)
    total = np.zeros(len(pack.bodies))
    np.add.at(total, contacts[:, 0].astype(int), normal)
    others = contacts[:, 1].astype(int)
    np.add.at(total, others[others >= 0], normal[others >= 0])
    weight = 2300.0 * DN ** 3 * 9.81
    return total[units] / weight


def test_a_strip_one_unit_wider_holds_its_units_alike(placed, tmp_path):
    """The same layer on a strip one unit wider (5 cubes a row, 6.25 Dn): the units' summed
    contact force over their weight has the same mean within the spread the placement itself
    gives (the larger standard deviation of the two over the units): a narrow strip holds its
    units as a wider one does, where walls would add their own forces at every row's ends."""
    _, narrow = placed
    text = (CASE.read_text().replace("width = 0.23", "width = 0.2875")
            .replace("units_per_row = 4", "units_per_row = 5"))
    case = parse_case(text, source="wide_strip.toml", base_dir=CASE.parent)
    wide = tmp_path / "wide"
    summary = run_placement(case, output_directory=wide, progress=False)
    assert summary["units_placed"] == 20 and summary["units_at_rest"] == 20
    a, b = _unit_contact_forces(narrow), _unit_contact_forces(wide)
    spread = max(a.std(), b.std())
    assert 0.5 < a.mean() < 5.0 and 0.5 < b.mean() < 5.0      # they carry their weight
    assert abs(a.mean() - b.mean()) < spread, (a.mean(), b.mean(), spread)
