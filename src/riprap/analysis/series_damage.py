"""Damage curves of a test series beside the design formulas (``docs/campaign.md``).

Each step of a series gives, from its survey (damage counted from the series' start) and its
waves: the incident Hm0 at the toe and the stability number N_s = Hm0 / (Delta Dn), the units
displaced and N_od, the damage level S, the rocking events of the step, the waves run and the
overtopping q. Beside them, per step:

- Hudson's N_s for the unit's K_D (no damage, 0-5 % displaced; no N-dependence);
- for cubes, Van der Meer's (1988) double-layer N_od with the formula's own N-dependence applied
  to the waves actually run, cumulatively over the steps as Van der Meer (1988) sums a sequence
  of sea states: the damage of the steps before is carried into step k as the number of step k's
  waves that would have done it (equivalent waves), and step k's waves are added to those;
- for cubes, the single-layer thresholds of Van Gent (2002; ``docs/campaign.md``, The formulas
  beside the damage curve): N_s = 2.9-3.0 start of damage, 3.5-3.75 failure;
- EurOtop's (2018, eq. 5.18, mean value approach) mean overtopping discharge for the section,
  q / sqrt(g Hm0^3) = 0.09 exp(-(1.5 Rc / (Hm0 gamma_f))^1.3), with the roughness factor
  gamma_f of the unit (EurOtop 2018 table 6.2) and Rc the crest freeboard (the overtopping
  gauge's level above still water), times the crest-width factor C_r = 3.06 exp(-1.5 G_c / Hm0),
  at most 1 (EurOtop 2018, section 6.3.3, eq. 6.8), G_c the width of the crest in front of the
  overtopping gauge: the water that sinks into a wide permeable crest does not reach its rear
  edge, where q is measured. Without a crest width C_r = 1, and the results say so.

The first displacement: the lowest step's N_s at which a unit moved more than the threshold,
against the formula's start of damage (Hudson's N_s; for cubes N_od = 0.2 by Van der Meer, and
Van Gent's 2.9).
"""
from __future__ import annotations

import math

from scipy.optimize import brentq

from riprap.analysis.design_formulas import hudson_stability_number, van_der_meer_cubes_damage
from riprap.analysis.rock_formulas import (etemad_shahidi_2020_damage, van_der_meer_2021_damage,
                                           van_gent_2003_damage)
from riprap.analysis.stability_report import HUDSON_TRUNK_STABILITY
from riprap.errors import CaseFileError

__all__ = ["series_curve", "cumulative_damage", "eurotop_mean_overtopping",
           "eurotop_crest_width_factor", "ROUGHNESS_FACTORS",
           "SINGLE_LAYER_CUBES_START", "SINGLE_LAYER_CUBES_FAILURE"]

GRAVITY = 9.81
#: Van Gent (2002) single-layer cubes, N_s at the start of damage and at failure (lower ends of
#: the ranges 2.9-3.0 and 3.5-3.75; docs/campaign.md).
SINGLE_LAYER_CUBES_START = 2.9
SINGLE_LAYER_CUBES_FAILURE = 3.5
#: Van der Meer's N_od taken as the start of damage of double-layer cubes (a few units moved).
CUBES_START_NOD = 0.2
#: EurOtop (2018) table 6.2, roughness factor gamma_f of a permeable-core slope per unit kind.
ROUGHNESS_FACTORS = {"core_loc_like": 0.44, "accropode_like": 0.46, "xbloc_like": 0.45,
                     "tetrapod": 0.38, "cube": 0.47, "antifer_cube": 0.50,
                     # EurOtop (2018) Table 6.2: rock, two layers, permeable core
                     "armour_stone": 0.40}
#: Columns of a rock series' curve, one per formula, each cumulative over the steps.
ROCK_FORMULA_COLUMNS = {"van_der_meer_2021_S": "Van der Meer (2021)",
                        "van_gent_2003_S": "Van Gent et al. (2003)",
                        "etemad_shahidi_2020_S": "Etemad-Shahidi et al. (2020)"}


