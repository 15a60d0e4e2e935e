"""Synthetic forcing generators (docs/design.md §6).

Every generator returns a :class:`forcing.records.RecordField` whose records
sit on a :class:`forcing.records.RegularGrid` (build one covering the domain's
bounding box with :meth:`RegularGrid.from_bbox`) every ``interval_s``
(default 6 h), so synthetic and file forcing share the same time/space
interpolation.  Random generators are deterministic from ``seed``
(``numpy.random.default_rng(seed)``).

Directions follow the mathematical convention: the direction a vector
points **towards**, in degrees counter-clockwise from +x.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lagice.errors import ConfigError, check_range

from .base import ConstantField
from .records import DAY_S, HOUR_S, InMemoryRecords, RecordField, RegularGrid

DEFAULT_INTERVAL_S = 6.0 * HOUR_S


def record_times(t_end_s, interval_s=DEFAULT_INTERVAL_S, t_start_s=0.0):
    """Record times ``t_start, t_start + Δ, ...`` [s] up to the first one ≥ ``t_end``."""
    check_range("interval_s", interval_s, 0.0, None, low_open=True, unit="s")
    if not t_end_s >= t_start_s:
        raise ConfigError(f"t_end_s = {t_end_s} s is before t_start_s = {t_start_s} s")
    n = int(np.ceil((t_end_s - t_start_s) / interval_s - 1e-9)) + 1
    return t_start_s + interval_s * np.arange(max(n, 2), dtype=np.float64)


def _check_grid(grid):
    if not isinstance(grid, RegularGrid):
        raise ConfigError(f"synthetic forcing needs a RegularGrid; got {type(grid).__name__}")


def _vector_field(grid, times, u, v, name, **field_kw):
    data = np.stack([u, v], axis=1)
    src = InMemoryRecords(times, grid, data, ("u", "v"), units="m s-1", name=name)
    return RecordField(src, **field_kw)


# ----------------------------------------------------------------------------
# uniform winds
# ----------------------------------------------------------------------------
def uniform_wind(grid, t_end_s, *, speed_m_s=10.0, direction_deg=90.0, ramp_s=6.0 * HOUR_S,
                 turn_deg=90.0, turn_start_s=6.0 * HOUR_S, turn_duration_s=DAY_S,
                 interval_s=DEFAULT_INTERVAL_S, **field_kw):
    """Spatially uniform wind with a speed ramp and a direction schedule.

    speed(t) = ``speed_m_s`` · min(1, t / ``ramp_s``) (ramp from 0);
    direction(t) = ``direction_deg`` + ``turn_deg`` · clip((t − ``turn_start_s``)
    / ``turn_duration_s``, 0, 1).  Defaults: ramp up to 10 m s-1 over 6 h
    blowing towards +y, then turn by 90° (counter-clockwise) over one day.

    Returns a vector :class:`RecordField` [m s-1].
    """
    _check_grid(grid)
    check_range("speed_m_s", speed_m_s, 0.0, 150.0, unit="m s-1")
    check_range("ramp_s", ramp_s, 0.0, None, unit="s")
    check_range("turn_duration_s", turn_duration_s, 0.0, None, unit="s")
    times = record_times(t_end_s, interval_s)
    speed = speed_m_s * (np.minimum(1.0, times / ramp_s) if ramp_s > 0 else np.ones_like(times))
    frac = (np.clip((times - turn_start_s) / turn_duration_s, 0.0, 1.0) if turn_duration_s > 0
            else (times >= turn_start_s).astype(float))
    ang = np.deg2rad(direction_deg + turn_deg * frac)
    shape = (times.size,) + grid.shape
    u = np.broadcast_to((speed * np.cos(ang))[:, None, None], shape)
    v = np.broadcast_to((speed * np.sin(ang))[:, None, None], shape)
    return _vector_field(grid, times, u, v, "<synthetic uniform wind>", **field_kw)


def random_wind(grid, t_end_s, *, seed, mean_speed_m_s=8.0, speed_std_m_s=3.0,
                interval_s=DEFAULT_INTERVAL_S, **field_kw):
    """Spatially uniform wind drawn anew every ``interval_s``: direction
    uniform in [0, 360)°, speed |N(mean, std)| [m s-1]; linear in time
    between records.  Deterministic from ``seed``."""
    _check_grid(grid)
    check_range("mean_speed_m_s", mean_speed_m_s, 0.0, 150.0, unit="m s-1")
    check_range("speed_std_m_s", speed_std_m_s, 0.0, 150.0, unit="m s-1")
    times = record_times(t_end_s, interval_s)
    rng = np.random.default_rng(seed)
    ang = rng.uniform(0.0, 2.0 * np.pi, times.size)
    speed = np.abs(rng.normal(mean_speed_m_s, speed_std_m_s, times.size))
    shape = (times.size,) + grid.shape
    u = np.broadcast_to((speed * np.cos(ang))[:, None, None], shape)
    v = np.broadcast_to((speed * np.sin(ang))[:, None, None], shape)
    return _vector_field(grid, times, u, v, f"<synthetic random wind seed={seed}>", **field_kw)


# ----------------------------------------------------------------------------
# cyclones
# ----------------------------------------------------------------------------
@dataclass(frozen=True)
class Cyclone:
    """A parametric moving cyclone (or anticyclone), northern hemisphere.

    Attributes
    ----------
    x0_m, y0_m : centre at ``t_start_s`` [m]
    velocity_m_s : (vx, vy) translation velocity of the centre (straight track) [m s-1]
    radius_m : radius of maximum wind R [m]
    max_speed_m_s : maximum wind speed at full strength [m s-1]
    inflow_angle_deg : angle between the wind and the circle around the
        centre, towards the centre for a cyclone, outwards for an anticyclone [deg]
    t_start_s : birth time [s]; lifetime_s : life span [s]
    anticyclone : False (counter-clockwise, convergent) or True (clockwise, divergent)

    Wind speed profile ``V(r) = Vmax (r/R) exp(1 − r/R)`` (zero at the centre,
    maximum at R), times the life envelope ``sin²(π s)``,
    ``s = (t − t_start)/lifetime`` in [0, 1] (zero outside).
    """

    x0_m: float
    y0_m: float
    velocity_m_s: tuple = (0.0, 0.0)
    radius_m: float = 300e3
    max_speed_m_s: float = 15.0
    inflow_angle_deg: float = 20.0
    t_start_s: float = 0.0
    lifetime_s: float = 3.0 * DAY_S
    anticyclone: bool = False

    def __post_init__(self):
        check_range("radius_m", self.radius_m, 0.0, None, low_open=True, unit="m")
        check_range("max_speed_m_s", self.max_speed_m_s, 0.0, 150.0, unit="m s-1")
        check_range("inflow_angle_deg", self.inflow_angle_deg, -90.0, 90.0, unit="deg")
        check_range("lifetime_s", self.lifetime_s, 0.0, None, low_open=True, unit="s")

    def centre(self, t_s):
        """Centre position [m] at time(s) ``t_s``."""
        t = np.asarray(t_s, dtype=np.float64) - self.t_start_s
        return self.x0_m + self.velocity_m_s[0] * t, self.y0_m + self.velocity_m_s[1] * t

    def wind(self, t_s, x, y):
        """Wind ``(u, v)`` [m s-1] at time ``t_s`` [s] (scalar) and points ``x, y`` [m]."""
        s = (t_s - self.t_start_s) / self.lifetime_s
        amp = np.sin(np.pi * s) ** 2 if 0.0 <= s <= 1.0 else 0.0
        cx, cy = self.centre(t_s)
        dx = x - cx
        dy = y - cy
        r = np.hypot(dx, dy)
        rr = r / self.radius_m
        speed = amp * self.max_speed_m_s * rr * np.exp(1.0 - rr)
        with np.errstate(invalid="ignore", divide="ignore"):
            er_x = np.where(r > 0, dx / r, 0.0)
            er_y = np.where(r > 0, dy / r, 0.0)
        # counter-clockwise tangent e_θ = (−e_r,y, e_r,x)
        a = np.deg2rad(self.inflow_angle_deg)
        sense = -1.0 if self.anticyclone else 1.0
        ca, sa = np.cos(a), np.sin(a)
        u = speed * sense * (ca * -er_y - sa * er_x)
        v = speed * sense * (ca * er_x - sa * er_y)
        return u, v


def random_cyclones(bbox, t_end_s, n, *, seed, radius_range_m=(150e3, 500e3),
                    max_speed_range_m_s=(8.0, 20.0), translation_speed_max_m_s=8.0,
                    lifetime_range_s=(1.0 * DAY_S, 4.0 * DAY_S), inflow_angle_deg=20.0,
                    anticyclone_fraction=0.3):
    """``n`` random :class:`Cyclone` objects over ``bbox = (xmin, xmax, ymin, ymax)`` [m]
    born uniformly in ``[0, t_end_s]``; deterministic from ``seed``."""
    if int(n) < 0:
        raise ConfigError(f"number of cyclones n = {n!r} must be >= 0")
    xmin, xmax, ymin, ymax = bbox
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(int(n)):
        ang = rng.uniform(0.0, 2.0 * np.pi)
        sp = rng.uniform(0.0, translation_speed_max_m_s)
        out.append(Cyclone(
            x0_m=float(rng.uniform(xmin, xmax)), y0_m=float(rng.uniform(ymin, ymax)),
            velocity_m_s=(float(sp * np.cos(ang)), float(sp * np.sin(ang))),
            radius_m=float(rng.uniform(*radius_range_m)),
            max_speed_m_s=float(rng.uniform(*max_speed_range_m_s)),
            inflow_angle_deg=float(inflow_angle_deg),
            t_start_s=float(rng.uniform(0.0, t_end_s)) if t_end_s > 0 else 0.0,
            lifetime_s=float(rng.uniform(*lifetime_range_s)),
            anticyclone=bool(rng.uniform() < anticyclone_fraction)))
    return out


def cyclone_wind(grid, t_end_s, cyclones, *, background_m_s=(0.0, 0.0),
                 interval_s=DEFAULT_INTERVAL_S, **field_kw):
    """Wind of one or several :class:`Cyclone` (superposed) plus a uniform
    background [m s-1], sampled as records every ``interval_s``."""
    _check_grid(grid)
    if isinstance(cyclones, Cyclone):
        cyclones = [cyclones]
    times = record_times(t_end_s, interval_s)
    X, Y = grid.mesh()
    shape = (times.size,) + grid.shape
    u = np.full(shape, float(background_m_s[0]))
    v = np.full(shape, float(background_m_s[1]))
    for k, t in enumerate(times):
        for c in cyclones:
            cu, cv = c.wind(t, X, Y)
            u[k] += cu
            v[k] += cv
    return _vector_field(grid, times, u, v, f"<synthetic cyclone wind ({len(cyclones)} systems)>",
                         **field_kw)


# ----------------------------------------------------------------------------
# ocean currents
# ----------------------------------------------------------------------------
def ocean_at_rest():
    """Ocean at rest: a constant zero vector field (no records, no work)."""
    return ConstantField((0.0, 0.0), units="m s-1")


def uniform_current(grid, u_m_s, v_m_s, **field_kw):
    """Steady uniform current ``(u, v)`` [m s-1] as a single steady record."""
    _check_grid(grid)
    shape = (1,) + grid.shape
    return _vector_field(grid, np.zeros(1), np.full(shape, float(u_m_s)), np.full(shape, float(v_m_s)),
                         "<synthetic uniform current>", **field_kw)


def gyre_current(grid, max_speed_m_s=0.1, *, bbox=None, clockwise=True, **field_kw):
    """Steady single gyre filling ``bbox`` (default the grid extent) [m s-1].

    Stream function ψ = ψ0 sin(πξ) sin(πη) with ξ, η ∈ [0, 1] across the box,
    u = −∂ψ/∂y, v = ∂ψ/∂x (non-divergent); ψ0 = Umax·min(Lx, Ly)/π so the
    maximum speed is ``max_speed_m_s``; zero outside the box; clockwise
    (Beaufort-like, anticyclonic) by default.
    """
    _check_grid(grid)
    check_range("max_speed_m_s", max_speed_m_s, 0.0, 20.0, unit="m s-1")
    if bbox is None:
        bbox = (grid.x_m[0], grid.x_m[-1], grid.y_m[0], grid.y_m[-1])
    xmin, xmax, ymin, ymax = bbox
    lx, ly = xmax - xmin, ymax - ymin
    if not (lx > 0 and ly > 0):
        raise ConfigError(f"gyre bbox {bbox} is empty")
    psi0 = max_speed_m_s * min(lx, ly) / np.pi * (1.0 if clockwise else -1.0)
    X, Y = grid.mesh()
    xi = (X - xmin) / lx
    eta = (Y - ymin) / ly
    inside = (xi >= 0) & (xi <= 1) & (eta >= 0) & (eta <= 1)
    u = np.where(inside, -psi0 * np.pi / ly * np.sin(np.pi * xi) * np.cos(np.pi * eta), 0.0)
    v = np.where(inside, psi0 * np.pi / lx * np.cos(np.pi * xi) * np.sin(np.pi * eta), 0.0)
    return _vector_field(grid, np.zeros(1), u[None], v[None], "<synthetic gyre current>", **field_kw)


def check_eddy_resolution(radius_m, spacing_m, key="eddy radius_m"):
    """ConfigError unless an eddy of ``radius_m`` spans at least three record spacings."""
    if radius_m < 3.0 * spacing_m:
        raise ConfigError(f"{key} = {radius_m:g} m spans fewer than three forcing grid spacings "
                          f"({spacing_m:g} m): the eddies would not be resolved by the records (lower "
                          f"forcing.grid_spacing_m or raise radius_m)")


def eddy_current(grid, eddy_speed_m_s=0.05, radius_m=30e3, *, spacing_radii=4.0, seed=0, bbox=None,
                 **field_kw):
    """Steady field of ocean eddies of both senses [m s-1], deterministic from ``seed``.

    Stream function ψ = Σᵢ sᵢ ψ0 exp(−|x − xᵢ|²/(2R²)), u = −∂ψ/∂y, v = ∂ψ/∂x
    (non-divergent; computed analytically at the grid points). Centres xᵢ are uniform
    random in ``bbox`` (default the grid extent), one per (``spacing_radii`` R)² of area,
    senses sᵢ = ±1 at random (cyclonic and anticyclonic alike). ψ0 = U R e^(1/2) with
    U = ``eddy_speed_m_s``, so that one isolated eddy's largest speed (at r = R) is U;
    where eddies overlap the field can be faster (the record's name gives its largest
    speed).
    A stand-in for the mesoscale and sub-mesoscale variability of the surface current
    under the ice, whose curl varies on scales of tens of km; ``radius_m`` must span at
    least three grid spacings.
    """
    _check_grid(grid)
    check_range("eddy_speed_m_s", eddy_speed_m_s, 0.0, 2.0, unit="m s-1")
    check_range("radius_m", radius_m, 0.0, None, low_open=True, unit="m")
    check_range("spacing_radii", spacing_radii, 1.0, 100.0, unit="eddy radii")
    check_eddy_resolution(radius_m, min(abs(grid.x_m[1] - grid.x_m[0]), abs(grid.y_m[1] - grid.y_m[0])))
    if bbox is None:
        bbox = (grid.x_m[0], grid.x_m[-1], grid.y_m[0], grid.y_m[-1])
    xmin, xmax, ymin, ymax = bbox
    area = (xmax - xmin) * (ymax - ymin)
    if not area > 0:
        raise ConfigError(f"eddy bbox {bbox} is empty")
    rng = np.random.default_rng(seed)
    n = max(1, int(round(area / (spacing_radii * radius_m) ** 2)))
    xc = rng.uniform(xmin, xmax, n)
    yc = rng.uniform(ymin, ymax, n)
    sense = rng.choice([-1.0, 1.0], n)
    X, Y = grid.mesh()
    u = np.zeros_like(X, dtype=np.float64)
    v = np.zeros_like(X, dtype=np.float64)
    # u = −∂ψ/∂y = s ψ0 (y − yᵢ)/R² exp(...), v = ∂ψ/∂x = −s ψ0 (x − xᵢ)/R² exp(...)
    amp = eddy_speed_m_s * np.exp(0.5)
    for i in range(n):  # one pass per eddy over the grid (set-up only, not per step)
        rx, ry = X - xc[i], Y - yc[i]
        g = sense[i] * amp * np.exp(-(rx * rx + ry * ry) / (2.0 * radius_m * radius_m))
        u += (ry / radius_m) * g
        v -= (rx / radius_m) * g
    top = float(np.hypot(u, v).max())
    name = (f"<synthetic eddy current: {n} eddies, R = {radius_m / 1e3:g} km, {eddy_speed_m_s:g} m/s each, "
            f"largest speed {top:.3f} m/s, seed {seed}>")
    return _vector_field(grid, np.zeros(1), u[None], v[None], name, **field_kw)
