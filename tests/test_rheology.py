"""Maxwell-EB rheology: envelope, d_crit, damage/healing update, moduli, bad input."""
import math

import numpy as np
import pytest

from lagice.errors import ConfigError
from lagice.params import MaxwellEBParams
from lagice.rheology import (
    MaxwellEB,
    dcrit,
    draw_cohesion,
    envelope,
    plane_stress_matrix,
    principal_stresses,
    relaxation_time,
    young_modulus,
)


def rotate(s1, s2, theta):
    """Stress (xx, yy, xy) with principal values s1, s2 rotated by theta."""
    c, s = np.cos(theta), np.sin(theta)
    sxx = s1 * c * c + s2 * s * s
    syy = s1 * s * s + s2 * c * c
    sxy = (s1 - s2) * s * c
    return np.stack([sxx, syy, sxy], axis=-1)


def test_dansereau2016_q_and_strength_ratio():
    q, sc, st = envelope(37.5e3, 0.7)
    assert q == pytest.approx(3.69, abs=0.005)
    assert st / sc == pytest.approx(0.27, abs=0.005)
    assert sc == pytest.approx(2 * 37.5e3 / (math.sqrt(1.49) - 0.7))


def test_points_on_envelope_have_dcrit_one(rng):
    C = rng.uniform(25e3, 50e3, 400)
    q, sc, st = envelope(C, 0.7)
    theta = rng.uniform(0, np.pi, 400)
    # Mohr-Coulomb branch: q s1 - s2 = sigma_c with s1 in [-sigma_c, sigma_T]
    s1 = rng.uniform(-2 * sc, st)
    s2 = q * s1 - sc
    sig = rotate(s1, s2, theta)
    p1, p2 = principal_stresses(sig)
    assert np.allclose(p1, s1, atol=1e-6 * sc) and np.allclose(p2, s2, atol=1e-6 * sc)
    assert np.allclose(dcrit(sig, C, 0.7), 1.0, atol=1e-12)
    # tensile cut-off branch: s1 = sigma_T, s2 between q*sigma_T - sigma_c = 0 and sigma_T
    s2t = rng.uniform(0.0, st)
    assert np.allclose(dcrit(rotate(st, s2t, theta), C, 0.7), 1.0, atol=1e-12)
    # scaling a state outside by k gives dcrit = 1/k (radial return to envelope)
    assert np.allclose(dcrit(1.7 * sig, C, 0.7), 1 / 1.7, rtol=1e-12)


def test_uniaxial_strengths():
    C = 40e3
    q, sc, st = envelope(C, 0.7)
    for eps in (0.05, 0.3):
        comp = np.array([[0.0, -sc * (1 + eps), 0.0]])
        tens = np.array([[st * (1 + eps), 0.0, 0.0]])
        assert dcrit(comp, C, 0.7)[0] == pytest.approx(1 / (1 + eps), rel=1e-12)
        assert dcrit(tens, C, 0.7)[0] == pytest.approx(1 / (1 + eps), rel=1e-12)
    assert dcrit(np.array([[0.0, -0.999 * sc, 0.0]]), C, 0.7)[0] == 1.0
    assert dcrit(np.array([[0.999 * st, 0.0, 0.0]]), C, 0.7)[0] == 1.0
    # biaxial compression is never critical (no cap on the envelope)
    assert dcrit(np.array([[-1e9, -1e9, 0.0]]), C, 0.7)[0] == 1.0


def test_damage_update_with_dt_equal_td_is_dansereau2016_recursion(rng):
    rheo = MaxwellEB(healing_time_s=None)
    m = 500
    C = rng.uniform(25e3, 50e3, m)
    q, sc, _ = envelope(C, 0.7)
    sig = rotate(rng.uniform(-3, 0.2, m) * sc, rng.uniform(-3, 0, m) * sc, rng.uniform(0, np.pi, m))
    d0 = rng.uniform(0, 0.9, m)
    dc = dcrit(sig, C, 0.7)
    d = d0.copy()
    s = sig.copy()
    td = np.full(m, 20.0)
    rheo.damage_update(s, d, C, 20.0, td, np.zeros(m))
    # Dansereau et al. 2016: d_seed^{n+1} = dcrit d_seed^n with d_seed = 1 - d
    assert np.allclose(1 - d, dc * (1 - d0), rtol=1e-14)
    assert np.allclose(s, sig * dc[:, None], rtol=1e-14)
    # after the update, every stress is inside or on the envelope
    assert np.all(dcrit(s, C, 0.7) > 1 - 1e-12)
    # half step: half of the increment
    d = d0.copy()
    s = sig.copy()
    rheo.damage_update(s, d, C, 10.0, td, np.zeros(m))
    assert np.allclose(1 - d, (1 - d0) * (1 - 0.5 * (1 - dc)), rtol=1e-14)


