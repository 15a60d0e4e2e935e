"""Measured time-step limits of the solvers (``benchmarks/stability.py``).

The limits ship in ``lagice/data/stability_limits.json`` as the coefficient of
the law that the measurements follow:

* explicit: the elastic sub-step is bounded by the wave speed,
  ``Δt_s,max = C · Δx_min / sqrt(E/ρi)``, with Δx_min = sqrt(2·min area) and E the
  stiffest element's modulus (E0 for undamaged, compact ice). C was fitted over
  resolution, E0 and α (see ``docs/solvers.md``) on meshes of uniform E. Where E
  varies between elements (damage, concentration), ``solver.substep_limit = "element"``
  applies it element by element, ``C · min_e Δx_e / sqrt(E_e/ρi)`` (:func:`effective_dx`;
  the default, "mesh", keeps the smallest Δx with the stiffest E): the largest
  eigenvalue of the lumped-mass system is bounded by the largest element eigenvalue
  (Irons' element eigenvalue theorem; the usual rule of explicit finite elements), and
  an element's scales as E_e/(ρi Δx_e²), its thickness cancelling between stiffness
  and mass. On uniform E this is the fitted law itself.
* implicit: the JSON says whether a limit was found (``dt_over_td_max``:
  Δt_max / td, td = Δx/cs) or none within the range tested.

:func:`check_explicit_substep` and :func:`check_implicit_step` raise
:class:`~lagice.errors.ConfigError` naming the limit and by how much it is
exceeded, or, with ``allow_unstable=True``, warn with :class:`StabilityWarning`.
"""
from __future__ import annotations

import json
import math
import warnings
from functools import lru_cache
from pathlib import Path

from .errors import ConfigError
from .params import MaxwellEBParams

LIMITS_PATH = Path(__file__).parent / "data" / "stability_limits.json"


class StabilityWarning(UserWarning):
    """A time step beyond a measured stability limit (run allowed by the user)."""


@lru_cache(maxsize=4)
def load_limits(path: str | None = None) -> dict:
    """The shipped (or given) limits table as a dict."""
    p = Path(path) if path else LIMITS_PATH
    try:
        return json.loads(p.read_text())
    except (OSError, ValueError) as exc:
        raise ConfigError(f"stability limits file {p} is unreadable: {exc}") from None


def wave_speed(E_pa: float, rho_ice: float) -> float:
    """sqrt(E/ρ) [m s-1]."""
    return math.sqrt(E_pa / rho_ice)


def explicit_substep_limit(dx_min_m: float, E_pa: float, params: MaxwellEBParams | None = None,
                           rho_ice: float | None = None) -> float:
    """Largest stable explicit sub-step Δt_s,max [s] = C Δx_min / sqrt(E/ρi)."""
    if rho_ice is None:
        rho_ice = (params or MaxwellEBParams()).rho_ice
    C = float(load_limits()["explicit"]["C"])
    return C * dx_min_m / wave_speed(E_pa, rho_ice)


def effective_dx(dx_min_m: float, E_max_pa: float, stiffness_max: float) -> float:
    """The element size Δx_eff [m] that, with the stiffest modulus E_max [Pa], gives the
    element-wise bound of the module doc: C Δx_eff / sqrt(E_max/ρ) = C min_e Δx_e / sqrt(E_e/ρ).
    With Δx_e² = 2 area_e, Δx_eff = sqrt(2 E_max / max_e(E_e/area_e)); ``stiffness_max`` is
    that max_e(E_e/area_e) [Pa m-2]. Never below ``dx_min_m`` (the bound of uniform E, to
    which it reduces); ``dx_min_m`` where the maximum is not a positive finite number."""
    if not (math.isfinite(stiffness_max) and stiffness_max > 0.0 and E_max_pa > 0.0):
        return float(dx_min_m)
    return max(float(dx_min_m), math.sqrt(2.0 * E_max_pa / stiffness_max))


def _verdict(what, value, limit, detail, allow_unstable):
    if value <= limit:
        return
    msg = (f"{what} = {value:.4g} s exceeds the measured stability limit {limit:.4g} s "
           f"by a factor {value / limit:.2f} ({detail}; limits from {LIMITS_PATH.name}, "
           "benchmarks/stability.py)")
    if allow_unstable:
        warnings.warn(msg + "; running anyway because allow_unstable=True", StabilityWarning,
                      stacklevel=4)
        return
    raise ConfigError(msg + "; use more sub-steps / a smaller dt, or allow_unstable=True")


def check_explicit_substep(dt_s: float, dx_min_m: float, E_pa: float,
                           params: MaxwellEBParams | None = None, *, allow_unstable: bool = False) -> float:
    """Raise ConfigError (or warn) if the explicit sub-step Δt_s [s] is beyond
    ``explicit_substep_limit``; returns the limit [s]."""
    p = params or MaxwellEBParams()
    lim = explicit_substep_limit(dx_min_m, E_pa, p)
    C = float(load_limits()["explicit"]["C"])
    _verdict("explicit sub-step dt_s", dt_s, lim,
             f"elastic-wave limit dt_s <= {C:g} dx/sqrt(E/rho) with dx = {dx_min_m:.4g} m, "
             f"E = {E_pa:.4g} Pa", allow_unstable)
    return lim


def implicit_step_limit(dx_min_m: float, params: MaxwellEBParams | None = None) -> float | None:
    """Largest stable implicit Δt [s] if one was measured, else None."""
    p = params or MaxwellEBParams()
    r = load_limits().get("implicit", {}).get("dt_over_td_max")
    if r is None:
        return None
    return float(r) * dx_min_m / p.shear_wave_speed


def check_implicit_step(dt: float, dx_min_m: float, params: MaxwellEBParams | None = None, *,
                        allow_unstable: bool = False) -> float | None:
    """Raise ConfigError (or warn) if the implicit Δt [s] is beyond the measured limit."""
    lim = implicit_step_limit(dx_min_m, params)
    if lim is not None:
        r = float(load_limits()["implicit"]["dt_over_td_max"])
        _verdict("implicit dt", dt, lim, f"dt <= {r:g} td with td = dx/cs, dx = {dx_min_m:.4g} m",
                 allow_unstable)
    return lim
