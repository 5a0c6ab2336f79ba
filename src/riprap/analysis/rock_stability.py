"""Rock armour judged as a designer judges it (issue 55): the damage level S the waves made,
its class in the Rock Manual, where on the slope the stones left, and what the three rock
formulas say the same waves would have done.

The structure (:class:`RockSection`): the armour's D_n50 and grading width, the filter's and the
core's D_n50 (0 for an impermeable core), the depth at the toe. Van der Meer's notional
permeability P follows from the layers (:func:`riprap.analysis.rock_formulas.notional_permeability`,
Van der Meer 1988). The formulas, each with its validity cautions
(:mod:`riprap.analysis.rock_formulas`):

- Van der Meer (2021), H_s and T_m-1,0, c_pl 6.49 and c_s 0.97, with P;
- Van Gent, Smale & Kuiper (2003), with the core's D_n50 (no period);
- Etemad-Shahidi, Bali & van Gent (2020, with its 2022 corrigendum), T_m-1,0 and the core's
  D_n50 in C_p.

Their spread is the band the measured S is set beside; none of them is called the truth.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from riprap.analysis.rock_formulas import (etemad_shahidi_2020_cautions, etemad_shahidi_2020_damage,
                                           notional_permeability, rock_damage_class,
                                           van_der_meer_2021_cautions, van_der_meer_2021_damage,
                                           van_gent_2003_cautions, van_gent_2003_damage)
from riprap.errors import CaseFileError

__all__ = ["RockSection", "rock_stability", "eroded_zone", "NOMINAL_OVER_SIEVE_DIAMETER"]

#: D_n50 / D_50 of quarry stone: about 0.84 (CIRIA, CUR, CETMEF 2007, The Rock Manual, 3.4.1.2);
#: a porous zone's ``stone_diameter`` is a sieve D_50, the core formulas take D_n50.
NOMINAL_OVER_SIEVE_DIAMETER = 0.84
#: An armour / core D_n50 ratio above this is a core far finer than Van der Meer's permeable
#: cores (armour on a core about 3.2; on a filter on a core, a few times that): his P is then
#: cautioned, not changed.
FINE_CORE_RATIO = 16.0
#: A profile point counts as eroded (or accreted) beyond this fraction of D_n50.
_PROFILE_CHANGE_DN = 0.1


@dataclass(frozen=True)
class RockSection:
    """What the rock formulas need of a cross-section.

    Attributes
    ----------
    filter_dn50 : float or None
        D_n50 of the filter (underlayer) under the armour (m); None where there is none.
    core_dn50 : float
        D_n50 of the core (m); 0 for an impermeable one.
    core_note : str
        Where the core's D_n50 came from (the case's zone, or why impermeable is assumed).
    grading_ratio : float or None
        D_n85 / D_n15 of the armour stones.
    water_depth : float or None
        Depth at the toe (m).
    """

    filter_dn50: float | None
    core_dn50: float
    core_note: str
    grading_ratio: float | None = None
    water_depth: float | None = None


def _formula(name: str, damage, cautions, inputs: dict) -> dict:
    """One formula's S and its cautions; a formula that cannot be evaluated says why."""
    entry = {"name": name}
    try:
        entry["S"] = float(damage(**inputs["damage"]))
    except (CaseFileError, ValueError, ZeroDivisionError) as error:
        entry["S"] = None
        entry["not_computed"] = str(error)
    try:
        entry["cautions"] = cautions(**inputs["cautions"])
    except CaseFileError as error:
        entry["cautions"] = [f"validity not checked: {error}"]
    return entry


