"""Healing of damage (docs/design.md §3; Girard 2010 §5.2.3; Dansereau et al. 2016).

Damage convention of lagice: ``d = 0`` undamaged, ``d = 1`` fully damaged
(Girard 2010 and Dansereau et al. 2016 use ``d_seed = 1 − d``).  The damage update calls

    rate = healing.rate(air_temperature_c, damage)      # [s-1], >= 0
    healing.apply(damage, air_temperature_c, dt_s)      # d ← max(0, d − rate·dt)

Three laws:

* :class:`ConstantHealing` — ``H = 1/th`` (Dansereau et al. 2016, th = 1e5 s); independent
  of temperature.
* :class:`ThermodynamicHealing` — neXtSIM form
  ``H = max(0, Tf − Ta) / (ΔT0 · th0)`` (th = th0·ΔT0/ΔT; th0 = 20 days,
  ΔT0 = 20 K): no healing at or above freezing, proportionally faster when
  colder.
* :class:`FreezingDegreeDayHealing` — Girard 2010 eqs. 5.8–5.11: healing of
  ``d_seed = 1 − d`` like ice growth, ``d_seed = k √(t (Tf − Ta))``, i.e.
  ``∂d_seed/∂t = 1/(th d_seed)`` with ``th = β/(Tf − Ta)``.  In lagice's
  convention ``rate = (Tf − Ta) / (β (1 − d))``.  :meth:`apply` integrates it
  exactly over the step for constant Ta, ``(1 − d)² += 2 Δt (Tf − Ta)/β``
  (eq. 5.11 is its explicit Euler form), which stays finite at ``d = 1``.

Flooring at ``d = 0`` is the normal end of healing, not a loss: undamaged ice
stays undamaged; :meth:`apply` returns the per-element decrease actually
applied (>= 0), so nothing is removed silently.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from lagice.errors import ConfigError, check_range

DAY_S = 86400.0


def _as_array(air_temperature_c, damage):
    ta = np.asarray(air_temperature_c, dtype=np.float64)
    if damage is not None:
        ta = np.broadcast_to(ta, np.shape(damage))
    return ta


class Healing:
    """Base class: subclasses implement :meth:`rate`."""

    def rate(self, air_temperature_c, damage=None):
        """Healing rate H [s-1] per element (>= 0)."""
        raise NotImplementedError

    def apply(self, damage, air_temperature_c, dt_s):
        """Heal ``damage`` in place over ``dt_s`` [s]: ``d ← max(0, d − H·dt)``.

        Returns the decrease applied per element (>= 0; smaller than
        ``H·dt`` where the floor d = 0 is reached — the normal end of healing).
        """
        check_range("dt_s", dt_s, 0.0, None, unit="s")
        old = damage.copy()
        np.maximum(damage - self.rate(air_temperature_c, damage) * dt_s, 0.0, out=damage)
        return old - damage

    def effective_rate(self, air_temperature_c, damage, dt_s):
        """(m,) the rate [s-1] that takes ``damage`` where :meth:`apply` would take it
        over ``dt_s``: ``(d − d_after)/Δt``, with ``damage`` left unchanged (what the
        stepper applies as ``d ← d − rate·Δt``)."""
        trial = np.array(damage, dtype=np.float64)
        return self.apply(trial, air_temperature_c, dt_s) / dt_s


class ConstantHealing(Healing):
    """Constant-rate healing ``H = 1/th`` [s-1] (Dansereau et al. 2016; th = 1e5 s).

    Temperature is ignored (accepted for a uniform interface).
    """

    def __init__(self, healing_time_s=1.0e5):
        self.healing_time_s = check_range("healing_time_s (th)", healing_time_s, 0.0, None,
                                          low_open=True, unit="s")

    def rate(self, air_temperature_c=None, damage=None):
        r = 1.0 / self.healing_time_s
        if damage is not None:
            return np.full(np.shape(damage), r)
        if air_temperature_c is not None:
            return np.full(np.shape(air_temperature_c), r)
        return r


class ThermodynamicHealing(Healing):
    """neXtSIM temperature-dependent healing ``H = max(0, Tf − Ta)/(ΔT0·th0)`` [s-1].

    Parameters
    ----------
    th0_s : reference healing time at ΔT = ΔT0 [s] (20 days; docs/design.md §3: 15–25 days)
    delta_t0_k : reference temperature difference ΔT0 [K] (20)
    freezing_point_c : Tf [°C] (−1.8)
    """

    def __init__(self, th0_s=20.0 * DAY_S, delta_t0_k=20.0, freezing_point_c=-1.8):
        self.th0_s = check_range("th0_s", th0_s, 0.0, None, low_open=True, unit="s")
        self.delta_t0_k = check_range("delta_t0_k (ΔT0)", delta_t0_k, 0.0, None, low_open=True, unit="K")
        self.freezing_point_c = check_range("freezing_point_c (Tf)", freezing_point_c, -10.0, 0.0,
                                            unit="degC")

    def rate(self, air_temperature_c, damage=None):
        ta = _as_array(air_temperature_c, damage)
        return np.maximum(self.freezing_point_c - ta, 0.0) / (self.delta_t0_k * self.th0_s)

    def effective_rate(self, air_temperature_c, damage, dt_s):
        """As :meth:`Healing.effective_rate`, in one compiled pass over the elements
        (the numpy form made six temporary arrays; this runs every step). The same
        operations in the same order, so the same values bit for bit (tested)."""
        check_range("dt_s", dt_s, 0.0, None, low_open=True, unit="s")
        d = np.ascontiguousarray(damage, dtype=np.float64)
        ta = np.ascontiguousarray(_as_array(air_temperature_c, d))
        out = np.empty(d.shape[0])
        _thermodynamic_effective_rate(ta, d, float(self.freezing_point_c),
                                      float(self.delta_t0_k * self.th0_s), float(dt_s), out)
        return out


class FreezingDegreeDayHealing(Healing):
    """Girard 2010 √(freezing-degree-days) healing (eqs. 5.8–5.11), lagice convention.

    Parameters
    ----------
    beta_s_k : β, healing parameter [s K] (th = β/(Tf − Ta)); Girard 2010
        Fig. 5.4 uses β = 1e3 day K
    freezing_point_c : Tf [°C] (−1.8)
    """

    def __init__(self, beta_s_k=1.0e3 * DAY_S, freezing_point_c=-1.8):
        self.beta_s_k = check_range("beta_s_k (β)", beta_s_k, 0.0, None, low_open=True, unit="s K")
        self.freezing_point_c = check_range("freezing_point_c (Tf)", freezing_point_c, -10.0, 0.0,
                                            unit="degC")

    def rate(self, air_temperature_c, damage=None):
        """``(Tf − Ta)⁺ / (β (1 − d))`` [s-1] (Girard 2010 eq. 5.10); needs ``damage``
        (infinite where d = 1 and it is freezing: use :meth:`apply`)."""
        if damage is None:
            raise ConfigError("FreezingDegreeDayHealing.rate needs the damage (rate ∝ 1/(1 − d))")
        ta = _as_array(air_temperature_c, damage)
        dT = np.maximum(self.freezing_point_c - ta, 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            r = dT / (self.beta_s_k * (1.0 - np.asarray(damage)))
        return np.where(dT > 0.0, r, 0.0)

    def apply(self, damage, air_temperature_c, dt_s):
        """Exact step for constant Ta: ``(1 − d)² ← (1 − d)² + 2 Δt (Tf − Ta)⁺/β``,
        floored at d = 0.  Returns the decrease applied (>= 0)."""
        check_range("dt_s", dt_s, 0.0, None, unit="s")
        ta = _as_array(air_temperature_c, damage)
        dT = np.maximum(self.freezing_point_c - ta, 0.0)
        old = damage.copy()
        ds = 1.0 - damage
        new = 1.0 - np.sqrt(ds * ds + 2.0 * dt_s * dT / self.beta_s_k)
        np.maximum(np.where(dT > 0.0, new, damage), 0.0, out=damage)
        return old - damage


@njit(cache=True)
def _thermodynamic_effective_rate(ta, d, tf, scale, dt, out):
    """``(d − max(d − max(Tf − Ta, 0)/scale·Δt, 0))/Δt`` per element, as numpy evaluates
    ``ThermodynamicHealing.apply`` on a copy (``np.maximum`` keeps a NaN)."""
    for e in range(d.shape[0]):
        x = tf - ta[e]
        if not (x < 0.0):  # np.maximum(x, 0.0): x itself when x >= 0 or NaN
            r = x / scale
        else:
            r = 0.0 / scale
        y = d[e] - r * dt
        if y < 0.0:
            y = 0.0
        out[e] = (d[e] - y) / dt


HEALING_LAWS = {"constant": ConstantHealing, "thermodynamic": ThermodynamicHealing,
                "fdd": FreezingDegreeDayHealing}


def make_healing(law, **params):
    """Healing object for ``law`` in {"constant", "thermodynamic", "fdd"}, or
    ``None`` for ``law`` in {None, "none", False} (healing off: no work)."""
    if law is None or law is False or (isinstance(law, str) and law.lower() in ("none", "off")):
        return None
    if law not in HEALING_LAWS:
        raise ConfigError(f"healing law {law!r}; expected one of {sorted(HEALING_LAWS)} or None")
    try:
        return HEALING_LAWS[law](**params)
    except TypeError as exc:
        raise ConfigError(f"healing law {law!r}: {exc}") from None
