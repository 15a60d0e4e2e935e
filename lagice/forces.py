"""External forces on the ice per unit area (docs/design.md §3): wind stress, ocean
drag and Coriolis, usable by both time steppers.

Momentum per unit area:  ρi h du/dt = ∇·(hσ) + τa + τw − ρi h f k×u

* wind stress     τa = ρa Ca |Ua| Ua                          (Girard et al. 2011; docs/design.md §3)
* ocean drag      τw = ρw Cw |Uw − u| Rθ (Uw − u)             (Rθ: rotation by the
  turning angle θ, counter-clockwise positive)
* Coriolis        −ρi h f k×u,  k×u = (−v, u)

Winds and currents are any callable ``f(t_s, x_m, y_m)`` returning ``(u, v)``
(numbers or ``(n,)`` arrays) or a ``(2, n)`` array — the convention of the
``forcing`` package, whose fields plug in unchanged — or a constant pair
``(u, v)`` [m s-1]. Fields are evaluated at the **current** node positions.

Two interfaces, one object per force:

* ``linearise(t, nodes, vel, mass_per_area) -> (A (n,2,2), b (n,2))`` for the
  implicit solver: force per unit area ≈ b − A·u, with the quadratic drag
  linearised about the iterate ``vel`` (Picard): A = ρw Cw |Uw−u*| Rθ,
  b = ρw Cw |Uw−u*| Rθ Uw + τa; Coriolis A = ρi h f [[0,−1],[1,0]].
* ``add_explicit_terms(t, nodes, terms)`` for the explicit solver: fills an
  :class:`ExplicitTerms` (per-node arrays the numba node kernel reads): a
  velocity-independent stress ``tau``, the ocean drag coefficient, current
  and turning angle, and the Coriolis parameter. The kernel treats drag and
  Coriolis implicitly per sub-step (a 2×2 solve per node; drag coefficient
  from the previous sub-step velocity, Coriolis Crank–Nicolson).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import ConfigError, ForcingError, check_range
from .params import RHO_AIR, RHO_WATER, DragParams, coriolis_from_latitude

ROT90 = np.array([[0.0, -1.0], [1.0, 0.0]])  # k×  as a matrix


def evaluate_vector(field, t: float, nodes: np.ndarray, name: str = "field") -> np.ndarray:
    """Values (n, 2) [m s-1] of a vector field at time ``t`` [s] and ``nodes`` (n, 2) [m].

    ``field``: a callable ``f(t, x, y)`` returning ``(u, v)`` or a ``(2, n)``
    array, or a constant ``(u, v)`` pair. Raises :class:`ForcingError` naming
    the field on a wrong shape or non-finite values.
    """
    n = len(nodes)
    out = np.empty((n, 2))
    res = field(t, nodes[:, 0], nodes[:, 1]) if callable(field) else field
    try:
        if isinstance(res, (tuple, list)):
            if len(res) != 2:
                raise ValueError("expected a pair (u, v)")
            out[:, 0] = np.broadcast_to(np.asarray(res[0], np.float64), (n,))
            out[:, 1] = np.broadcast_to(np.asarray(res[1], np.float64), (n,))
        else:
            arr = np.asarray(res, np.float64)
            if arr.shape == (2,):
                out[:] = arr
            else:
                out[:] = np.broadcast_to(arr, (2, n)).T
    except ValueError as exc:
        raise ForcingError(f"{name}: value of shape {np.shape(res)} at t = {t} s; expected (u, v) "
                           f"or an array of shape (2, {n}) [m s-1] ({exc})") from None
    if not np.all(np.isfinite(out)):
        raise ForcingError(f"{name}: non-finite values at t = {t} s")
    return out


def _check_field(field, name):
    if field is None or callable(field):
        return field
    try:
        arr = np.asarray(field, np.float64)
    except (TypeError, ValueError):
        arr = None
    if arr is None or arr.shape != (2,) or not np.all(np.isfinite(arr)):
        raise ConfigError(f"{name} = {field!r} must be a callable f(t, x, y) -> (u, v) or a "
                          "constant pair (u, v) in m s-1")
    return (float(arr[0]), float(arr[1]))


@dataclass
class ExplicitTerms:
    """Per-node external-force data for the explicit node kernel.

    ``tau`` (n, 2) [N m-2]: velocity-independent stress (wind, ...);
    ``drag_coef`` (n,) [kg m-3]: ρw Cw of the quadratic ocean drag (0: none);
    ``current`` (n, 2) [m s-1]: ocean velocity Uw;
    ``cos_turn, sin_turn``: cos θ, sin θ of the turning angle;
    ``coriolis`` (n,) [s-1]: f (0: off).
    """

    tau: np.ndarray
    drag_coef: np.ndarray
    current: np.ndarray
    coriolis: np.ndarray
    cos_turn: float = 1.0
    sin_turn: float = 0.0
    has_drag: bool = False

    @classmethod
    def zeros(cls, n: int) -> ExplicitTerms:
        return cls(np.zeros((n, 2)), np.zeros(n), np.zeros((n, 2)), np.zeros(n))


class WindStress:
    """Air drag τa = ρa Ca |Ua| Ua [N m-2] (Girard et al. 2011; docs/design.md §3).

    Args:
        wind: 10 m wind [m s-1], callable ``f(t, x, y)`` or constant ``(u, v)``.
        rho_air: ρa [kg m-3]; drag: Ca [-].
    """

    def __init__(self, wind, rho_air: float = RHO_AIR, drag: float = 1.2e-3):
        self.wind = _check_field(wind, "wind")
        if self.wind is None:
            raise ConfigError("wind = None; give a callable f(t, x, y) -> (u, v) or a pair (u, v) m s-1")
        self.rho_air = check_range("rho_air", rho_air, 0.0, None, low_open=True, unit="kg m-3")
        self.drag = check_range("air drag Ca", drag, 0.0, None)

    def stress(self, t: float, nodes: np.ndarray) -> np.ndarray:
        """τa (n, 2) [N m-2] at time t [s]."""
        ua = evaluate_vector(self.wind, t, nodes, "wind")
        speed = np.hypot(ua[:, 0], ua[:, 1])
        return (self.rho_air * self.drag) * speed[:, None] * ua

    def linearise(self, t, nodes, vel, mass_per_area):
        return np.zeros((len(nodes), 2, 2)), self.stress(t, nodes)

    def add_explicit_terms(self, t, nodes, terms: ExplicitTerms) -> None:
        terms.tau += self.stress(t, nodes)


class OceanDrag:
    """Quadratic ocean drag τw = ρw Cw |Uw − u| Rθ (Uw − u) [N m-2].

    Args:
        current: ocean surface velocity Uw [m s-1], callable ``f(t, x, y)``,
            constant ``(u, v)`` or None (ocean at rest).
        rho_water: ρw [kg m-3]; drag: Cw [-].
        turning_angle_deg: θ [deg], counter-clockwise positive (Rθ =
            [[cos θ, −sin θ], [sin θ, cos θ]]).
        min_speed: floor on |Uw − u| [m s-1] of the linearisation (keeps the
            implicit system non-singular at rest; 0 is allowed).
    """

    def __init__(self, current=None, rho_water: float = RHO_WATER, drag: float = 5.5e-3,
                 turning_angle_deg: float = 0.0, min_speed: float = 0.0):
        self.current = _check_field(current, "current")
        self.rho_water = check_range("rho_water", rho_water, 0.0, None, low_open=True, unit="kg m-3")
        self.drag = check_range("water drag Cw", drag, 0.0, None)
        self.turning_angle_deg = check_range("turning_angle_deg", turning_angle_deg, -90.0, 90.0,
                                             unit="deg")
        self.min_speed = check_range("min_speed", min_speed, 0.0, None, unit="m s-1")
        th = math.radians(self.turning_angle_deg)
        self.cos_turn, self.sin_turn = math.cos(th), math.sin(th)
        self.rotation = np.array([[self.cos_turn, -self.sin_turn], [self.sin_turn, self.cos_turn]])

    def current_at(self, t, nodes) -> np.ndarray:
        if self.current is None:
            return np.zeros((len(nodes), 2))
        return evaluate_vector(self.current, t, nodes, "ocean current")

    def stress(self, t, nodes, vel) -> np.ndarray:
        """τw (n, 2) [N m-2] for ice velocity ``vel`` (n, 2)."""
        rel = self.current_at(t, nodes) - vel
        c = self.rho_water * self.drag * np.hypot(rel[:, 0], rel[:, 1])
        return c[:, None] * (rel @ self.rotation.T)

    def linearise(self, t, nodes, vel, mass_per_area):
        uw = self.current_at(t, nodes)
        rel = uw - vel
        c = self.rho_water * self.drag * np.maximum(np.hypot(rel[:, 0], rel[:, 1]), self.min_speed)
        A = c[:, None, None] * self.rotation[None, :, :]
        b = c[:, None] * (uw @ self.rotation.T)
        return A, b

    def add_explicit_terms(self, t, nodes, terms: ExplicitTerms) -> None:
        if terms.has_drag:
            raise ConfigError("more than one OceanDrag force given; combine them into one")
        terms.has_drag = True
        terms.drag_coef[:] = self.rho_water * self.drag
        terms.current[:] = self.current_at(t, nodes)
        terms.cos_turn, terms.sin_turn = self.cos_turn, self.sin_turn


class Coriolis:
    """Coriolis force −ρi h f k×u [N m-2].

    Args:
        f: Coriolis parameter [s-1] (constant), or
        latitude_deg: f = 2Ω sin(latitude) (constant), or
        crs: the model plane's CRS (pyproj string): f = 2Ω sin(φ) with φ the latitude
            of each node where it is now (exactly one of the three).
    """

    def __init__(self, f: float | None = None, latitude_deg: float | None = None, crs=None):
        if sum(v is not None for v in (f, latitude_deg, crs)) != 1:
            raise ConfigError("Coriolis: give exactly one of f [s-1], latitude_deg [deg] or crs (per-node latitude)")
        self.crs = crs
        self._cache = None
        if crs is not None:
            from .crs import model_crs

            model_crs(crs, "Coriolis crs")
            self.f = None
            return
        if latitude_deg is not None:
            check_range("latitude_deg", latitude_deg, -90.0, 90.0, unit="deg")
            f = coriolis_from_latitude(latitude_deg)
        self.f = check_range("Coriolis f", f, -2e-4, 2e-4, unit="s-1")

    def f_at(self, nodes: np.ndarray):
        """f [s-1] at ``nodes`` (n, 2) [m]: the constant, or 2Ω sin φ per node (cached
        while the nodes do not move)."""
        if self.crs is None:
            return self.f
        c = self._cache
        if c is not None and c[0].shape == nodes.shape and np.array_equal(c[0], nodes):
            return c[1]
        from .crs import latitudes
        from .params import OMEGA_EARTH

        f = 2.0 * OMEGA_EARTH * np.sin(np.deg2rad(latitudes(self.crs, nodes[:, 0], nodes[:, 1])))
        self._cache = (nodes.copy(), f)
        return f

    def linearise(self, t, nodes, vel, mass_per_area):
        mpa = np.broadcast_to(np.asarray(mass_per_area, np.float64), (len(nodes),))
        A = (mpa * self.f_at(nodes))[:, None, None] * ROT90[None, :, :]
        return A, np.zeros((len(nodes), 2))

    def add_explicit_terms(self, t, nodes, terms: ExplicitTerms) -> None:
        terms.coriolis += self.f_at(nodes)


def standard_forces(wind=None, current=None, drag: DragParams | None = None,
                    coriolis_f: float | None = None, latitude_deg: float | None = None):
    """The usual list [WindStress, OceanDrag, Coriolis] from :class:`DragParams`
    (wind omitted when None; Coriolis when neither f nor latitude is given and
    ``drag.coriolis_f`` is 0)."""
    p = drag or DragParams()
    out = []
    if wind is not None:
        out.append(WindStress(wind, rho_air=p.rho_air, drag=p.air_drag))
    out.append(OceanDrag(current, rho_water=p.rho_water, drag=p.water_drag,
                         turning_angle_deg=p.turning_angle_deg, min_speed=p.ocean_drag_min_speed_m_s))
    if latitude_deg is not None:
        out.append(Coriolis(latitude_deg=latitude_deg))
    elif coriolis_f is not None or p.coriolis_f != 0.0:
        out.append(Coriolis(f=p.coriolis_f if coriolis_f is None else coriolis_f))
    return out


def explicit_terms(forces, t: float, nodes: np.ndarray) -> ExplicitTerms:
    """Collect the explicit-kernel data of a list of forces at time t [s]."""
    terms = ExplicitTerms.zeros(len(nodes))
    for f in forces:
        if not hasattr(f, "add_explicit_terms"):
            raise ConfigError(f"force {f!r} has no add_explicit_terms(); the explicit solver "
                              "needs WindStress/OceanDrag/Coriolis-like objects")
        f.add_explicit_terms(t, nodes, terms)
    return terms


def free_drift_velocity(wind_stress, f: float, mass_per_area: float, rho_water: float = RHO_WATER,
                        drag: float = 5.5e-3, turning_angle_deg: float = 0.0) -> complex:
    """Steady free-drift velocity u + iv [m s-1] with the ocean at rest:
    τa − ρw Cw |u| e^{iθ} u − i ρi h f u = 0 (complex form of docs/design.md §3).

    Solved for the speed s = |u| from s |ρw Cw s e^{iθ} + i ρi h f| = |τa|
    (monotone in s), then u = τa / (ρw Cw s e^{iθ} + i ρi h f).
    """
    from scipy.optimize import brentq

    tau = complex(*wind_stress) if not isinstance(wind_stress, complex) else wind_stress
    if tau == 0:
        return 0j
    c = rho_water * drag
    rot = complex(math.cos(math.radians(turning_angle_deg)), math.sin(math.radians(turning_angle_deg)))
    g = lambda s: s * abs(c * s * rot + 1j * mass_per_area * f) - abs(tau)  # noqa: E731
    hi = 1.0
    while g(hi) < 0:
        hi *= 2.0
    s = brentq(g, 0.0, hi, xtol=1e-15, rtol=1e-14)
    return tau / (c * s * rot + 1j * mass_per_area * f)