def rock_stability(*, hs: float, spectral_period: float | None, waves: float, slope_cot: float,
                   armour_density: float, water_density: float, nominal_diameter: float,
                   damage: float | None, section: RockSection) -> dict:
    """The rock part of a flume test's stability report (a dict for JSON): the measured S, its
    Rock Manual class, P and the three formulas' S for these waves (H_s ``hs`` at the toe,
    T_m-1,0 ``spectral_period``, N ``waves``), each with its cautions, and their band."""
    dn = nominal_diameter
    result = {"nominal_diameter_m": dn, "S": damage,
              "filter_dn50_m": section.filter_dn50, "core_dn50_m": section.core_dn50,
              "core": section.core_note, "grading_dn85_over_dn15": section.grading_ratio,
              "spectral_period_s": spectral_period}
    if damage is not None and math.isfinite(damage):
        name, row = rock_damage_class(max(damage, 0.0), slope_cot)
        result["damage_class"] = name
        result["damage_class_thresholds"] = {
            "slope_cot": row.slope_cot, "start": row.start,
            "intermediate": list(row.intermediate), "failure": row.failure, "note": row.note,
            "source": "The Rock Manual (2007) Table 5.22, after Van der Meer (1988)"}
    permeability, reason = notional_permeability(
        dn, filter_dn50=section.filter_dn50,
        core_dn50=section.core_dn50 if section.core_dn50 > 0 else None,
        core_permeable=section.core_dn50 > 0)
    result["notional_permeability"] = permeability
    result["notional_permeability_reason"] = reason
    if section.core_dn50 > 0 and dn / section.core_dn50 > FINE_CORE_RATIO:
        result.setdefault("cautions", []).append(
            f"the core is {dn / section.core_dn50:.0f} times finer than the armour (D_n50): far "
            f"finer than the cores of Van der Meer's permeable structures, so P = {permeability:g} "
            "from the layers likely overstates how permeable it is (between it and the "
            "impermeable core's 0.1); Van Gent et al. and Etemad-Shahidi et al. take the core's "
            "size itself")
    common = {"hs": hs, "waves": waves, "slope_cot": slope_cot, "armour_density": armour_density,
              "water_density": water_density, "nominal_diameter": dn}
    context = {"water_depth": section.water_depth, "grading_ratio": section.grading_ratio}
    measured = {"damage": damage} if damage is not None and damage > 0 else {}
    formulas = []
    if spectral_period is not None and math.isfinite(spectral_period) and spectral_period > 0:
        vdm = {**common, "spectral_period": spectral_period, "permeability": permeability}
        formulas.append(_formula("Van der Meer (2021)", van_der_meer_2021_damage,
                                 van_der_meer_2021_cautions,
                                 {"damage": vdm, "cautions": {**vdm, **context, **measured}}))
    else:
        result.setdefault("not_computed", []).append(
            "Van der Meer (2021) and Etemad-Shahidi et al. (2020): no T_m-1,0 at the toe")
    core = {"core_nominal_diameter": section.core_dn50}
    formulas.append(_formula("Van Gent et al. (2003)", van_gent_2003_damage, van_gent_2003_cautions,
                             {"damage": {**common, **core},
                              "cautions": {**common, **core,
                                           **({"spectral_period": spectral_period}
                                              if spectral_period else {})}}))
    if spectral_period is not None and math.isfinite(spectral_period) and spectral_period > 0:
        es = {**common, **core, "spectral_period": spectral_period}
        formulas.append(_formula("Etemad-Shahidi et al. (2020)", etemad_shahidi_2020_damage,
                                 etemad_shahidi_2020_cautions,
                                 {"damage": es, "cautions": {**es, **measured}}))
    result["formulas"] = formulas
    values = [f["S"] for f in formulas if f["S"] is not None]
    if values:
        result["formula_band_S"] = [min(values), max(values)]
        if damage is not None and math.isfinite(damage):
            low, high = result["formula_band_S"]
            result["measured_against_band"] = ("below" if damage < low else
                                               "above" if damage > high else "inside")
    return result


def eroded_zone(profiles: dict, *, nominal_diameter: float, still_water_level: float | None,
                significant_height: float | None = None) -> dict:
    """Where the profile lost and gained material: the x range eroded by more than a tenth of
    D_n50, the deepest erosion (its x, its level and that level's distance from the still water
    level in D_n50 and in H_s), the area eroded above and below the still water level and the
    area accreted. ``profiles``: the layer analysis's ``damage_profiles`` (x, before, after)."""
    x = np.asarray(profiles.get("x_m", []), dtype=float)
    before = np.asarray(profiles.get("before_z_m", []), dtype=float)
    after = np.asarray(profiles.get("after_z_m", []), dtype=float)
    if len(x) < 2 or len(before) != len(x) or len(after) != len(x):
        return {"not_computed": "no damage profiles"}
    dx = float(x[1] - x[0])
    loss = np.clip(before - after, 0.0, None)
    gain = np.clip(after - before, 0.0, None)
    eroded = np.flatnonzero(loss > _PROFILE_CHANGE_DN * nominal_diameter)
    zone = {"eroded_area_m2": float(loss.sum() * dx), "accreted_area_m2": float(gain.sum() * dx)}
    if len(eroded) == 0:
        zone["note"] = (f"no point of the profile lowered by more than "
                        f"{_PROFILE_CHANGE_DN:g} D_n50")
        return zone
    deepest = int(np.argmax(loss))
    zone.update({"eroded_from_x_m": float(x[eroded[0]]), "eroded_to_x_m": float(x[eroded[-1]]),
                 "deepest_x_m": float(x[deepest]), "deepest_z_m": float(before[deepest]),
                 "deepest_depth_over_dn50": float(loss[deepest] / nominal_diameter)})
    if still_water_level is not None:
        level = float(before[deepest] - still_water_level)
        zone["deepest_below_still_water_over_dn50"] = -level / nominal_diameter
        if significant_height:
            zone["deepest_below_still_water_over_hs"] = -level / significant_height
        above = before >= still_water_level
        zone["eroded_area_above_still_water_m2"] = float(loss[above].sum() * dx)
        zone["eroded_area_below_still_water_m2"] = float(loss[~above].sum() * dx)
    return zone
