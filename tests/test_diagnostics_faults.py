"""Fault orientation, Coulomb angle and coast masks (lagice.diagnostics.faults, issue 7)."""
import numpy as np
import pytest

from lagice.diagnostics.faults import (
    angle_to_axis_deg,
    boundary_edges,
    damage_mode_fault_angle_deg,
    damage_mode_growth,
    distance_to_boundary,
    fault_orientations,
    interior_triangles,
    mohr_coulomb_fault_angle_deg,
)
from lagice.errors import ConfigError
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.rheology.maxwell_eb import envelope, plane_stress_matrix


def _band(rng, angle_deg, centre, half_length, n, width=1e3):
    t = np.deg2rad(angle_deg)
    s = rng.uniform(-half_length, half_length, n)
    off = rng.normal(0.0, width, n)
    return np.column_stack([centre[0] + s * np.cos(t) - off * np.sin(t),
                            centre[1] + s * np.sin(t) + off * np.cos(t)])


@pytest.mark.parametrize("theta", [27.5, 35.0, 20.0])
def test_conjugate_bands_found_in_noise(theta):
    """Two bands at ±θ from the y axis (a conjugate fault pair) over a noisy
    background of 10 times as many weaker samples: both directions recovered."""
    rng = np.random.default_rng(int(theta * 10))
    bg = rng.uniform([0, 0], [100e3, 200e3], (10_000, 2))
    a = _band(rng, 90 - theta, (50e3, 110e3), 70e3, 500)
    b = _band(rng, 90 + theta, (45e3, 80e3), 60e3, 400)
    xy = np.vstack([bg, a, b])
    w = np.concatenate([rng.uniform(0, 0.1, bg.shape[0]), np.ones(900)])
    r = fault_orientations(xy, w, strip_width_m=5e3)
    assert sorted(np.round(r.angles_deg, 2)) == pytest.approx(sorted([90 - theta, 90 + theta]), abs=0.5)
    assert angle_to_axis_deg(r.angles_deg) == pytest.approx([theta, theta], abs=0.5)
    # the longer, heavier band is the stronger one and its strip passes through its centre
    assert r.angles_deg[0] == pytest.approx(90 - theta, abs=0.5)
    t = np.deg2rad(r.angles_deg[0])
    off_true = -50e3 * np.sin(t) + 110e3 * np.cos(t)  # the band passes through (50, 110) km
    assert r.offsets_m[0] == pytest.approx(off_true, abs=1e3)
    assert r.scores[0] > 3 * np.median(r.trial_scores)


def test_uniform_field_has_no_preferred_direction():
    """Without a band the best strip holds about strip/extent of the weight at every angle."""
    rng = np.random.default_rng(0)
    xy = rng.uniform(0, 100e3, (20_000, 2))
    r = fault_orientations(xy, np.ones(20_000), strip_width_m=5e3, n_faults=1)
    assert r.trial_scores.max() < 1.5 * np.median(r.trial_scores)


def test_coulomb_angle():
    assert mohr_coulomb_fault_angle_deg(0.7) == pytest.approx(45 - 0.5 * np.degrees(np.arctan(0.7)))
    assert mohr_coulomb_fault_angle_deg(0.7) == pytest.approx(27.5, abs=0.01)
    assert mohr_coulomb_fault_angle_deg(1e-12) == pytest.approx(45.0)
    assert angle_to_axis_deg([62.5, 117.5, 0.0, 179.0, 90.0]) == pytest.approx([27.5, 27.5, 90.0, 89.0, 0.0])
    with pytest.raises(ConfigError, match="friction_coefficient"):
        mohr_coulomb_fault_angle_deg(-0.1)


def test_bad_weights_named():
    xy = np.zeros((3, 2))
    with pytest.raises(ConfigError, match="weights must be >= 0"):
        fault_orientations(xy, [1.0, -1.0, 0.0], 1.0)
    with pytest.raises(ConfigError, match="weights sum to zero"):
        fault_orientations(xy, [0.0, 0.0, 0.0], 1.0)
    with pytest.raises(ConfigError, match="strip_width_m"):
        fault_orientations(xy, [1.0, 1.0, 1.0], 0.0)


def test_distance_to_boundary_on_gmsh_rectangle():
    """On a real gmsh rectangle the boundary is the rectangle: the distance of
    each centroid is min(x, W − x, y, H − y) exactly; the mask keeps those ≥ b."""
    W, H = 100e3, 60e3
    poly, _ = rectangle_domain(W, H)
    mesh = generate_mesh(poly, 5e3)
    tri = mesh.triangles
    c = mesh.nodes[tri].mean(axis=1)
    expect = np.minimum.reduce([c[:, 0], W - c[:, 0], c[:, 1], H - c[:, 1]])
    d = distance_to_boundary(mesh.nodes, tri, c)
    np.testing.assert_allclose(d, expect, atol=1e-6)
    keep = interior_triangles(mesh.nodes, tri, 15e3)
    np.testing.assert_array_equal(keep, expect >= 15e3)
    assert 0 < keep.sum() < tri.shape[0]
    assert interior_triangles(mesh.nodes, tri, 0.0).all()
    # boundary edges: their total length is the perimeter
    e = boundary_edges(tri)
    seg = mesh.nodes[e[:, 1]] - mesh.nodes[e[:, 0]]
    assert np.hypot(seg[:, 0], seg[:, 1]).sum() == pytest.approx(2 * (W + H), rel=1e-12)
    with pytest.raises(ConfigError, match="buffer_m"):
        interior_triangles(mesh.nodes, tri, -1.0)