def cumulative_damage(formula, sea_states) -> list[float]:
    """The damage after each of ``sea_states`` ((hs, tm, waves) run one after the other) by
    ``formula(hs, tm, waves)``, increasing in waves: the damage so far is carried into the next
    sea state as the number of its waves that would do it (Van der Meer 1988)."""
    damage, out = 0.0, []
    for hs, tm, waves in sea_states:
        equivalent = 0.0
        if damage > 0:
            if formula(hs, tm, 1e9) <= damage:
                out.append(damage)           # this sea cannot add to what was done
                continue
            equivalent = brentq(lambda n: formula(hs, tm, n) - damage, 1e-9, 1e9, xtol=1e-9,
                                rtol=1e-12)
        damage = max(damage, formula(hs, tm, equivalent + waves))
        out.append(damage)
    return out


def rock_formula_curves(sea_states, *, slope_cot: float, delta: float, nominal_diameter: float,
                        permeability: float, core_nominal_diameter: float) -> dict:
    """The three rock formulas' S after each of ``sea_states`` ((H_s, T_m-1,0, N) run one after
    the other), damage carried from step to step as equivalent waves (:func:`cumulative_damage`);
    NaN where a step's waves are unmeasured. Columns :data:`ROCK_FORMULA_COLUMNS`."""
    common = {"slope_cot": slope_cot, "armour_density": 1000.0 * (1.0 + delta),
              "water_density": 1000.0, "nominal_diameter": nominal_diameter}
    formulas = {
        "van_der_meer_2021_S": lambda hs, tm, n: van_der_meer_2021_damage(
            hs=hs, spectral_period=tm, waves=max(n, 1e-12), permeability=permeability, **common),
        "van_gent_2003_S": lambda hs, tm, n: van_gent_2003_damage(
            hs=hs, waves=max(n, 1e-12), core_nominal_diameter=core_nominal_diameter, **common),
        "etemad_shahidi_2020_S": lambda hs, tm, n: etemad_shahidi_2020_damage(
            hs=hs, spectral_period=tm, waves=max(n, 1e-12),
            core_nominal_diameter=core_nominal_diameter, **common)}
    usable = all(math.isfinite(h) and h > 0 and math.isfinite(t) and t > 0 and n > 0
                 for h, t, n in sea_states)
    return {name: (cumulative_damage(formula, sea_states) if usable
                   else [math.nan] * len(sea_states))
            for name, formula in formulas.items()}


def eurotop_mean_overtopping(hm0: float, freeboard: float, roughness: float) -> float:
    """q (m^3/s per m): EurOtop (2018) eq. 5.18, mean value approach."""
    if not (hm0 > 0 and roughness > 0):
        return math.nan
    relative = max(freeboard, 0.0) / (hm0 * roughness)
    return 0.09 * math.exp(-(1.5 * relative) ** 1.3) * math.sqrt(GRAVITY * hm0 ** 3)


def eurotop_crest_width_factor(crest_width: float | None, hm0: float) -> float:
    """C_r = min(1, 3.06 exp(-1.5 G_c / Hm0)) (-): EurOtop (2018) section 6.3.3, eq. 6.8, the
    reduction of the mean overtopping discharge behind a crest of width G_c = ``crest_width``
    (m) for waves of ``hm0`` (m) at the toe. 1 without a crest width (None); NaN without a wave
    height.

    >>> round(eurotop_crest_width_factor(1.0, 1.0), 3)
    0.683
    """
    if crest_width is None:
        return 1.0
    if not (math.isfinite(crest_width) and crest_width >= 0):
        raise CaseFileError(f"EurOtop crest-width factor: crest_width must be a length >= 0 m, "
                            f"got {crest_width!r}")
    if not (math.isfinite(hm0) and hm0 > 0):
        return math.nan
    return min(1.0, 3.06 * math.exp(-1.5 * crest_width / hm0))


