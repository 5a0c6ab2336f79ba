"""``units.csv`` of a deformable run: one row per body with the largest tensile principal stress
of the run (Pa), the element and point where it was and when, the largest at the end of the run
(for a body brought to rest: its stresses at rest), and the ratio of the run's largest to the
material's tensile strength where one is given (NaN otherwise); with fracture the broken joints'
area (m^2, one side of the cracks), the number of pieces and the largest one's mass fraction
(0, 1 and 1 for a body without joints)."""
from __future__ import annotations

import csv
from pathlib import Path

from riprap.io.output_folder import naming_the_file

__all__ = ["UNIT_COLUMNS", "FRAGMENT_COLUMNS", "write_units_csv", "write_fragments_csv"]

UNIT_COLUMNS = ("body", "name", "mass_kg", "elements", "element_type", "max_tensile_stress_Pa",
                "max_tensile_element", "max_tensile_x_m", "max_tensile_y_m", "max_tensile_z_m",
                "max_tensile_time_s", "final_max_tensile_stress_Pa", "tensile_strength_Pa",
                "stress_over_strength", "broken_area_m2", "fragments",
                "largest_fragment_mass_fraction")
#: ``fragments.csv``: every piece of every cracking body (riprap.models.deformable.fragment_rows).
FRAGMENT_COLUMNS = ("body", "name", "fragment", "elements", "volume_m3", "mass_kg", "mass_fraction",
                    "x_m", "y_m", "z_m", "vx_m_s", "vy_m_s", "vz_m_s")


def write_units_csv(path, rows) -> Path:
    return _write_rows(path, rows, UNIT_COLUMNS)


def write_fragments_csv(path, rows) -> Path:
    return _write_rows(path, rows, FRAGMENT_COLUMNS)


def _write_rows(path, rows, columns) -> Path:
    path = Path(path)
    with naming_the_file(path), open(path, "w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=columns)
        writer.writeheader()
        for row in rows:
            writer.writerow({key: (f"{value:.6g}" if isinstance(value, float) else value)
                             for key, value in row.items()})
    return path
