"""A stationary gyre wind over a rectangle: the stream function
ψ = U (L/π) sin(π x/L) sin(π y/H) gives the divergence-free wind

    u = U sin(π x/L) cos(π y/H) (L/H),   v = −U cos(π x/L) sin(π y/H),

one closed circulation tangent to the coast (zero normal component on the sides of the
box [0, L] × [0, H]). Its stress ρa Ca |u| u is not divergence-free, but mostly
rotational, so broken ice that cannot converge should still turn with it: the test of the
volumetric locking of ice whose mean stress is kept (``tests/test_volumetric_locking.py``,
``solver.volumetric_strain``)."""
from __future__ import annotations

import numpy as np

HOUR = 3600.0


def gyre(t, x, y, speed_m_s=15.0, width_m=500e3, height_m=500e3, ramp_h=3.0):
    """The wind (u, v) [m s-1] at time ``t`` [s], ramped from 0 to ``speed_m_s`` over ``ramp_h`` hours."""
    s = speed_m_s * min(1.0, t / (ramp_h * HOUR)) if ramp_h > 0 else speed_m_s
    kx, ky = np.pi / width_m, np.pi / height_m
    u = s * np.sin(kx * x) * np.cos(ky * y) * (width_m / height_m)
    v = -s * np.cos(kx * x) * np.sin(ky * y)
    return u, v
