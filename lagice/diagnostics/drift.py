"""Ice drift against the wind: the complex wind factor (docs/diagnostics.md §13).

Thorndike and Colony (1982, "Sea ice motion in response to geostrophic winds",
J. Geophys. Res. 87, 5845–5852) fitted daily buoy velocities to the daily
geostrophic wind by least squares in complex form (a vector (u, v) is the number
u + iv):

    U = A G + C

|A| is the *wind factor*, arg A the turning angle of the ice from the geostrophic
wind (counter-clockwise positive, so a negative angle is ice moving to the right
of the wind), C the mean (ocean) current, and the fit's R² the fraction of the
ice-velocity variance the wind explains. It is a measure of how freely the pack
answers the wind that involves no deformation statistic: a pack that is too
strong for its forcing moves at a small fraction of the wind.

Functions work on plain arrays:

- :func:`daily_drift`: velocities over whole days from drifter tracks;
- :func:`track_mean`: the mean of a vector field along each track over the same days;
- :func:`geostrophic_from_surface`: the geostrophic wind of a 10-m wind made from
  it by a surface factor and a cross-isobar turning (the climatology's relation);
- :func:`wind_factor`: the complex regression, as :class:`WindFactor`.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from lagice.errors import ConfigError

DAY_S = 86400.0
#: Thorndike and Colony (1982), Arctic buoys against the geostrophic wind, winter (November–April):
#: |A| about 0.008, the ice about 5° to the right of the wind, R² about 0.7 (values recalled from the
#: literature, not re-read for this work). The band of |A|, ±25 % around 0.008, is ours.
THORNDIKE_COLONY_WINTER = {"factor": (0.006, 0.010), "angle_deg": -5.0, "r2": 0.7}


@dataclass(frozen=True)
class WindFactor:
    """The fit U = A G + C of ice velocities U on winds G (complex numbers)."""

    factor: float  #: |A| [-]
    angle_deg: float  #: arg A [deg], counter-clockwise positive (negative: ice to the right)
    current_m_s: tuple  #: C = (u, v) [m s-1] (0, 0) when fitted without it
    r2: float  #: fraction of the variance of U explained by the fit [-]
    n: int  #: number of (ice velocity, wind) pairs
    speed_ratio: float  #: mean |U| / mean |G| [-]
    mean_ice_speed_m_s: float
    mean_wind_speed_m_s: float

    def as_dict(self) -> dict:
        d = asdict(self)
        d["current_m_s"] = list(self.current_m_s)
        return d


def _check_tracks(times_s, x, y):
    t = np.asarray(times_s, np.float64)
    x = np.asarray(x, np.float64)
    y = np.asarray(y, np.float64)
    if t.ndim != 1 or t.size < 2:
        raise ConfigError(f"times_s: expected a 1-D array of at least 2 times [s], got shape {t.shape}")
    if np.any(np.diff(t) <= 0):
        raise ConfigError("times_s must increase strictly")
    if x.ndim == 1:
        x, y = x[None, :], y[None, :]
    if x.shape != y.shape or x.shape[1] != t.size:
        raise ConfigError(f"x and y: expected shape (n_tracks, {t.size}) matching times_s, got {x.shape} and {y.shape}")
    return t, x, y


def _position_at(t, x, y, tq):
    """Track positions at times ``tq`` (linear in time between samples); NaN outside."""
    out = np.full((x.shape[0], np.size(tq), 2), np.nan)
    inside = (tq >= t[0] - 1e-6) & (tq <= t[-1] + 1e-6)
    tq_in = np.clip(np.asarray(tq)[inside], t[0], t[-1])
    for k in range(x.shape[0]):
        out[k, inside, 0] = np.interp(tq_in, t, x[k])
        out[k, inside, 1] = np.interp(tq_in, t, y[k])
    return out


def day_starts(times_s, day_s: float = DAY_S, start_s: float | None = None) -> np.ndarray:
    """Start times [s] of the whole days ``[t0 + j day_s, t0 + (j + 1) day_s]`` inside ``times_s``."""
    t = np.asarray(times_s, np.float64)
    t0 = float(t[0]) if start_s is None else float(start_s)
    n = int(math.floor((t[-1] - t0) / day_s + 1e-9))
    return t0 + day_s * np.arange(max(n, 0))


def daily_drift(times_s, x, y, lost=None, day_s: float = DAY_S, start_s: float | None = None):
    """Mean velocity of each track over each whole day.

    Parameters
    ----------
    times_s : (k,) sample times [s], strictly increasing
    x, y : (n, k) positions [m] (or (k,) for one track); NaN where a track has no position
    lost : (n,) bool, optional: tracks flagged lost (their days are dropped whole,
        since the loss time is not known)
    day_s : the averaging interval [s] (one day: Thorndike and Colony's daily velocities)

    Returns ``(starts (d,), velocity (n, d, 2) [m s-1], ok (n, d) bool)``: the displacement
    over ``[start, start + day_s]`` divided by ``day_s`` (positions at those times
    interpolated linearly between samples); ``ok`` is False where a day-end position is
    missing or the track is lost. A gap inside a day does not change its displacement.
    """
    t, x, y = _check_tracks(times_s, x, y)
    starts = day_starts(t, day_s, start_s)
    p0 = _position_at(t, x, y, starts)
    p1 = _position_at(t, x, y, starts + day_s)
    vel = (p1 - p0) / day_s
    ok = np.all(np.isfinite(vel), axis=2)
    if lost is not None:
        lost = np.asarray(lost, bool).reshape(-1)
        if lost.size != x.shape[0]:
            raise ConfigError(f"lost: expected {x.shape[0]} flags, got {lost.size}")
        ok &= ~lost[:, None]
    return starts, vel, ok


def track_mean(field, times_s, x, y, starts, day_s: float = DAY_S, every_s: float = 3600.0) -> np.ndarray:
    """Mean of a vector field ``field(t, x, y) -> (u, v)`` along each track over each day.

    The field is sampled at the track positions every ``every_s`` [s] over
    ``[start, start + day_s]`` (both ends included, trapezoidal weights), so the
    mean follows the ice as a buoy's wind would. Returns (n, d, 2); NaN where the
    track has no position.
    """
    t, x, y = _check_tracks(times_s, x, y)
    m = max(1, int(round(day_s / every_s)))
    frac = np.linspace(0.0, 1.0, m + 1)
    w = np.full(m + 1, 1.0 / m)
    w[0] = w[-1] = 0.5 / m
    out = np.zeros((x.shape[0], len(starts), 2))
    for j, s in enumerate(np.asarray(starts, np.float64)):
        tq = s + day_s * frac
        pos = _position_at(t, x, y, tq)
        for i, ti in enumerate(tq):
            px, py = pos[:, i, 0], pos[:, i, 1]
            good = np.isfinite(px)
            val = np.full((x.shape[0], 2), np.nan)
            if np.any(good):
                res = field(float(ti), np.ascontiguousarray(px[good]), np.ascontiguousarray(py[good]))
                val[good, 0] = np.asarray(res[0], np.float64)
                val[good, 1] = np.asarray(res[1], np.float64)
            out[:, j] += w[i] * val
    return out


def geostrophic_from_surface(wind, surface_factor: float, cross_isobar_angle_deg: float) -> np.ndarray:
    """Geostrophic wind G of a 10-m wind U10 = s R(θ) G (s ``surface_factor``, θ the
    counter-clockwise turning towards low pressure): G = R(−θ) U10 / s. ``wind``: (..., 2)."""
    if not surface_factor > 0:
        raise ConfigError(f"surface_factor = {surface_factor!r}: expected > 0")
    w = np.asarray(wind, np.float64)
    th = math.radians(cross_isobar_angle_deg)
    c, s = math.cos(th), math.sin(th)
    g = np.empty_like(w)
    g[..., 0] = (c * w[..., 0] + s * w[..., 1]) / surface_factor
    g[..., 1] = (-s * w[..., 0] + c * w[..., 1]) / surface_factor
    return g


def wind_factor(ice_velocity, wind, with_current: bool = True) -> WindFactor:
    """Least-squares fit U = A G (+ C) of ice velocities on winds, both (..., 2) [m s-1].

    Pairs where either value is not finite are left out (their count is the
    difference between ``n`` and the input size). Raises ConfigError (a ValueError) when
    fewer than three pairs remain or the winds do not vary.
    """
    u = np.asarray(ice_velocity, np.float64).reshape(-1, 2)
    g = np.asarray(wind, np.float64).reshape(-1, 2)
    if u.shape != g.shape:
        raise ConfigError(f"ice_velocity and wind: expected the same shape, got {u.shape} and {g.shape}")
    good = np.all(np.isfinite(u), axis=1) & np.all(np.isfinite(g), axis=1)
    U = u[good, 0] + 1j * u[good, 1]
    G = g[good, 0] + 1j * g[good, 1]
    if U.size < 3:
        raise ConfigError(f"wind_factor: {U.size} valid (velocity, wind) pairs; need at least 3")
    if with_current:
        Gm, Um = G.mean(), U.mean()
        dg = G - Gm
        den = float(np.sum(np.abs(dg) ** 2))
        if den == 0.0:
            raise ConfigError("wind_factor: the wind does not vary; A and C cannot be separated")
        A = np.sum((U - Um) * np.conj(dg)) / den
        C = Um - A * Gm
    else:
        den = float(np.sum(np.abs(G) ** 2))
        if den == 0.0:
            raise ConfigError("wind_factor: all winds are zero")
        A = np.sum(U * np.conj(G)) / den
        C = 0.0 + 0.0j
    res = U - (A * G + C)
    var = float(np.sum(np.abs(U - U.mean()) ** 2))
    r2 = 1.0 - float(np.sum(np.abs(res) ** 2)) / var if var > 0 else float("nan")
    su, sg = float(np.mean(np.abs(U))), float(np.mean(np.abs(G)))
    return WindFactor(factor=float(abs(A)), angle_deg=float(np.degrees(np.angle(A))),
                      current_m_s=(float(C.real), float(C.imag)), r2=r2, n=int(U.size),
                      speed_ratio=su / sg if sg > 0 else float("nan"),
                      mean_ice_speed_m_s=su, mean_wind_speed_m_s=sg)


def run_wind(cfg: dict):
    """A run's wind field ``f(t, x, y) -> (u, v)`` [m s-1] rebuilt from its configuration
    (the scene builder's mesh and :func:`lagice.scenes.components.scene_wind`, the function
    that gave the run its wind), and the kind of wind: ``"geostrophic"`` with the
    climatology's (surface factor, cross-isobar angle), or ``"10 m"`` for other winds."""
    from forcing.climatology import ClimatologyParams
    from lagice.scenes.builder import build_mesh, override_config_of, validate_config
    from lagice.scenes.components import scene_wind
    from lagice.schedule import parse_duration

    cfg = override_config_of({"config": cfg})  # the defaults of keys added since the run
    validate_config(cfg)
    if cfg["forcing"]["wind"] is None:
        raise ConfigError("the run has no wind (forcing.wind is not set): no drift response to measure")
    mesh, _poly = build_mesh(cfg)
    wind = scene_wind(cfg, mesh, parse_duration(cfg["run"]["duration"], "run.duration"))
    wt = cfg["forcing"]["wind"]
    if wt.get("kind") == "climatology":
        p = ClimatologyParams()
        return wind, ("geostrophic", float(wt.get("surface_factor", p.surface_factor)),
                      float(wt.get("cross_isobar_angle_deg", p.cross_isobar_angle_deg)))
    return wind, ("10 m", None, None)


def run_drift_response(run_dir, n_resamples: int = 400) -> dict:
    """The wind factor of the drifters of a finished run (``RUN/drifters.nc``).

    The run's wind is rebuilt from the configuration stored in the drifter file
    (:func:`run_wind`); with the climatology the fit is on the geostrophic wind, as
    Thorndike and Colony's, otherwise on the 10-m wind (``"wind"`` says which). Returns the
    fit with and without a mean current, a 5–95 % range of |A| over ``n_resamples`` draws
    of the drifters with replacement (a drifter's days are not independent), and the daily
    (|G|, |U|) pairs [m s-1].
    """
    import json
    from pathlib import Path

    import xarray as xr

    path = Path(run_dir) / "drifters.nc"
    if not path.exists():
        raise ConfigError(f"{path}: no drifter file (the run needs [drifters] count > 0 or positions_m)")
    with xr.open_dataset(path) as ds:
        if "lagice_config" not in ds.attrs:
            raise ConfigError(f"{path}: no lagice_config attribute; cannot rebuild the run's wind")
        cfg = json.loads(ds.attrs["lagice_config"])
        t = ds["time"].values[0]
        t_s = (t - t[0]) / np.timedelta64(1, "s")
        x, y = ds["x"].values, ds["y"].values
        lost = ds["lost"].values.astype(bool)
    wind, (kind, s, th) = run_wind(cfg)
    starts, vel, ok = daily_drift(t_s, x, y, lost=lost)
    if len(starts) == 0:
        raise ConfigError(f"{path}: the tracks span {t_s[-1] / DAY_S:.2f} days; at least one whole day is needed")
    w = track_mean(wind, t_s, x, y, starts)
    g = geostrophic_from_surface(w, s, th) if kind == "geostrophic" else w
    vel = np.where(ok[..., None], vel, np.nan)
    fit = wind_factor(vel, g)
    fit0 = wind_factor(vel, g, with_current=False)
    rng = np.random.default_rng(0)
    boot = []
    for _ in range(n_resamples):
        k = rng.integers(0, vel.shape[0], vel.shape[0])
        try:
            boot.append(wind_factor(vel[k], g[k]).factor)
        except ConfigError:  # a draw whose days are all flagged out, or one drifter with a constant wind
            continue
    spread = [float(np.percentile(boot, 5)), float(np.percentile(boot, 95))] if boot else None
    good = np.all(np.isfinite(vel), axis=2) & np.all(np.isfinite(g), axis=2)
    pairs = np.column_stack([np.hypot(*g[good].T), np.hypot(*vel[good].T)])
    return {"wind": kind, "surface_factor": s, "cross_isobar_angle_deg": th,
            "drifters": int(x.shape[0]), "lost": int(lost.sum()), "days": int(len(starts)),
            "fit": fit.as_dict(), "fit_without_current": fit0.as_dict(), "factor_5_95_over_drifters": spread,
            "daily_speeds_g_u_m_s": np.round(pairs, 5).tolist()}
