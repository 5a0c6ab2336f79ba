"""A flume test judged as a design is: the damage the waves did beside what the design formulas say
those waves would do (issue 15's one report).

From the run's ``waves_report.json`` (``riprap.waves.report.flume_report``): the incident Hm0 at the
toe (the mean of the Goda-Suzuki splits of the gauge pairs, else the first surface gauge's Hm0), the
mean period Tz and the number of waves there; from the layer analysis: the units displaced and N_od
(``riprap.analysis.damage``). Then the stability number N_s = Hm0 / (Delta D_n) beside

- Hudson's for the unit (K_D of the trunk, non-breaking waves: ``HUDSON_TRUNK_STABILITY``, from
  ``shared/validation/armour_design.md`` §5.2: the Deltares coastal-structures-toolbox and the Rock
  Manual), N_s,Hudson = (K_D cot alpha)^(1/3), meant for no damage (0-5 % of units displaced);
- for cubes, Van der Meer's (1988) double-layer N_od for the same Hm0, Tz and number of waves;
- for rock armour (``unit_kind`` ``"armour_stone"``), the damage level S, its Rock Manual class,
  where the profile eroded and the three rock formulas for the same H_s, T_m-1,0 and N
  (:mod:`riprap.analysis.rock_stability`).
"""
from __future__ import annotations

import math

from riprap.analysis.design_formulas import hudson_stability_number, van_der_meer_cubes_damage
from riprap.analysis.rock_stability import eroded_zone, rock_stability
from riprap.geometry.unit_kinds import UNIT_RECORDS

__all__ = ["flume_stability", "incident_at_toe", "incident_peak_period_at_toe", "reflection_at_toe",
           "incident_spectral_period_at_toe",
           "HUDSON_TRUNK_STABILITY"]

#: K_D of a trunk under non-breaking waves per unit kind (armour_design.md §5.2, kept in each
#: kind's record); None: no value retrieved for it (cubes: Van der Meer's formula instead).
HUDSON_TRUNK_STABILITY = {record.name: record.hudson_trunk_stability for record in UNIT_RECORDS}


def _finite(value) -> bool:
    """A number the report can use (a null, a string or NaN of a run too short is not)."""
    return (isinstance(value, (int, float)) and not isinstance(value, bool)
            and math.isfinite(value))


def incident_at_toe(waves_report: dict):
    """(incident Hm0, Tz, waves, where it was read) at the toe; values the waves report left
    null (not computed) are passed over."""
    gauges = waves_report.get("gauges", {})
    gauges = [g for g in (gauges.values() if isinstance(gauges, dict) else [])
              if isinstance(g, dict) and _finite(g.get("Hm0_m"))]
    period = gauges[0].get("Tz_s") if gauges and _finite(gauges[0].get("Tz_s")) else None
    waves = gauges[0].get("waves") if gauges and _finite(gauges[0].get("waves")) else None
    # three gauges first (Mansard & Funke: no singular spacings, less noise), then pairs
    for key, method in (("reflection_three_gauge", "Mansard-Funke, mean of the gauge triples"),
                        ("reflection", "Goda-Suzuki, mean of the gauge pairs")):
        entries = waves_report.get(key, [])
        heights = [e.get("incident_Hm0_m", e.get("incident_height_m"))
                   for e in (entries if isinstance(entries, list) else [])
                   if isinstance(e, dict)]
        heights = [h for h in heights if _finite(h)]
        if heights:
            return sum(heights) / len(heights), period, waves, f"incident ({method})"
    if gauges:
        return gauges[0]["Hm0_m"], period, waves, "first surface gauge (incident and reflected)"
    return None, None, None, "no analysed surface gauge"


def _mean_of_triples(waves_report: dict, key: str) -> float | None:
    entries = waves_report.get("reflection_three_gauge", [])
    values = [e.get(key) for e in (entries if isinstance(entries, list) else [])
              if isinstance(e, dict)]
    values = [v for v in values if _finite(v)]
    return sum(values) / len(values) if values else None


def incident_peak_period_at_toe(waves_report: dict) -> float | None:
    """The incident waves' peak period Tp (s) at the toe: the mean of the three-gauge splits'
    smoothed peak periods (``incident_Tp_s``), None where no split gave one."""
    return _mean_of_triples(waves_report, "incident_Tp_s")