def series_curve(steps: list[dict], *, unit_kind: str, nominal_diameter: float, delta: float,
                 slope_cot: float, freeboard: float | None, crest_width: float | None = None,
                 crest_width_source: str | None = None) -> dict:
    """The damage curve of a series: ``steps`` one dict per step with ``step``, ``Hm0_m``
    (incident at the toe, NaN when not measured), ``Tm_s`` (the mean period), ``waves`` (waves
    run), ``units_displaced``, ``N_od``, ``S``, ``rocking_events``, ``q_m3_s_m``; returns
    ``{"curve": columns, "first_displacement": ..., "formulas": ...}``. ``delta``: the relative
    density rho_armour / rho_water - 1; ``freeboard``: the crest's height above still water (m);
    ``crest_width``: G_c (m) of EurOtop's crest-width factor (None: C_r = 1), found as
    ``crest_width_source`` says (for the results)."""
    curve = {name: [] for name in (
        "step", "Hm0_m", "Tm_s", "waves", "cumulative_waves", "stability_number",
        "units_displaced", "N_od", "S", "rocking_events", "q_m3_s_m", "hudson_stability_number",
        "van_der_meer_cubes_N_od", "eurotop_crest_width_factor", "eurotop_q_m3_s_m")}
    coefficient = HUDSON_TRUNK_STABILITY.get(unit_kind)
    hudson = (hudson_stability_number(coefficient, slope_cot) if coefficient else math.nan)
    cubes = unit_kind in ("cube", "antifer_cube")
    measured = [(s["Hm0_m"], s["Tm_s"], s["waves"]) for s in steps]
    usable = all(math.isfinite(h) and h > 0 and math.isfinite(t) and t > 0 and n > 0
                 for h, t, n in measured)
    vdm = (cumulative_damage(lambda hs, tm, n: van_der_meer_cubes_damage(
        hs=hs, tm=tm, waves=max(n, 1e-12), delta=delta, nominal_diameter=nominal_diameter),
        measured) if cubes and usable else [math.nan] * len(steps))
    roughness = ROUGHNESS_FACTORS.get(unit_kind, math.nan)
    total = 0
    for step, formula_nod in zip(steps, vdm):
        total += step["waves"]
        hm0 = step["Hm0_m"]
        curve["step"].append(step["step"])
        curve["Hm0_m"].append(hm0)
        curve["Tm_s"].append(step["Tm_s"])
        curve["waves"].append(step["waves"])
        curve["cumulative_waves"].append(total)
        curve["stability_number"].append(hm0 / (delta * nominal_diameter))
        for name in ("units_displaced", "N_od", "S", "rocking_events", "q_m3_s_m"):
            curve[name].append(step[name])
        curve["hudson_stability_number"].append(hudson)
        curve["van_der_meer_cubes_N_od"].append(formula_nod)
        factor = eurotop_crest_width_factor(crest_width, hm0)
        curve["eurotop_crest_width_factor"].append(factor)
        curve["eurotop_q_m3_s_m"].append(
            factor * eurotop_mean_overtopping(hm0, freeboard, roughness)
            if freeboard is not None and math.isfinite(hm0) else math.nan)
    crest_source = ("none: no crest-width factor (C_r = 1)" if crest_width is None
                    else crest_width_source or "given")
    first = next((k for k, count in enumerate(curve["units_displaced"]) if count > 0), None)
    start = {"hudson_stability_number": hudson if coefficient else None}
    if cubes:
        start["single_layer_cubes_start"] = SINGLE_LAYER_CUBES_START
        start["single_layer_cubes_failure"] = SINGLE_LAYER_CUBES_FAILURE
        start["van_der_meer_cubes_start_N_od"] = CUBES_START_NOD
    return {
        "curve": curve,
        "first_displacement": None if first is None else {
            "step": curve["step"][first], "stability_number": curve["stability_number"][first],
            "below": (curve["stability_number"][first - 1] if first > 0 else None)},
        "formulas": {"relative_density": delta, "nominal_diameter_m": nominal_diameter,
                     "slope_cot": slope_cot, "unit": unit_kind, "start_of_damage": start,
                     "roughness_factor": roughness if math.isfinite(roughness) else None,
                     "freeboard_m": freeboard,
                     "crest_width_m": crest_width,
                     "crest_width_source": crest_source,
                     "sources": "Hudson (1959), CEM VI-5-2; Van der Meer (1988) double-layer "
                                "cubes with cumulative equivalent waves; Van Gent (2002) single "
                                "layer cubes; EurOtop (2018) eq. 5.18, table 6.2 and the "
                                "crest-width factor C_r of eq. 6.8"},
    }