def test_constant_healing_rate():
    rheo = MaxwellEB(healing_time_s=1e5)
    d = np.array([0.5, 0.001, 0.0])
    s = np.zeros((3, 3))
    rheo.damage_update(s, d, np.full(3, 3e4), 100.0, np.full(3, 5.0), rheo.constant_heal_rate(3))
    assert d[0] == pytest.approx(0.5 - 100.0 / 1e5, rel=1e-14)
    assert d[1] == 0.0 and d[2] == 0.0  # fully healed, floor of the law


def test_damage_cap_is_counted():
    rheo = MaxwellEB(healing_time_s=None)
    q, sc, _ = envelope(30e3, 0.7)
    d = np.array([1 - 1e-7])
    s = np.array([[0.0, -10 * sc, 0.0]])
    rheo.damage_update(s, d, np.array([30e3]), 5.0, np.array([5.0]), np.zeros(1))
    assert d[0] == rheo.params.max_damage
    assert rheo.n_capped_total == 1


def test_moduli_and_viscosity_scaling():
    p = MaxwellEBParams()
    assert p.E0 == pytest.approx(2 * 500**2 * 1.3 * 900)
    d = np.array([0.0, 0.5, 0.9])
    E = young_modulus(p.E0, d, 1.0, 20.0)
    lam = relaxation_time(1e7, d, 1.0, 20.0, 4.0)
    assert np.allclose(E, p.E0 * (1 - d))
    eta = E * lam
    assert np.allclose(eta / eta[0], (1 - d) ** 4)
    # concentration dependence exp(-c*(1-A))
    assert young_modulus(p.E0, 0.0, 0.9, 20.0) == pytest.approx(p.E0 * math.exp(-2.0))


def test_cohesion_field_seeded(rng):
    p = MaxwellEBParams()
    a = draw_cohesion(1000, p, np.random.default_rng(3))
    b = draw_cohesion(1000, p, np.random.default_rng(3))
    c = draw_cohesion(1000, p, np.random.default_rng(4))
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    assert a.min() >= 25e3 and a.max() <= 50e3
    assert abs(a.mean() - 37.5e3) < 1.5e3


def test_mean_stress_correction_keeps_the_mean_and_lands_on_the_envelope(rng):
    """rheology.stress_correction = "mean_stress": with dt = td a super-critical stress is
    brought onto the envelope (d_crit 1 after the update) along the path towards θ m I
    (m the mean normal stress): θ = 1 scales only the deviatoric part, so the mean is kept;
    θ = 0.5 moves the mean to θ m + d_crit (1 − θ) m; the origin path scales everything.
    Damage grows by the factor the path needs: 1 − d = d_crit (Dansereau et al. 2016, d0 = 0)."""
    C, mu = 30e3, 0.7
    q, sc, st = envelope(C, mu)
    n = 200
    # compressive mean, a deviatoric radius 1.05-3 times the envelope's at that mean
    m = -rng.uniform(0.0, 2.0, n) * sc
    r_env = (sc - (q - 1.0) * m) / (q + 1.0)
    r = r_env * rng.uniform(1.05, 3.0, n)
    sig = rotate(m + r, m - r, rng.uniform(0, np.pi, n))
    dcs = {}
    for theta in (0.0, 0.5, 1.0, 1.5):
        kw = {} if theta == 0.0 else {"stress_correction": "mean_stress",
                                      "stress_correction_mean_fraction": None if theta == 1.0 else theta}
        rh = MaxwellEB(cohesion_min_pa=C, cohesion_max_pa=C, friction=mu, **kw)
        assert rh.params.mean_fraction == theta
        s = sig.copy()
        d = np.zeros(n)
        dc = rh.damage_update(s, d, np.full(n, C), 1.0, np.ones(n), np.zeros(n))
        np.testing.assert_allclose(dcrit(s, C, mu), 1.0, rtol=0, atol=1e-9)  # on the envelope
        s1, s2 = principal_stresses(s)
        np.testing.assert_allclose(q * s1 - s2, sc, rtol=1e-9)
        np.testing.assert_allclose(1.0 - d, dc, rtol=1e-12)
        np.testing.assert_allclose(0.5 * (s[:, 0] + s[:, 1]), theta * m + dc * (1.0 - theta) * m, rtol=1e-12)
        dcs[theta] = dc
    np.testing.assert_allclose(dcs[1.0], r_env / r, rtol=1e-9)
    # keeping more of the (compressive) mean costs less damage
    assert np.all(dcs[0.0] < dcs[0.5]) and np.all(dcs[0.5] < dcs[1.0]) and np.all(dcs[1.0] < dcs[1.5])