def _band_envelope_growth(theta_deg, mu, nu, eps_star):
    """Change of q σ1 − σ2 inside a band at θ from the y axis in a plate under σ0 = (0, −1),
    when the band takes the inelastic strain ``eps_star`` (xx, yy, xy tensor components):
    solved as plane-stress elasticity (the model's K) with the band's normal traction free
    to adjust, not from the closed form."""
    K = plane_stress_matrix(nu)
    t = np.radians(theta_deg)
    n = np.array([np.cos(t), -np.sin(t)])             # normal of the band direction (sin θ, cos θ)

    def stress(v):                                      # K (sym(n ⊗ v) − ε*), Voigt (xx, yy, xy)
        e = np.array([n[0] * v[0], n[1] * v[1], 0.5 * (n[0] * v[1] + n[1] * v[0])])
        return K @ (e - eps_star)

    def traction(v):
        sx, sy, sxy = stress(v)
        return np.array([sx * n[0] + sxy * n[1], sxy * n[0] + sy * n[1]])

    A = np.column_stack([traction(np.eye(2)[i]) - traction(np.zeros(2)) for i in range(2)])
    v = np.linalg.solve(A, -traction(np.zeros(2)))     # the band keeps the plate's traction
    ds = stress(v)
    assert np.allclose(traction(v), 0.0, atol=1e-12)
    q = envelope(1.0, mu)[0]

    def f(sig):
        m, r = 0.5 * (sig[0] + sig[1]), np.hypot(0.5 * (sig[0] - sig[1]), sig[2])
        return q * (m + r) - (m - r)

    s0, h = np.array([0.0, -1.0, 0.0]), 1e-6
    return (f(s0 + h * ds) - f(s0)) / h


@pytest.mark.parametrize("mu,nu", [(0.7, 0.3), (0.4, 0.1), (1.0, 0.45), (0.7, 0.0)])
def test_damage_mode_angle_is_the_fastest_growing_band(mu, nu):
    # origin correction: the band's inelastic strain is the elastic strain of σ0 (K⁻¹σ0)
    eps_star = np.linalg.solve(plane_stress_matrix(nu), [0.0, -1.0, 0.0])
    thetas = np.arange(0.5, 90.0, 0.05)
    g = np.array([_band_envelope_growth(th, mu, nu, eps_star) for th in thetas])
    predicted = damage_mode_fault_angle_deg(mu, poisson_ratio=nu)
    assert thetas[np.argmax(g)] == pytest.approx(predicted, abs=0.06)
    # the same growth, up to a positive factor, as damage_mode_growth (which the docs plot)
    sin_psi = -(1.0 - nu) / (1.0 + nu)
    g2 = damage_mode_growth(thetas, mu, sin_psi)
    assert np.allclose(g / g.max(), g2 / g2.max(), atol=1e-6)
    # and far from Mohr–Coulomb: the band at the Coulomb angle does not grow at all
    mc = mohr_coulomb_fault_angle_deg(mu)
    assert predicted - mc > 10.0
    assert _band_envelope_growth(mc, mu, nu, eps_star) == pytest.approx(0.0, abs=1e-6)


def test_damage_mode_angle_paths():
    # the associated return (inelastic strain normal to the envelope, ψ = φ) gives Coulomb's angle
    for mu in (0.4, 0.7, 1.0):
        phi = np.degrees(np.arctan(mu))
        assert damage_mode_fault_angle_deg(mu, dilatancy_angle_deg=phi) == pytest.approx(
            mohr_coulomb_fault_angle_deg(mu), abs=1e-9)
    # the shipped plate (μ = 0.7, ν = 0.3): 44.5°, and steeper for a smaller ν or μ
    assert damage_mode_fault_angle_deg(0.7, poisson_ratio=0.3) == pytest.approx(44.5, abs=0.05)
    assert damage_mode_fault_angle_deg(0.7, poisson_ratio=0.1) > damage_mode_fault_angle_deg(0.7, poisson_ratio=0.45)
    assert damage_mode_fault_angle_deg(0.4, poisson_ratio=0.3) > damage_mode_fault_angle_deg(1.0, poisson_ratio=0.3)
    # isochoric flow (ψ = 0): cos 2θ = sin φ / 2
    assert damage_mode_fault_angle_deg(0.7, dilatancy_angle_deg=0.0) == pytest.approx(
        0.5 * np.degrees(np.arccos(0.5 * np.sin(np.arctan(0.7)))))
    with pytest.raises(ConfigError, match="exactly one"):
        damage_mode_fault_angle_deg(0.7)
    with pytest.raises(ConfigError, match="poisson_ratio"):
        damage_mode_fault_angle_deg(0.7, poisson_ratio=1.2)
    with pytest.raises(ConfigError, match="friction_coefficient"):
        damage_mode_fault_angle_deg(-0.7, poisson_ratio=0.3)
