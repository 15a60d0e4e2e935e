"""Adapters from ``thermo`` to the component protocols of ``lagice.Model``.

``lagice/model.py`` (as of this writing) expects

* ``thermo``: an object with ``step(state, t_s, dt_s) -> dict`` (and
  optionally ``checkpoint_arrays()``, ``checkpoint_meta()``,
  ``load_checkpoint(arrays, meta)``);
* ``healing``: a callable ``(state, t_s) -> rate (m,) [s-1]`` used by the
  solver's damage update ``d ← d − rate·dt``.

These adapters evaluate the air temperature at the element centroids and
call :class:`thermo.zero_layer.ZeroLayerThermo` / a
:class:`thermo.healing.Healing` law on the state's element arrays
(``thickness``, ``concentration``, ``snow``, ``damage``). They hold no
physics of their own. Each keeps its own forcing field object, because the
weights are cached per set of positions.
"""
from __future__ import annotations

import numpy as np

from forcing.base import SCALAR, as_field
from lagice.errors import ConfigError

from .healing import ConstantHealing
from .zero_layer import VolumeBudget, ZeroLayerThermo


def _centroids_xy(mesh):
    c = mesh.centroids()
    return np.ascontiguousarray(c[:, 0]), np.ascontiguousarray(c[:, 1])


class ThermoComponent:
    """``Model(thermo=ThermoComponent(air_temperature))``.

    Parameters
    ----------
    air_temperature : scalar field [°C] (a Field, callable ``f(t, x, y)`` or number)
    zero_layer : ZeroLayerThermo, optional (default parameters)
    """

    def __init__(self, air_temperature, zero_layer=None):
        self.air_temperature = as_field(air_temperature, SCALAR, "degC")
        if self.air_temperature is None:
            raise ConfigError("ThermoComponent needs an air temperature field")
        self.zero_layer = zero_layer if zero_layer is not None else ZeroLayerThermo()
        self.budget = None

    def step(self, state, t_s, dt_s):
        """One thermodynamic step on ``state`` (in place); returns the step's
        volume changes [m³] and the running budget terms."""
        mesh = state.mesh
        xc, yc = _centroids_xy(mesh)
        area = np.abs(mesh.areas())
        if self.budget is None:
            self.budget = VolumeBudget.from_state(state.thickness, area)
        ta = self.air_temperature.evaluate(t_s, xc, yc)
        tend = self.zero_layer.step(state.thickness, state.concentration, ta, dt_s,
                                    hs=state.snow, budget=self.budget, area_m2=area)
        return {"thermo_volume_change_m3": float(np.sum(tend.total * area)),
                "new_ice_m3": float(np.sum(tend.new_ice * area)),
                "floor_removed_m3": float(np.sum(tend.floor_removed * area)),
                "air_temperature_mean_c": float(np.mean(ta)) if ta.size else float("nan"),
                "budget": self.budget.as_dict()}

    def checkpoint_meta(self):
        return {"budget": None if self.budget is None else self.budget.as_dict()}

    def load_checkpoint(self, arrays, meta):
        b = meta.get("budget")
        self.budget = None if b is None else VolumeBudget.from_dict(b)


class HealingComponent:
    """``Model(healing=HealingComponent(law, air_temperature, dt_s=...))``.

    Returns the healing rate [s-1] per element for the solver's
    ``d ← max(0, d − rate·dt)``. With ``dt_s`` given, the rate is the
    *effective* rate of the law's exact step over ``dt_s``
    (``healing.apply`` on a copy, divided by ``dt_s``). That keeps the
    √(freezing-degree-day) law finite at d = 1. Without ``dt_s`` it is
    ``healing.rate``.

    Parameters
    ----------
    healing : thermo.healing.Healing
    air_temperature : scalar field [°C], or None for laws that ignore it
        (ConstantHealing)
    dt_s : float, optional
        The step over which the solver applies the rate [s].
    """

    def __init__(self, healing, air_temperature=None, dt_s=None):
        self.healing = healing
        self.air_temperature = as_field(air_temperature, SCALAR, "degC")
        if self.air_temperature is None and not isinstance(healing, ConstantHealing):
            raise ConfigError(f"{type(healing).__name__} needs an air temperature field")
        self.dt_s = dt_s

    def __call__(self, state, t_s):
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
