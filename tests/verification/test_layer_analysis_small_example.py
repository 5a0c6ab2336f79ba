"""riprap analyse on the small Core-Loc example (``examples/coreloc_small.toml``, placed in full by
the session fixture ``small_placement``).

Checks and sources:

- Static equilibrium (the seed paper: at the end of a POSITIT run "the particles are touching and
  in static force equilibrium"): for every unit, the contact forces read back from the pack
  (``contacts.csv``) balance its weight within ``EQUILIBRIUM_TOLERANCE`` = 5 % of the weight
  (measured here: 0.0-4.2 %; the placement stops once every unit is slower than 0.02 m/s and
  its net force is under 5 % of its weight, ``riprap.models.rigid.at_rest``; with 10 % there,
  a unit still rocking came out at 5.8 % on CI).
- Coordination numbers within the range the seed paper reports for its 242-unit Core-Loc layer,
  2 to 10 (Xiang et al., Fig. 3b).
- The layer figures equal those that ``riprap place`` reported for the same layer (one definition,
  ``riprap.placement.layer_metrics``; the pack's poses read back to rounding): relative 1e-9.
- Every file the issue names is written; ``units.csv`` has one row per unit.
"""
import numpy as np
import pytest

from riprap.workflows.analyse import analyse
from riprap.solid.contact_statistics import unit_contacts

EQUILIBRIUM_TOLERANCE = 0.05
PAPER_COORDINATION_RANGE = (2, 10)


@pytest.fixture(scope="module")
def analysed(small_placement, tmp_path_factory):
    summary, folder = small_placement
    out = tmp_path_factory.mktemp("analysis")
    return summary, analyse(folder, out=out), out


def test_units_are_in_static_equilibrium_with_the_stored_contact_forces(analysed):
    _, analysis, _ = analysed
    state = analysis.state
    stats = unit_contacts(state.n_bodies, state.contacts)
    bodies = state.layer.unit_bodies
    weights = analysis.units["weight_N"]
    down = state.gravity / np.linalg.norm(state.gravity)
    residual = np.linalg.norm(stats.total_contact_force[bodies] + weights[:, None] * down, axis=1)
    assert np.all(residual < EQUILIBRIUM_TOLERANCE * weights)


def test_coordination_numbers_within_the_papers_range(analysed):
    _, analysis, _ = analysed
    low, high = PAPER_COORDINATION_RANGE
    coordination = analysis.units["coordination_number"]
    assert coordination.min() >= low and coordination.max() <= high
    assert sum(analysis.layer["coordination_number_histogram"].values()) == len(coordination)


def test_layer_figures_match_the_placement_summary(analysed):
    summary, analysis, _ = analysed
    for key in ("packing_density_coefficient", "porosity", "layer_thickness_m"):
        assert analysis.layer[key] == pytest.approx(summary[key], rel=1e-9), key
    assert analysis.layer["design_packing_density_coefficient"] == pytest.approx(
        summary["design_packing_density_coefficient"], rel=1e-12)


def test_report_files_and_units_table(analysed):
    summary, analysis, out = analysed
    for name in ("report.html", "stereonet.png", "units.csv", "layer.vtu", "contacts.csv"):
        assert (out / name).is_file(), name
    lines = (out / "units.csv").read_text().splitlines()
    assert len(lines) == 1 + summary["units_placed"]
    header = lines[0].split(",")
    assert header[0] == "unit_id"
    largest = max(float(dict(zip(header, line.split(",")))["max_contact_force_N"])
                  for line in lines[1:])
    assert largest == pytest.approx(analysis.layer["max_contact_force_N"], rel=1e-12)
