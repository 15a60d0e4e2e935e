"""Viscous-plastic sea-ice rheology of Hibler (1979) with an elliptical yield curve:
the comparison rheology (what is solved; the mEVP iterations that solve it live in
:mod:`lagice.solvers.evp`).

Vertically integrated stress S [N m-1] (Girard et al. 2011, eqs. 10-14):

    P = P* h exp(−C*(1−A)),   Δ = sqrt(ε̇I² + (ε̇II/e)²),
    ζ = P / (2 max(Δ, Δmin)),  η = ζ/e²,
    S = 2η ε̇' + (ζ ε̇I − Pr/2) I,

with ε̇I = ε̇xx + ε̇yy, ε̇II = sqrt((ε̇xx − ε̇yy)² + 4ε̇xy²) (the invariants of
:mod:`lagice.deformation`), ε̇' = ε̇ − ½ε̇I I the deviator, and Pr = P
(standard Hibler, default) or Pr = 2ζΔ = P Δ/max(Δ, Δmin) (replacement
pressure: no stress at rest).

Default parameters: P* = 27.5 kN m-2, C* = 20, e = 2 (Hibler 1979);
Δmin = 2e-9 s-1 (Hunke 2001, as in CICE).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from ..errors import ConfigError

#: P* [N m-2], C* [-], e [-], Δmin [s-1] defaults
P_STAR = 27.5e3
C_STAR = 20.0
ELLIPSE = 2.0
DELTA_MIN = 2e-9


def _vp_stress(exx, eyy, exy, P, e2inv, delta_min, repl):
    """Hibler VP stress (S_xx, S_yy, S_xy) [N m-1] and ζ [kg s-1] for strain rate
    (ε̇xx, ε̇yy, ε̇xy) [s-1] and strength P [N m-1]."""
    div = exx + eyy
    shear2 = (exx - eyy) ** 2 + 4.0 * exy * exy
    delta = math.sqrt(div * div + shear2 * e2inv)
    dd = delta if delta > delta_min else delta_min
    zeta = 0.5 * P / dd
    eta = zeta * e2inv
    pr = P * delta / dd if repl else P
    iso = zeta * div - 0.5 * pr
    hd = 0.5 * div
    return (2.0 * eta * (exx - hd) + iso, 2.0 * eta * (eyy - hd) + iso, 2.0 * eta * exy, zeta)


#: numba core of the VP law, inlined by the mEVP element kernel
vp_stress = njit(cache=True, inline="always")(_vp_stress)


def ice_strength(thickness, concentration, p_star: float = P_STAR, c_star: float = C_STAR):
    """P = P* h exp(−C*(1−A)) [N m-1]."""
    return p_star * np.asarray(thickness, np.float64) * np.exp(-c_star * (1.0 - np.asarray(concentration,
                                                                                              np.float64)))


def vp_stress_of(eps, P, ellipse: float = ELLIPSE, delta_min: float = DELTA_MIN,
                 replacement_pressure: bool = False):
    """Hibler VP stress (m, 3) [N m-1] and ζ (m,) of strain rates ``eps`` (m, 3)
    (ε̇xx, ε̇yy, ε̇xy) and strengths ``P`` (m,) (numpy, for tests and diagnostics)."""
    eps = np.asarray(eps, np.float64)
    P = np.broadcast_to(np.asarray(P, np.float64), eps.shape[:1])
    exx, eyy, exy = eps[:, 0], eps[:, 1], eps[:, 2]
    div = exx + eyy
    delta = np.sqrt(div ** 2 + ((exx - eyy) ** 2 + 4 * exy ** 2) / ellipse ** 2)
    dd = np.maximum(delta, delta_min)
    zeta = 0.5 * P / dd
    eta = zeta / ellipse ** 2
    pr = P * delta / dd if replacement_pressure else P
    iso = zeta * div - 0.5 * pr
    out = np.empty_like(eps)
    out[:, 0] = eta * (exx - eyy) + iso
    out[:, 1] = eta * (eyy - exx) + iso
    out[:, 2] = 2 * eta * exy
    return out, zeta


@dataclass(frozen=True)
class ViscousPlasticParams:
    """Hibler VP parameters: P* [N m-2], C* [-], ellipse aspect e [-], Δmin [s-1],
    replacement pressure on/off, ice density [kg m-3] (lumped mass)."""

    p_star: float = P_STAR
    c_star: float = C_STAR
    ellipse: float = ELLIPSE
    delta_min: float = DELTA_MIN
    replacement_pressure: bool = False
    rho_ice: float = 900.0

    def __post_init__(self):
        for nm, val, lo in (("p_star", self.p_star, 0.0), ("ellipse", self.ellipse, 0.0),
                            ("delta_min", self.delta_min, 0.0), ("rho_ice", self.rho_ice, 0.0)):
            if not (np.isfinite(val) and val > lo):
                raise ConfigError(f"rheology.{nm} = {val!r} must be > {lo:g}")
        if not (np.isfinite(self.c_star) and self.c_star >= 0):
            raise ConfigError(f"rheology.c_star = {self.c_star!r} must be >= 0")


class ViscousPlastic:
    """The Hibler (1979) viscous-plastic rheology (elliptical yield curve).

    Solved by :class:`lagice.solvers.evp.EVPSolver` (mEVP iterations). It has no
    damage and no healing; ``state.stress`` holds the depth-averaged S/h [Pa].
    """

    name = "viscous_plastic"

    def __init__(self, params: ViscousPlasticParams | None = None, **overrides):
        params = params or ViscousPlasticParams()
        self.params = ViscousPlasticParams(**{**params.__dict__, **overrides}) if overrides else params
        self.n_capped_total = 0

    def strength(self, thickness, concentration) -> np.ndarray:
        """Ice strength P [N m-1] per element."""
        p = self.params
        return ice_strength(thickness, concentration, p.p_star, p.c_star)
