"""report.html of riprap analyse: the verdict against design is computed from the values and the
tolerances, factors of safety beyond the display cap (inf, 222) are shown as "> cap" and the cap
is explained, a unit at rest below 1 is explained, unit labels keep their capitals, design rows
are indented. (The shared colour scale of the 3D and face views is tested in
test_analyse_pack_files.py, on its hand-made pack.)

The layers here are hand-written dictionaries (the keys of ``LayerAnalysis.layer``), so that each
verdict is known by hand: e.g. a measured thickness 11 % above design is outside +-10 %.
"""
import html
import re
from types import SimpleNamespace

import numpy as np
import pytest

from riprap.io.analysis_figures import FACTOR_OF_SAFETY_DISPLAY_CAP, PER_UNIT_FIELDS
from riprap.io.analysis_report import (DESIGN_TOLERANCES, _factor_of_safety_text, _write_report,
                                       design_verdict)

CAP_TEXT = f"> {FACTOR_OF_SAFETY_DISPLAY_CAP:g}"


def _layer(**measured):
    layer = {"source": "hand-written", "time_s": 0.0, "unit": "core_loc_like",
             "nominal_diameter_m": 0.5, "slope_angle_deg": 36.9, "units": 3,
             "underlayer_bodies": 10, "unit_weight_N": 2943.0, "max_contact_force_N": 8000.0,
             "design_packing_density_coefficient": 0.6, "design_layer_thickness_m": 1.0,
             "design_porosity": 0.6, "packing_density_coefficient": 0.6,
             "layer_thickness_m": 1.0, "porosity": 0.6,
             "coordination_number_histogram": {"3": 2, "4": 1},
             "factor_of_safety_min": 0.797, "factor_of_safety_median": np.inf,
             "units_below_factor_of_safety_1": [1]}
    layer.update(measured)
    return layer


def _units():
    return {"unit_id": np.arange(3), "row": np.array([0, 1, 1]),
            "coordination_number": np.array([3, 4, 3]),
            "unit_contacts": np.array([1, 4, 1]), "underlayer_contacts": np.array([2, 0, 2]),
            "max_contact_force_N": np.array([1000.0, 8000.0, 2000.0]),
            "factor_of_safety": np.array([1.2, 0.797, 2.0]),
            "factor_of_safety_sliding": np.array([1.2, 1.346, 2.0]),
            "factor_of_safety_rocking": np.array([np.inf, 0.797, 222.0]),
            "height_above_underlayer_m": np.array([0.3, 0.81, 0.3])}


def _verdicts(layer):
    return {row["key"]: row["inside"] for row in design_verdict(layer)}


@pytest.mark.parametrize("measured, inside", [
    # Packing density +-5 % of 0.6 = +-0.03; thickness +-10 % of 1.0 m; porosity +-0.05 absolute.
    ({"packing_density_coefficient": 0.62}, True),
    ({"packing_density_coefficient": 0.64}, False),
    ({"packing_density_coefficient": 0.56}, False),
    ({"layer_thickness_m": 1.09}, True),
    ({"layer_thickness_m": 1.11}, False),
    ({"porosity": 0.649}, True),
    ({"porosity": 0.549}, False),
])
def test_design_verdict_is_computed_from_the_values(measured, inside):
    (key, value), = measured.items()
    verdicts = _verdicts(_layer(**measured))
    assert list(verdicts) == [key for key, *_ in DESIGN_TOLERANCES]
    assert verdicts[key] is inside
    # The other two are at their design values.
    assert all(verdicts[other] for other in verdicts if other != key)
    row = next(row for row in design_verdict(_layer(**measured)) if row["key"] == key)
    assert abs(row["difference"] - (value - _layer()[f"design_{key}"])) < 1e-12


def test_design_verdict_without_a_design_value_gives_no_verdict():
    verdicts = _verdicts(_layer(design_porosity=float("nan")))
    assert verdicts["porosity"] is None and verdicts["layer_thickness_m"] is True


def test_factors_of_safety_beyond_the_cap_are_shown_as_above_it():
    assert _factor_of_safety_text(np.inf) == CAP_TEXT
    assert _factor_of_safety_text(222.0) == CAP_TEXT
    assert _factor_of_safety_text(0.797) == "0.797"
    assert _factor_of_safety_text(float("nan")) == "-"


@pytest.fixture
def report(tmp_path):
    # Thickness 15 % over design (outside), the rest inside.
    analysis = SimpleNamespace(layer=_layer(layer_thickness_m=1.15), units=_units())
    return _write_report(tmp_path, analysis).read_text()


def _table_rows(page, table_class):
    table = re.search(rf"<table class='{table_class}'>(.*?)</table>", page).group(1)
    return re.findall(r"<tr><th class='name'>(.*?)</th>.*?<td[^>]*>(inside|outside)</td></tr>",
                      table)


def test_report_has_the_verdict_table_with_three_rows(report):
    rows = _table_rows(report, "verdict")
    assert [label for label, _ in rows] == [html.escape(label) for _, label, *_ in DESIGN_TOLERANCES]
    assert [verdict for _, verdict in rows] == ["inside", "outside", "inside"]


def test_report_caps_large_factors_of_safety_and_explains_the_cap(report):
    table = re.search(r"Units with the smallest factor of safety</h2>(.*?)</table>", report).group(1)
    # Rocking factors inf and 222 of units 0 and 2: both shown as the cap, neither number.
    assert table.count(html.escape(CAP_TEXT)) == 2
    assert "inf" not in table and "222" not in table
    assert f"Factors of safety above {FACTOR_OF_SAFETY_DISPLAY_CAP:g} are shown as" in report
    # The median factor of safety is inf in this layer: the summary table shows the cap too.
    assert re.search(r"median factor of safety</th><td>" + re.escape(html.escape(CAP_TEXT)), report)


def test_report_explains_a_unit_at_rest_below_one(report):
    assert "unit 1 (row 1): rocking 0.797, sliding 1.346" in report
    assert "it rests on other units only" in report
    assert "held back by their reactions" in report and "interlocking" in report
    assert "href=#reading-factors-of-safety" in report


def test_report_unit_labels_keep_their_capitals_and_design_rows_are_indented(report):
    assert "Largest contact force (N)" in report
    assert "(n)" not in report
    for column, (label, _) in PER_UNIT_FIELDS.items():
        if column in _units():          # the displacement needs a reference state: none here
            assert label[:1].upper() + label[1:] in report
    assert re.findall(r"<th class='name detail'>(.*?)</th>", report) == [
        "design", "design", "design (m)"]
    assert "<th class='name'>  " not in report

