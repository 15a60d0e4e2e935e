"""Hooks of the ``shear_channel`` scenes: an annulus between an island of radius
r_i and a coast of radius R, and the azimuthal velocity profile

    u_θ(r) = U sin(π (r − r_i) / (R − r_i))      (zero on both coasts, U mid-channel)

used as the prescribed ice velocity (``shear_channel``: kinematic, exercises
mesh motion, remeshing and remapping) or as the ocean current that drags the
ice (``shear_channel_implicit``). Initial fields with structure and noise
(deterministic: fixed seeds) give remapping something to carry.
"""
from __future__ import annotations

import numpy as np
import shapely

RADIUS_M = 100e3
INNER_RADIUS_M = 30e3


def annulus(radius_m=RADIUS_M, inner_radius_m=INNER_RADIUS_M, vertex_spacing_m=10e3):
    """The annulus as a polygon with an island (vertices every ``vertex_spacing_m``)."""
    n_out = max(12, int(np.ceil(2 * np.pi * radius_m / vertex_spacing_m)))
    n_in = max(8, int(np.ceil(2 * np.pi * inner_radius_m / vertex_spacing_m)))
    t_out = np.linspace(0, 2 * np.pi, n_out, endpoint=False)
    t_in = np.linspace(0, 2 * np.pi, n_in, endpoint=False)
    outer = np.column_stack([radius_m * np.cos(t_out), radius_m * np.sin(t_out)])
    inner = np.column_stack([inner_radius_m * np.cos(t_in), inner_radius_m * np.sin(t_in)])
    return shapely.Polygon(outer, [inner])


def velocity(t, x, y, speed_m_s=0.1, radius_m=RADIUS_M, inner_radius_m=INNER_RADIUS_M):
    """Azimuthal velocity (u, v) [m s-1] of the profile in the module docstring."""
    x = np.asarray(x, np.float64)
    y = np.asarray(y, np.float64)
    r = np.hypot(x, y)
    s = np.clip((r - inner_radius_m) / (radius_m - inner_radius_m), 0.0, 1.0)
    ut = speed_m_s * np.sin(np.pi * s)
    with np.errstate(invalid="ignore", divide="ignore"):
        ex = np.where(r > 0, -y / np.where(r > 0, r, 1.0), 0.0)
        ey = np.where(r > 0, x / np.where(r > 0, r, 1.0), 0.0)
    return ut * ex, ut * ey


def _noise(x, seed, lo, hi):
    return np.random.default_rng(seed).uniform(lo, hi, np.size(x))


def thickness(x, y):
    """0.5 m at the island to 2 m at the coast, plus U(0, 0.2) m noise [m]."""
    r = np.hypot(x, y)
    return 0.5 + 1.5 * (r - INNER_RADIUS_M) / (RADIUS_M - INNER_RADIUS_M) + _noise(x, 11, 0.0, 0.2)


def concentration(x, y):
    """U(0.8, 1) [-]."""
    return _noise(x, 12, 0.8, 1.0)


def damage(x, y):
    """A radial band of damage 0.95, 12 km wide, on the positive x axis; U(0, 0.1) elsewhere."""
    band = (np.abs(y) < 6e3) & (x > 0)
    return np.where(band, 0.95, _noise(x, 13, 0.0, 0.1))


def cohesion(x, y):
    """U(20, 30) kPa [Pa]."""
    return _noise(x, 14, 20e3, 30e3)


def snow(x, y):
    """U(0, 0.3) m."""
    return _noise(x, 15, 0.0, 0.3)


def stress(x, y):
    """(σxx, σyy, σxy) ~ N(0, 1 kPa) per element [Pa] (something for remapping to carry)."""
    return np.random.default_rng(16).normal(0.0, 1e3, (np.size(x), 3))
