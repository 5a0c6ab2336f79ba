"""Wave theories for the flume's generation zone: surface elevation and orbital velocity.

Why these: a flume test is specified by the waves at the toe (H, T or Hs, Tp in a depth d). Linear
(Airy) theory is exact in the limit of small steepness and is what the spectral (irregular) sea is
made of; Stokes' second order adds the sharper crests and flatter troughs of moderately steep
waves (Dean & Dalrymple 1991, *Water Wave Mechanics for Engineers and Scientists*, ch. 4 and 11).

Conventions: x along the flume (waves travel towards +x), z up with z = 0 at the still water level
and the bed at z = -depth; phase theta = k x - omega t + phase; SI units. Velocities above the
still water level (in a crest) are evaluated at the point itself (the linear profile continued
upwards, which is what linear theory gives to first order), and above the surface they are not
asked for: the relaxation zone multiplies them by the target water fraction.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from riprap.errors import CaseFileError
from riprap.schema import default_of

__all__ = ["wave_number", "wave_length", "group_velocity", "LinearWave", "StokesSecondOrderWave", "IrregularWave",
           "jonswap_spectrum", "ramp", "envelope"]

GRAVITY = 9.81


def wave_number(period: float, depth: float, gravity: float = GRAVITY) -> float:
    """k (rad/m) of the linear dispersion relation omega^2 = g k tanh(k d), to round-off.

    Newton's method from Fenton & McKee's (1990) explicit approximation, which is already within
    1.7 % everywhere; two or three steps reach machine precision."""
    if not (period > 0 and depth > 0):
        raise CaseFileError(f"waves: period ({period!r} s) and depth ({depth!r} m) must be positive")
    omega = 2.0 * math.pi / period
    deep = omega * omega / gravity
    if not (math.isfinite(deep) and deep * depth > 1e-200):
        # omega^2 underflows to 0 (or overflows) for a period near 1e308 (or 1e-308) s
        raise CaseFileError(f"waves: period = {period:g} s makes no wave in water {depth:g} m deep "
                            "(its frequency squared is not a float64 number); give the period in "
                            "seconds")
    k = deep / math.tanh((deep * depth) ** 0.75) ** (2.0 / 3.0)
    for _ in range(50):
        t = math.tanh(k * depth)
        residual = gravity * k * t - omega * omega
        slope = gravity * (t + k * depth * (1.0 - t * t))
        step = residual / slope
        k -= step
        if abs(step) < 1e-15 * k:
            break
    return k


def wave_length(period: float, depth: float, gravity: float = GRAVITY) -> float:
    """L = 2 pi / k (m) of linear theory."""
    return 2.0 * math.pi / wave_number(period, depth, gravity)


def group_velocity(period: float, depth: float, wave_length: float) -> float:
    """c_g = c/2 (1 + 2kd / sinh(2kd)) (m/s)."""
    k = 2.0 * math.pi / wave_length
    c = wave_length / period
    return 0.5 * c * (1.0 + 2.0 * k * depth / math.sinh(2.0 * k * depth))


def ramp(time, ramp_time: float):
    """Start-up factor 0 -> 1 over ``ramp_time`` (s), smooth at both ends:
    t/T - sin(2 pi t/T)/(2 pi); 1 after it (and always 1 for ramp_time 0)."""
    if ramp_time <= 0:
        return np.ones_like(np.asarray(time, dtype=float))
    s = np.clip(np.asarray(time, dtype=float) / ramp_time, 0.0, 1.0)
    return s - np.sin(2.0 * math.pi * s) / (2.0 * math.pi)


def envelope(time, ramp_time: float, stop_time: float = 0.0):
    """The wave maker's factor: ``ramp`` up from t = 0 and, with ``stop_time`` > 0, the same ramp
    down to nothing at ``stop_time`` (a test step's sea ends; the flume calms); 0 after it."""
    factor = ramp(time, ramp_time)
    if stop_time > 0:
        if ramp_time > 0:
            factor = factor * ramp(stop_time - np.asarray(time, dtype=float), ramp_time)
        else:
            factor = factor * (np.asarray(time, dtype=float) < stop_time)
    return factor


@dataclass(frozen=True)
class LinearWave:
    """A regular linear (Airy) wave of ``height`` H (m, crest to trough) and ``period`` T (s) in
    water of ``depth`` d (m)."""

    #: One wave height and period (the analysis reads H, not Hm0; the Ursell limit applies).
    regular: ClassVar[bool] = True
    height_name: ClassVar[str] = "H"
    ursell_limited: ClassVar[bool] = True

    height: float
    period: float
    depth: float
    phase: float = default_of("waves", "phase")
    gravity: float = GRAVITY

    def __post_init__(self):
        for name in ("height", "period", "depth"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise CaseFileError(f"waves: {name} must be a positive number, got {value!r}")

    @property
    def wave_number(self) -> float:
        return wave_number(self.period, self.depth, self.gravity)

    @property
    def wave_length(self) -> float:
        return 2.0 * math.pi / self.wave_number

    @property
    def angular_frequency(self) -> float:
        return 2.0 * math.pi / self.period

    @property
    def steepness(self) -> float:
        """H / L."""
        return self.height / self.wave_length

    @property
    def relative_depth(self) -> float:
        """k d."""
        return self.wave_number * self.depth

    @property
    def ursell_number(self) -> float:
        """H L^2 / d^3: above ~26 Stokes theories no longer hold (cnoidal waves)."""
        return self.height * self.wave_length ** 2 / self.depth ** 3

    def _theta(self, x, t):
        return self.wave_number * np.asarray(x, dtype=float) - self.angular_frequency * t + self.phase

    def elevation(self, x, t):
        """eta (m) above the still water level at x (m), time t (s)."""
        return 0.5 * self.height * np.cos(self._theta(x, t))

    def velocity(self, x, z, t):
        """(u, w) (m/s) at x, z (m, z = 0 at the still water level), time t."""
        k, d, omega = self.wave_number, self.depth, self.angular_frequency
        theta = self._theta(x, t)
        depth_from_bed = np.maximum(np.asarray(z, dtype=float) + d, 0.0)
        amplitude = 0.5 * self.height * omega / math.sinh(k * d)
        return (amplitude * np.cosh(k * depth_from_bed) * np.cos(theta),
                amplitude * np.sinh(k * depth_from_bed) * np.sin(theta))

    def velocity_grid(self, x, z, t):
        """(u, w) (len(x), len(z)) on every pair of ``x`` (m) and ``z`` (m above the still
        water level): what a relaxation zone needs, without repeating the phase per level."""
        return self.velocity(np.asarray(x, dtype=float)[:, None], np.asarray(z, dtype=float)[None, :], t)


@dataclass(frozen=True)
class StokesSecondOrderWave(LinearWave):
    """A regular Stokes second-order wave (Dean & Dalrymple 1991, eqs. 11.35-11.37): the linear
    wave plus its second harmonic, with the same wave number (the dispersion relation is changed
    only at third order). Valid while the second harmonic stays small: below an amplitude ratio of
    1/4 (``second_harmonic_ratio``) the trough has no secondary crest; in shallow water (Ursell
    number above ~26) cnoidal or stream-function theory is needed instead."""

    def _second(self):
        k, d = self.wave_number, self.depth
        return k, d, math.sinh(k * d), math.cosh(k * d)

    def elevation(self, x, t):
        k, d, s, c = self._second()
        theta = self._theta(x, t)
        second = k * self.height ** 2 / 16.0 * c * (2.0 + math.cosh(2.0 * k * d)) / s ** 3
        return 0.5 * self.height * np.cos(theta) + second * np.cos(2.0 * theta)

    def velocity(self, x, z, t):
        u1, w1 = super().velocity(x, z, t)
        k, d, s, _ = self._second()
        omega = self.angular_frequency
        theta = self._theta(x, t)
        depth_from_bed = np.maximum(np.asarray(z, dtype=float) + d, 0.0)
        amplitude = 3.0 / 16.0 * self.height ** 2 * omega * k / s ** 4
        return (u1 + amplitude * np.cosh(2.0 * k * depth_from_bed) * np.cos(2.0 * theta),
                w1 + amplitude * np.sinh(2.0 * k * depth_from_bed) * np.sin(2.0 * theta))

    def second_harmonic_ratio(self) -> float:
        """Amplitude of the second harmonic of eta over the first's."""
        k, d, s, c = self._second()
        second = k * self.height ** 2 / 16.0 * c * (2.0 + math.cosh(2.0 * k * d)) / s ** 3
        return second / (0.5 * self.height)


def jonswap_spectrum(frequencies, significant_height: float, peak_period: float,
                     peak_enhancement: float = default_of("waves", "peak_enhancement")):
    """JONSWAP variance density S(f) (m^2 s) scaled so that 4 sqrt(m0) over ``frequencies`` is
    ``significant_height`` (Hm0; Hasselmann et al. 1973; sigma = 0.07 below the peak, 0.09 above).
    ``frequencies`` must be evenly spaced (Hz)."""
    f = np.asarray(frequencies, dtype=float)
    fp = 1.0 / peak_period
    sigma = np.where(f <= fp, 0.07, 0.09)
    shape = np.zeros_like(f)
    positive = f > 0
    fq = f[positive]
    shape[positive] = (fq ** -5 * np.exp(-1.25 * (fp / fq) ** 4)
                       * peak_enhancement ** np.exp(-((fq - fp) ** 2) / (2.0 * sigma[positive] ** 2 * fp ** 2)))
    spacing = f[1] - f[0] if f.size > 1 else 1.0
    m0 = shape.sum() * spacing
    if m0 <= 0:
        raise CaseFileError("waves: the JONSWAP spectrum has no energy over the chosen frequencies")
    # (Hm0 / 4)^2 / m0 scaled in numpy floats: an absurd Hm0 gives inf here (and the flume's
    # breaking check names it), not Python's OverflowError
    with np.errstate(over="ignore"):
        return shape * (np.float64(significant_height) / 4.0) ** 2 / m0


#: Most frequency components of an irregular sea: each is summed at every relaxation cell and
#: boundary face on every step.
MAXIMUM_COMPONENTS = 10_000


@dataclass(frozen=True)
class IrregularWave:
    """A linear irregular sea: the sum of ``components`` regular linear waves with a JONSWAP
    spectrum of ``significant_height`` Hm0 (m) and ``peak_period`` Tp (s), random phases drawn
    from ``seed``. The frequencies are evenly spaced over [0.5, 3] / Tp with spacing 1/``duration``
    (so the sea does not repeat within the duration); each amplitude is sqrt(2 S(f) df)."""

    #: A spectrum, read as Hm0 and Tp; each component is linear, far inside the Ursell limit.
    regular: ClassVar[bool] = False
    height_name: ClassVar[str] = "Hm0"
    ursell_limited: ClassVar[bool] = False

    significant_height: float
    peak_period: float
    depth: float
    duration: float
    peak_enhancement: float = default_of("waves", "peak_enhancement")
    seed: int = default_of("waves", "seed")
    gravity: float = GRAVITY

    def __post_init__(self):
        for name in ("significant_height", "peak_period", "depth", "duration", "peak_enhancement"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise CaseFileError(f"waves: {name} must be a positive number, got {value!r}")
        if self.duration < 10.0 * self.peak_period:
            raise CaseFileError(f"waves: duration {self.duration:g} s is shorter than ten peak "
                                f"periods ({10.0 * self.peak_period:g} s): too few frequencies for "
                                f"a spectrum")
        # 2.5 components per peak period of the duration (frequencies 0.5 .. 3 fp, 1/duration
        # apart): counted before they are allocated, so that a duration in the wrong unit is named
        # rather than exhausting the memory
        components = 2.5 * (self.duration / self.peak_period)
        if components > MAXIMUM_COMPONENTS:
            raise CaseFileError(
                f"waves: duration = {self.duration:g} s is {self.duration / self.peak_period:.3g} "
                f"peak periods, at 2.5 frequency components each more than the "
                f"{MAXIMUM_COMPONENTS:,} riprap sums ({MAXIMUM_COMPONENTS / 2.5:,.0f} peak periods; "
                "a storm test runs about 1000 waves); give duration in seconds (it defaults to "
                "[simulation] end_time)")
        spacing = 1.0 / self.duration
        fp = 1.0 / self.peak_period
        frequencies = np.arange(math.ceil(0.5 * fp / spacing), math.floor(3.0 * fp / spacing) + 1) * spacing
        density = jonswap_spectrum(frequencies, self.significant_height, self.peak_period,
                                   self.peak_enhancement)
        rng = np.random.default_rng(self.seed)
        object.__setattr__(self, "frequencies", frequencies)
        object.__setattr__(self, "amplitudes", np.sqrt(2.0 * density * spacing))
        object.__setattr__(self, "phases", rng.uniform(0.0, 2.0 * math.pi, frequencies.size))
        object.__setattr__(self, "wave_numbers",
                           np.array([wave_number(1.0 / f, self.depth, self.gravity) for f in frequencies]))

    @property
    def period(self) -> float:
        return self.peak_period

    @property
    def height(self) -> float:
        return self.significant_height

    @property
    def wave_length(self) -> float:
        """Linear wave length at the peak period (m)."""
        return wave_length(self.peak_period, self.depth, self.gravity)

    def _theta(self, x, t):
        x = np.asarray(x, dtype=float)[..., None]
        return self.wave_numbers * x - 2.0 * math.pi * self.frequencies * t + self.phases

    def elevation(self, x, t):
        return np.sum(self.amplitudes * np.cos(self._theta(x, t)), axis=-1)

    def _decays(self, z):
        """cosh(k (z + d)) / sinh(k d) and sinh(k (z + d)) / sinh(k d) (..., components), written
        without overflow for the short components in deep water."""
        k = self.wave_numbers
        depth_from_bed = np.maximum(np.asarray(z, dtype=float) + self.depth, 0.0)[..., None]
        above_bed = np.exp(k * (depth_from_bed - self.depth))
        below = np.exp(-k * (depth_from_bed + self.depth))
        scale = 1.0 - np.exp(-2.0 * k * self.depth)
        return (above_bed + below) / scale, (above_bed - below) / scale

    def velocity_grid(self, x, z, t):
        """(u, w) (len(x), len(z)): the sum over components as two matrix products."""
        theta = self._theta(np.asarray(x, dtype=float), t)
        decay_c, decay_s = self._decays(np.asarray(z, dtype=float))
        amplitude = self.amplitudes * 2.0 * math.pi * self.frequencies
        return ((amplitude * np.cos(theta)) @ decay_c.T, (amplitude * np.sin(theta)) @ decay_s.T)

    def velocity(self, x, z, t):
        theta = self._theta(x, t)
        decay_c, decay_s = self._decays(z)
        amplitude = self.amplitudes * 2.0 * math.pi * self.frequencies
        return (np.sum(amplitude * decay_c * np.cos(theta), axis=-1),
                np.sum(amplitude * decay_s * np.sin(theta), axis=-1))
