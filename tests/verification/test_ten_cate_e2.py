"""ten Cate et al. (2002) case E2: a sphere settling in a closed box, two-way coupled, at two
resolutions.

Source: A. ten Cate, C. H. Nieuwstad, J. J. Derksen, H. E. A. Van den Akker (2002), Physics of Fluids
14(11), 4012-4025; sphere velocity digitised from their figure in ``shared/validation/ten_cate_E2.csv``
(musubi's digitisation), gap to the floor in ``ten_cate_E2_basilisk.csv`` (Basilisk sandbox's). Case in
``riprap.benchmarks.ten_cate``.

What is stated and checked, at 4 and 6 cells per sphere diameter (~1.5 minutes here for both; finer
grids are in ``bench/ten_cate_e2.py``):

- peak settling speed within ``PEAK_TOLERANCE`` of the record: 10 % at 4 cells per diameter, 6 % at
  6 (measured -8.6 % and -4.7 %);
- relative L2 error of the velocity over the plateau within ``PLATEAU_TOLERANCE``: 10 % and 7 %
  (measured 8.1 % and 5.4 %);
- the sphere reaches the floor within ``CONTACT_TOLERANCE`` = 0.3 s of the record's 2.49 s (measured
  -0.06 s and -0.15 s: the film under the sphere is thinner than a cell, and there is no sub-grid
  lubrication yet).

Convergence is not yet monotone: at 7.95 cells per diameter (the bench) the peak is -6.1 % and the
plateau L2 6.1 %, worse than at 6; the issue's 3 % at the finer grid is not reached. This test keeps
what holds today from getting worse; ``docs/coupling.md`` records the sequence.
"""
import csv
from pathlib import Path

import numpy as np
import pytest

from riprap.benchmarks.ten_cate import compare_with_experiment, run_ten_cate_e2

VALIDATION = Path(__file__).resolve().parents[3] / "shared" / "validation"
RESOLUTIONS = (4, 6)
PEAK_TOLERANCE = (0.10, 0.06)
PLATEAU_TOLERANCE = (0.10, 0.07)
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
    assert result["plateau_velocity_l2"] < PLATEAU_TOLERANCE[level]
    assert abs(result["contact_time_error"]) < CONTACT_TOLERANCE