@pytest.mark.parametrize("theta", [0.5, 1.0, 1.25, 1.5])
def test_mean_stress_correction_dilatancy(theta):
    """Uniaxial compression along y past the envelope: the correction towards θ m I takes out
    the inelastic strain K⁻¹(σ − σ'), whose dilatancy is sin ψ = (θ − 1)(1 − ν)/(1 + ν):
    compactive below θ = 1, isochoric at 1, dilatant above (the angle that
    damage_mode_fault_angle_deg turns into a fault angle)."""
    C, mu, nu = 30e3, 0.7, 0.3
    q, sc, st = envelope(C, mu)
    rh = MaxwellEB(cohesion_min_pa=C, cohesion_max_pa=C, friction=mu, poisson=nu, stress_correction="mean_stress",
                   stress_correction_mean_fraction=theta)
    sig = np.array([[0.0, -1.3 * sc, 0.0]])
    s = sig.copy()
    rh.damage_update(s, np.zeros(1), np.full(1, C), 1.0, np.ones(1), np.zeros(1))
    s1, s2 = principal_stresses(s)
    assert q * s1[0] - s2[0] == pytest.approx(sc, rel=1e-9)
    eps = np.linalg.solve(plane_stress_matrix(nu), (sig - s)[0])   # xx lateral, yy axial
    sin_psi = (eps[0] + eps[1]) / (eps[0] - eps[1])
    assert sin_psi == pytest.approx((theta - 1.0) * (1.0 - nu) / (1.0 + nu), abs=1e-12)
    assert np.sign(round(sin_psi, 9)) == np.sign(theta - 1.0)


def test_associated_correction_returns_along_the_envelope_normal(rng):
    """rheology.stress_correction = "associated": with dt = td a super-critical stress lands
    on the envelope, its principal axes kept, and the correction σ − σ' is parallel (in
    principal axes) to K n, n the normal of the branch it was past: (q, −1) for the
    Mohr–Coulomb branch, (1, 0) for the tensile one. The inelastic strain K⁻¹(σ − σ') is
    then normal to the envelope, so its dilatancy is that of associated flow: in uniaxial
    compression the origin path compacts (ε1/ε2 = −ν) and this one dilates."""
    C, mu, nu = 30e3, 0.7, 0.3
    q, sc, st = envelope(C, mu)
    K = plane_stress_matrix(nu)
    rh = MaxwellEB(cohesion_min_pa=C, cohesion_max_pa=C, friction=mu, poisson=nu, stress_correction="associated")
    assert rh.params.mean_fraction == 0.0
    n = 400
    # past the Mohr-Coulomb branch (compressive mean) and past the tensile cut-off (a
    # tensile mean below σT; beyond it, near isotropic tension, the path would cross the
    # isotropic axis and the origin path acts, as for "mean_stress")
    u = rng.uniform(0.7, 0.98, n)
    m = np.concatenate([-rng.uniform(0.0, 2.0, n) * sc, u * st])
    r = np.concatenate([(sc - (q - 1.0) * m[:n]) / (q + 1.0) * rng.uniform(1.02, 1.5, n),
                        (1.0 - u) * rng.uniform(1.05, 1.5, n) * st])
    # each past one branch only: the first group below σT, the second inside Mohr-Coulomb
    keep = np.where(np.arange(2 * n) < n, m + r < st, (q - 1.0) * m + (q + 1.0) * r < sc)
    mc = (np.arange(2 * n) < n)[keep]
    m, r = m[keep], r[keep]
    assert mc.sum() > 100 and (~mc).sum() > 100
    angle = rng.uniform(0, np.pi, m.size)
    sig = rotate(m + r, m - r, angle)
    s = sig.copy()
    d = np.zeros(m.size)
    dc = rh.damage_update(s, d, np.full(m.size, C), 1.0, np.ones(m.size), np.zeros(m.size))
    np.testing.assert_allclose(dcrit(s, C, mu), 1.0, rtol=0, atol=1e-9)
    np.testing.assert_allclose(1.0 - d, dc, rtol=1e-12)
    s1, s2 = principal_stresses(s)
    delta = np.column_stack([m + r - s1, m - r - s2])  # the correction in principal axes
    for rows, normal in ((mc, np.array([q, -1.0])), (~mc, np.array([1.0, 0.0]))):
        kn = K[:2, :2] @ normal
        cross = delta[rows, 0] * kn[1] - delta[rows, 1] * kn[0]
        np.testing.assert_allclose(cross, 0.0, atol=1e-9 * sc)
        assert np.all(delta[rows] @ kn > 0.0)
    np.testing.assert_allclose(q * s1[mc] - s2[mc], sc, rtol=1e-9)
    np.testing.assert_allclose(s1[~mc], st, rtol=1e-9)
    # the principal axes are kept
    s_back = rotate(s1, s2, angle)
    np.testing.assert_allclose(s, s_back, atol=1e-9 * sc)
    # uniaxial compression along y: the inelastic strain of the origin path is ∝ K⁻¹σ
    # (lateral/axial = −ν, compaction); that of this path is ∝ n (dilation, sin ψ = sin φ)
    u = np.array([[0.0, -1.2 * sc, 0.0]])
    for kw, ratio in (({}, -nu), ({"stress_correction": "associated"}, -q)):
        rh2 = MaxwellEB(cohesion_min_pa=C, cohesion_max_pa=C, friction=mu, poisson=nu, **kw)
        s = u.copy()
        rh2.damage_update(s, np.zeros(1), np.full(1, C), 1.0, np.ones(1), np.zeros(1))
        de = np.linalg.solve(K[:2, :2], (u - s)[0, :2])
        assert de[0] / de[1] == pytest.approx(ratio, rel=1e-9)


