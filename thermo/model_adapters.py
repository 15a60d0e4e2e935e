"""Components of ``lagice.Model`` (:mod:`lagice.components`) built on ``thermo``:

* :class:`ThermoComponent` (``thermodynamics``): evaluates the air temperature
  at the element centroids and runs :class:`thermo.zero_layer.ZeroLayerThermo`
  on the state's element arrays, booking the volume change in the model's
  volume ledger (:class:`lagice.budget.VolumeLedger`);
* :class:`HealingComponent` (``healing``): the healing rate [s-1] per element
  that the time stepper's damage update applies (``d ← d − rate·dt``).

They hold no physics of their own. Each keeps its own forcing field object,
because the interpolation weights are cached per set of positions.
"""
from __future__ import annotations

import numpy as np

from forcing.base import SCALAR, as_field
from lagice.components import RateComponent
from lagice.errors import ConfigError

from .healing import ConstantHealing
from .zero_layer import ZeroLayerThermo


def _centroids_xy(mesh):
    c = mesh.centroids()
    return np.ascontiguousarray(c[:, 0]), np.ascontiguousarray(c[:, 1])


class ThermoComponent:
    """Component ``thermodynamics``: ``Model(thermo=ThermoComponent(air_temperature))``.

    Parameters
    ----------
    air_temperature : scalar field [°C] (a Field, callable ``f(t, x, y)`` or number)
    zero_layer : ZeroLayerThermo, optional (default parameters)

    The running breakdown of the volume change (congelation growth/melt, new
    ice in open water, ice removed below the thickness floor, snow removed) is
    kept in :attr:`totals_m3` [m³] and carried in checkpoints; the net change is
    booked in the model's ledger as ``thermo``.
    """

    name = "thermodynamics"
    TOTALS = ("congelation", "new_ice", "floor_removed", "snow_removed")

    def __init__(self, air_temperature, zero_layer=None):
        self.air_temperature = as_field(air_temperature, SCALAR, "degC")
        if self.air_temperature is None:
            raise ConfigError("ThermoComponent needs an air temperature field")
        self.zero_layer = zero_layer if zero_layer is not None else ZeroLayerThermo()
        self.totals_m3 = dict.fromkeys(self.TOTALS, 0.0)

    def step(self, state, t_s, dt_s, ledger=None):
        """One thermodynamic step on ``state`` (in place) with the air temperature at
        ``t_s`` [s]; books the net volume change in ``ledger`` (if given) and
        returns the step's volume changes [m³]."""
        mesh = state.mesh
        xc, yc = _centroids_xy(mesh)
        area = np.abs(mesh.areas())
        ta = self.air_temperature.evaluate(t_s, xc, yc)
        tend = self.zero_layer.step(state.thickness, state.concentration, ta, dt_s, hs=state.snow)
        dv = float(np.sum(tend.total * area))
        if ledger is not None:
            ledger.book("thermo", dv)
        rep = {"thermo_volume_change_m3": dv,
               "air_temperature_mean_c": float(np.mean(ta)) if ta.size else float("nan")}
        for k in self.TOTALS:
            v = float(np.sum(getattr(tend, k) * area))
            self.totals_m3[k] += v
            rep[f"{k}_m3"] = v
        return rep

    def advance(self, model, dt_s):
        """Component protocol: the step ends at ``model.clock.time_s + dt_s``; the air
        temperature is taken there (as the stepper's forcing)."""
        return self.step(model.state, model.clock.time_s + dt_s, dt_s, model.ledger)

    def checkpoint_state(self):
        return {}, {"totals_m3": dict(self.totals_m3)}

    def restore(self, arrays, meta):
        self.totals_m3.update(meta.get("totals_m3", {}))


class HealingComponent(RateComponent):
    """Component ``healing``: ``Model(healing=HealingComponent(law, air_temperature, dt_s=...))``.

    :meth:`rate` returns the healing rate [s-1] per element for the stepper's
    ``d ← max(0, d − rate·dt)``. With ``dt_s`` given, the rate is the
    *effective* rate of the law's exact step over ``dt_s``
    (``healing.apply`` on a copy, divided by ``dt_s``). That keeps the
    √(freezing-degree-day) law finite at d = 1. Without ``dt_s`` it is
    ``healing.rate``. It holds no state of its own.

    Parameters
    ----------
    healing : thermo.healing.Healing
    air_temperature : scalar field [°C], or None for laws that ignore it
        (ConstantHealing)
    dt_s : float, optional
        The step over which the solver applies the rate [s].
    """

    name = "healing"

    def __init__(self, healing, air_temperature=None, dt_s=None):
        self.healing = healing
        self.air_temperature = as_field(air_temperature, SCALAR, "degC")
        if self.air_temperature is None and not isinstance(healing, ConstantHealing):
            raise ConfigError(f"{type(healing).__name__} needs an air temperature field")
        self.dt_s = dt_s

    def rate(self, state, t_s):
        """Healing rate [s-1] per element of ``state`` at time ``t_s`` [s]."""
        d = state.damage
        if self.air_temperature is None:
            ta = np.zeros_like(d)
        else:
            xc, yc = _centroids_xy(state.mesh)
            ta = self.air_temperature.evaluate(t_s, xc, yc)
        if self.dt_s is None:
            return np.asarray(self.healing.rate(ta, d), dtype=np.float64)
        trial = d.copy()
        return self.healing.apply(trial, ta, self.dt_s) / self.dt_s

