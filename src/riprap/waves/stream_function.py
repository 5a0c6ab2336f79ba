"""A fully nonlinear regular wave: the stream-function (Fourier approximation) solution of
Rienecker & Fenton (1981, J. Fluid Mech. 104: 119) in the form of Fenton (1988, "The numerical
solution of steady water wave problems", Computers & Geosciences 14: 357).

Why: Stokes' second order fails for steep waves in intermediate depth (a secondary crest in the
trough, wrong crest velocities); a flume test of an armour layer is run with the steepest waves
the structure must take. The stream-function wave satisfies the full free-surface conditions at
N + 1 points to round-off, for any height up to close to breaking.

In the frame moving with the wave (x measured from a crest, z from the bed):

    psi(x, z) = -U z + sum_{j=1..N} B_j sinh(j k z) / cosh(j k d) cos(j k x)

with psi = -Q on the surface z = eta(x) (kinematic), 1/2 |grad psi|^2 + g eta = R there
(Bernoulli), at the points x_m = m L / (2N), m = 0..N; the mean of eta is d, eta(0) - eta(L/2)
= H, c T = L, and a current criterion: the flume's (no mass transport, c d = Q: Stokes' second
definition, right for a closed flume) or no Eulerian mean current (c = U). The 2N + 6 equations
are solved for k, eta_0..eta_N, B_1..B_N, U, Q, R, c by Newton's method, with the
height raised in steps from a linear wave (Newton's method). In the fixed frame u = c - U + sum j k B_j cosh(j k z)
/cosh(j k d) cos(j k X), w = sum j k B_j sinh(j k z)/cosh(j k d) sin(j k X), X = x - c t.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from riprap.errors import CaseFileError
from riprap.schema import default_of
from riprap.waves.theory import GRAVITY, wave_number

__all__ = ["StreamFunctionWave", "NO_MASS_TRANSPORT", "NO_EULERIAN_CURRENT"]

NO_MASS_TRANSPORT = "no_mass_transport"
NO_EULERIAN_CURRENT = "no_eulerian_current"
#: Fourier terms: Fenton (1988) finds 10-20 enough to the highest waves but the last few per cent.
DEFAULT_TERMS = 16
_HEIGHT_STEPS = 4


def _ratio_sinh(j_k, z, depth):
    """sinh(j k z) / cosh(j k d) without overflow (z <= d + a crest's height)."""
    return np.exp(j_k * (z - depth)) * (1.0 - np.exp(-2.0 * j_k * z)) / (1.0 + np.exp(-2.0 * j_k * depth))


def _ratio_cosh(j_k, z, depth):
    return np.exp(j_k * (z - depth)) * (1.0 + np.exp(-2.0 * j_k * z)) / (1.0 + np.exp(-2.0 * j_k * depth))


@dataclass(frozen=True)
class StreamFunctionWave:
    """A steady nonlinear wave of ``height`` H (m) and ``period`` T (s) in ``depth`` d (m);
    ``terms`` N Fourier terms; ``current`` the mean-current criterion (NO_MASS_TRANSPORT, the
    default for a closed flume, or NO_EULERIAN_CURRENT); ``phase`` as the other theories'."""

    #: Regular; the Fourier solution holds at any Ursell number (up to breaking).
    regular: ClassVar[bool] = True
    height_name: ClassVar[str] = "H"
    ursell_limited: ClassVar[bool] = False

    height: float
    period: float
    depth: float
    phase: float = default_of("waves", "phase")
    terms: int = DEFAULT_TERMS
    current: str = NO_MASS_TRANSPORT
    gravity: float = GRAVITY
    _solution: dict = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self):
        for name in ("height", "period", "depth"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise CaseFileError(f"waves: {name} must be a positive number, got {value!r}")
        if self.current not in (NO_MASS_TRANSPORT, NO_EULERIAN_CURRENT):
            raise CaseFileError(f"waves: current must be {NO_MASS_TRANSPORT!r} or "
                                f"{NO_EULERIAN_CURRENT!r}, got {self.current!r}")
        self._solution.update(self._solve())

    # -------------------------------------------------------------- the solution
    def _residuals(self, unknowns, height, period):
        n = self.terms
        k = unknowns[0]
        eta = unknowns[1:n + 2]
        b = unknowns[n + 2:2 * n + 2]
        mean_speed, flux, bernoulli, celerity = unknowns[2 * n + 2:2 * n + 6]
        j_k = np.arange(1, n + 1) * k
        x = np.arange(n + 1) * math.pi / (n * k)
        phase = np.outer(x, j_k)
        s = _ratio_sinh(j_k[None, :], eta[:, None], 1.0)
        c = _ratio_cosh(j_k[None, :], eta[:, None], 1.0)
        psi = -mean_speed * eta + (b * s * np.cos(phase)).sum(axis=1)
        u = -mean_speed + (j_k * b * c * np.cos(phase)).sum(axis=1)
        w = (j_k * b * s * np.sin(phase)).sum(axis=1)
        kinematic = psi + flux
        dynamic = 0.5 * (u * u + w * w) + eta - bernoulli
        mean = (0.5 * eta[0] + eta[1:-1].sum() + 0.5 * eta[-1]) / n - 1.0
        criterion = celerity - flux if self.current == NO_MASS_TRANSPORT else celerity - mean_speed
        return np.concatenate([kinematic, dynamic, [mean, eta[0] - eta[-1] - height,
                                                   k * celerity * period - 2.0 * math.pi,
                                                   criterion]])

    def _newton(self, start, height, period):
        """Newton's method with a central-difference Jacobian and step halving; returns the
        solution and its largest residual."""
        with np.errstate(over="ignore", invalid="ignore"):     # wild trial steps are refused below
            return self._newton_steps(start, height, period)

    def _newton_steps(self, start, height, period):
        unknowns = start.copy()
        residual = self._residuals(unknowns, height, period)
        size = unknowns.size
        for _ in range(50):
            norm = np.abs(residual).max()
            if norm < 1e-13:
                break
            jacobian = np.empty((size, size))
            for i in range(size):
                step = 1e-7 * max(1.0, abs(unknowns[i]))
                shift = np.zeros(size)
                shift[i] = step
                jacobian[:, i] = (self._residuals(unknowns + shift, height, period)
                                  - self._residuals(unknowns - shift, height, period)) / (2.0 * step)
            change = np.linalg.solve(jacobian, -residual)
            factor = 1.0
            while factor > 1e-3:
                trial = unknowns + factor * change
                trial_residual = self._residuals(trial, height, period)
                if np.isfinite(trial_residual).all() and np.abs(trial_residual).max() < norm:
                    break
                factor *= 0.5
            else:
                break
            unknowns, residual = trial, trial_residual
        return unknowns, float(np.abs(residual).max())

    def _solve(self) -> dict:
        """Dimensionless (d = 1, g = 1) solution, raised in height steps from a linear wave."""
        d, g = self.depth, self.gravity
        height, period = self.height / d, self.period * math.sqrt(g / d)
        n = self.terms
        k = wave_number(period, 1.0, 1.0)
        celerity = 2.0 * math.pi / (k * period)
        x = np.arange(n + 1) * math.pi / (n * k)
        guess = np.zeros(2 * n + 6)
        guess[0] = k
        steps = np.linspace(height / _HEIGHT_STEPS, height, _HEIGHT_STEPS)
        guess[1:n + 2] = 1.0 + 0.5 * steps[0] * np.cos(k * x)
        guess[n + 2] = 0.5 * steps[0] * celerity / math.tanh(k)
        guess[2 * n + 2:] = (celerity, celerity, 0.5 * celerity ** 2 + 1.0, celerity)
        previous = None
        for step in steps:
            start = guess if previous is None else 2.0 * guess - previous   # extrapolate
            solution, residual = self._newton(start, step, period)
            if not residual < 1e-9:
                raise CaseFileError(
                    f"waves: no stream-function wave of H = {self.height:g} m, T = {self.period:g} "
                    f"s in d = {d:g} m (largest residual {residual:.1e} at H = {step * d:.3g} m): "
                    f"too close to breaking")
            previous, guess = guess, solution
        return {"unknowns": guess, "residual": residual}

    # -------------------------------------------------------------- dimensional results
    def _parts(self):
        n = self.terms
        z = self._solution["unknowns"]
        return z[0], z[1:n + 2], z[n + 2:2 * n + 2], z[2 * n + 2], z[2 * n + 5]

    @property
    def residual(self) -> float:
        """Largest residual of the dimensionless equations (round-off when solved)."""
        return self._solution["residual"]

    @property
    def wave_number(self) -> float:
        return self._parts()[0] / self.depth

    @property
    def wave_length(self) -> float:
        return 2.0 * math.pi / self.wave_number

    @property
    def celerity(self) -> float:
        return self._parts()[4] * math.sqrt(self.gravity * self.depth)

    @property
    def angular_frequency(self) -> float:
        return 2.0 * math.pi / self.period

    @property
    def crest_elevation(self) -> float:
        """Crest height above the still (mean) water level (m)."""
        return (self._parts()[1][0] - 1.0) * self.depth

    def _x_phase(self, x, t):
        """k X of the fixed frame (crest at X = 0 when phase = 0)."""
        return self.wave_number * np.asarray(x, dtype=float) - self.angular_frequency * t + self.phase

    def elevation(self, x, t):
        """eta (m) above the mean water level: the surface points' cosine series."""
        n = self.terms
        _, eta, _, _, _ = self._parts()
        weights = np.full(n + 1, 2.0 / n)
        weights[0] = weights[-1] = 1.0 / n
        j = np.arange(n + 1)
        # cosine coefficients of eta over the half wave (trapezoidal rule of the N + 1 points)
        coefficients = (weights[None, :] * eta[None, :] * np.cos(np.outer(j, j) * math.pi / n)).sum(axis=1)
        coefficients[0] *= 0.5
        coefficients[-1] *= 0.5
        theta = self._x_phase(x, t)
        series = (coefficients * np.cos(np.multiply.outer(theta, j))).sum(axis=-1)
        return (series - 1.0) * self.depth

    def velocity(self, x, z, t):
        """(u, w) (m/s) at x, z (z = 0 at the mean water level), time t."""
        k, _, b, mean_speed, celerity = self._parts()
        n = self.terms
        j_k = np.arange(1, n + 1) * k
        theta = np.asarray(self._x_phase(x, t))[..., None] * np.arange(1, n + 1)
        height = np.maximum(np.asarray(z, dtype=float) / self.depth + 1.0, 0.0)[..., None]
        scale = math.sqrt(self.gravity * self.depth)
        u = celerity - mean_speed + (j_k * b * _ratio_cosh(j_k, height, 1.0) * np.cos(theta)).sum(axis=-1)
        w = (j_k * b * _ratio_sinh(j_k, height, 1.0) * np.sin(theta)).sum(axis=-1)
        return u * scale, w * scale

    def velocity_grid(self, x, z, t):
        return self.velocity(np.asarray(x, dtype=float)[:, None], np.asarray(z, dtype=float)[None, :], t)
