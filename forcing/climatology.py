"""Synthetic winter wind climatology: 6-hourly 10-m winds with Arctic winter statistics.

The targets (mean speed, variability, synoptic time scale, spatial decorrelation
length, cyclone frequency, intensity, size, tracks, extremes) and their sources
are in ``docs/physics.md`` (section "Wind climatology"); ``TARGETS`` below holds
the bands that ``benchmarks/wind_climatology.py`` prints and
``tests/test_wind_climatology.py`` checks.

The wind is the surface wind of a sea-level pressure field made of two parts:

1. **background weather**: a stationary, isotropic Gaussian random field p_b with
   a Gaussian covariance of length ``correlation_length_m`` (Thorndike 1982 treats
   the Arctic surface pressure as such a field), built from ``n_modes`` random
   Fourier modes (wave vectors k_j ~ N(0, I/L²), the spectral density of that
   covariance). Each mode carries two amplitudes that follow independent
   random processes, and the whole
   pattern is carried by a uniform ``steering_m_s`` flow (the amplitudes are smooth
   AR(2) processes whose correlation falls to 1/e after ``decorrelation_time_s``):
   ``p_b = Σ_j a_j(t) cos(k_j·(x − c t)) + b_j(t) sin(k_j·(x − c t))``;
2. **cyclones**: a Poisson process of moving Gaussian lows
   ``p_c = −Δp env(t) exp(−|x − x_c(t)|²/(2R²))``, born at ``cyclone_rate`` per
   10⁶ km² per day uniformly over the domain and a margin around it (so they also
   enter from outside), moving on straight tracks at the steering flow plus a
   random velocity, with a ``sin²`` life envelope; depth Δp (gamma distributed),
   radius R (log-normal, clipped) and lifetime (gamma, clipped) are drawn per system.

The 10-m wind is the geostrophic wind of p = p_b + p_c, reduced by
``surface_factor`` and turned by ``cross_isobar_angle_deg`` towards low pressure
(counter-clockwise in the northern hemisphere), plus a uniform ``mean_wind_m_s``:
``U10 = mean + s R(θ) k×∇p/(ρa f)``. Everything is linear in p, so the wind is
evaluated analytically on the record grid (no finite differences).

Any run length, one climate: record k of the background uses random numbers drawn
from ``SeedSequence([seed, 1, k])`` and the cyclones born on day j from
``SeedSequence([seed, 2, j])``; a 5-day run is therefore exactly the first 5 days
of the 28-day run with the same seed (``tests/test_wind_climatology.py`` checks
it), never a squeezed storm schedule. Deterministic from ``seed``.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields

import numpy as np

from lagice.errors import ConfigError, check_range

from .records import DAY_S, HOUR_S, InMemoryRecords, RecordField, RegularGrid

#: Coriolis: Earth's rotation rate [rad s-1]
OMEGA_EARTH = 7.2921e-5
#: air density for the geostrophic wind [kg m-3] (the value lagice's wind stress uses)
RHO_AIR = 1.3
#: shapes of the background spectrum (:attr:`ClimatologyParams.background_spectrum`)
BACKGROUND_SPECTRA = ("exponential", "gaussian")


@dataclass(frozen=True)
class ClimatologyParams:
    """Parameters of :func:`climatology_wind` (units in the names; sources and the
    calibration of each value in ``docs/physics.md``)."""

    #: standard deviation of each 10-m wind component of the background weather [m s-1]
    background_wind_std_m_s: float = 4.2
    #: e-folding length of the background covariance [m]: of the surface pressure for
    #: the ``"gaussian"`` spectrum, of the 10-m wind for the ``"exponential"`` one
    correlation_length_m: float = 1000e3
    #: shape of the background spectrum: ``"exponential"`` (wind covariance
    #: exp(-r/L), kinetic-energy spectrum ~ k^-2 above 1/L, the slope of scatterometer
    #: surface-wind spectra) or ``"gaussian"`` (pressure covariance exp(-r^2/2L^2),
    #: almost no energy at wavelengths below a few hundred km; the first version)
    background_spectrum: str = "exponential"
    #: shortest wavelength of the background modes [m] (``"exponential"`` only): about
    #: the effective resolution of a reanalysis wind like ERA5's, whose drag the scenes use
    shortest_wavelength_m: float = 100e3
    #: e-folding time of the correlation of the background mode amplitudes [s]
    decorrelation_time_s: float = 3.0 * DAY_S
    #: uniform flow carrying the background pattern and steering the cyclones [m s-1]
    steering_m_s: tuple = (5.0, 0.0)
    #: climatological mean 10-m wind added everywhere [m s-1]
    mean_wind_m_s: tuple = (0.0, 0.0)
    #: cyclone births per 10^6 km² per day (over the domain and its margin)
    cyclone_rate_per_mkm2_day: float = 0.08
    #: mean and shape of the gamma distribution of the cyclone depth Δp [hPa]
    cyclone_depth_mean_hpa: float = 20.0
    cyclone_depth_shape: float = 4.0
    #: largest cyclone depth [hPa] (deeper draws are clipped; counted in the statistics)
    cyclone_depth_max_hpa: float = 50.0
    #: median radius R of a cyclone of mean depth [m]; R scales as sqrt(Δp / mean depth)
    #: (deeper systems are larger) times a log-normal factor of log-std
    #: ``cyclone_radius_log_std``, clipped to ``cyclone_radius_range_m``
    cyclone_radius_median_m: float = 450e3
    cyclone_radius_log_std: float = 0.2
    cyclone_radius_range_m: tuple = (300e3, 900e3)
    #: mean and range of the cyclone lifetime [s] (gamma, shape 3)
    cyclone_lifetime_mean_s: float = 3.5 * DAY_S
    cyclone_lifetime_range_s: tuple = (1.0 * DAY_S, 10.0 * DAY_S)
    #: standard deviation of each component of the cyclone velocity about the steering flow [m s-1]
    cyclone_speed_std_m_s: float = 3.0
    #: 10-m wind / geostrophic wind over sea ice [-] and the cross-isobar turning [deg]
    surface_factor: float = 0.7
    cross_isobar_angle_deg: float = 25.0
    #: latitude giving the Coriolis parameter of the geostrophic wind [deg N]
    latitude_deg: float = 80.0
    #: number of random Fourier modes of the background field
    n_modes: int = 256
    #: factor on the whole 10-m wind (sensitivity runs; 1 = the climatology)
    wind_scale: float = 1.0

    def __post_init__(self):
        c = check_range
        c("background_wind_std_m_s", self.background_wind_std_m_s, 0.0, 15.0, unit="m s-1")
        c("correlation_length_m", self.correlation_length_m, 100e3, 5000e3, unit="m")
        if self.background_spectrum not in BACKGROUND_SPECTRA:
            raise ConfigError(f"background_spectrum = {self.background_spectrum!r}: expected one of "
                              f"{list(BACKGROUND_SPECTRA)}")
        c("shortest_wavelength_m", self.shortest_wavelength_m, 10e3, 1000e3, unit="m")
        c("decorrelation_time_s", self.decorrelation_time_s, 6 * HOUR_S, 30 * DAY_S, unit="s")
        for name in ("steering_m_s", "mean_wind_m_s"):
            v = getattr(self, name)
            if not (isinstance(v, (tuple, list)) and len(v) == 2):
                raise ConfigError(f"{name} = {v!r}: expected a pair [u, v] in m s-1")
            for comp, x in zip("uv", v):
                c(f"{name} ({comp})", x, -30.0, 30.0, unit="m s-1")
        c("cyclone_rate_per_mkm2_day", self.cyclone_rate_per_mkm2_day, 0.0, 2.0, unit="per 10^6 km2 per day")
        c("cyclone_depth_mean_hpa", self.cyclone_depth_mean_hpa, 0.0, 60.0, low_open=True, unit="hPa")
        c("cyclone_depth_shape", self.cyclone_depth_shape, 0.5, 50.0)
        c("cyclone_depth_max_hpa", self.cyclone_depth_max_hpa, self.cyclone_depth_mean_hpa, 100.0, unit="hPa")
        c("cyclone_radius_median_m", self.cyclone_radius_median_m, 50e3, 3000e3, unit="m")
        c("cyclone_radius_log_std", self.cyclone_radius_log_std, 0.0, 2.0)
        _range_pair("cyclone_radius_range_m", self.cyclone_radius_range_m, 50e3, 3000e3, "m")
        c("cyclone_lifetime_mean_s", self.cyclone_lifetime_mean_s, 6 * HOUR_S, 30 * DAY_S, unit="s")
        _range_pair("cyclone_lifetime_range_s", self.cyclone_lifetime_range_s, 3 * HOUR_S, 60 * DAY_S, "s")
        c("cyclone_speed_std_m_s", self.cyclone_speed_std_m_s, 0.0, 20.0, unit="m s-1")
        c("surface_factor", self.surface_factor, 0.0, 1.0, low_open=True)
        c("cross_isobar_angle_deg", self.cross_isobar_angle_deg, 0.0, 60.0, unit="deg")
        c("latitude_deg", self.latitude_deg, 30.0, 90.0, unit="deg")
        if int(self.n_modes) != self.n_modes:
            raise ConfigError(f"n_modes = {self.n_modes!r}: expected an integer in [16, 4096]")
        c("n_modes", self.n_modes, 16, 4096)
        c("wind_scale", self.wind_scale, 0.0, 3.0)

    @property
    def coriolis_s(self) -> float:
        return 2.0 * OMEGA_EARTH * math.sin(math.radians(self.latitude_deg))

    def as_dict(self) -> dict:
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items()}


def _range_pair(name, v, lo, hi, unit):
    if not (isinstance(v, (tuple, list)) and len(v) == 2):
        raise ConfigError(f"{name} = {v!r}: expected a pair [min, max] in {unit}")
    check_range(f"{name} (min)", v[0], lo, hi, unit=unit)
    check_range(f"{name} (max)", v[1], v[0], hi, unit=unit)


def make_params(**kw) -> ClimatologyParams:
    """:class:`ClimatologyParams` from keyword arguments; unknown keys are errors
    naming the key and the known ones (scene tables come here)."""
    names = {f.name for f in fields(ClimatologyParams)}
    for k in kw:
        if k not in names:
            raise ConfigError(f"unknown wind climatology parameter {k!r}; known: {sorted(names)}")
    kw = {k: (tuple(v) if isinstance(v, list) else v) for k, v in kw.items()}
    return ClimatologyParams(**kw)


@dataclass
class CycloneTrack:
    """One synthetic cyclone: birth position [m] and time [s], velocity [m s-1],
    depth [hPa], radius [m], lifetime [s]."""

    x0_m: float
    y0_m: float
    t0_s: float
    u_m_s: float
    v_m_s: float
    depth_hpa: float
    radius_m: float
    lifetime_s: float

    def centre(self, t_s):
        dt = np.asarray(t_s, np.float64) - self.t0_s
        return self.x0_m + self.u_m_s * dt, self.y0_m + self.v_m_s * dt

    def envelope(self, t_s):
        s = (np.asarray(t_s, np.float64) - self.t0_s) / self.lifetime_s
        return np.where((s >= 0.0) & (s <= 1.0), np.sin(np.pi * np.clip(s, 0.0, 1.0)) ** 2, 0.0)

    def max_surface_wind_m_s(self, p: ClimatologyParams) -> float:
        """Largest 10-m wind of the isolated system at full strength [m s-1]:
        s Δp e^(−1/2) / (ρa f R) (at r = R)."""
        return p.surface_factor * self.depth_hpa * 100.0 * math.exp(-0.5) / (RHO_AIR * p.coriolis_s * self.radius_m)


@dataclass
class ClimatologyWind:
    """The generated records and what made them (for statistics and plots)."""

    field: RecordField
    times_s: np.ndarray
    grid: RegularGrid
    u: np.ndarray          # (nt, ny, nx) [m s-1]
    v: np.ndarray
    params: ClimatologyParams
    cyclones: list = field(default_factory=list)
    domain_bbox: tuple = (0.0, 0.0, 0.0, 0.0)
    seed: int = 0


def _rng(seed, stream, index):
    # index may be negative (cyclones born before t = 0): shift it into the non-negative integers
    return np.random.default_rng(np.random.SeedSequence([int(seed) & 0xFFFFFFFF, stream, int(index) + (1 << 30)]))


def _modes(p: ClimatologyParams, seed):
    """Wave vectors (n, 2) [m-1] of the background modes.

    * ``"gaussian"``: k ~ N(0, I/L²), the spectral density of the pressure covariance
      exp(−r²/(2L²)).
    * ``"exponential"``: k from the 2-D Cauchy law (the bivariate Student t with one
      degree of freedom and scale 1/L: k = z / (L sqrt(w)), z ~ N(0, I), w ~ χ²₁),
      whose characteristic function is exp(−|r|/L); modes with a wavelength shorter
      than ``shortest_wavelength_m`` are drawn again (about 2 % at L = 1000 km and
      100 km). With equal wind variance per mode (:func:`_pressure_amplitudes`) the
      wind covariance is exp(−r/L) (truncated) and its kinetic-energy spectrum falls
      as k⁻² at wavelengths below 2πL.
    """
    rng = _rng(seed, 0, 0)
    n = int(p.n_modes)
    L = p.correlation_length_m
    if p.background_spectrum == "gaussian":
        return rng.normal(0.0, 1.0 / L, size=(n, 2))
    kmax = 2.0 * math.pi / p.shortest_wavelength_m
    k = np.empty((0, 2))
    while k.shape[0] < n:
        z = rng.standard_normal((n, 2))
        w = rng.chisquare(1.0, n)
        kk = z / (L * np.sqrt(w))[:, None]
        k = np.concatenate([k, kk[np.hypot(kk[:, 0], kk[:, 1]) <= kmax]])
    return k[:n]


def _pressure_amplitudes(p: ClimatologyParams, k):
    """Standard deviation (n,) [Pa] of the two pressure amplitudes of each background
    mode, such that each 10-m wind component has the standard deviation
    ``background_wind_std_m_s``: the same for every mode with the gaussian spectrum,
    ∝ 1/|k_j| (the same wind variance per mode) with the exponential one."""
    n = k.shape[0]
    scale = p.background_wind_std_m_s * RHO_AIR * p.coriolis_s / p.surface_factor
    if p.background_spectrum == "gaussian":
        ksq = float(np.sum(k * k)) / 2.0  # Σ k_x² ≈ Σ k_y²
        return np.full(n, scale / math.sqrt(ksq) if ksq > 0 else 0.0)
    # var(u) = (s/ρf)² Σ_j σ_j² |k_j|² / 2 = σw²  with  σ_j = c/|k_j|,  c = σw (ρf/s) sqrt(2/n)
    return scale * math.sqrt(2.0 / n) / np.hypot(k[:, 0], k[:, 1])


#: e-folding time of the correlation (1 + s) e^(−s) of the amplitudes, in units of the
#: AR(2) time scale: (1 + s) e^(−s) = e^(−1) at s = 2.1462
_EFOLD_AR2 = 2.1461932206


def _background_amplitudes(p: ClimatologyParams, seed, times_s, interval_s):
    """Amplitudes (a, b) (nt, n) [Pa] of the background modes at ``times_s``
    (multiples of interval_s from 0).

    Each amplitude is a critically damped AR(2) process (the sampled form of two
    Ornstein–Uhlenbeck filters in series): x_k = 2φ x_{k−1} − φ² x_{k−2} + e_k,
    φ = exp(−Δ/τ), τ = ``decorrelation_time_s`` / 2.146, whose autocorrelation
    (1 + t/τ) e^(−t/τ) falls to 1/e at ``decorrelation_time_s`` and is smooth at
    lag 0 (a single OU process would change the wind by ~40 % of its standard
    deviation every 6 h; weather does not). Record k uses fresh normals from
    SeedSequence([seed, 1, k]); records −1 and 0 are a stationary draw. The pressure
    amplitude σa is set so that each 10-m wind component has the standard
    deviation ``background_wind_std_m_s``."""
    k = _modes(p, seed)
    n = k.shape[0]
    sigma_a = _pressure_amplitudes(p, k)  # (n,): equal (gaussian) or ∝ 1/|k| (exponential)
    phi = math.exp(-interval_s * _EFOLD_AR2 / p.decorrelation_time_s)
    a1, a2 = 2.0 * phi, -phi * phi
    # innovation std giving the stationary variance σa²: var = (1 + φ²) σe² / (1 − φ²)³
    sig_e = sigma_a * math.sqrt((1.0 - phi * phi) ** 3 / (1.0 + phi * phi))
    rho1 = a1 / (1.0 - a2)  # lag-1 autocorrelation of the stationary process
    idx = np.rint(np.asarray(times_s) / interval_s).astype(np.int64)
    if np.any(np.abs(idx * interval_s - np.asarray(times_s)) > 1e-6 * interval_s) or idx.min() < 0:
        raise ConfigError("climatology records must lie on multiples of interval_s from t = 0")
    kmax = int(idx.max())
    x = np.empty((kmax + 2, 2, n))  # x[j + 1] is record j; x[0] is record −1
    z = _rng(seed, 1, 0).standard_normal((2, 2, n))
    x[0] = sigma_a * z[0]
    x[1] = sigma_a * (rho1 * z[0] + math.sqrt(1.0 - rho1 * rho1) * z[1])
    for j in range(1, kmax + 1):  # over records (a few hundred), not grid points
        x[j + 1] = a1 * x[j] + a2 * x[j - 1] + sig_e * _rng(seed, 1, j).standard_normal((2, n))
    x = x[idx + 1]
    return k, x[:, 0], x[:, 1], sigma_a


def draw_cyclones(p: ClimatologyParams, seed, bbox, t_start_s, t_end_s) -> list:
    """Cyclones alive at some time in [t_start, t_end] [s] near ``bbox`` (xmin, xmax,
    ymin, ymax) [m]. Births of day j (from day floor((t_start − max lifetime)/1 d))
    come from SeedSequence([seed, 2, j]) over a fixed region around the box
    ``bbox`` expanded by the largest travel distance, so a longer run only
    adds systems, it never changes the earlier ones."""
    xmin, xmax, ymin, ymax = bbox
    lmax = p.cyclone_lifetime_range_s[1]
    smax = math.hypot(*p.steering_m_s) + 3.0 * p.cyclone_speed_std_m_s
    margin = smax * lmax + 2.0 * p.cyclone_radius_range_m[1]
    # birth region: snapped to a 500 km lattice so that nearby domains share it
    cell = 500e3
    bx0 = math.floor((xmin - margin) / cell) * cell
    bx1 = math.ceil((xmax + margin) / cell) * cell
    by0 = math.floor((ymin - margin) / cell) * cell
    by1 = math.ceil((ymax + margin) / cell) * cell
    area_mkm2 = (bx1 - bx0) * (by1 - by0) / 1e12
    lam = p.cyclone_rate_per_mkm2_day * area_mkm2  # births per day
    out = []
    j0 = math.floor((t_start_s - lmax) / DAY_S)
    j1 = math.floor(t_end_s / DAY_S)
    kshape = 3.0
    for j in range(j0, j1 + 1):
        rng = _rng(seed, 2, j)
        nb = rng.poisson(lam)
        if nb == 0:
            continue
        t0 = (j + rng.uniform(0.0, 1.0, nb)) * DAY_S
        x0 = rng.uniform(bx0, bx1, nb)
        y0 = rng.uniform(by0, by1, nb)
        uv = rng.normal(0.0, p.cyclone_speed_std_m_s, (nb, 2)) + np.asarray(p.steering_m_s, float)
        depth = np.minimum(rng.gamma(p.cyclone_depth_shape, p.cyclone_depth_mean_hpa / p.cyclone_depth_shape, nb),
                           p.cyclone_depth_max_hpa)
        rad = np.clip(p.cyclone_radius_median_m * np.sqrt(depth / p.cyclone_depth_mean_hpa)
                      * np.exp(p.cyclone_radius_log_std * rng.standard_normal(nb)), *p.cyclone_radius_range_m)
        life = np.clip(rng.gamma(kshape, p.cyclone_lifetime_mean_s / kshape, nb), *p.cyclone_lifetime_range_s)
        for i in range(nb):
            c = CycloneTrack(float(x0[i]), float(y0[i]), float(t0[i]), float(uv[i, 0]), float(uv[i, 1]),
                             float(depth[i]), float(rad[i]), float(life[i]))
            if c.t0_s + c.lifetime_s < t_start_s or c.t0_s > t_end_s:
                continue
            # keep systems whose track (whole life, so that the choice does not depend on
            # the run length) comes within 4R of the box: farther ones change the wind in
            # the box by < 0.3 % of their peak (r/R e^(−r²/2R²) at r = 4R)
            tt = np.linspace(c.t0_s, c.t0_s + c.lifetime_s, 48)
            cx, cy = c.centre(tt)
            dx = np.maximum(np.maximum(xmin - cx, cx - xmax), 0.0)
            dy = np.maximum(np.maximum(ymin - cy, cy - ymax), 0.0)
            if np.min(np.hypot(dx, dy)) <= 4.0 * c.radius_m:
                out.append(c)
    return out


def _rotate(p: ClimatologyParams):
    """Matrix s R(θ) k×(·)/(ρa f) taking ∇p (Pa m-1) to the 10-m wind [m s-1]."""
    th = math.radians(p.cross_isobar_angle_deg)
    rot = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
    kx = np.array([[0.0, -1.0], [1.0, 0.0]])  # k×(gx, gy) = (−gy, gx)
    return p.surface_factor / (RHO_AIR * p.coriolis_s) * (rot @ kx)


def wind_on_points(p: ClimatologyParams, seed, times_s, x, y, *, interval_s=6 * HOUR_S, cyclones=None):
    """10-m wind (u, v), each (nt, npts) [m s-1], at points ``x, y`` [m] and record
    times ``times_s`` (multiples of ``interval_s``)."""
    times_s = np.asarray(times_s, np.float64)
    x = np.asarray(x, np.float64).ravel()
    y = np.asarray(y, np.float64).ravel()
    k, a, b, _ = _background_amplitudes(p, seed, times_s, interval_s)
    M = _rotate(p)
    ph = k[:, 0:1] * x[None, :] + k[:, 1:2] * y[None, :]   # (n, npts)
    C, S = np.cos(ph), np.sin(ph)
    c = np.asarray(p.steering_m_s, float)
    u = np.empty((times_s.size, x.size))
    v = np.empty((times_s.size, x.size))
    for it, t in enumerate(times_s):  # over records; each a (n × npts) product
        w = (k @ c) * t  # phase shift of the carried pattern
        cw, sw = np.cos(w), np.sin(w)
        A = a[it] * cw - b[it] * sw
        B = a[it] * sw + b[it] * cw
        # p = Σ A cos φ + B sin φ  ⇒ ∇p = Σ k (−A sin φ + B cos φ)
        gx = (k[:, 0] * B) @ C - (k[:, 0] * A) @ S
        gy = (k[:, 1] * B) @ C - (k[:, 1] * A) @ S
        u[it] = M[0, 0] * gx + M[0, 1] * gy
        v[it] = M[1, 0] * gx + M[1, 1] * gy
    for cy in cyclones or ():
        env = cy.envelope(times_s)
        for it in np.flatnonzero(env > 0.0):
            cx, cyy = cy.centre(times_s[it])
            dx, dy = x - cx, y - cyy
            g = (env[it] * cy.depth_hpa * 100.0 / cy.radius_m**2) * np.exp(-(dx * dx + dy * dy)
                                                                            / (2.0 * cy.radius_m**2))
            gx, gy = g * dx, g * dy  # ∇(−Δp e^(−r²/2R²)) = Δp (r/R²) e^(...) ê_r
            u[it] += M[0, 0] * gx + M[0, 1] * gy
            v[it] += M[1, 0] * gx + M[1, 1] * gy
    u += p.mean_wind_m_s[0]
    v += p.mean_wind_m_s[1]
    if p.wind_scale != 1.0:
        u *= p.wind_scale
        v *= p.wind_scale
    return u, v


def climatology_wind(grid, t_end_s, *, seed, domain_bbox=None, interval_s=6 * HOUR_S, t_start_s=0.0,
                     return_details=False, **params):
    """Records of the synthetic winter wind climatology on ``grid`` [m s-1].

    Args:
        grid: :class:`forcing.records.RegularGrid` (metres).
        t_end_s: last time to cover [s]; records every ``interval_s`` from the
            multiple of ``interval_s`` at or before ``t_start_s``.
        seed: integer; the same seed gives the same climate for any run length.
        domain_bbox: (xmin, xmax, ymin, ymax) [m] near which cyclones are kept
            (default: the grid extent).
        return_details: also return a :class:`ClimatologyWind` (records, cyclone tracks).
        **params: :class:`ClimatologyParams` fields (checked: unknown keys and
            out-of-range values raise ConfigError naming key, value and range).

    Returns a vector :class:`RecordField` (and the details if asked).
    """
    if not isinstance(grid, RegularGrid):
        raise ConfigError(f"the wind climatology needs a RegularGrid; got {type(grid).__name__}")
    p = make_params(**params)
    check_range("interval_s", interval_s, 0.0, 1.0 * DAY_S, low_open=True, unit="s")
    if not t_end_s > t_start_s:
        raise ConfigError(f"t_end_s = {t_end_s} s must be after t_start_s = {t_start_s} s")
    k0 = math.floor(t_start_s / interval_s + 1e-9)
    k1 = math.ceil(t_end_s / interval_s - 1e-9)
    times = interval_s * np.arange(k0, max(k1, k0 + 1) + 1, dtype=np.float64)
    if domain_bbox is None:
        domain_bbox = (float(grid.x_m[0]), float(grid.x_m[-1]), float(grid.y_m[0]), float(grid.y_m[-1]))
    cyc = draw_cyclones(p, seed, domain_bbox, times[0], times[-1])
    X, Y = grid.mesh()
    u, v = wind_on_points(p, seed, times, X, Y, interval_s=interval_s, cyclones=cyc)
    shape = (times.size,) + grid.shape
    u = u.reshape(shape)
    v = v.reshape(shape)
    src = InMemoryRecords(times, grid, np.stack([u, v], axis=1), ("u", "v"), units="m s-1",
                          name=f"<wind climatology seed={seed}>")
    fld = RecordField(src)
    if return_details:
        return fld, ClimatologyWind(fld, times, grid, u, v, p, cyc, tuple(domain_bbox), int(seed))
    return fld


# ----------------------------------------------------------------------------
# statistics of generated records (benchmark and tests)
# ----------------------------------------------------------------------------
#: target bands: name -> (low, high, unit, source); see docs/physics.md for the sources
TARGETS = {
    "mean_speed_m_s": (5.0, 7.0, "m s-1",
                       "winter 10-m wind over the Arctic pack, drifting stations and reanalyses (docs/physics.md)"),
    "speed_std_m_s": (2.3, 4.0, "m s-1", "Weibull shape ≈ 2: std ≈ 0.5 × mean (docs/physics.md)"),
    "speed_p99_m_s": (13.0, 20.0, "m s-1", "strong-wind tail of winter storms (docs/physics.md)"),
    "calm_basin_fraction": (0.0, 0.10, "-",
                            "fraction of records with basin-mean speed < 3 m s-1: rare in winter (docs/physics.md)"),
    "temporal_efolding_days": (1.0, 3.0, "day", "synoptic time scale (docs/physics.md)"),
    "spatial_efolding_km": (700.0, 1300.0, "km",
                            "ice-velocity / geostrophic-wind correlation length ≈ 1000 km (docs/physics.md)"),
    "spectral_slope": (-2.9, -1.6, "-",
                       "kinetic-energy spectrum ∝ k^slope of ocean-surface winds: QuikSCAT −1.6 to −2.9 "
                       "(Xu, Fu & Tulloch 2011), near −5/3 to −2 from 1 to 1000 km (Wikle, Milliff & Large 1999)"),
    "cyclone_passages_per_box_year": (5.0, 40.0, "per yr",
                                      "passages per 300 km × 300 km box: 20 (5–40), Brümmer et al. 2000"),
    "cyclone_max_wind_mean_m_s": (8.0, 16.0, "m s-1", "storm winds of winter Arctic cyclones (docs/physics.md)"),
    "cyclone_radius_mean_km": (300.0, 900.0, "km", "effective radius 300–900 km, Rudeva & Gulev 2007"),
    "cyclone_translation_mean_m_s": (4.0, 12.0, "m s-1", "synoptic translation speeds (docs/physics.md)"),
}


def _efold(lags, corr):
    """First lag at which corr falls below 1/e (linear interpolation); nan if never."""
    e = math.exp(-1.0)
    below = np.flatnonzero(corr < e)
    if below.size == 0:
        return float("nan")
    i = below[0]
    if i == 0:
        return float(lags[0])
    c0, c1 = corr[i - 1], corr[i]
    return float(lags[i - 1] + (c0 - e) / (c0 - c1) * (lags[i] - lags[i - 1]))


def wind_statistics(w: ClimatologyWind, *, seed=0, n_pairs=200_000, box_km=300.0) -> dict:
    """Statistics of generated records over the domain box (``w.domain_bbox``).

    * speed: mean, std, 50/95/99th percentiles and max over points and records;
    * calm_basin_fraction: records whose domain-mean speed is < 3 m s-1;
    * temporal_efolding_days: lag at which the autocorrelation of the wind-component
      anomalies (time mean removed at each point), averaged over points, drops to 1/e;
    * spatial_efolding_km: separation at which the correlation of wind-vector
      anomalies between random point pairs (same record) drops to 1/e;
    * cyclones: passages per ``box_km`` box per year (tracks whose centre enters the
      box while the envelope is > 0.5, averaged over boxes tiling the domain),
      mean largest 10-m wind, radius and translation speed of the systems that
      enter the domain.
    """
    xmin, xmax, ymin, ymax = w.domain_bbox
    X, Y = w.grid.mesh()
    inside = (X >= xmin) & (X <= xmax) & (Y >= ymin) & (Y <= ymax)
    u = w.u[:, inside]
    v = w.v[:, inside]
    sp = np.hypot(u, v)
    out = {"n_records": int(u.shape[0]), "n_points": int(u.shape[1]),
           "duration_days": float((w.times_s[-1] - w.times_s[0]) / DAY_S),
           "mean_speed_m_s": float(sp.mean()), "speed_std_m_s": float(sp.std()),
           "speed_p50_m_s": float(np.percentile(sp, 50)), "speed_p95_m_s": float(np.percentile(sp, 95)),
           "speed_p99_m_s": float(np.percentile(sp, 99)), "speed_max_m_s": float(sp.max())}
    basin_speed = sp.mean(axis=1)
    out["basin_mean_speed_min_m_s"] = float(basin_speed.min())
    out["calm_basin_fraction"] = float(np.mean(basin_speed < 3.0))
    out["basin_mean_vector_speed_m_s"] = float(np.mean(np.hypot(u.mean(axis=1), v.mean(axis=1))))
    # temporal autocorrelation of anomalies
    ua, va = u - u.mean(axis=0), v - v.mean(axis=0)
    var = float(np.mean(ua * ua + va * va))
    dt_days = float(np.median(np.diff(w.times_s))) / DAY_S
    nlag = min(u.shape[0] - 1, round(8.0 / dt_days))
    lags = np.arange(nlag + 1) * dt_days
    corr = np.array([np.mean(ua[: ua.shape[0] - L] * ua[L:] + va[: va.shape[0] - L] * va[L:]) / var
                     for L in range(nlag + 1)])
    out["temporal_efolding_days"] = _efold(lags, corr)
    out["temporal_lags_days"] = lags.tolist()
    out["temporal_correlation"] = corr.tolist()
    # spatial correlation from random point pairs within records
    rng = np.random.default_rng(seed)
    xs, ys = X[inside], Y[inside]
    npt = xs.size
    i = rng.integers(0, npt, n_pairs)
    j = rng.integers(0, npt, n_pairs)
    r = np.hypot(xs[i] - xs[j], ys[i] - ys[j]) / 1e3
    t = rng.integers(0, u.shape[0], n_pairs)
    prod = (ua[t, i] * ua[t, j] + va[t, i] * va[t, j]) / var
    edges = np.arange(0.0, min(2000.0, r.max()) + 50.0, 50.0)
    kb = np.digitize(r, edges) - 1
    ok = (kb >= 0) & (kb < edges.size - 1)
    sums = np.bincount(kb[ok], weights=prod[ok], minlength=edges.size - 1)
    cnt = np.bincount(kb[ok], minlength=edges.size - 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        sc = sums / cnt
    mid = 0.5 * (edges[1:] + edges[:-1])
    good = cnt > 50
    out["spatial_efolding_km"] = _efold(np.concatenate([[0.0], mid[good]]), np.concatenate([[1.0], sc[good]]))
    out["spatial_distance_km"] = mid[good].tolist()
    out["spatial_correlation"] = sc[good].tolist()
    out.update(spectral_slope(w))
    # cyclones
    years = (w.times_s[-1] - w.times_s[0]) / (365.25 * DAY_S)
    tt = np.arange(w.times_s[0], w.times_s[-1] + 1.0, 3 * HOUR_S)
    box = box_km * 1e3
    nbx = max(1, int((xmax - xmin) // box))
    nby = max(1, int((ymax - ymin) // box))
    passages = np.zeros((nbx, nby))
    entered = []
    for c in w.cyclones:
        env = c.envelope(tt)
        alive = env > 0.5
        if not alive.any():
            continue
        cx, cy = c.centre(tt[alive])
        ix = np.floor((cx - xmin) / box).astype(int)
        iy = np.floor((cy - ymin) / box).astype(int)
        ok = (ix >= 0) & (ix < nbx) & (iy >= 0) & (iy < nby)
        for a, b in set(zip(ix[ok].tolist(), iy[ok].tolist())):
            passages[a, b] += 1
        if ok.any():
            entered.append(c)
    out["n_cyclones_in_domain"] = len(entered)
    out["cyclones_in_domain_per_30_days"] = len(entered) / max((w.times_s[-1] - w.times_s[0]) / (30 * DAY_S), 1e-9)
    out["cyclone_passages_per_box_year"] = float(passages.mean() / years) if years > 0 else float("nan")
    if entered:
        out["cyclone_max_wind_mean_m_s"] = float(np.mean([c.max_surface_wind_m_s(w.params) for c in entered]))
        out["cyclone_radius_mean_km"] = float(np.mean([c.radius_m for c in entered]) / 1e3)
        out["cyclone_translation_mean_m_s"] = float(np.mean([math.hypot(c.u_m_s, c.v_m_s) for c in entered]))
        out["cyclone_depth_mean_hpa"] = float(np.mean([c.depth_hpa for c in entered]))
        out["cyclone_lifetime_mean_days"] = float(np.mean([c.lifetime_s for c in entered]) / DAY_S)
    else:
        for k in ("cyclone_max_wind_mean_m_s", "cyclone_radius_mean_km", "cyclone_translation_mean_m_s",
                  "cyclone_depth_mean_hpa", "cyclone_lifetime_mean_days"):
            out[k] = float("nan")
    return out


def spectral_slope(w: ClimatologyWind, r_min_km=75.0, r_max_km=300.0) -> dict:
    """Slope of the kinetic-energy wavenumber spectrum E(k) ∝ k^slope of the records
    inside the domain box, from the second-order structure function
    D(r) = <|u(x + r) − u(x)|²> along the grid rows and columns: D ∝ r^ζ with
    slope = −(1 + ζ) for 1 < −slope < 3 (a smooth field gives ζ = 2, slope −3).
    ζ is the least-squares log-log slope of D over separations ``r_min_km`` to
    ``r_max_km`` (scales the records resolve and a 1000-km basin contains)."""
    xmin, xmax, ymin, ymax = w.domain_bbox
    gx, gy = w.grid.x_m, w.grid.y_m
    ix = np.flatnonzero((gx >= xmin) & (gx <= xmax))
    iy = np.flatnonzero((gy >= ymin) & (gy <= ymax))
    u = w.u[:, iy[0]:iy[-1] + 1, ix[0]:ix[-1] + 1]
    v = w.v[:, iy[0]:iy[-1] + 1, ix[0]:ix[-1] + 1]
    h_km = float(gx[1] - gx[0]) / 1e3
    lags = np.arange(1, min(u.shape[1], u.shape[2]) // 2)
    r = lags * h_km
    D = np.array([0.5 * (np.mean((u[:, :, L:] - u[:, :, :-L]) ** 2 + (v[:, :, L:] - v[:, :, :-L]) ** 2)
                         + np.mean((u[:, L:, :] - u[:, :-L, :]) ** 2 + (v[:, L:, :] - v[:, :-L, :]) ** 2))
                  for L in lags])
    sel = (r >= r_min_km) & (r <= r_max_km)
    zeta = float(np.polyfit(np.log(r[sel]), np.log(D[sel]), 1)[0]) if sel.sum() >= 2 else float("nan")
    return {"spectral_slope": -(1.0 + zeta), "structure_function_exponent": zeta,
            "structure_distance_km": r.tolist(), "structure_function_m2_s2": D.tolist()}


def generate_for_box(width_m=1000e3, height_m=1000e3, days=28.0, *, seed=0, spacing_m=25e3, **params):
    """Records over a ``width × height`` box centred on the origin (with the same
    margin as the scene builder) and their details; for benchmarks and tests."""
    margin = max(4 * spacing_m, 0.2 * max(width_m, height_m))
    bbox = (-0.5 * width_m, 0.5 * width_m, -0.5 * height_m, 0.5 * height_m)
    grid = RegularGrid.from_bbox(*bbox, spacing_m, margin_m=margin)
    _, det = climatology_wind(grid, days * DAY_S, seed=seed, domain_bbox=bbox, return_details=True, **params)
    return det


# ----------------------------------------------------------------------------
# one moving cyclone, for the mesh-imprint scene (examples/imprint_cyclone_disk.toml)
# ----------------------------------------------------------------------------
#: depth 20 hPa, radius 300 km (largest 10-m wind 15 m/s), moving at (3, 1) m/s; at
#: full strength (t = 1.5 days) its centre is 70 km east of the disk's centre
IMPRINT_CYCLONE = CycloneTrack(x0_m=-450e3, y0_m=-150e3, t0_s=-0.5 * DAY_S, u_m_s=3.0, v_m_s=1.0,
                               depth_hpa=20.0, radius_m=300e3, lifetime_s=4.0 * DAY_S)


def cyclone_point_wind(track: CycloneTrack, t_s: float, x, y, params: ClimatologyParams | None = None):
    """10-m wind (u, v) [m s-1] of one cyclone alone at time ``t_s`` and points x, y."""
    p = params or ClimatologyParams()
    x = np.asarray(x, np.float64)
    y = np.asarray(y, np.float64)
    env = float(track.envelope(t_s))
    cx, cy = track.centre(t_s)
    dx, dy = x - cx, y - cy
    g = (env * track.depth_hpa * 100.0 / track.radius_m**2) * np.exp(-(dx * dx + dy * dy) / (2 * track.radius_m**2))
    M = _rotate(p)
    return M[0, 0] * g * dx + M[0, 1] * g * dy, M[1, 0] * g * dx + M[1, 1] * g * dy


def imprint_cyclone_u(t, x, y):
    """u of :data:`IMPRINT_CYCLONE` (scene hook ``forcing.climatology:imprint_cyclone_u``)."""
    return cyclone_point_wind(IMPRINT_CYCLONE, t, x, y)[0]


def imprint_cyclone_v(t, x, y):
    """v of :data:`IMPRINT_CYCLONE` (scene hook ``forcing.climatology:imprint_cyclone_v``)."""
    return cyclone_point_wind(IMPRINT_CYCLONE, t, x, y)[1]
