"""What a flume's gauges say: wave heights, periods, and the split into incident and reflected waves.

Definitions as a coastal laboratory uses them (Goda 2010, *Random Seas and Design of Maritime
Structures*, 3rd ed., ch. 2 and 4; EurOtop 2018 for the spectral period):

- ``Hm0 = 4 sqrt(m0)``, m0 the variance of the elevation (the zeroth spectral moment);
- zero-down-crossing waves: a wave runs from one down-crossing of the mean level to the next; its
  height is its highest crest minus its lowest trough; ``H1/3`` the mean of the highest third,
  ``H2%`` the height exceeded by 2 % of the waves (linear interpolation between ranked waves),
  ``Hmax`` the highest;
- ``Tp`` the period of the spectral peak, ``Tm-1,0 = m-1 / m0``;
- incident and reflected waves from two gauges a distance ``dx`` apart along the flume (Goda &
  Suzuki 1976, Port Harbour Res. Inst. Tech. Note 248): per frequency the complex amplitudes at
  the gauges are ``Z1 = a_I + a_R``, ``Z2 = a_I e^{ik dx} + a_R e^{-ik dx}``, solved for a_I, a_R
  where 0.05 <= dx / L <= 0.45 (outside it sin(k dx) is too small); the reflection coefficient
  is ``K_r = sqrt(E_R / E_I)`` over the frequencies that carry the wave's energy;
- the same from three gauges (Mansard & Funke 1980, Proc. 17th ICCE, 154-172): per frequency the
  least-squares a_I, a_R of ``Z_p = a_I e^{ik x_p} + a_R e^{-ik x_p}`` at the three gauges, which
  stays defined where one pair's spacing is a whole number of half wave lengths and averages the
  noise of three records; a frequency is used where the least-squares system is as well posed as
  the two-gauge one at its band's edge.

Records may be sampled at uneven times (fluid steps); they are put on an even grid first.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from riprap.errors import CaseFileError
from riprap.waves.theory import GRAVITY, wave_number

__all__ = ["WaveStatistics", "wave_statistics", "ReflectionAnalysis", "separate_incident_reflected",
           "separate_regular_wave", "separate_three_gauges", "harmonic_amplitude",
           "even_record", "zero_down_crossing_heights", "variance_density", "three_gauge_split",
           "gauge_spectra", "smoothed_peak_period"]

# The band of the Goda-Suzuki split: where the gauge spacing is within this fraction of a wave length.
_GODA_SUZUKI_BAND = (0.05, 0.45)


def even_record(times, values, samples_per_second: float | None = None):
    """(t, eta) on an evenly spaced grid over the record (linear interpolation); by default as
    many samples as the record has."""
    times = np.asarray(times, dtype=float)
    values = np.asarray(values, dtype=float)
    if times.size < 8:
        raise CaseFileError(f"wave analysis: a record of {times.size} samples is too short")
    if samples_per_second is None:
        count = times.size
    else:
        count = max(8, int((times[-1] - times[0]) * samples_per_second) + 1)
    even = np.linspace(times[0], times[-1], count)
    return even, np.interp(even, times, values)


def zero_down_crossing_heights(eta) -> tuple[np.ndarray, np.ndarray]:
    """(heights, indices of the down-crossings that start them) of the zero-down-crossing waves
    of ``eta`` (its mean removed first)."""
    eta = np.asarray(eta, dtype=float) - np.mean(eta)
    crossings = np.flatnonzero((eta[:-1] >= 0.0) & (eta[1:] < 0.0))
    heights = np.array([eta[a:b + 1].max() - eta[a:b + 1].min()
                        for a, b in zip(crossings[:-1], crossings[1:])])
    return heights, crossings[:-1]


@dataclass(frozen=True)
class WaveStatistics:
    """Heights (m) and periods (s) of one gauge's record."""

    hm0: float
    h_one_third: float
    h_two_percent: float
    h_max: float
    h_mean: float
    waves: int
    peak_period: float
    spectral_period: float       # Tm-1,0
    mean_period: float           # zero-down-crossing mean

    def as_dict(self) -> dict:
        return {"Hm0_m": self.hm0, "H1/3_m": self.h_one_third, "H2%_m": self.h_two_percent,
                "Hmax_m": self.h_max, "Hmean_m": self.h_mean, "waves": self.waves,
                "Tp_s": self.peak_period, "Tm-1,0_s": self.spectral_period,
                "Tz_s": self.mean_period}


