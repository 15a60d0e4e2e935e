"""Synthetic 2 m air temperature (docs/design.md §3 and §6).

Seasonal cycle plus synoptic variability, deterministic from a seed, as
records every 6 h through the forcing machinery
(:class:`forcing.records.RecordField`, scalar, °C):

    Ta(t, x, y) = mean − amplitude·cos(2π (day(t) − coldest_day)/365.25)
                  + s(t) + gx (x − xc) + gy (y − yc)

* ``day(t) = start_day_of_year + t/86400`` (day of year, 1 = 1 January);
* ``s`` is an AR(1) process sampled at the record interval Δ,
  ``s_{k+1} = φ s_k + σ √(1 − φ²) ε_k``, ``φ = exp(−Δ/τ)``, ``s_0 = σ ε_0``,
  ``ε ~ N(0, 1)`` from ``numpy.random.default_rng(seed)`` (stationary
  standard deviation σ, e-folding time τ);
* a weak uniform gradient ``(gx, gy)`` [K per 1000 km] about the grid centre
  ``(xc, yc)`` (default none: spatially uniform).
"""
from __future__ import annotations

import numpy as np

from forcing.records import DAY_S, HOUR_S, InMemoryRecords, RecordField, RegularGrid
from forcing.synthetic import record_times
from lagice.errors import ConfigError, check_range


def synthetic_air_temperature(grid, t_end_s, *, seed, mean_c=-14.0, seasonal_amplitude_k=15.0,
                              start_day_of_year=1.0, coldest_day_of_year=45.0,
                              synoptic_std_k=4.0, synoptic_time_s=3.0 * DAY_S,
                              gradient_k_per_1000km=(0.0, 0.0), interval_s=6.0 * HOUR_S,
                              t_start_s=0.0, **field_kw):
    """Air temperature records [°C] on ``grid`` every ``interval_s`` (see module docstring).

    Defaults give an Arctic-like year: ≈ −29 °C in mid February to ≈ +1 °C
    in mid August, with ±4 K synoptic weather of 3-day memory.

    Returns
    -------
    forcing.records.RecordField
        Scalar field [°C]; pass it as ``Forcing(air_temperature=...)``.
    """
    if not isinstance(grid, RegularGrid):
        raise ConfigError(f"synthetic air temperature needs a RegularGrid; got {type(grid).__name__}")
    check_range("seasonal_amplitude_k", seasonal_amplitude_k, 0.0, 60.0, unit="K")
    check_range("synoptic_std_k", synoptic_std_k, 0.0, 30.0, unit="K")
    check_range("synoptic_time_s", synoptic_time_s, 0.0, None, low_open=True, unit="s")
    times = record_times(t_end_s, interval_s, t_start_s)
    day = start_day_of_year + times / DAY_S
    seasonal = mean_c - seasonal_amplitude_k * np.cos(2.0 * np.pi * (day - coldest_day_of_year) / 365.25)
    rng = np.random.default_rng(seed)
    eps = rng.standard_normal(times.size)
    phi = np.exp(-interval_s / synoptic_time_s)
    s = np.empty(times.size)
    s[0] = synoptic_std_k * eps[0]
    q = synoptic_std_k * np.sqrt(1.0 - phi * phi)
    for k in range(1, times.size):  # over records (a few hundred), not nodes
        s[k] = phi * s[k - 1] + q * eps[k]
    X, Y = grid.mesh()
    gx, gy = (g / 1.0e6 for g in gradient_k_per_1000km)
    spatial = gx * (X - 0.5 * (grid.x_m[0] + grid.x_m[-1])) + gy * (Y - 0.5 * (grid.y_m[0] + grid.y_m[-1]))
    data = (seasonal + s)[:, None, None] + spatial[None]
    src = InMemoryRecords(times, grid, data[:, None], ("air_temperature",), units="degC",
                          name=f"<synthetic air temperature seed={seed}>")
    return RecordField(src, **field_kw)
