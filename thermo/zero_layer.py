"""Zero-layer (Semtner 1976) thermodynamics on element arrays (docs/design.md §3).

Simple on purpose (Girard 2010 §5.2.3 asks only for something growth-like):
the ice has no heat capacity, its surface is at the air temperature ``Ta``
and its base at the freezing point ``Tf``, so the conductive flux through
ice of thickness ``hi = h/A`` and snow ``hsi = hs/A`` in series is

    Fc = (Tf − Ta) / (hi/ki + hsi/ks)                      [W m-2]

and it grows (Ta < Tf) or melts (Ta > Tf) the ice at ``dhi/dt = Fc/(ρi Lf)``.
For constant ``Ta`` over a step this integrates exactly (no time-step
error, unconditionally stable):

    hi²/(2 ki) + hsi·hi/ks  increases by  (Tf − Ta)·Δt/(ρi Lf)

which without snow is Stefan's law ``hi² = hi0² + 2 ki (Tf − Ta) t/(ρi Lf)``.
Ice whose quadratic energy reaches zero melts completely within the step.

Open water (fraction 1 − A) loses ``Qow = kow (Tf − Ta)`` [W m-2] when
``Ta < Tf``; that heat freezes new ice of volume per element area
``ΔV = (1 − A) Qow Δt/(ρi Lf)`` spread at thickness ``h0``:
``A ← min(1, A + ΔV/h0)``, ``h ← h + ΔV`` (all volume kept).  Warm air
over open water does nothing (the heat goes to the ocean, not tracked).

Minimum thickness: ice thinner than ``h_min`` (``h/A < h_min``) keeps its
volume and shrinks its area, ``A ← h/h_min``.  If that leaves
``A < min_concentration`` the ice is removed and its volume is booked in
``floor_removed`` (and its snow in ``snow_removed``).  Snow has no
thermodynamics here: it insulates, and it is removed only with its ice.

Booking: every change of ``h`` is returned per element in m (ice volume per
unit element area; multiply by element area for m³) by term, and
:class:`VolumeBudget` accumulates them in m³ so that
``V(t) − V(0) = Σ thermodynamic change − Σ outflow`` is checkable to
round-off.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np
from numba import prange

from forcing._numba_util import pick, serial_and_parallel
from lagice.errors import ConfigError, LagiceError, check_range
from lagice.params import RHO_ICE


@dataclass(frozen=True)
class ThermoParams:
    """Zero-layer thermodynamics parameters (units in the names).

    Attributes
    ----------
    conductivity_ice_w_m_k : ki, ice thermal conductivity [W m-1 K-1] (2.0, Semtner 1976)
    conductivity_snow_w_m_k : ks, snow thermal conductivity [W m-1 K-1] (0.31, Maykut & Untersteiner 1971)
    rho_ice_kg_m3 : ρi, ice density [kg m-3] (900, Dansereau et al. 2016 Table 1)
    latent_heat_j_kg : Lf, latent heat of fusion [J kg-1] (3.34e5)
    freezing_point_c : Tf, sea-water freezing point [°C] (−1.8)
    open_water_heat_transfer_w_m2_k : kow, linearised open-water heat loss
        per K of (Tf − Ta) [W m-2 K-1] (15: ≈ 300 W m-2 at 20 K, sensible +
        latent + long-wave of an Arctic lead)
    new_ice_thickness_m : h0, thickness of new ice formed in open water [m] (0.1)
    min_ice_thickness_m : h_min, floor on the ice thickness h/A [m] (0.05)
    min_concentration : A below which thin ice is removed (booked) [-] (1e-6)
    """

    conductivity_ice_w_m_k: float = 2.0
    conductivity_snow_w_m_k: float = 0.31
    rho_ice_kg_m3: float = RHO_ICE
    latent_heat_j_kg: float = 3.34e5
    freezing_point_c: float = -1.8
    open_water_heat_transfer_w_m2_k: float = 15.0
    new_ice_thickness_m: float = 0.1
    min_ice_thickness_m: float = 0.05
    min_concentration: float = 1.0e-6

    def __post_init__(self):
        check_range("conductivity_ice_w_m_k (ki)", self.conductivity_ice_w_m_k, 0.0, None,
                    low_open=True, unit="W m-1 K-1")
        check_range("conductivity_snow_w_m_k (ks)", self.conductivity_snow_w_m_k, 0.0, None,
                    low_open=True, unit="W m-1 K-1")
        check_range("rho_ice_kg_m3", self.rho_ice_kg_m3, 0.0, None, low_open=True, unit="kg m-3")
        check_range("latent_heat_j_kg (Lf)", self.latent_heat_j_kg, 0.0, None, low_open=True, unit="J kg-1")
        check_range("freezing_point_c (Tf)", self.freezing_point_c, -10.0, 0.0, unit="degC")
        check_range("open_water_heat_transfer_w_m2_k", self.open_water_heat_transfer_w_m2_k, 0.0, None,
                    unit="W m-2 K-1")
        check_range("min_ice_thickness_m (h_min)", self.min_ice_thickness_m, 0.0, None, unit="m")
        check_range("new_ice_thickness_m (h0)", self.new_ice_thickness_m, self.min_ice_thickness_m, None,
                    low_open=self.min_ice_thickness_m == 0.0, unit="m")
        check_range("min_concentration", self.min_concentration, 0.0, 1.0, high_open=True)

    def replace(self, **changes) -> ThermoParams:
        names = {f.name for f in fields(self)}
        for k in changes:
            if k not in names:
                raise ConfigError(f"unknown thermodynamics parameter {k!r}; known: {sorted(names)}")
        return replace(self, **changes)


@dataclass
class ThermoTendencies:
    """Per-element changes of one step, in m (ice volume per unit element area).

    ``total = h_new − h_old`` exactly (as stored);
    ``congelation + new_ice + floor_removed`` equals it to round-off.
    """

    congelation: np.ndarray  #: growth (>0) / melt (<0) of existing ice [m]
    new_ice: np.ndarray  #: new ice formed in open water (>= 0) [m]
    floor_removed: np.ndarray  #: ice removed below the thickness floor (<= 0) [m]
    total: np.ndarray  #: h_new − h_old [m]
    snow_removed: np.ndarray  #: snow removed with vanished ice (<= 0) [m]


def _zero_layer_kernel(h, A, hs, Ta, dt, ki, ks, rho_l, tf, kow, h0, hmin, amin,
                       d_cong, d_new, d_floor, d_tot, d_snow):
    """In-place zero-layer step on element arrays (see module docstring)."""
    n = h.shape[0]
    a2 = 1.0 / (2.0 * ki)
    for k in prange(n):
        h_old = h[k]
        a_k = A[k]
        hv = h_old
        s = hs[k]
        dT = tf - Ta[k]
        cong = 0.0
        new = 0.0
        floor = 0.0
        snow = 0.0
        if hv <= 0.0 or a_k <= 0.0:
            # no ice: normalise (a zero volume changes nothing in the budget)
            if hv != 0.0:
                floor = -hv
            hv = 0.0
            a_k = 0.0
        else:
            # --- existing ice: exact integration of dhi/dt = dT/(ρL(hi/ki + hsi/ks))
            hi = hv / a_k
            # (s/a_k)/ks is exactly ±0 without snow: skip its two divisions (same bits)
            b = s if s == 0.0 else (s / a_k) / ks
            e = a2 * hi * hi + b * hi + dT * dt / rho_l
            if e <= 0.0:
                hi_new = 0.0
            else:
                hi_new = 2.0 * e / (b + math.sqrt(b * b + 4.0 * a2 * e))
            h_new = a_k * hi_new
            cong = h_new - hv
            hv = h_new
            if hv <= 0.0:
                hv = 0.0
                a_k = 0.0
                snow = -s
                s = 0.0
        # --- new ice in open water (fraction at the start of the step)
        ow = 1.0 - A[k]
        if ow > 0.0 and dT > 0.0:
            dv = ow * kow * dT * dt / rho_l
            hv_new = hv + dv
            new = hv_new - hv
            hv = hv_new
            a_k = min(1.0, a_k + dv / h0)
        # --- thickness floor: keep volume, shrink area; remove if too small
        if hv > 0.0 and hv < a_k * hmin:
            a_k = hv / hmin
            if a_k < amin:
                floor = floor - hv
                hv = 0.0
                a_k = 0.0
                snow = snow - s
                s = 0.0
        h[k] = hv
        A[k] = a_k
        hs[k] = s
        d_cong[k] = cong
        d_new[k] = new
        d_floor[k] = floor
        d_tot[k] = hv - h_old
        d_snow[k] = snow


_ZERO_LAYER = serial_and_parallel(_zero_layer_kernel)


class ZeroLayerThermo:
    """Zero-layer thermodynamics acting on element arrays (module docstring).

    Parameters
    ----------
    params : ThermoParams
    """

    def __init__(self, params=None):
        self.params = ThermoParams() if params is None else params
        if not isinstance(self.params, ThermoParams):
            raise ConfigError(f"params must be a ThermoParams; got {type(params).__name__}")

    def growth_rate(self, h_ice_m, air_temperature_c, h_snow_m=0.0):
        """Instantaneous growth rate dhi/dt [m s-1] of ice ``h_ice_m`` thick
        (conductive flux / (ρi Lf)); negative for melt."""
        p = self.params
        r = np.asarray(h_ice_m) / p.conductivity_ice_w_m_k + np.asarray(h_snow_m) / p.conductivity_snow_w_m_k
        rho_l = p.rho_ice_kg_m3 * p.latent_heat_j_kg
        return (p.freezing_point_c - np.asarray(air_temperature_c)) / (r * rho_l)

    def step(self, h, A, air_temperature_c, dt_s, *, hs=None, budget=None, area_m2=None):
        """Advance ``h`` [m], ``A`` [-] (and ``hs`` [m] if given) in place by ``dt_s``.

        Parameters
        ----------
        h, A : ndarray (n_elements,) float64
            Ice volume per unit area [m] and concentration, updated in place.
        air_temperature_c : float or ndarray (n_elements,)
            Air temperature Ta [°C], held constant over the step.
        dt_s : float
            Time step [s].
        hs : ndarray, optional
            Snow volume per unit area [m], updated in place (only zeroed where
            the ice vanishes).
        budget : VolumeBudget, optional
            Books the step's change (needs ``area_m2``).
        area_m2 : ndarray, optional
            Element areas [m²].

        Returns
        -------
        ThermoTendencies
            Per-element changes in m (volume per element area).
        """
        p = self.params
        check_range("dt_s", dt_s, 0.0, None, unit="s")
        for name, arr in (("h", h), ("A", A)) + ((("hs", hs),) if hs is not None else ()):
            if not (isinstance(arr, np.ndarray) and arr.dtype == np.float64 and arr.ndim == 1
                    and arr.flags.c_contiguous):
                raise ConfigError(f"thermodynamics: {name} must be a contiguous 1-D float64 array")
            if arr.shape != h.shape:
                raise ConfigError(f"thermodynamics: {name} has shape {arr.shape}; expected {h.shape}")
        n = h.shape[0]
        ta = np.ascontiguousarray(np.broadcast_to(np.asarray(air_temperature_c, dtype=np.float64), (n,)))
        if not np.all(np.isfinite(ta)):
            raise ConfigError("thermodynamics: air temperature has non-finite values")
        snow = hs if hs is not None else np.zeros(n)
        out = [np.empty(n) for _ in range(5)]
        pick(_ZERO_LAYER, n)(h, A, snow, ta, float(dt_s), p.conductivity_ice_w_m_k,
                           p.conductivity_snow_w_m_k, p.rho_ice_kg_m3 * p.latent_heat_j_kg,
                           p.freezing_point_c, p.open_water_heat_transfer_w_m2_k,
                           p.new_ice_thickness_m, p.min_ice_thickness_m, p.min_concentration, *out)
        tend = ThermoTendencies(*out)
        if budget is not None:
            if area_m2 is None:
                raise ConfigError("thermodynamics: booking a budget needs area_m2")
            budget.book_thermo(tend, area_m2)
        return tend


class VolumeBudget:
    """Global ice-volume budget [m³] (docs/design.md §3, Lagrangian mass update).

    ``V(t) − V(0) = Σ thermodynamic change − Σ outflow`` where the
    thermodynamic change is booked by :meth:`ZeroLayerThermo.step` and the
    outflow (ice leaving through open boundaries, > 0 when leaving) by the
    caller with :meth:`book_outflow`.

    Parameters
    ----------
    initial_volume_m3 : float
        V(0) = Σ h·area at the start [m³].
    """

    def __init__(self, initial_volume_m3):
        self.initial_volume_m3 = float(initial_volume_m3)
        self.congelation_m3 = 0.0
        self.new_ice_m3 = 0.0
        self.floor_removed_m3 = 0.0
        self.thermo_m3 = 0.0
        self.outflow_m3 = 0.0
        self.snow_removed_m3 = 0.0

    @classmethod
    def from_state(cls, h, area_m2):
        """Budget starting from ice volume Σ h·area."""
        return cls(float(np.sum(np.asarray(h) * np.asarray(area_m2))))

    def book_thermo(self, tendencies, area_m2):
        """Add one step's :class:`ThermoTendencies` (times element areas)."""
        area = np.asarray(area_m2)
        self.thermo_m3 += float(np.sum(tendencies.total * area))
        self.congelation_m3 += float(np.sum(tendencies.congelation * area))
        self.new_ice_m3 += float(np.sum(tendencies.new_ice * area))
        self.floor_removed_m3 += float(np.sum(tendencies.floor_removed * area))
        self.snow_removed_m3 += float(np.sum(tendencies.snow_removed * area))

    def book_outflow(self, volume_m3):
        """Book ice volume leaving the domain [m³] (negative for inflow)."""
        self.outflow_m3 += float(volume_m3)

    def expected_volume(self):
        """V(0) + thermodynamic change − outflow [m³]."""
        return self.initial_volume_m3 + self.thermo_m3 - self.outflow_m3

    def residual(self, volume_m3):
        """(V(t) − V(0)) − (thermodynamic change − outflow) [m³]."""
        return (float(volume_m3) - self.initial_volume_m3) - (self.thermo_m3 - self.outflow_m3)

    def relative_residual(self, volume_m3):
        """|residual| / max(V(0), V(t), tiny)."""
        scale = max(abs(self.initial_volume_m3), abs(float(volume_m3)), 1e-300)
        return abs(self.residual(volume_m3)) / scale

    def check(self, volume_m3, rtol=1e-12):
        """Raise :class:`LagiceError` if the budget does not close to ``rtol``."""
        rel = self.relative_residual(volume_m3)
        if not rel <= rtol:
            raise LagiceError(
                f"ice volume budget does not close: V = {volume_m3:.17g} m3, V0 = "
                f"{self.initial_volume_m3:.17g} m3, thermodynamic change = {self.thermo_m3:.17g} m3, "
                f"outflow = {self.outflow_m3:.17g} m3; relative residual {rel:.3g} > {rtol:g}")
        return rel

    @classmethod
    def from_dict(cls, terms):
        """Budget restored from :meth:`as_dict` (checkpoint)."""
        b = cls(terms["initial_volume_m3"])
        for k, v in terms.items():
            setattr(b, k, float(v))
        return b

    def as_dict(self):
        """Budget terms [m³] (for output/checkpoint)."""
        return dict(initial_volume_m3=self.initial_volume_m3, thermo_m3=self.thermo_m3,
                    congelation_m3=self.congelation_m3, new_ice_m3=self.new_ice_m3,
                    floor_removed_m3=self.floor_removed_m3, outflow_m3=self.outflow_m3,
                    snow_removed_m3=self.snow_removed_m3)
