"""Hook of the ``wind_square`` scene: a spatially uniform wind that ramps up, then
turns (the forcing of the speed–accuracy and stability benchmarks)."""
from __future__ import annotations

import math

import numpy as np

HOUR = 3600.0


def wind_components(t: float, speed_m_s=20.0, ramp_h=6.0, turn_h=24.0, turn_deg=90.0, dir0_deg=0.0):
    """(u, v) [m s-1] at time ``t`` [s]: speed ramped 0 → ``speed_m_s`` over ``ramp_h``
    hours, direction ``dir0_deg`` (towards, counter-clockwise from +x), then turning
    by ``turn_deg`` linearly over the following ``turn_h`` hours."""
    ramp_s, turn_s = ramp_h * HOUR, turn_h * HOUR
    s = speed_m_s * min(1.0, max(0.0, t / ramp_s)) if ramp_s > 0 else speed_m_s
    frac = min(1.0, max(0.0, (t - ramp_s) / turn_s)) if turn_s > 0 else 1.0
    ang = math.radians(dir0_deg + turn_deg * frac)
    return s * math.cos(ang), s * math.sin(ang)


def turning_wind(t, x, y, speed_m_s=20.0, ramp_h=6.0, turn_h=24.0, turn_deg=90.0, dir0_deg=0.0):
    """The wind field f(t, x, y) -> (u, v) of :func:`wind_components`, uniform in space."""
    u, v = wind_components(t, speed_m_s, ramp_h, turn_h, turn_deg, dir0_deg)
    return np.full(np.shape(x), u), np.full(np.shape(x), v)
