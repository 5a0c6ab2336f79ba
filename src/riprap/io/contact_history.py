"""The contact history a pack starts from (``contact_history.csv`` beside ``pack.toml``).

A placed pack is a state in equilibrium: every resting contact overlaps by the depth at which its
potential force carries the load, and carries a tangential (friction) force that the run built up
while the units settled. Neither can be found again from the poses alone, so ``riprap place``
writes them here, and ``[simulation] contact_history`` in the pack makes ``riprap run pack.toml``
start from them:

- the elastic tangential force, the twisting torque and the stiffnesses they were built with
  become the solver's contact history (so the first step sees the same friction as the last step
  of the placement, without a jump);
- each listed pair may overlap at the start by up to the depth written here (``overlap_depth_m``,
  the mean overlap depth: potential force over contact stiffness), where an ordinary case
  refuses any overlap. A pair that is not listed, or that overlaps deeper than written (a body
  moved by hand), is still refused.

Columns, one row per touching pair (bodies in the order of the pack's ``[[bodies]]``, walls in
the order of its ``[[walls]]``, ``body_j = -1 - w`` for wall ``w``): see :data:`HISTORY_COLUMNS`.
Every problem names the file and the line.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from riprap.errors import CaseFileError
from riprap.io.case_text import read_text_file

__all__ = ["CONTACT_HISTORY_FILE_NAME", "HISTORY_COLUMNS", "ContactHistory",
           "write_contact_history", "read_contact_history"]

CONTACT_HISTORY_FILE_NAME = "contact_history.csv"

#: Columns of the file, in order (forces in N, torques in N m, stiffnesses in N/m and N m/rad).
HISTORY_COLUMNS = ("body_i", "body_j", "tangential_spring_force_x_N", "tangential_spring_force_y_N",
                   "tangential_spring_force_z_N", "twisting_spring_torque_Nm",
                   "tangential_stiffness_N_per_m", "twisting_stiffness_Nm_per_rad",
                   "overlap_depth_m")


class ContactHistory:
    """Touching pairs and their spring state.

    Attributes
    ----------
    body_i, body_j : (n,) int64
        The pair; ``body_j = -1 - w`` for wall ``w``.
    springs : (n, 6) float64
        Elastic tangential force (3, N), twisting torque (N m), tangential and twisting stiffness
        they were built with, in the solver's history layout.
    overlap_depths : (n,) float64
        Mean overlap depth of each pair when it was written (m).
    """

    def __init__(self, body_i, body_j, springs, overlap_depths):
        self.body_i = np.asarray(body_i, dtype=np.int64).reshape(-1)
        self.body_j = np.asarray(body_j, dtype=np.int64).reshape(-1)
        self.springs = np.asarray(springs, dtype=np.float64).reshape(-1, 6)
        self.overlap_depths = np.asarray(overlap_depths, dtype=np.float64).reshape(-1)

    def __len__(self) -> int:
        return len(self.body_i)

    def accepted_depths(self) -> dict[tuple[int, int], float]:
        """``{(body_i, body_j): overlap depth}`` of every listed pair."""
        return {(int(i), int(j)): float(d)
                for i, j, d in zip(self.body_i, self.body_j, self.overlap_depths)}


def write_contact_history(path, history: ContactHistory) -> Path:
    """Write ``history`` as CSV; numbers with ``repr`` so that they read back bit for bit."""
    path = Path(path)
    lines = ["# riprap contact history: the contacts a pack starts from (riprap.io.contact_history)",
             ",".join(HISTORY_COLUMNS)]
    for k in range(len(history)):
        values = [str(int(history.body_i[k])), str(int(history.body_j[k]))]
        values += [repr(float(v)) for v in history.springs[k]]
        values.append(repr(float(history.overlap_depths[k])))
        lines.append(",".join(values))
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text("\n".join(lines) + "\n")
    tmp.replace(path)
    return path


def read_contact_history(path, *, n_bodies: int | None = None,
                         n_walls: int | None = None) -> ContactHistory:
    """Read a contact history; with ``n_bodies`` and ``n_walls`` every index is checked too."""
    path = Path(path)
    text = read_text_file(path, what="contact history", extension=".csv")
    rows, header_seen = [], False
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        cells = [cell.strip() for cell in stripped.split(",")]
        if not header_seen:
            if tuple(cells) != HISTORY_COLUMNS:
                raise CaseFileError(f"{path}:{number}: expected the header "
                                    f"{','.join(HISTORY_COLUMNS)}, got {stripped!r}")
            header_seen = True
            continue
        if len(cells) != len(HISTORY_COLUMNS):
            raise CaseFileError(f"{path}:{number}: {len(cells)} values, expected "
                                f"{len(HISTORY_COLUMNS)} ({','.join(HISTORY_COLUMNS)})")
        rows.append(_parse_row(path, number, cells, n_bodies, n_walls))
    if not header_seen:
        raise CaseFileError(f"{path}: empty; a contact history has the header line "
                            f"{','.join(HISTORY_COLUMNS)} (and one line per contact)")
    if not rows:
        return ContactHistory(np.zeros(0), np.zeros(0), np.zeros((0, 6)), np.zeros(0))
    body_i, body_j, springs, depths = zip(*rows)
    return ContactHistory(body_i, body_j, springs, depths)


def _parse_row(path, number, cells, n_bodies, n_walls):
    integers = []
    for name, cell in zip(HISTORY_COLUMNS[:2], cells[:2]):
        try:
            integers.append(int(cell))
        except ValueError:
            raise CaseFileError(f"{path}:{number}: {name} = {cell!r} is not a whole number") from None
    body_i, body_j = integers
    numbers = []
    for name, cell in zip(HISTORY_COLUMNS[2:], cells[2:]):
        try:
            value = float(cell)
        except ValueError:
            raise CaseFileError(f"{path}:{number}: {name} = {cell!r} is not a number") from None
        if not math.isfinite(value):
            raise CaseFileError(f"{path}:{number}: {name} = {cell} is not finite")
        numbers.append(value)
    if numbers[-1] < 0 or numbers[4] < 0 or numbers[5] < 0:
        raise CaseFileError(f"{path}:{number}: stiffnesses and the overlap depth must be >= 0")
    if n_bodies is not None:
        if not 0 <= body_i < n_bodies:
            raise CaseFileError(f"{path}:{number}: body_i = {body_i} but the case has {n_bodies} "
                                f"bodies (0..{n_bodies - 1})")
        if body_j >= 0 and not body_i < body_j < n_bodies:
            raise CaseFileError(f"{path}:{number}: body_j = {body_j} must be a body after body_i "
                                f"= {body_i} and below {n_bodies}, or -1 - wall index")
        if body_j < 0 and n_walls is not None and not -1 - body_j < n_walls:
            raise CaseFileError(f"{path}:{number}: body_j = {body_j} names wall {-1 - body_j} but "
                                f"the case has {n_walls} walls")
    return body_i, body_j, numbers[:6], numbers[6]
