"""Rules of armour-layer design that a placement must keep before any rock is dropped: the units
of a row fit across the section, and the units suit the underlayer they rest on (the filter rule).

Both are judged from the case alone, so ``riprap check`` and ``riprap place`` refuse (or warn
about) the same layers with the same words.
"""
from __future__ import annotations

import warnings

from riprap.errors import CaseFileError
from riprap.work_estimate import RiprapWarning

__all__ = ["FILTER_RULE", "check_row_fits", "check_filter_rule"]

#: The filter rule of single- and double-layer armour (CIRIA/CUR/CETMEF, The Rock Manual, 2007,
#: chapter 6, underlayers; Coastal Engineering Manual, part VI, chapter 5): the underlayer stones
#: weigh W/10 to W/15 of the armour unit (rock, cubes, Tetrapods, Core-Loc, Accropode, Xbloc
#: alike), so the armour's Dn over the underlayer's Dn50 is 10^(1/3) to 15^(1/3), about 2.2-2.5.
FILTER_RULE = (2.15, 2.47)
#: Outside this band of Dn / Dn50 riprap warns: underlayer stones of W/6 to W/27, already beyond
#: what the guides allow (they give W/10 to W/15, some W/20 for rock armour).
FILTER_WARN = (1.8, 3.0)
#: Outside this band it refuses. Below 1.3 (stones of half the unit's mass) the "underlayer" is a
#: second armour layer, and the units rest on stones nearly their own size instead of keying into
#: a bed; above 4 (stones of W/64) the stones are smaller than the voids of the armour and would
#: be washed out through it, and a unit bridges many stones (the 3 m units on 0.28 m rocks that
#: stood three high). Both are far outside any design.
FILTER_REFUSE = (1.3, 4.0)


def check_row_fits(*, units_per_row: int, nominal_diameter: float, width: float,
                   where: str, key: str = "units_per_row") -> None:
    """Refuse a design-grid row whose units cannot stand side by side across the section: each
    unit takes at least its nominal diameter Dn of the row (its volume is Dn^3, and interlocking
    units are placed 1.1-1.3 H, about 2 Dn, apart), so ``units_per_row`` x Dn must fit the
    section's ``width``."""
    need = units_per_row * nominal_diameter
    if need > width:
        most = int(width // nominal_diameter)
        raise CaseFileError(
            f"{where}: [placement] {key} = {units_per_row}: {units_per_row} units of Dn = "
            f"{nominal_diameter:.3g} m need at least {need:.3g} m across (a unit takes at least "
            f"its Dn of a row), but the section (slope.width) is {width:g} m wide; place at most "
            f"{most} per row, use smaller units or a wider section")


def check_filter_rule(*, nominal_diameter: float, dn50: float, unit: str, where: str) -> None:
    """Refuse units grossly unsuited to the underlayer (Dn / Dn50 outside
    :data:`FILTER_REFUSE`) and warn outside :data:`FILTER_WARN`, quoting the rule."""
    ratio = nominal_diameter / dn50
    rule = (f"the filter rule (Rock Manual 2007, ch. 6; CEM part VI, ch. 5) puts underlayer stones of "
            f"W/10 to W/15 under an armour unit of mass W, Dn / Dn50 = {FILTER_RULE[0]:.2f} to "
            f"{FILTER_RULE[1]:.2f}")
    figure = (f"[armour] {unit} units of Dn = {nominal_diameter:.3g} m on [underlayer] dn50 = "
              f"{dn50:g} m: Dn / Dn50 = {ratio:.2f}")
    low, high = FILTER_REFUSE
    if not low <= ratio <= high:
        what = ("the stones would wash out through the armour's voids" if ratio > high
                else "the units would rest on stones nearly their own size")
        raise CaseFileError(
            f"{where}: {figure}, where {rule}; riprap refuses outside {low:g} to {high:g} "
            f"({what}). Give underlayer dn50 = {nominal_diameter / FILTER_RULE[1]:.3g} to "
            f"{nominal_diameter / FILTER_RULE[0]:.3g} m, or another unit size")
    if not FILTER_WARN[0] <= ratio <= FILTER_WARN[1]:
        warnings.warn(f"{where}: {figure}, outside {FILTER_WARN[0]:g} to {FILTER_WARN[1]:g}; {rule}",
                      RiprapWarning, stacklevel=2)
