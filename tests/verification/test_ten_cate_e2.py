"""ten Cate et al. (2002) case E2: a sphere settling in a closed box, two-way coupled, at two
resolutions.

Source: A. ten Cate, C. H. Nieuwstad, J. J. Derksen, H. E. A. Van den Akker (2002), Physics of Fluids
14(11), 4012-4025; sphere velocity digitised from their figure in ``shared/validation/ten_cate_E2.csv``
(musubi's digitisation), gap to the floor in ``ten_cate_E2_basilisk.csv`` (Basilisk sandbox's). Case in
``riprap.benchmarks.ten_cate``.

What is stated and checked, at 4 and 6 cells per sphere diameter (~1.5 minutes here for both; finer
grids are in ``bench/ten_cate_e2.py``), measured values in brackets:

- peak settling speed within ``PEAK_TOLERANCE`` of the record: 6 % at 4 cells per diameter, the
  issue's 3 % at 6 (-4.4 %, -0.7 %), and smaller at 6 than at 4;
- the speed at the gaps the record passes from 7 D to D/4 (``velocity_by_gap_l2``, free of any
  time offset between run and record) within ``BY_GAP_TOLERANCE``: 6 % and 4 % (4.7 %, 2.7 %),
  smaller at 6 than at 4;
- the time-aligned L2 over the plateau within 8 % (5.1 %, 7.3 %) and the contact within 0.3 s of the
  record's 2.49 s (-0.16 s, -0.26 s). These two do not fall with resolution: the two digitised
  records disagree with each other (the speed record integrated travels 8.3 D before contact in a
  box that leaves 8 D, and the gap record's steady fall is 2 % slower), so a run that matches the
  speeds by gap reaches each gap earlier than the gap record; and the film under the sphere is
  thinner than a cell (no sub-grid lubrication).

Where the cells cut the sphere matters by about 3 %: at 6 cells per diameter the sphere's axis lies
on cell faces (-0.7 %); moved half a cell (axis through cell centres, as at 7.95 cells per diameter)
it gives -3.4 %, and 7.95 gives -3.3 % (``docs/coupling.md``).
"""
import csv
from pathlib import Path

import numpy as np
import pytest

from riprap.benchmarks.ten_cate import compare_with_experiment, run_ten_cate_e2

VALIDATION = Path(__file__).resolve().parents[3] / "shared" / "validation"
RESOLUTIONS = (4, 6)
PEAK_TOLERANCE = (0.06, 0.03)
BY_GAP_TOLERANCE = (0.06, 0.04)
PLATEAU_TOLERANCE = 0.08
CONTACT_TOLERANCE = 0.3


def _record(name, quantity):
    with open(VALIDATION / name) as stream:
        rows = [(float(row["t_s"]), float(row["value"])) for row in csv.DictReader(stream)
                if row["quantity"] == quantity]
    return np.array(sorted(rows))


@pytest.fixture(scope="module")
def errors():
    velocity = _record("ten_cate_E2.csv", "u_z_m_per_s")
    gap = _record("ten_cate_E2_basilisk.csv", "gap_over_D")
    return [compare_with_experiment(run_ten_cate_e2(n), velocity, gap) for n in RESOLUTIONS]


@pytest.mark.slow
@pytest.mark.parametrize("level", [0, 1], ids=[f"{n}_cells_per_diameter" for n in RESOLUTIONS])
def test_settling_velocity_and_contact_match_the_experiment(errors, level):
    result = errors[level]
    assert abs(result["peak_speed_error"]) < PEAK_TOLERANCE[level]
    assert result["velocity_by_gap_l2"] < BY_GAP_TOLERANCE[level]
    assert result["plateau_velocity_l2"] < PLATEAU_TOLERANCE
    assert abs(result["contact_time_error"]) < CONTACT_TOLERANCE


@pytest.mark.slow
def test_the_speed_errors_fall_with_resolution(errors):
    coarse, fine = errors
    assert abs(fine["peak_speed_error"]) < abs(coarse["peak_speed_error"])
    assert fine["velocity_by_gap_l2"] < coarse["velocity_by_gap_l2"]