def _spectrum(t, eta):
    """(frequencies (Hz), one-sided variance density (m^2 s)) of an evenly sampled record."""
    dt = t[1] - t[0]
    n = eta.size
    coefficients = np.fft.rfft(eta - eta.mean())
    frequencies = np.fft.rfftfreq(n, dt)
    density = 2.0 * np.abs(coefficients) ** 2 * dt / n
    density[0] = 0.0
    if n % 2 == 0:
        density[-1] *= 0.5
    return frequencies, density


def variance_density(times, eta, bands: int = 1):
    """(frequencies (Hz), one-sided variance density (m^2 s)) of the record ``eta`` at ``times``
    (put on an even grid first), averaged over ``bands`` neighbouring frequencies (a record of a
    few dozen waves gives a raw spectrum too ragged to read beside a target)."""
    t, e = even_record(times, eta)
    frequencies, density = _spectrum(t, e)
    bands = max(1, int(bands))
    if bands > 1 and frequencies.size >= bands:
        count = frequencies.size // bands * bands
        frequencies = frequencies[:count].reshape(-1, bands).mean(axis=1)
        density = density[:count].reshape(-1, bands).mean(axis=1)
    return frequencies, density


def wave_statistics(times, eta) -> WaveStatistics:
    """Statistics of the elevation record ``eta`` (m) sampled at ``times`` (s)."""
    t, e = even_record(times, eta)
    heights, starts = zero_down_crossing_heights(e)
    ranked = np.sort(heights)[::-1]
    frequencies, density = _spectrum(t, e)
    df = frequencies[1] - frequencies[0]
    m0 = float(np.var(e))
    positive = frequencies > 0
    m_minus_1 = float(np.sum(density[positive] / frequencies[positive]) * df)
    spectral_sum = float(np.sum(density) * df)
    peak = int(np.argmax(density))
    if ranked.size:
        third = ranked[:max(1, ranked.size // 3)]
        # the height exceeded by 2 % of the waves: rank 0.02 N counted from the highest
        position = 0.02 * ranked.size - 0.5
        h2 = float(np.interp(position, np.arange(ranked.size), ranked)) if position > 0 else float(ranked[0])
        zero_period = (float((t[starts[-1]] - t[starts[0]]) / (starts.size - 1))
                       if starts.size > 1 else float("nan"))
    else:
        third, h2, zero_period = np.zeros(1), 0.0, float("nan")
    return WaveStatistics(hm0=4.0 * math.sqrt(m0), h_one_third=float(third.mean()),
                          h_two_percent=h2, h_max=float(ranked[0]) if ranked.size else 0.0,
                          h_mean=float(ranked.mean()) if ranked.size else 0.0,
                          waves=int(ranked.size),
                          peak_period=1.0 / frequencies[peak] if frequencies[peak] > 0 else float("nan"),
                          spectral_period=m_minus_1 / spectral_sum if spectral_sum > 0 else float("nan"),
                          mean_period=zero_period)


@dataclass(frozen=True)
class ReflectionAnalysis:
    """Incident and reflected waves between two gauges."""

    incident_hm0: float          # m
    reflected_hm0: float         # m
    reflection_coefficient: float
    band: tuple                  # (lowest, highest) frequency used (Hz)
    #: the incident spectrum's peak period (s) by Read's Fp5 (irregular three-gauge splits only)
    incident_peak_period: float | None = None
    #: the incident spectrum's T_m-1,0 = m_-1 / m_0 over the band split (s; irregular three-gauge
    #: splits only): the period of the rock formulas (Van der Meer 2021, Etemad-Shahidi 2020)
    incident_spectral_period: float | None = None

    def as_dict(self) -> dict:
        entry = {"incident_Hm0_m": self.incident_hm0, "reflected_Hm0_m": self.reflected_hm0,
                 "reflection_coefficient": self.reflection_coefficient,
                 "band_Hz": list(self.band)}
        if self.incident_peak_period is not None:
            entry["incident_Tp_s"] = self.incident_peak_period
        if self.incident_spectral_period is not None:
            entry["incident_Tm-1,0_s"] = self.incident_spectral_period
        return entry


def smoothed_peak_period(frequencies, energies) -> float:
    """The peak period (s) of a spectrum given as energies per frequency, by Read's (1988)
    Fp5 = sum f E^5 / sum E^5: the raw periodogram of a few dozen waves puts its highest bin
    several per cent either side of the sea's peak, the fifth power weighs the bins near the
    top and averages over them (the IAHR list of sea state parameters, 1989, names it)."""
    frequencies = np.asarray(frequencies, dtype=float)
    weights = np.asarray(energies, dtype=float) ** 5
    total = float(np.sum(weights))
    if not total > 0.0:
        return float("nan")
    return float(total / np.sum(weights * frequencies))


def separate_incident_reflected(times, eta_1, eta_2, spacing: float, depth: float,
                                peak_period: float | None = None,
                                gravity: float = GRAVITY,
                                band=(0.5, 2.0)) -> ReflectionAnalysis:
    """Goda & Suzuki's two-gauge split of records ``eta_1`` (the gauge nearer the wavemaker) and
    ``eta_2`` (``spacing`` m further along the flume), in water of ``depth`` m. The energy is summed
    over the frequencies from ``band`` times the peak's (``peak_period``, default the spectral
    peak of gauge 1) where the spacing is 0.05..0.45 wave lengths; the peak itself must be there.
    For a regular wave give a narrow band about its frequency (e.g. 0.8..1.25): its bound higher
    harmonics travel at the wave's speed, not at their own, and would be read as reflection."""
    t, e1 = even_record(times, eta_1)
    e2 = np.interp(t, np.asarray(times, dtype=float), np.asarray(eta_2, dtype=float))
    if not spacing > 0:
        raise CaseFileError(f"wave analysis: gauge spacing must be positive, got {spacing!r} m")
    n = e1.size
    dt = t[1] - t[0]
    frequencies = np.fft.rfftfreq(n, dt)
    # complex amplitudes of exp(-i omega t) at each gauge (numpy's rfft is of exp(+i omega t))
    z1 = np.conj(np.fft.rfft(e1 - e1.mean())) * 2.0 / n
    z2 = np.conj(np.fft.rfft(e2 - e2.mean())) * 2.0 / n
    if peak_period is None:
        peak_period = 1.0 / frequencies[1 + int(np.argmax(np.abs(z1[1:])))]
    fp = 1.0 / peak_period
    peak_spacing = spacing * wave_number(peak_period, depth, gravity) / (2.0 * math.pi)
    if not _GODA_SUZUKI_BAND[0] <= peak_spacing <= _GODA_SUZUKI_BAND[1]:
        wave_len = spacing / peak_spacing
        raise CaseFileError(f"wave analysis: gauges {spacing:g} m apart are {peak_spacing:.2f} wave "
                            f"lengths apart at the peak (L = {wave_len:.3g} m, T = {peak_period:.3g} "
                            f"s); the two-gauge split needs 0.05..0.45: place them about "
                            f"{0.2 * wave_len:.3g} m apart")
    chosen = []
    for m, f in enumerate(frequencies):
        if m == 0 or not band[0] * fp <= f <= band[1] * fp:
            continue
        k = wave_number(1.0 / f, depth, gravity)
        if _GODA_SUZUKI_BAND[0] <= spacing * k / (2.0 * math.pi) <= _GODA_SUZUKI_BAND[1]:
            chosen.append((m, k))
    if not chosen:
        raise CaseFileError(f"wave analysis: the record ({t[-1] - t[0]:.3g} s) is too short to "
                            f"resolve frequencies near the peak ({fp:.3g} Hz)")
    energy_incident = energy_reflected = 0.0
    for m, k in chosen:
        shift = np.exp(1j * k * spacing)
        denominator = shift - 1.0 / shift
        incident = (z2[m] - z1[m] / shift) / denominator
        reflected = (z1[m] * shift - z2[m]) / denominator
        energy_incident += 0.5 * abs(incident) ** 2
        energy_reflected += 0.5 * abs(reflected) ** 2
    band = (frequencies[chosen[0][0]], frequencies[chosen[-1][0]])
    return ReflectionAnalysis(incident_hm0=4.0 * math.sqrt(energy_incident),
                              reflected_hm0=4.0 * math.sqrt(energy_reflected),
                              reflection_coefficient=math.sqrt(energy_reflected / energy_incident)
                              if energy_incident > 0 else float("nan"),
                              band=band)


# Smallest eigenvalue, per gauge, of the three-gauge least-squares system that is used: the
# two-gauge system's at a spacing of 0.05 wave lengths (the Goda-Suzuki band's edge).
_THREE_GAUGE_CONDITION = (2.0 - 2.0 * math.cos(2.0 * math.pi * _GODA_SUZUKI_BAND[0])) / 2.0


def three_gauge_split(amplitudes, k, offsets):
    """(a_I, a_R) by least squares from the complex amplitudes at the gauges, or None where the
    system is ill posed (all spacings near whole numbers of half wave lengths)."""
    phases = np.exp(1j * k * offsets)
    # normal matrix [[n, S], [conj(S), n]] with S = sum e^{-2ikx}: eigenvalues n -+ |S|
    n = offsets.size
    if (n - abs(np.sum(phases ** -2))) / n < _THREE_GAUGE_CONDITION:
        return None
    matrix = np.column_stack([phases, 1.0 / phases])
    (incident, reflected), *_ = np.linalg.lstsq(matrix, amplitudes, rcond=None)
    return incident, reflected


def gauge_spectra(times, records, peak_period: float | None = None):
    """(t, frequencies, spectra, peak period) of gauge ``records`` on ``times``: the records put
    on the first one's even grid, and per gauge the complex amplitudes of exp(-i omega t) at each
    frequency (numpy's rfft is of exp(+i omega t)); the peak period is ``peak_period`` or, if
    None, the spectral peak of the first gauge."""
    t, first = even_record(times, records[0])
    evens = [first] + [np.interp(t, np.asarray(times, dtype=float), np.asarray(r, dtype=float))
                       for r in records[1:]]
    n = first.size
    frequencies = np.fft.rfftfreq(n, t[1] - t[0])
    spectra = np.array([np.conj(np.fft.rfft(e - e.mean())) * 2.0 / n for e in evens])
    if peak_period is None:
        peak_period = 1.0 / frequencies[1 + int(np.argmax(np.abs(spectra[0, 1:])))]
    return t, frequencies, spectra, peak_period


def separate_three_gauges(times, records, positions, depth: float,
                          peak_period: float | None = None, gravity: float = GRAVITY,
                          band=(0.5, 2.0), regular: bool = False) -> ReflectionAnalysis:
    """Mansard & Funke's three-gauge split of ``records`` (three elevation series on ``times``) at
    ``positions`` (m along the flume), in water of ``depth`` m. Irregular waves: the energy summed
    over the frequencies from ``band`` times the peak's (``peak_period``, default the spectral peak
    of the first gauge) where the system is well posed. ``regular``: at the one frequency
    1/``peak_period`` (``harmonic_amplitude`` at each gauge); the heights are then regular-wave
    heights (H = 2 a), in the fields named Hm0."""
    positions = np.asarray(positions, dtype=float)
    if positions.size != 3 or len(records) != 3:
        raise CaseFileError(f"wave analysis: the three-gauge split needs three gauges, got "
                            f"{positions.size}")
    offsets = positions - positions[0]
    if np.unique(np.round(offsets, 9)).size != 3:
        raise CaseFileError(f"wave analysis: the three gauges must stand apart along the flume, "
                            f"got x = {positions.tolist()} m")
    if regular:
        if peak_period is None:
            raise CaseFileError("wave analysis: the three-gauge split of a regular wave needs its period")
        k = wave_number(peak_period, depth, gravity)
        amplitudes = np.array([harmonic_amplitude(times, r, peak_period) for r in records])
        split = three_gauge_split(amplitudes, k, offsets)
        if split is None:
            raise CaseFileError(f"wave analysis: gauges at x = {positions.tolist()} m are all whole "
                                f"numbers of half wave lengths apart (L = {2 * math.pi / k:.3g} m): "
                                "move one by about a tenth of a wave length")
        incident, reflected = split
        return ReflectionAnalysis(incident_hm0=2.0 * abs(incident), reflected_hm0=2.0 * abs(reflected),
                                  reflection_coefficient=abs(reflected) / abs(incident),
                                  band=(1.0 / peak_period, 1.0 / peak_period))
    t, frequencies, spectra, peak_period = gauge_spectra(times, records, peak_period)
    fp = 1.0 / peak_period
    energy_incident = energy_reflected = 0.0
    used, incident_energies = [], []
    for m, f in enumerate(frequencies):
        if m == 0 or not band[0] * fp <= f <= band[1] * fp:
            continue
        split = three_gauge_split(spectra[:, m], wave_number(1.0 / f, depth, gravity), offsets)
        if split is None:
            continue
        energy_incident += 0.5 * abs(split[0]) ** 2
        energy_reflected += 0.5 * abs(split[1]) ** 2
        used.append(f)
        incident_energies.append(0.5 * abs(split[0]) ** 2)
    if not used:
        raise CaseFileError(f"wave analysis: no frequency near the peak ({fp:.3g} Hz) can be split "
                            f"with gauges at x = {positions.tolist()} m over a record of "
                            f"{t[-1] - t[0]:.3g} s")
    return ReflectionAnalysis(incident_hm0=4.0 * math.sqrt(energy_incident),
                              reflected_hm0=4.0 * math.sqrt(energy_reflected),
                              reflection_coefficient=math.sqrt(energy_reflected / energy_incident)
                              if energy_incident > 0 else float("nan"),
                              band=(used[0], used[-1]),
                              incident_peak_period=smoothed_peak_period(used, incident_energies),
                              incident_spectral_period=_spectral_period(used, incident_energies))


def _spectral_period(frequencies, energies) -> float:
    """T_m-1,0 = m_-1 / m_0 (s) of a spectrum given as energies per frequency."""
    frequencies = np.asarray(frequencies, dtype=float)
    energies = np.asarray(energies, dtype=float)
    total = float(energies.sum())
    return float((energies / frequencies).sum() / total) if total > 0 else float("nan")


def harmonic_amplitude(times, eta, period: float) -> complex:
    """Complex amplitude Z of exp(-i omega t) at exactly the frequency 1/``period`` (least squares
    of a cosine, a sine and a mean over the record): eta ~ Re(Z e^{-i omega t}) + mean. Why not
    the FFT for a regular wave: a record that is not a whole number of periods leaks the wave into
    neighbouring bins, each of which the split would then treat with its own wave number."""
    times = np.asarray(times, dtype=float)
    omega = 2.0 * math.pi / period
    basis = np.column_stack([np.cos(omega * times), np.sin(omega * times), np.ones_like(times)])
    (a, b, _), *_ = np.linalg.lstsq(basis, np.asarray(eta, dtype=float), rcond=None)
    # a cos(wt) + b sin(wt) = Re((a + i b) e^{-i w t})
    return complex(a, b)


def separate_regular_wave(times, eta_1, eta_2, spacing: float, depth: float, period: float,
                          gravity: float = GRAVITY) -> ReflectionAnalysis:
    """Goda & Suzuki's split at the one frequency of a regular wave (``harmonic_amplitude`` at
    each gauge). The heights are regular-wave heights (H = 2 a), in the fields named Hm0."""
    k = wave_number(period, depth, gravity)
    if not _GODA_SUZUKI_BAND[0] <= spacing * k / (2.0 * math.pi) <= _GODA_SUZUKI_BAND[1]:
        wave_len = 2.0 * math.pi / k
        raise CaseFileError(f"wave analysis: gauges {spacing:g} m apart are "
                            f"{spacing / wave_len:.2f} wave lengths apart (L = {wave_len:.3g} m); "
                            f"the two-gauge split needs 0.05..0.45: place them about "
                            f"{0.2 * wave_len:.3g} m apart")
    z1, z2 = harmonic_amplitude(times, eta_1, period), harmonic_amplitude(times, eta_2, period)
    shift = complex(math.cos(k * spacing), math.sin(k * spacing))
    denominator = shift - 1.0 / shift
    incident = (z2 - z1 / shift) / denominator
    reflected = (z1 * shift - z2) / denominator
    return ReflectionAnalysis(incident_hm0=2.0 * abs(incident), reflected_hm0=2.0 * abs(reflected),
                              reflection_coefficient=abs(reflected) / abs(incident),
                              band=(1.0 / period, 1.0 / period))