def test_mean_stress_correction_falls_back_to_the_origin_beyond_the_tensile_strength():
    """Isotropic tension above σT cannot be fixed by the deviatoric part: the origin path acts."""
    C, mu = 30e3, 0.7
    _, _, st = envelope(C, mu)
    s_mean = MaxwellEB(cohesion_min_pa=C, cohesion_max_pa=C, stress_correction="mean_stress")
    s_origin = MaxwellEB(cohesion_min_pa=C, cohesion_max_pa=C)
    out = []
    for rh in (s_mean, s_origin):
        s = np.array([[2.0 * st, 2.0 * st, 0.0], [1.5 * st, 1.2 * st, 0.1 * st]])
        d = np.zeros(2)
        rh.damage_update(s, d, np.full(2, C), 1.0, np.ones(2), np.zeros(2))
        out.append((s, d))
    np.testing.assert_array_equal(out[0][0], out[1][0])
    np.testing.assert_array_equal(out[0][1], out[1][1])
    np.testing.assert_allclose(principal_stresses(out[0][0])[0], st, rtol=1e-12)


@pytest.mark.parametrize("kw,name", [
    ({"poisson": 0.5}, "poisson"), ({"poisson": 0.7}, "poisson"), ({"alpha": 1.0}, "alpha"),
    ({"alpha": 0.5}, "alpha"), ({"cohesion_min_pa": -1.0}, "cohesion_min_pa"),
    ({"cohesion_max_pa": 1.0}, "cohesion_max_pa"), ({"relaxation_time_s": 0}, "relaxation_time_s"),
    ({"stress_correction": "normal"}, "stress_correction"),
    ({"stress_correction_mean_fraction": 0.0, "stress_correction": "mean_stress"}, "stress_correction_mean_fraction"),
    ({"stress_correction_mean_fraction": 2.5, "stress_correction": "mean_stress"}, "stress_correction_mean_fraction"),
])
def test_bad_parameters_name_the_parameter(kw, name):
    with pytest.raises(ConfigError, match=name) as e:
        MaxwellEBParams(**kw)
    assert "expected" in str(e.value)
    assert repr(list(kw.values())[0]) in str(e.value)


def test_mean_fraction_needs_the_mean_stress_path():
    """A θ with the origin path would be ignored: refused, naming both keys."""
    with pytest.raises(ConfigError, match="stress_correction_mean_fraction = 0.5 applies to stress_correction = "
                                          "'mean_stress' only"):
        MaxwellEBParams(stress_correction_mean_fraction=0.5)


def test_unknown_parameter():
    with pytest.raises(ConfigError, match="unknown rheology parameter 'youngs'"):
        MaxwellEB(youngs=1.0)
