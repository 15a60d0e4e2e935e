"""Components of ``lagice.Model`` (:mod:`lagice.components`) built on ``thermo``:

* :class:`ThermoComponent` (``thermodynamics``): evaluates the air temperature
  at the element centroids and runs :class:`thermo.zero_layer.ZeroLayerThermo`
  on the state's element arrays, booking the volume change in the model's
  volume ledger (:class:`lagice.budget.VolumeLedger`);
* :class:`HealingComponent` (``healing``): the healing rate [s-1] per element
  that the time stepper's damage update applies (``d ← d − rate·dt``).

They hold no physics of their own. Both take the air temperature at the element
centroids through :func:`air_at_centroids`: one :class:`CentroidAirTemperature` per
field object, shared by the components that use that field. In a step the
thermodynamics takes it at the end of the step (t + Δt, nodes moved), and the next
step's healing rate at its start: the same time and, unless a remesh came between,
the same centroids. The second caller then gets the first one's array (the same
values, since the evaluation depends only on the time and the positions) instead of
a second interpolation.
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


class CentroidAirTemperature:
    """The air temperature [°C] of ``field`` at the element centroids of a mesh, kept
    for the next caller at the same time and the same mesh.

    "The same mesh" is the same :class:`~lagice.mesh.Mesh` object with the same
    triangle array and node positions equal to those of the last evaluation
    (compared element by element; the nodes move in place every step, and a remesh
    or a checkpoint load makes a new mesh). The time is compared exactly. Anything
    else evaluates the field again. The array returned is shared with later
    callers at the same time and mesh: callers must not write to it.

    ``n_evaluations`` and ``n_reused`` count the two outcomes (diagnostics, tests).
    """

    def __init__(self, field):
        self.field = field
        self._t = None
        self._mesh = None
        self._triangles = None
        self._nodes = None
        self._values = None
        self.n_evaluations = 0
        self.n_reused = 0

    def values(self, mesh, t_s: float) -> np.ndarray:
        """(m,) air temperature [°C] at the centroids of ``mesh`` at ``t_s`` [s]."""
        nodes = mesh.nodes
        if (self._values is not None and self._t == t_s and self._mesh is mesh
                and self._triangles is mesh.triangles and self._nodes.shape == nodes.shape
                and np.array_equal(self._nodes, nodes)):
            self.n_reused += 1
            return self._values
        xc, yc = _centroids_xy(mesh)
        ta = self.field.evaluate(t_s, xc, yc)
        if self._nodes is not None and self._nodes.shape == nodes.shape:
            np.copyto(self._nodes, nodes)
        else:
            self._nodes = nodes.copy()
        self._t, self._mesh, self._triangles, self._values = t_s, mesh, mesh.triangles, ta
        self.n_evaluations += 1
        return ta


def air_at_centroids(field) -> CentroidAirTemperature:
    """The one :class:`CentroidAirTemperature` of ``field``, kept on the field object (made
    at the first call; the field and its memo are freed together). A field that takes no
    new attribute (a frozen dataclass) gets a new one each time, which shares nothing."""
    memo = getattr(field, "_centroid_air_temperature", None)
    if not isinstance(memo, CentroidAirTemperature):
        memo = CentroidAirTemperature(field)
        try:
            field._centroid_air_temperature = memo
        except (AttributeError, TypeError):
            pass
    return memo


class ThermoComponent:
    """Component ``thermodynamics``: ``Model(thermo=ThermoComponent(air_temperature))``.

    Parameters
    ----------
    air_temperature : scalar field [°C] (a Field, callable ``f(t, x, y)`` or number)
    zero_layer : ZeroLayerThermo, optional (default parameters)
    new_ice_undamaged : bool, default False
        Ice formed in open water is undamaged (scene key ``thermo.new_ice_undamaged``).
        Where the concentration grows from A to A' > A in a step, the element's damage
        becomes the area-weighted mean of the old ice's damage and the new ice's 0,
        d ← d A/A', so the damaged ice area d·A is unchanged by the growth. This is
        neXtSIM-DG's lateral-growth healing (``ConstantHealing::updateElement`` in
        ``physics/src/modules/DamageHealingModule``, which adds its constant healing after
        it); classic neXtSIM instead keeps new ice in a young-ice category that the
        rheology's concentration leaves out. Off by default: new ice then takes the damage
        of its element, as it always did in lagice. Elements whose concentration falls (the
        thickness floor, or the ice vanishing) keep their damage.

    The running breakdown of the volume change (congelation growth/melt, new
    ice in open water, ice removed below the thickness floor, snow removed) is
    kept in :attr:`totals_m3` [m³] and carried in checkpoints; the net change is
    booked in the model's ledger as ``thermo``. With ``new_ice_undamaged``, the
    damage that new ice removed (Σ Δd · area [m²] of fully damaged ice equivalent) is
    added up in :attr:`damage_diluted_m2` and reported per step.
    """

    name = "thermodynamics"
    TOTALS = ("congelation", "new_ice", "floor_removed", "snow_removed")

    def __init__(self, air_temperature, zero_layer=None, new_ice_undamaged=False):
        self.air_temperature = as_field(air_temperature, SCALAR, "degC")
        if self.air_temperature is None:
            raise ConfigError("ThermoComponent needs an air temperature field")
        if not isinstance(new_ice_undamaged, bool):
            raise ConfigError(f"thermo.new_ice_undamaged = {new_ice_undamaged!r}: expected true or false")
        self.zero_layer = zero_layer if zero_layer is not None else ZeroLayerThermo()
        self.new_ice_undamaged = new_ice_undamaged
        self.totals_m3 = dict.fromkeys(self.TOTALS, 0.0)
        self.damage_diluted_m2 = 0.0
        self._air = air_at_centroids(self.air_temperature)

    def step(self, state, t_s, dt_s, ledger=None):
        """One thermodynamic step on ``state`` (in place) with the air temperature at
        ``t_s`` [s]; books the net volume change in ``ledger`` (if given) and
        returns the step's volume changes [m³]."""
        mesh = state.mesh
        area = np.abs(mesh.areas())
        ta = self._air.values(mesh, t_s)
        a_old = state.concentration.copy() if self.new_ice_undamaged else None
        tend = self.zero_layer.step(state.thickness, state.concentration, ta, dt_s, hs=state.snow)
        dv = float(np.sum(tend.total * area))
        if ledger is not None:
            ledger.book("thermo", dv)
        rep = {"thermo_volume_change_m3": dv,
               "air_temperature_mean_c": float(np.mean(ta)) if ta.size else float("nan")}
        if self.new_ice_undamaged:
            removed = dilute_damage(state.damage, a_old, state.concentration)
            diluted = float(np.sum(removed * area))
            self.damage_diluted_m2 += diluted
            rep["damage_diluted_by_new_ice_m2"] = diluted
        for k in self.TOTALS:
            v = float(np.sum(getattr(tend, k) * area))
            self.totals_m3[k] += v
            rep[f"{k}_m3"] = v
        return rep

    def advance(self, model, dt_s):
        """Component protocol: the step ends at ``model.clock.time_s + dt_s``; the air
        temperature is taken there (as the stepper's forcing). With ``new_ice_undamaged`` it
        edits the damage, so a device stepper first brings it to the host (free on the CPU)."""
        state = model.needs_host_state(("damage",)) if self.new_ice_undamaged else model.state
        return self.step(state, model.clock.time_s + dt_s, dt_s, model.ledger)

    def checkpoint_state(self):
        meta = {"totals_m3": dict(self.totals_m3)}
        if self.new_ice_undamaged:
            meta["damage_diluted_m2"] = self.damage_diluted_m2
        return {}, meta

    def restore(self, arrays, meta):
        self.totals_m3.update(meta.get("totals_m3", {}))
        self.damage_diluted_m2 = float(meta.get("damage_diluted_m2", 0.0))


def dilute_damage(damage, a_old, a_new):
    """Undamaged new ice (:class:`ThermoComponent`, ``new_ice_undamaged``): where the
    concentration grew (a_new > a_old), d ← d a_old/a_new in place, so d·A is unchanged.
    Returns the decrease of each element's damage (≥ 0; 0 where A did not grow)."""
    grew = a_new > a_old
    old = damage[grew]
    damage[grew] = old * (a_old[grew] / a_new[grew])
    removed = np.zeros_like(damage)
    removed[grew] = old - damage[grew]
    return removed


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
        self._air = None if self.air_temperature is None else air_at_centroids(self.air_temperature)

    def rate(self, state, t_s):
        """Healing rate [s-1] per element of ``state`` at time ``t_s`` [s]."""
        d = state.damage
        if self.air_temperature is None:
            ta = np.zeros_like(d)
        else:
            ta = self._air.values(state.mesh, t_s)
        if self.dt_s is None:
            return np.asarray(self.healing.rate(ta, d), dtype=np.float64)
        return self.healing.effective_rate(ta, d, self.dt_s)

