"""The exact travelling solitary wave of the discrete Hertz (or power-law) chain.

Contact overlaps r_n of a uniform chain (bead mass m, contact constant A) obey
m r_n'' = A (G(r_{n+1}) - 2 G(r_n) + G(r_{n-1})), G(r) = max(r, 0)^p, where p = 3/2 for
Hertz and any 1 < p <= 3 for a power-law contact F = A delta^p (keyword ``n``). A wave
r_n(t) = r0 + w(n - c t) travelling at c contacts per second satisfies, in Fourier space
(xi in bead numbers, wavenumber k),

    mu w = P(w),   P(w) = IFFT[ sinc^2(k/2) FFT[G(r0 + w) - G(r0)] ],   mu = m c^2 / A.

It is solved as a nonlinear eigenvalue problem at fixed amplitude: iterate
w <- P(w) / mu with mu = max P(w) / w_max, which removes the scaling direction that makes
the plain iteration diverge (the idea behind Petviashvili's stabilising factor,
Pelinovsky & Stepanyants, SIAM J. Numer. Anal. 42, 1110 (2004); spectral renormalisation,
Ablowitz & Musslimani, Opt. Lett. 30, 2140 (2005)). For r0 = 0 it converges to the wave
whose existence English & Pego (2005) proved and that Ahnert & Pikovsky (2009) computed;
the long-wave Eq (4) differs from it by about one percent.

The speed in m/s is c times the undisturbed centre spacing, diameter - r0.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rig.errors import RigError, invalid

_POINTS_PER_BEAD = 32
MIN_FORCE_RATIO = 1.05  # Fm / F0 below which the iteration converges too slowly
MAX_STRAIN = 0.1  # contact overlap / diameter beyond which a small-overlap contact law says nothing


def _grid(n_beads: float):
    """xi (bead numbers) on a power-of-two grid spanning n_beads, and sinc^2(k/2)."""
    n = int(2 ** math.ceil(math.log2(n_beads * _POINTS_PER_BEAD)))
    h = 1.0 / _POINTS_PER_BEAD
    xi = (np.arange(n) - n // 2) * h
    half = np.pi * np.fft.rfftfreq(n, h)
    sinc2 = np.ones_like(half)
    sinc2[1:] = (np.sin(half[1:]) / half[1:]) ** 2
    return xi, sinc2


def _peak(xi, y):
    """Maximum of a sampled smooth profile by parabolic refinement."""
    i = int(np.argmax(y))
    y0, y1, y2 = y[i - 1], y[i], y[i + 1]
    den = y0 - 2 * y1 + y2
    return y1 - 0.125 * (y2 - y0) ** 2 / den if den != 0 else y1


@dataclass(frozen=True)
class SolitaryWave:
    """A stationary solitary wave of a uniform chain.

    speed (m/s, in the laboratory: contacts_per_s times the precompressed spacing),
    contacts_per_s (1/s), xi (bead numbers), force (N, whole contact force profile along
    xi, at t = 0), F0, Fm (N), spacing (m, diameter less the static overlap), diameter (m).
    """

    speed: float
    contacts_per_s: float
    xi: np.ndarray
    force: np.ndarray
    F0: float
    Fm: float
    spacing: float
    diameter: float

    @property
    def long_wave_speed(self) -> float:
        """The speed (m/s) as the long-wave theory counts it, Eqs (1), (2) and (4): contacts
        per second times the bead diameter (the chain's Lagrangian coordinate). It scales
        exactly as those equations do, so its ratio to them depends on F_m/F_0 alone."""
        return self.contacts_per_s * self.diameter

    @property
    def beta(self) -> float:
        """Max dynamic contact force over the max dynamic mean of two neighbouring contacts
        (what a rigid gauge bead reads): beta = F_d / F_m,e (Daraio et al. 2006)."""
        per = _POINTS_PER_BEAD
        dyn = self.force - self.F0
        avg = 0.5 * (dyn[per:] + dyn[:-per])
        return _peak(self.xi, dyn) / _peak(self.xi[per:], avg)

    @property
    def width_beads(self) -> float:
        """Full width (bead diameters) where the dynamic force exceeds 1% of its maximum."""
        dyn = self.force - self.F0
        above = self.xi[dyn > 0.01 * dyn.max()]
        return float(above[-1] - above[0])


def overlap_reason(A: float, diameter: float, force: float, n: float = 1.5) -> str | None:
    """Why the contact law cannot carry ``force`` (N) between beads of ``diameter`` (m) with
    contact constant A (N/m^n), or None: its overlap (force/A)^(1/n) passes MAX_STRAIN of
    the diameter, where a contact law of small overlaps (Hertz) and every speed built on it
    say nothing about the beads."""
    strain = math.exp((math.log(force) - math.log(A)) / n - math.log(diameter)) if force > 0 else 0.0
    if strain <= MAX_STRAIN:
        return None
    return (f"at {force:.4g} N the contacts overlap by {strain:.3g} of the {diameter:.4g} m diameter; the contact "
            f"law holds for small overlaps only (at most {MAX_STRAIN:g} of it)")


def solitary_wave(mass: float, A: float, diameter: float, Fm: float, F0: float = 0.0,
                  tol: float = 1e-13, n: float = 1.5) -> SolitaryWave:
    """The exact discrete solitary wave of amplitude Fm (N) on a uniform chain of beads of
    mass (kg), contact law F = A delta^n (A in N/m^n; Hertz: n = 3/2) and diameter (m),
    precompressed by F0 (N). A linear contact (n = 1) has no solitary wave: 1 < n <= 3.

    It is solved in dimensionless form, the overlap w in units of its amplitude w_max and
    forces in units of Fm, so that the iteration and its tolerance do not depend on the
    scale of the chain: c^2 = mu_1 Fm (1 - q)^n / (m w_max), q = (F0/Fm)^(1/n), mu_1 the
    eigenvalue at unit amplitude."""
    if not 1.0 < n <= 3.0:
        raise invalid("n", n, "the contact exponent must be in (1, 3]")
    for name, val in (("mass", mass), ("A", A), ("diameter", diameter), ("Fm", Fm)):
        if not 0 < val < math.inf:
            raise invalid(name, val, "must be > 0 and finite")
    if not 0 <= F0 < math.inf:
        raise invalid("F0", F0, "precompression must be >= 0 N")
    if not Fm >= F0 * MIN_FORCE_RATIO:
        raise invalid("Fm", Fm, f"the discrete solitary wave is computed for Fm >= "
                                f"{MIN_FORCE_RATIO} F0 = {MIN_FORCE_RATIO * F0:.4g} N (closer to F0 it "
                                f"is a wide, weakly nonlinear wave: use Eq (1) or power_law_wave_speed)")
    q = (F0 / Fm) ** (1.0 / n)  # r0 / (r0 + w_max); 1.0 / 1.5 is the same double as 2.0 / 3.0
    s = q / (1.0 - q)  # r0 / w_max
    log_w_max = (math.log(Fm) - math.log(A)) / n + math.log1p(-q)  # w_max = (Fm/A)^(1/n) - r0, in m
    # the wave widens like 1/sqrt(f_r - 1) towards the sound speed: size the domain for it
    fr_less_1 = (Fm - F0) / F0 if F0 > 0 else math.inf
    xi, sinc2 = _grid(48 if fr_less_1 > 1 else 64 / math.sqrt(fr_less_1))
    g0 = s**n
    u = np.exp(-(xi / 2.0) ** 2)
    for _ in range(20000):
        P = np.fft.irfft(sinc2 * np.fft.rfft(np.maximum(s + u, 0.0) ** n - g0), len(u))
        mu = _peak(xi, P)
        u_new = P / mu
        done = np.max(np.abs(u_new - u)) < tol
        u = u_new
        if done:
            break
    else:
        raise RigError(f"the discrete solitary wave (Fm = {Fm:.4g} N, F0 = {F0:.4g} N) did not converge")
    scale = Fm * (1.0 - q) ** n  # A w_max^n, N
    c = math.sqrt(mu * scale / mass) * math.exp(-0.5 * log_w_max)
    r0 = s * math.exp(log_w_max)
    return SolitaryWave(c * (diameter - r0), c, xi, scale * np.maximum(s + u, 0.0) ** n, F0, Fm,
                        diameter - r0, diameter)


def beta(force_ratio: float, n: float = 1.5) -> float:
    """beta(F_m/F_0) = F_d / F_m,e of a uniform chain from its exact solitary wave.

    The ratio of the maximum dynamic contact force to the maximum dynamic mean of two
    neighbouring contacts (what a rigid gauge bead reads) depends on F_m/F_0 alone, not on
    the material (Daraio et al. 2006); ``force_ratio = inf`` gives the sonic-vacuum value.
    ``n`` is the contact exponent of F = A delta^n (Hertz: 3/2).
    """
    if not force_ratio >= MIN_FORCE_RATIO:
        raise invalid("force_ratio", force_ratio, f"F_m/F_0 must be >= {MIN_FORCE_RATIO}")
    if math.isinf(force_ratio):
        return solitary_wave(1.0, 1.0, 1.0, 1.0, n=n).beta
    return solitary_wave(1.0, 1.0, 1.0, force_ratio, 1.0, n=n).beta


def elastic_amplitude(reading: float, F0: float, n: float = 1.5, rtol: float = 1e-10) -> float:
    """F_d (N) from a rigid gauge bead's reading F_m,e (N, the peak of the mean of its two
    dynamic contact forces), as Daraio et al. (2006) converted their gauges: F_d = beta
    F_m,e with beta = beta(F_m/F_0) of the elastic chain (``beta``), F_m = F_d + F_0 the
    total contact force on the precompression F0 (N; 0: the sonic vacuum, beta(inf)).

    F_m is not known before F_d, so F_d is the fixed point of x -> beta(1 + x/F_0) F_m,e,
    iterated from x = F_m,e until a step changes x by less than ``rtol`` of it: beta >= 1
    rises with F_m/F_0, so the iterates rise to the fixed point, and the map's slope
    (dbeta/dln f_r (f_r - 1)/(f_r beta), about 0.1 at most) makes each step about ten times
    smaller than the last. RigError (invalid) for a reading that is not > 0 or whose
    F_m/F_0 stays below MIN_FORCE_RATIO (beta is computed from there up)."""
    if not 0 < reading < math.inf:
        raise invalid("reading", reading, "a gauge reading F_m,e must be > 0 N and finite")
    if not 0 <= F0 < math.inf:
        raise invalid("F0", F0, "precompression must be >= 0 N")
    if F0 == 0:
        return beta(math.inf, n) * reading
    if 1.0 + reading / F0 < MIN_FORCE_RATIO:
        raise invalid("reading", reading, f"F_m/F_0 below {MIN_FORCE_RATIO} on F_0 = {F0:.4g} N: beta is "
                                          f"computed from F_m/F_0 = {MIN_FORCE_RATIO} up")
    x = reading
    for _ in range(100):
        new = beta(1.0 + x / F0, n) * reading
        if abs(new - x) <= rtol * new:
            return new
        x = new
    raise RigError(f"the elastic conversion of the reading {reading:.4g} N on F_0 = {F0:.4g} N did not converge")