def incident_spectral_period_at_toe(waves_report: dict) -> tuple[float | None, str]:
    """T_m-1,0 (s) at the toe and where it was read: the mean of the three-gauge splits'
    incident T_m-1,0, else the first analysed surface gauge's (incident and reflected)."""
    period = _mean_of_triples(waves_report, "incident_Tm-1,0_s")
    if period is not None:
        return period, "incident (Mansard-Funke, mean of the gauge triples)"
    gauges = waves_report.get("gauges", {})
    for gauge in (gauges.values() if isinstance(gauges, dict) else []):
        if isinstance(gauge, dict) and _finite(gauge.get("Tm-1,0_s")):
            return gauge["Tm-1,0_s"], "first surface gauge (incident and reflected)"
    return None, "no analysed surface gauge"


def reflection_at_toe(waves_report: dict) -> float | None:
    """The structure's reflection coefficient K_r = Hm0,reflected / Hm0,incident: the mean of
    the three-gauge splits', None where no split gave one."""
    return _mean_of_triples(waves_report, "reflection_coefficient")


def flume_stability(waves_report: dict, layer_summary: dict, *, unit_kind: str,
                    nominal_diameter: float, armour_density: float, water_density: float,
                    slope_cot: float, rock_section=None, still_water_level=None) -> dict:
    """The stability part of the flume test's report (a dict for JSON); ``rock_section`` (a
    :class:`riprap.analysis.rock_stability.RockSection`) and ``still_water_level`` for rock
    armour."""
    height, period, waves, source = incident_at_toe(waves_report)
    delta = armour_density / water_density - 1.0
    result = {"unit": unit_kind, "nominal_diameter_m": nominal_diameter, "relative_density": delta,
              "slope_cot": slope_cot, "wave_height_source": source,
              "units_displaced": len(layer_summary.get("units_displaced", [])),
              "damage_number_nod": layer_summary.get("damage_number_nod"),
              "damage_threshold_over_dn": layer_summary.get("damage_threshold_over_dn")}
    # What the waves report could not compute, and its cautions (few waves), go on to the report.
    result["not_computed"] = list(waves_report.get("not_computed", []))
    result["cautions"] = list(waves_report.get("cautions", []))
    stability_coefficient = HUDSON_TRUNK_STABILITY.get(unit_kind)
    if stability_coefficient is not None:
        # Hudson's limit depends on the unit and the slope only: given with or without waves
        result["hudson"] = {"K_D": stability_coefficient,
                            "stability_number": hudson_stability_number(stability_coefficient,
                                                                        slope_cot),
                            "meaning": "Hudson's no-damage (0-5 % displaced) limit for a trunk "
                                       "under non-breaking waves; ratio < 1: below it"}
    if height is None:
        result["note"] = "the waves report has no analysed surface gauge: no stability number"
        result["not_computed"].append(
            "stability number: no incident wave height (no surface gauge could be analysed"
            + (f"; the record ends at t = {waves_report['record_end_s']:g} s"
               if waves_report.get("record_end_s") is not None else "") + ")")
        return result
    stability = height / (delta * nominal_diameter)
    result.update({"Hm0_m": height, "Tz_s": period, "waves": waves, "stability_number": stability,
                   "incident_Tp_s": incident_peak_period_at_toe(waves_report),
                   "reflection_coefficient": reflection_at_toe(waves_report)})
    if "hudson" in result:
        result["hudson"]["ratio"] = stability / result["hudson"]["stability_number"]
    if unit_kind == "armour_stone" and rock_section is not None and waves:
        spectral, spectral_source = incident_spectral_period_at_toe(waves_report)
        damage = layer_summary.get("damage_level_s")
        result["rock"] = rock_stability(
            hs=height, spectral_period=spectral, waves=waves, slope_cot=slope_cot,
            armour_density=armour_density, water_density=water_density,
            nominal_diameter=nominal_diameter,
            damage=damage if _finite(damage) else None, section=rock_section)
        result["rock"]["spectral_period_source"] = spectral_source
        result["rock"]["eroded_zone"] = eroded_zone(
            layer_summary.get("damage_profiles", {}), nominal_diameter=nominal_diameter,
            still_water_level=still_water_level, significant_height=height)
    if unit_kind in ("cube", "antifer_cube") and period and waves and math.isfinite(period):
        result["van_der_meer_cubes"] = {
            "N_od": van_der_meer_cubes_damage(hs=height, tm=period, waves=waves, delta=delta,
                                              nominal_diameter=nominal_diameter),
            "meaning": "Van der Meer (1988) double-layer cubes on cot alpha = 1.5 for these waves"}
    return result
