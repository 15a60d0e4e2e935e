"""Strain-rate invariants on irregular triangular meshes (issue 7; Girard et al. 2011 eq. 10,
Girard 2010 eq. 2.1-2.2)."""

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.spatial import Delaunay

from lagice.diagnostics import (
    divergence_rate,
    lagrangian_velocity_gradients,
    shear_rate,
    total_deformation_rate,
    velocity_gradients,
)
from lagice.diagnostics.synthetic import jittered_grid_mesh
from lagice.errors import ConfigError, LagiceError

# A velocity gradient with divergence, shear and rotation (s-1)
G = np.array([[2.0e-6, 3.0e-6], [-1.0e-6, -0.5e-6]])
C = np.array([0.12, -0.03])  # uniform translation (m s-1)


def delaunay_mesh(n=400, size_m=50e3, seed=3):
    """Random points (corners included) triangulated by scipy; triangles made counter-clockwise."""
    rng = np.random.default_rng(seed)
    pts = np.vstack([rng.uniform(0, size_m, (n, 2)), [[0, 0], [size_m, 0], [0, size_m], [size_m, size_m]]])
    tri = Delaunay(pts).simplices.astype(np.int64)
    p = pts[tri]
    cross = ((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
             - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))
    tri[cross < 0] = tri[cross < 0][:, [0, 2, 1]]
    return pts, tri


@pytest.fixture(params=["delaunay", "jittered"])
def mesh(request):
    if request.param == "delaunay":
        return delaunay_mesh()
    return jittered_grid_mesh(23, 17, 40e3, 30e3, jitter=0.3, seed=5)


def analytic_invariants(g):
    div = g[0, 0] + g[1, 1]
    shear = np.sqrt((g[0, 0] - g[1, 1]) ** 2 + (g[0, 1] + g[1, 0]) ** 2)
    return div, shear, np.sqrt(div**2 + shear**2)


def test_instantaneous_linear_field_is_exact(mesh):
    xy, tri = mesh
    r = velocity_gradients(xy, tri, xy @ G.T + C)
    np.testing.assert_allclose(r.gradient_s, np.broadcast_to(G, r.gradient_s.shape), rtol=0,
                               atol=1e-12 * np.abs(G).max() * 1e3)
    div, shear, tot = analytic_invariants(G)
    np.testing.assert_allclose(r.divergence_s, div, rtol=1e-9)
    np.testing.assert_allclose(r.shear_s, shear, rtol=1e-9)
    np.testing.assert_allclose(r.total_s, tot, rtol=1e-9)
    np.testing.assert_allclose(r.vorticity_s, G[1, 0] - G[0, 1], rtol=1e-9)
    assert np.all(r.area_m2 > 0)


def test_lagrangian_affine_displacement_is_exact_on_start_geometry(mesh):
    """x1 = x0 + dt (G x0 + c): the start-geometry gradient of (x1 - x0)/dt is G exactly."""
    xy0, tri = mesh
    dt = 3 * 86400.0
    xy1 = xy0 + dt * (xy0 @ G.T + C)
    r = lagrangian_velocity_gradients(xy0, xy1, tri, dt, geometry="start")
    np.testing.assert_allclose(r.gradient_s, np.broadcast_to(G, r.gradient_s.shape), rtol=0,
                               atol=1e-9 * np.abs(G).max())


def test_lagrangian_mid_geometry_is_second_order(mesh):
    """Steady flow dx/dt = G x: mid geometry gives (2/dt) tanh(G dt/2) exactly, start gives (e^{G dt} - I)/dt.

    Both are exact matrix identities for any mesh (the node map x0 -> x1 is
    linear), and the mid estimate is closer to G (error O(dt^2) vs O(dt)).
    """
    xy0, tri = mesh
    dt = 3 * 86400.0
    M = expm(G * dt)
    xy1 = xy0 @ M.T
    eye = np.eye(2)
    start_expected = (M - eye) / dt
    mid_expected = 2.0 / dt * (M - eye) @ np.linalg.inv(M + eye)
    end_expected = (M - eye) @ np.linalg.inv(M) / dt
    for geometry, expected in (("start", start_expected), ("mid", mid_expected), ("end", end_expected)):
        r = lagrangian_velocity_gradients(xy0, xy1, tri, dt, geometry=geometry)
        np.testing.assert_allclose(r.gradient_s, np.broadcast_to(expected, r.gradient_s.shape),
                                   rtol=0, atol=1e-9 * np.abs(G).max(), err_msg=geometry)
    assert np.abs(mid_expected - G).max() < 0.2 * np.abs(start_expected - G).max()


def test_invariants_are_rotation_invariant(mesh):
    """Rotating the scene (positions and velocities) leaves ε̇I, ε̇II, ε̇tot unchanged."""
    xy, tri = mesh
    rng = np.random.default_rng(0)
    uv = rng.normal(0, 0.05, xy.shape)
    th = 0.7
    R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    a = velocity_gradients(xy, tri, uv)
    b = velocity_gradients(xy @ R.T, tri, uv @ R.T)
    for name in ("divergence_s", "shear_s", "total_s", "vorticity_s"):
        np.testing.assert_allclose(getattr(b, name), getattr(a, name), rtol=1e-9, atol=1e-18, err_msg=name)


def test_invariant_functions_broadcast():
    g = np.stack([G, 2 * G, np.zeros((2, 2))])
    np.testing.assert_allclose(divergence_rate(g), [1.5e-6, 3e-6, 0])
    np.testing.assert_allclose(shear_rate(g)[1], 2 * shear_rate(G))
    np.testing.assert_allclose(total_deformation_rate(g)[0], np.hypot(1.5e-6, shear_rate(G)))


def test_bad_arguments_raise_config_error():
    xy, tri = jittered_grid_mesh(4, 4, 1e3, 1e3)
    with pytest.raises(ConfigError, match="dt_s"):
        lagrangian_velocity_gradients(xy, xy, tri, 0.0)
    with pytest.raises(ConfigError, match="dt_s"):
        lagrangian_velocity_gradients(xy, xy, tri, -5)
    with pytest.raises(ConfigError, match="nodes_xy1"):
        lagrangian_velocity_gradients(xy, xy[:-1], tri, 1.0)
    with pytest.raises(ConfigError, match="nodes_xy0"):
        lagrangian_velocity_gradients(xy[:, :1], xy, tri, 1.0)
    with pytest.raises(ConfigError, match="triangles"):
        lagrangian_velocity_gradients(xy, xy, tri + 100, 1.0)
    with pytest.raises(ConfigError, match="triangles"):
        lagrangian_velocity_gradients(xy, xy, tri.astype(float), 1.0)
    with pytest.raises(ConfigError, match="geometry"):
        lagrangian_velocity_gradients(xy, xy, tri, 1.0, geometry="middle")
    with pytest.raises(ConfigError, match="non-positive area"):
        velocity_gradients(xy, tri[:, ::-1], np.zeros_like(xy))
    bad = xy.copy()
    bad[3] = np.nan
    with pytest.raises(LagiceError, match="non-finite"):
        velocity_gradients(bad, tri, np.zeros_like(xy))
