"""Explicit solver (issue 3): kernels against the rheology, patch test, Maxwell
relaxation, boundary conditions, agreement with the implicit solver on the
Dansereau et al. 2016 compression test, stability refusal/warning."""
import warnings

import numpy as np
import pytest

from lagice.errors import ConfigError, LagiceError
from lagice.fem import strain_rate
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.rheology import MaxwellEB
from lagice.solvers import SOLVERS, ExplicitSolver, VelocityBC
from lagice.solvers.explicit import (
    element_stress_damage_kernel,
    element_stress_damage_kernel_a4,
    element_stress_damage_kernel_a4_serial,
    element_stress_damage_kernel_serial,
    envelope_factors,
)
from lagice.stability import StabilityWarning, explicit_substep_limit, load_limits
from lagice.state import IceState

from helpers import compression_overrides, node_constants_reference, scene_sim, series, step

G = np.array([[2e-8, 0.7e-8], [-0.3e-8, -1.1e-8]])  # velocity gradient [s-1]


def linear_velocity(comp):
    return lambda t, x, y: G[comp, 0] * x + G[comp, 1] * y


@pytest.mark.parametrize("theta", [None, 1.0, 2.0])
@pytest.mark.parametrize("kernel", [element_stress_damage_kernel, element_stress_damage_kernel_serial,
                                    element_stress_damage_kernel_a4_serial])
def test_element_kernel_damage_matches_rheology(kernel, theta):
    """With zero strain rate and γ = 1 the element kernel is the rheology's damage/healing
    update (same formulas; to round-off, since the kernel may fuse a multiply-add into one
    FMA, ``explicit.KERNEL_FASTMATH``): the same elements damage, and stress and damage
    agree to 1e-13 relative (a wrong factor or a missed correction is ≥ 1e-3 off). The
    kernel's cheap inside-the-envelope test (``envelope_factors``) must not change which
    elements damage. θ None: the origin correction; θ = 1, 2: ``stress_correction =
    "mean_stress"`` (towards θ times the mean stress), against the implicit solver's
    ``damage_update`` with the same θ; the corrected stresses then differ from the origin
    path's by ≥ 1e-3."""
    rng = np.random.default_rng(0)
    m = 500
    rheo = (MaxwellEB() if theta is None else
            MaxwellEB(stress_correction="mean_stress", stress_correction_mean_fraction=theta))
    sigma = rng.normal(0, 8e4, (m, 3))
    damage = rng.uniform(0, 0.9, m)
    damage[:50] = 0.0
    coh = rng.uniform(2.5e4, 5e4, m)
    td = rng.uniform(10, 40, m)
    heal = np.full(m, 1e-5)
    conc_factor = np.ones(m)
    s1, d1 = sigma.copy(), damage.copy()
    dc = rheo.damage_update(s1, d1, coh, 7.0, td, heal)
    s2, d2 = sigma.copy(), damage.copy()
    tri = np.zeros((m, 3), np.int64)
    zeros3 = np.zeros((m, 3))
    flag = np.zeros(m, np.int8)
    p = rheo.params
    kc, kt = envelope_factors(rheo)
    e_dt, gam = np.zeros(m), np.ones(m)
    kernel(tri, zeros3, zeros3, np.zeros((1, 2)), s2, d2, conc_factor, coh, kc, kt, td, heal, e_dt, gam, None,
           None, theta, None, None, None, 7.0, 1.0, 0.3, 0.7, rheo.q, rheo._denom, p.max_damage, p.E0,
           p.relaxation_time_s, p.alpha, flag, None)
    assert (dc < 1).sum() > 100
    if theta is not None:  # the path differs from the origin's where the correction acted
        s0, d0 = sigma.copy(), damage.copy()
        MaxwellEB().damage_update(s0, d0, coh, 7.0, td, heal)
        assert np.abs(s2 - s0).max() > 1e-3 * np.abs(s0).max()
    assert np.allclose(s2, s1, rtol=1e-13, atol=1e-13 * np.abs(s1).max())
    assert np.allclose(d2, d1, rtol=1e-13, atol=1e-15)
    assert not np.allclose(s1, sigma, rtol=1e-6)  # the correction acted
    assert np.array_equal(flag.astype(bool), dc < 1)
    # moduli refreshed where damage changed, as the rheology computes them
    E, lam = rheo.moduli(d1, np.ones(m))
    ch = d1 != damage
    assert ch.sum() > 100
    assert np.allclose(e_dt[ch], 7.0 * E[ch], rtol=1e-13, atol=0)
    assert np.allclose(gam[ch], lam[ch] / (lam[ch] + 7.0), rtol=1e-13, atol=0)


@pytest.mark.parametrize("kernel", [element_stress_damage_kernel, element_stress_damage_kernel_serial,
                                    element_stress_damage_kernel_a4, element_stress_damage_kernel_a4_serial])
def test_element_kernel_stress_update_uses_rheology_moduli(kernel):
    """One sub-step on damaged, partly open ice with a strain rate and no damage event
    (huge cohesion, no healing), with Δt_s E and γ = λ/(λ+Δt_s) from ``MaxwellEB.moduli``
    as the stepper's set-up gives them: σ = γ (σ0 + Δt_s E K:ε̇) to 1e-13 relative
    (K and the strain rate as the rheology defines them), for α = 4 and 4.5."""
    from lagice.fem import shape_gradients
    from lagice.mesh import renumber_for_locality

    poly, _ = rectangle_domain(40e3, 40e3)
    mesh = renumber_for_locality(generate_mesh(poly, 8e3))[0]
    m, n = mesh.n_elements, mesh.n_nodes
    rng = np.random.default_rng(3)
    b, c, _ = shape_gradients(mesh.nodes, mesh.triangles)
    vel = rng.normal(0, 0.05, (n, 2))
    a4 = kernel in (element_stress_damage_kernel_a4, element_stress_damage_kernel_a4_serial)
    for alpha in (4.0,) if a4 else (4.0, 4.5):
        rheo = MaxwellEB(alpha=alpha)
        p = rheo.params
        damage = rng.uniform(0, 0.95, m)
        conc = rng.uniform(0.8, 1.0, m)
        conc_factor = np.exp(-p.concentration_c * (1.0 - conc))
        sigma0 = rng.normal(0, 1e4, (m, 3))
        sigma, d = sigma0.copy(), damage.copy()
        dt_s = 3.0
        kc, kt = envelope_factors(rheo)
        E, lam = rheo.moduli(damage, conc)
        kernel(mesh.triangles.astype(np.int32), b, c, vel, sigma, d, conc_factor, np.full(m, 1e15), kc, kt,
               np.full(m, 20.0), np.zeros(m), dt_s * E, lam / (lam + dt_s), None, None, None, None, None, None, dt_s,
               *rheo.K[0, :2],
               rheo.K[2, 2], rheo.q, rheo._denom, p.max_damage, p.E0, p.relaxation_time_s, float(alpha),
               np.zeros(m, np.int8), None)
        eps = strain_rate(mesh.triangles, b, c, vel)
        ref = (lam / (lam + dt_s))[:, None] * (sigma0 + dt_s * E[:, None] * (eps @ rheo.K.T))
        assert np.array_equal(d, damage)
        assert np.allclose(sigma, ref, rtol=1e-13, atol=1e-13 * np.abs(ref).max())
        assert not np.allclose(sigma, sigma0, rtol=1e-3)  # the strain rate acted


def _failure_ray(rheo, seed, shrink, m=400):
    """400 elements with random damage d and cohesion C on the uniaxial-compression ray
    σ = −s σc ŷŷ (σc the intact uniaxial strength of C), s = shrink(d) × 1.001 for even elements
    (just outside the shrunk envelope) and × 0.999 for odd ones (just inside).
    Returns (rng, m, d, C, σ)."""
    from lagice.rheology.maxwell_eb import envelope

    rng = np.random.default_rng(seed)
    d = rng.uniform(0.0, 0.95, m)
    coh = rng.uniform(1e4, 3e4, m)
    s = shrink(d) * np.where(np.arange(m) % 2 == 0, 1.001, 0.999)
    sig = np.zeros((m, 3))
    sig[:, 1] = -s * envelope(coh, rheo.params.friction)[1]
    return rng, m, d, coh, sig


def _run_failure_kernel(kernel, rheo, eff, cohesion, sigma, damage, td=20.0):
    """One sub-step of the element kernel at zero strain rate (no relaxation, no healing,
    Δt = 7 s, damage time ``td``) on copies of σ and d, with the failure-stress power ``eff``;
    returns (σ, d, flags)."""
    m = len(damage)
    p = rheo.params
    kc, kt = envelope_factors(rheo)
    tri, zeros3 = np.zeros((m, 3), np.int32), np.zeros((m, 3))
    sg, dm, flag = sigma.copy(), damage.copy(), np.zeros(m, np.int8)
    kernel(tri, zeros3, zeros3, np.zeros((1, 2)), sg, dm, np.ones(m), cohesion, kc, kt, np.full(m, td),
           np.zeros(m), np.zeros(m), np.ones(m), None, None, None, None, eff, None, 7.0, *rheo.K[0, :2],
           rheo.K[2, 2], rheo.q, rheo._denom, p.max_damage, p.E0, p.relaxation_time_s, 4.0, flag, None)
    return sg, dm, flag

def _check_scaled_cohesion(kernel, rheo, rng, eff, coh, d, shrink):
    """Random stresses, some tensile, some confined: the kernel with the failure-stress power
    ``eff`` equals the nominal kernel run with the cohesion C shrink(d), bit for bit (stress,
    damage, flags), with some elements damaging and some not; the implicit solver's damage
    update (the rheology's; zero strain rate, γ = 1) damages the same elements, to round-off.
    Returns (σ, the kernel's result)."""
    m = len(d)
    sig = rng.normal(0, 2e4, (m, 3))
    sig[:, :2] -= rng.uniform(0, 3e4, (m, 1))
    a = _run_failure_kernel(kernel, rheo, eff, coh, sig, d)
    b = _run_failure_kernel(kernel, rheo, None, coh * shrink(d), sig, d)
    assert 50 < a[2].sum() < m - 50
    for x, y in zip(a, b):
        assert np.array_equal(x, y)
    si, di = sig.copy(), d.copy()
    dc = rheo.damage_update(si, di, coh, 7.0, np.full(m, 20.0), np.zeros(m))
    assert np.array_equal(dc < 1.0, a[2].astype(bool))
    assert np.allclose(si, a[0], rtol=1e-13, atol=1e-13 * np.abs(si).max())
    assert np.allclose(di, a[1], rtol=1e-13, atol=1e-15)
    return sig, a



@pytest.mark.parametrize("kernel", [element_stress_damage_kernel_serial, element_stress_damage_kernel_a4])
def test_effective_failure_stress(kernel):
    """``rheology.failure_stress = "effective"``: the envelope judges σ/(1 − d). (1) On the
    uniaxial-compression ray, σ = −s σc ŷŷ (σc the intact uniaxial strength of the element's
    cohesion C), an element of damage d damages when s > 1 − d and not when s < 1 − d (by a
    margin of 1e-3), while the nominal criterion damages none with s < 1. (2) Everywhere it is
    the nominal kernel run with the cohesion C (1 − d): stress, damage and flags bit for bit
    (the friction is kept, only the cohesion scales). (3) Other steppers and the nonlocal damage
    refuse it, naming the key; the implicit solver's damage update agrees with the kernel."""
    rheo = MaxwellEB(failure_stress="effective", friction=0.7)
    rng, m, d, coh, sig0 = _failure_ray(rheo, 11, lambda d: 1.0 - d)

    def run(eff, cohesion, sigma, damage):
        return _run_failure_kernel(kernel, rheo, eff, cohesion, sigma, damage)

    _, d_eff, f_eff = run(1.0, coh, sig0, d)
    assert np.array_equal(f_eff.astype(bool), np.arange(m) % 2 == 0)
    assert np.all(d_eff[::2] > d[::2]) and np.array_equal(d_eff[1::2], d[1::2])
    _, d_nom, f_nom = run(None, coh, sig0, d)
    assert not f_nom.any() and np.array_equal(d_nom, d)
    # (2) random stresses: the same as the nominal kernel with C (1 − d), and the implicit update agrees
    _check_scaled_cohesion(kernel, rheo, rng, 1.0, coh, d, lambda d: 1.0 - d)
    # (3) implemented in the CPU and CUDA steppers and the implicit solver (the CUDA kernel against
    # this one: tests/test_cuda_explicit.py, simulator variants "effective*"); with the nonlocal damage
    # in the CPU stepper (tests/test_nonlocal_damage.py)
    rheo.require_stepper("explicit_cuda")
    rheo.require_stepper("explicit")
    rheo.require_stepper("implicit")
    with pytest.raises(ConfigError, match="rheology.failure_stress = 'plastic': expected one of"):
        MaxwellEB(failure_stress="plastic")


@pytest.mark.parametrize("kernel", [element_stress_damage_kernel_serial, element_stress_damage_kernel_a4])
def test_energy_equivalent_failure_stress(kernel):
    """``rheology.failure_stress = "energy"``: the envelope judges σ/√(1 − d), the effective stress
    of strain-energy equivalence for the modulus E0 (1 − d). (1) On the uniaxial-compression ray
    σ = −s σc ŷŷ an element of damage d damages when s > √(1 − d) and not when s < √(1 − d) (margin
    1e-3). (2) Its correction converges: from 50 % beyond the shrunk envelope, 40 full corrections
    (td = Δt, zero strain rate) bring σ back onto σc √(1 − d) with 1 − d lowered 1.5² times, where
    the effective criterion, whose correction does not move σ/(1 − d), runs to the cap. (3) Everywhere it
    is the nominal kernel run with the cohesion C √(1 − d), bit for bit, and the implicit solver's
    update agrees. (4) The CUDA stepper refuses it, naming the key and value."""
    from lagice.rheology.maxwell_eb import envelope

    rheo = MaxwellEB(failure_stress="energy", friction=0.7)
    p = rheo.params
    rng, m, d, coh, sig0 = _failure_ray(rheo, 12, lambda d: np.sqrt(1.0 - d))
    sigma_c = envelope(coh, p.friction)[1]
    root = np.sqrt(1.0 - d)

    def run(eff, cohesion, sigma, damage, td=20.0):
        return _run_failure_kernel(kernel, rheo, eff, cohesion, sigma, damage, td)

    _, d_en, f_en = run(0.5, coh, sig0, d)
    assert np.array_equal(f_en.astype(bool), np.arange(m) % 2 == 0)
    assert np.all(d_en[::2] > d[::2]) and np.array_equal(d_en[1::2], d[1::2])
    # (2) 50 % beyond each element's shrunk envelope, td = Δt (a sub-step applies the whole
    # correction factor k = 1/ρ to σ and 1 − d), no strain, no relaxation, no healing: the ratio ρ of
    # σ/√(1 − d) to the envelope goes to √ρ each sub-step, so 1 − d converges to (1 − d0)/1.5² and σ
    # to the envelope. The effective criterion's ratio σ/(1 − d) does not move, so it damages by
    # the same factor every sub-step, to the cap.
    sig_big = np.zeros((m, 3))
    sig_big[:, 1] = -1.5 * root * sigma_c
    sg, dn, se, de = sig_big, d, sig_big, d
    for _ in range(40):
        sg, dn, _ = run(0.5, coh, sg, dn, td=7.0)
        se, de, _ = run(1.0, coh, se, de, td=7.0)
    assert np.allclose((1.0 - dn) / (1.0 - d), 1.0 / 1.5 ** 2, rtol=1e-9)
    assert np.allclose(-sg[:, 1], sigma_c * np.sqrt(1.0 - dn), rtol=1e-9)
    assert np.all(de >= min(p.max_damage, 1.0 - 1e-6))
    # (3) random stresses: the same as the nominal kernel with C √(1 − d), and the implicit update
    # agrees; and not the effective criterion's result
    sig, a = _check_scaled_cohesion(kernel, rheo, rng, 0.5, coh, d, lambda d: np.sqrt(1.0 - d))
    assert not np.array_equal(run(1.0, coh, sig, d)[1], a[1])
    # (4) the CPU stepper and the implicit solver implement it; the CUDA stepper refuses it
    rheo.require_stepper("explicit")
    rheo.require_stepper("implicit")
    with pytest.raises(ConfigError, match="failure_stress = 'energy': the CUDA explicit stepper .* does not implement"):
        rheo.require_stepper("explicit_cuda")


@pytest.mark.parametrize("kernel", [element_stress_damage_kernel_serial, element_stress_damage_kernel_a4])
def test_crack_closure_builds_the_mean_stress_of_compressed_broken_ice_with_the_undamaged_modulus(kernel):
    """``rheology.crack_closure`` (quasi-unilateral damage, with ``relax_mean_stress`` false): one
    sub-step of a uniform strain rate on a real mesh, no damage event (huge cohesion, no healing),
    no relaxation (γ = 1). (1) Converging from σ = 0, broken ice (d = 0.99) builds the mean stress
    m = Δt_s E0 g tr(ε̇)/(2(1 − ν)) of intact ice (g the concentration factor), where the damaged
    modulus gives 1 − d of it; its deviator keeps the damaged modulus. (2) Diverging from a
    compressed state, the mean unloads with the undamaged modulus down to 0, and the rest of the
    step's opening adds tension with the damaged one. (3) A tensile element that converges takes
    the damaged modulus down to 0 and the undamaged one beyond. (4) Intact ice is unchanged to
    round-off. (5) Refusals: without relax_mean_stress false, and by the CUDA stepper and the
    implicit solver, naming the key."""
    from lagice.fem import shape_gradients

    poly, _ = rectangle_domain(40e3, 40e3)
    mesh = generate_mesh(poly, 8e3)
    m = mesh.n_elements
    b, c, _ = shape_gradients(mesh.nodes, mesh.triangles)
    tri = mesh.triangles.astype(np.int32)
    rheo = MaxwellEB(relax_mean_stress=False, crack_closure=True)
    p = rheo.params
    kc, kt = envelope_factors(rheo)
    dt_s = 5.0
    g = np.full(m, 0.8)
    d = np.full(m, 0.99)
    d[: m // 4] = 0.0  # a quarter intact
    E, lam = rheo.moduli(d, np.full(m, 1.0 + np.log(0.8) / p.concentration_c))
    assert np.allclose(E, p.E0 * (1.0 - d) * g, rtol=1e-12)
    kb = 0.5 * (rheo.K[0, 0] + rheo.K[0, 1])  # 1/(2(1 − ν))

    def run(closure, rate, sigma0, shear=0.0):
        """One sub-step under the velocity field u = rate·x (+ a simple shear)."""
        vel = rate * mesh.nodes + shear * np.column_stack([mesh.nodes[:, 1], 0.0 * mesh.nodes[:, 0]])
        sg, dm, flag = sigma0.copy(), d.copy(), np.zeros(m, np.int8)
        kernel(tri, b, c, vel, sg, dm, g, np.full(m, 1e15), kc, kt, np.full(m, 20.0), np.zeros(m), dt_s * E,
               np.ones(m), None, np.inf, None, None, None, closure, dt_s, *rheo.K[0, :2], rheo.K[2, 2], rheo.q,
               rheo._denom, p.max_damage, p.E0, p.relaxation_time_s, 4.0, flag, None)
        assert np.array_equal(dm, d) and not flag.any()
        return sg

    broken = d > 0
    mean = lambda s: 0.5 * (s[:, 0] + s[:, 1])  # noqa: E731
    dev = lambda s: np.column_stack([0.5 * (s[:, 0] - s[:, 1]), s[:, 2]])  # noqa: E731
    intact_mean = dt_s * p.E0 * g * kb * (2 * -1e-7)  # tr(ε̇) = −2e-7 s-1
    # (1) convergence from rest
    zero = np.zeros((m, 3))
    on, off = run(True, -1e-7, zero, shear=3e-8), run(None, -1e-7, zero, shear=3e-8)
    assert np.allclose(mean(on)[broken], intact_mean[broken], rtol=1e-12)
    assert np.allclose(mean(off)[broken], (1.0 - d[broken]) * intact_mean[broken], rtol=1e-12)
    assert np.allclose(dev(on), dev(off), rtol=0, atol=1e-12 * np.abs(dev(off)).max())
    assert np.abs(dev(off)[broken]).max() > 0
    # (4) intact ice: the same to round-off
    assert np.allclose(on[~broken], off[~broken], rtol=1e-13, atol=1e-13 * np.abs(off).max())
    # (2) divergence from a compressed state: unload with E0 g to 0, then open with E0 (1 − d) g
    p0 = 0.25 * np.abs(intact_mean)  # the step's undamaged unloading (|intact_mean|) overshoots it 4×
    sig_c = np.column_stack([-p0, -p0, np.zeros(m)])
    on = run(True, 1e-7, sig_c)
    expect = (1.0 - d) * (np.abs(intact_mean) - p0)
    assert np.allclose(mean(on)[broken], expect[broken], rtol=1e-10)
    assert np.all(mean(on)[broken] > 0)
    off = run(None, 1e-7, sig_c)
    assert np.allclose(mean(off)[broken], (-p0 + (1.0 - d) * np.abs(intact_mean))[broken], rtol=1e-10)
    # (3) convergence from tension: the damaged modulus to 0, the undamaged beyond
    t0 = 0.5 * (1.0 - d) * np.abs(intact_mean)  # half the step's damaged increment
    sig_t = np.column_stack([t0, t0, np.zeros(m)])
    on = run(True, -1e-7, sig_t)
    expect = -(np.abs(intact_mean) - t0 / (1.0 - d))
    assert np.allclose(mean(on)[broken], expect[broken], rtol=1e-10)
    # (5) refusals
    with pytest.raises(ConfigError, match="crack_closure = true needs rheology.relax_mean_stress = false"):
        MaxwellEB(crack_closure=True)
    rheo.require_stepper("explicit_cuda")  # the CUDA kernel against this one: simulator variants "closure*"
    from lagice.solvers.cuda_explicit import check_cuda_substep_limit

    assert check_cuda_substep_limit("element", False) == "element" and check_cuda_substep_limit("mesh", True) == "mesh"
    with pytest.raises(ConfigError, match=r"solver\.substep_limit = 'element' with rheology\.crack_closure = true: "
                                          r"the CUDA stepper does not implement"):
        check_cuda_substep_limit("element", True)
    with pytest.raises(ConfigError, match=r"implicit solver .* does not implement"):  # names its first term
        rheo.require_stepper("implicit")
    rheo.require_stepper("explicit")


def test_crack_closure_sets_the_substep_limit_with_the_undamaged_modulus(tmp_path):
    """With ``crack_closure`` the mean stress of closed cracks responds with E0 exp(−c*(1−A)), so
    a pack damaged everywhere (d = 0.9, E ten times lower) must keep the sub-steps of undamaged
    ice; without it the count follows the damaged E_max (a third of them: sqrt(10))."""
    import math

    from lagice.stability import explicit_substep_limit

    counts = {}
    for tag, ov in (("off", {}), ("on", {"rheology.crack_closure": True, "rheology.relax_mean_stress": False})):
        sim = scene_sim("wind_square", tmp_path / tag,
                        {"domain.resolution_m": 25e3, "run.duration": "1h", "output.timeseries": None,
                         "lagrangian.enabled": False, **ov})
        sim.model.state.damage = np.full(sim.model.mesh.n_elements, 0.9)
        sim.run(n_steps=1)
        st = sim.model.stepper
        counts[tag] = st.last_substeps
        assert np.isfinite(sim.model.state.velocity).all()
    E0 = st.rheology.params.E0
    assert counts["on"] == math.ceil(sim.dt / (0.7 * explicit_substep_limit(st.dx_min, E0)))
    assert counts["off"] == math.ceil(sim.dt / (0.7 * explicit_substep_limit(st.dx_min, 0.1 * E0)))
    assert counts["on"] >= 2.5 * counts["off"]


def test_alpha4_builds_equal_general_builds():
    """The α = 4 builds (λ = λ0 x³ compiled in) give bit for bit what the general kernel
    gives with α = 4 (stress, damage, flags and the refreshed moduli), on a sub-step where
    some elements damage and others heal."""
    rng = np.random.default_rng(5)
    poly, _ = rectangle_domain(40e3, 40e3)
    from lagice.fem import shape_gradients

    mesh = generate_mesh(poly, 6e3)
    m, n = mesh.n_elements, mesh.n_nodes
    b, c, _ = shape_gradients(mesh.nodes, mesh.triangles)
    rheo = MaxwellEB()
    p = rheo.params
    kc, kt = envelope_factors(rheo)
    vel = rng.normal(0, 0.2, (n, 2))
    sigma0 = rng.normal(0, 3e4, (m, 3))
    damage0 = rng.uniform(0, 1, m)
    coh = rng.uniform(1e4, 4e4, m)
    dt_s = 20.0
    E, lam = rheo.moduli(damage0, np.full(m, 0.99))
    out = []
    for kernel in (element_stress_damage_kernel_serial, element_stress_damage_kernel_a4_serial,
                   element_stress_damage_kernel, element_stress_damage_kernel_a4):
        sigma, d, flag = sigma0.copy(), damage0.copy(), np.zeros(m, np.int8)
        e_dt, gam = dt_s * E, lam / (lam + dt_s)
        capped = kernel(mesh.triangles.astype(np.int32), b, c, vel, sigma, d, np.full(m, 0.9),
                        coh, kc, kt, np.full(m, 30.0), np.full(m, 1e-6), e_dt, gam, None, None, None, None, None, None,
                        dt_s, *rheo.K[0, :2],
                        rheo.K[2, 2], rheo.q, rheo._denom, p.max_damage, p.E0, p.relaxation_time_s, 4.0, flag, None)
        out.append((sigma, d, flag, capped, e_dt, gam))
    assert 0 < out[0][2].sum() < m  # some elements damage, some do not
    assert np.any(out[0][1] < damage0)  # some heal
    assert not np.array_equal(out[0][4], dt_s * E)  # the moduli were refreshed
    for o in out[1:]:
        assert np.array_equal(o[0], out[0][0]) and np.array_equal(o[1], out[0][1])
        assert np.array_equal(o[2], out[0][2]) and o[3] == out[0][3]
        assert np.array_equal(o[4], out[0][4]) and np.array_equal(o[5], out[0][5])


def test_node_kernel_matches_general_2x2_solve():
    """The node kernel solves its 2×2 system as a scaled rotation; the general solve
    (``lagice.fem.solve_node_2x2``, as the CUDA kernel and mEVP do) of the same system, with
    free, half-prescribed and prescribed nodes and a turning angle, gives the same velocity
    to 1e-13 relative, and the gathered force is −Σ w·σ."""
    from lagice.fem import solve_node_2x2
    from lagice.solvers.explicit import node_velocity_kernel_serial

    poly, _ = rectangle_domain(40e3, 40e3)
    mesh = generate_mesh(poly, 6e3)
    ptr, elems, _local = mesh.node_elements
    n, m = mesh.n_nodes, mesh.n_elements
    rng = np.random.default_rng(11)
    sigma = rng.normal(0, 2e4, (m, 3))
    w = rng.normal(0, 1e7, (len(elems), 2))
    m_dt, cda, mass = rng.uniform(1e5, 1e6, n), rng.uniform(1e5, 1e7, n), rng.uniform(1e9, 1e10, n)
    cor = np.full(n, 1.4e-4)
    fext, cur = rng.normal(0, 1e6, (n, 2)), rng.normal(0, 0.1, (n, 2))
    fixed = np.zeros((n, 2), np.int8)
    fixed[::7, 0] = 1
    fixed[::5, 1] = 1
    pres0, pres1 = rng.normal(0, 0.1, (n, 2)), rng.normal(0, 0.1, (n, 2))
    vel0 = rng.normal(0, 0.2, (n, 2))
    cos_t, sin_t = np.cos(0.4), np.sin(0.4)
    vel, vsum = vel0.copy(), np.zeros((n, 2))
    node_velocity_kernel_serial(vel, vsum, sigma, ptr.astype(np.int32), elems.astype(np.int32), w,
                                node_constants_reference(m_dt, cda, mass, cor, fext, cur), cos_t, sin_t, fixed, pres0,
                                pres1, 0.25)
    ref = np.empty((n, 2))
    for i in range(n):
        pu, pv = pres0[i] + 0.25 * (pres1[i] - pres0[i])
        if fixed[i, 0] and fixed[i, 1]:
            ref[i] = pu, pv
            continue
        f = np.zeros(2)
        for p in range(ptr[i], ptr[i + 1]):
            sxx, syy, sxy = sigma[elems[p]]
            f -= (w[p, 0] * sxx + w[p, 1] * sxy, w[p, 0] * sxy + w[p, 1] * syy)
        u, v = vel0[i]
        cd = cda[i] * np.hypot(cur[i, 0] - u, cur[i, 1] - v)
        hf = 0.5 * mass[i] * cor[i]
        a11 = a22 = m_dt[i] + cd * cos_t
        a12, a21 = -cd * sin_t - hf, cd * sin_t + hf
        rx = m_dt[i] * u + f[0] + fext[i, 0] + cd * (cos_t * cur[i, 0] - sin_t * cur[i, 1]) + hf * v
        ry = m_dt[i] * v + f[1] + fext[i, 1] + cd * (sin_t * cur[i, 0] + cos_t * cur[i, 1]) - hf * u
        ref[i] = solve_node_2x2(a11, a12, a21, a22, rx, ry, fixed[i, 0], fixed[i, 1], pu, pv)
    assert fixed[:, 0].sum() and fixed[:, 1].sum() and (fixed.sum(axis=1) == 2).sum()
    assert np.allclose(vel, ref, rtol=1e-13, atol=1e-13 * np.abs(ref).max())
    assert np.array_equal(vsum, vel)


def test_fused_node_setup_equals_the_separate_passes_bit_for_bit():
    """The stepper's one-pass set-up (``NODE_SETUP``, serial and parallel builds) gives the
    adjacency weights, the per-node constants and the lumped mass of
    ``NodeSystem.setup`` + the constants from their parts bit for bit, on a gmsh mesh with a non-uniform
    thickness, wind stress, Coriolis parameter, drag and current: the published runs stay
    reproducible by the code that ships."""
    from lagice.fem import NodeSystem
    from lagice.forces import ExplicitTerms
    from lagice.solvers.explicit import NODE_SETUP

    poly, _ = rectangle_domain(60e3, 40e3)
    mesh = generate_mesh(poly, 5e3)
    nodes = mesh.nodes.copy()
    rng = np.random.default_rng(3)
    mesh.nodes[:] = nodes + rng.normal(0, 300.0, nodes.shape)  # non-uniform geometry
    ns = NodeSystem(mesh)
    n, m = mesh.n_nodes, mesh.n_elements
    h = rng.uniform(0.1, 3.0, m)
    terms = ExplicitTerms(rng.normal(0, 0.2, (n, 2)), rng.uniform(4.0, 6.0, n), rng.normal(0, 0.1, (n, 2)),
                          rng.uniform(1.2e-4, 1.45e-4, n))
    rho, dt_sub = 917.0, 3.7
    su = ns.setup(h, terms, rho, dt_sub, True)
    nc_ref = node_constants_reference(su.m_dt, su.cda, su.mass, terms.coriolis, su.fext, terms.current)
    ptr, elems, local = mesh.node_elements
    for build in NODE_SETUP:
        w, nc, mass = build(ptr, elems, local, ns.area, h, ns.b, ns.c, rho, dt_sub, terms.tau, terms.drag_coef,
                            terms.coriolis, terms.current)
        assert np.array_equal(w, su.w)
        assert np.array_equal(nc, nc_ref)
        assert np.array_equal(mass, su.mass)
    assert np.ptp(su.mass) > 0 and np.ptp(nc_ref[:, 2]) > 0  # the inputs did vary


def test_moduli_from_a_shared_concentration_factor_equal_the_rheology_functions():
    """``MaxwellEB.moduli`` with the stepper's shared exp(−c*(1−A)) equals the moduli
    computed with their own exponentials (``young_modulus``, ``relaxation_time``) bit for
    bit, for α = 4 and 5."""
    from lagice.params import MaxwellEBParams

    rng = np.random.default_rng(4)
    d, a = rng.uniform(0, 0.99, 5000), rng.uniform(0.5, 1.0, 5000)
    for alpha in (4.0, 5.0):
        rh = MaxwellEB(MaxwellEBParams(alpha=alpha))
        E, lam = rh.moduli(d, a)
        E2, lam2 = rh.moduli(d, a, rh.concentration_factor(a))
        assert np.array_equal(E, E2) and np.array_equal(lam, lam2)
        assert np.ptp(E) > 0


def test_patch_uniform_strain_rate(plate_mesh):
    """Linear velocity prescribed on the whole boundary of an irregular mesh:
    interior forces cancel, velocity stays linear, stress follows the sub-step
    recursion σ ← γ(σ + Δt_s E K ε̇) uniformly."""
    mesh = plate_mesh
    rheo = MaxwellEB(cohesion_min_pa=1e12, cohesion_max_pa=1e12)
    bcs = [VelocityBC(t, u=linear_velocity(0), v=linear_velocity(1)) for t in ("bottom", "right", "top", "left")]
    s = ExplicitSolver(rheo, mesh, bcs=bcs, substeps=4)
    st = IceState.uniform(mesh, cohesion_pa=1e12)
    st.velocity = mesh.nodes @ G.T
    eps = np.array([G[0, 0], G[1, 1], 0.5 * (G[0, 1] + G[1, 0])])
    dts = 5.0
    lam = rheo.params.relaxation_time_s
    gamma = lam / (lam + dts)
    sigma = np.zeros(3)
    for _ in range(3):
        step(s, st, 4 * dts)
        for _ in range(4):
            sigma = gamma * (sigma + dts * rheo.E0 * rheo.K @ eps)
    ref = mesh.nodes @ G.T
    assert np.abs(st.velocity - ref).max() < 1e-10 * np.abs(ref).max()
    assert np.abs(st.stress - sigma).max() < 1e-8 * np.abs(sigma).max()


def test_maxwell_relaxation_and_coast_no_slip():
    poly, _ = rectangle_domain(50e3, 50e3)
    mesh = generate_mesh(poly, 10e3)  # all coast
    rheo = MaxwellEB(relaxation_time_s=900.0, healing_time_s=None)
    s = ExplicitSolver(rheo, mesh, substeps=6)
    st = IceState.uniform(mesh, cohesion_pa=1e12)
    s0 = np.array([-3e4, 1e4, 5e3])
    st.stress[:] = s0
    for n in range(1, 4):
        step(s, st, 30.0)
        assert np.allclose(st.stress, s0 * (900.0 / 905.0) ** (6 * n), rtol=1e-12, atol=0)
    assert np.abs(st.velocity).max() < 1e-15  # every node is coast here
    assert s.name == "explicit" and SOLVERS["explicit"] is ExplicitSolver


def stress_at_rest(rheo, mesh, stress0, n_steps, dts, **state):
    """The stress after ``n_steps`` outer steps of 6 sub-steps of ``dts`` [s] from a uniform
    ``stress0`` on an all-coast mesh: no node moves (asserted), so only the element update
    (relaxation, compressive term, dilatancy) acts."""
    s = ExplicitSolver(rheo, mesh, substeps=6)
    st = IceState.uniform(mesh, cohesion_pa=1e12, **state)
    st.stress[:] = stress0
    for _ in range(n_steps):
        step(s, st, 6 * dts)
    assert np.abs(st.velocity).max() < 1e-12
    return st.stress


def test_max_pressure_relaxation_follows_nextsim():
    """neXtSIM's compressive term (``rheology.max_pressure_pa``): with no motion (uniform
    stress, boundary nodes coast) an isotropic stress −p I relaxes by
    λ/(λ + Δt_s (1 − P_max/p)) per sub-step while p > P_max = P* h^1.5: towards P_max, not
    to 0 (the discrete recursion to 1e-12, and the continuous p − P_max ∝ e^(−t/λ) to
    1 %); below P_max it does not relax at all, and in tension it relaxes as without the
    term (γ^n, as in the test above)."""
    poly, _ = rectangle_domain(50e3, 50e3)
    mesh = generate_mesh(poly, 10e3)
    lam, dts, h, n_steps = 900.0, 5.0, 2.0, 120
    rheo = MaxwellEB(relaxation_time_s=lam, healing_time_s=None, max_pressure_pa=10e3)
    pmax = 10e3 * h ** 1.5
    assert np.allclose(rheo.max_pressure(np.full(3, h), np.ones(3)), pmax, rtol=1e-14)

    def run(s0):
        return stress_at_rest(rheo, mesh, s0, n_steps, dts, thickness_m=h)

    p_ref = 3.0 * pmax
    for _ in range(6 * n_steps):
        p_ref = p_ref * lam / (lam + dts * (1.0 - pmax / p_ref))
    above = run([-3.0 * pmax, -3.0 * pmax, 0.0])
    assert np.allclose(above[:, :2], -p_ref, rtol=1e-12, atol=0)
    assert np.abs(above[:, 2]).max() < 1e-9 * pmax
    t = 6 * n_steps * dts
    assert p_ref == pytest.approx(pmax + 2.0 * pmax * np.exp(-t / lam), rel=1e-2)
    assert pmax < p_ref < 1.1 * pmax  # relaxed most of the way, and not below P_max
    below = run([-0.5 * pmax, -0.5 * pmax, 0.0])
    assert np.allclose(below[:, :2], -0.5 * pmax, rtol=1e-12, atol=0)  # elastic: no creep
    s_t = np.array([2e3, 1e3, 5e2])  # mean stress tensile: the term does not act
    assert np.allclose(run(s_t), s_t * (lam / (lam + dts)) ** (6 * n_steps), rtol=1e-12, atol=0)


def test_max_pressure_is_refused_where_it_is_not_implemented():
    """The implicit solver does not implement the term and must not silently ignore it
    (scenes: tests/test_compression.py::test_bad_input_fails_before_meshing)."""
    from lagice.solvers.implicit import ImplicitSolver
    with pytest.raises(ConfigError, match="max_pressure_pa = 10000.0: the implicit solver .* does not implement it"):
        ImplicitSolver(MaxwellEB(max_pressure_pa=10e3), mesh=None)


def test_deviatoric_relaxation_keeps_the_mean_stress():
    """``rheology.relax_mean_stress = False``: with no motion (uniform stress, boundary nodes
    coast) a stress m I + s relaxes to m I + s γ^n, γ = λ/(λ + Δt_s): the mean normal stress
    does not creep, where the default relaxes the whole tensor by γ^n. With neXtSIM's
    compressive term as well, the mean follows that term's recursion towards P_max (as in
    the test above) while the deviator still decays by γ^n; below P_max the mean is kept."""
    poly, _ = rectangle_domain(50e3, 50e3)
    mesh = generate_mesh(poly, 10e3)
    lam, dts, h, n_steps = 900.0, 5.0, 2.0, 120
    gn = (lam / (lam + dts)) ** (6 * n_steps)
    dev = np.array([2e3, -2e3, 1e3])

    def run(mean, **kw):
        return stress_at_rest(MaxwellEB(relaxation_time_s=lam, healing_time_s=None, **kw), mesh,
                              dev + [mean, mean, 0.0], n_steps, dts, thickness_m=h)

    m0 = -30e3
    whole = run(m0)
    assert np.allclose(whole, (dev + [m0, m0, 0.0]) * gn, rtol=1e-12, atol=0)
    kept = run(m0, relax_mean_stress=False)
    assert np.allclose(kept, dev * gn + [m0, m0, 0.0], rtol=1e-12, atol=1e-9)
    assert gn < 0.1  # the deviator relaxed by more than 90 %: the test can tell the two apart
    pmax = 10e3 * h ** 1.5
    p_ref = 3.0 * pmax
    for _ in range(6 * n_steps):
        p_ref = p_ref * lam / (lam + dts * (1.0 - pmax / p_ref))
    both = run(-3.0 * pmax, relax_mean_stress=False, max_pressure_pa=10e3)
    assert np.allclose(both, dev * gn + [-p_ref, -p_ref, 0.0], rtol=1e-12, atol=1e-9)
    below = run(-0.5 * pmax, relax_mean_stress=False, max_pressure_pa=10e3)
    assert np.allclose(below, dev * gn + [-0.5 * pmax, -0.5 * pmax, 0.0], rtol=1e-12, atol=1e-9)


def test_deviatoric_relaxation_is_refused_where_it_is_not_implemented():
    from lagice.solvers.implicit import ImplicitSolver
    with pytest.raises(ConfigError, match="relax_mean_stress = false: the implicit solver .* does not implement it"):
        ImplicitSolver(MaxwellEB(relax_mean_stress=False), mesh=None)
    with pytest.raises(ConfigError, match="relax_mean_stress = 1: expected true or false"):
        MaxwellEB(relax_mean_stress=1)


def test_partial_dirichlet_component():
    """A VelocityBC prescribing only v leaves u free; values are interpolated in
    time across the outer step so the end value is exact."""
    poly, segs = rectangle_domain(40e3, 40e3)
    mesh = generate_mesh(poly, 10e3, segments=segs, exterior_tag="free")
    rheo = MaxwellEB(healing_time_s=None)
    s = ExplicitSolver(rheo, mesh, bcs=[VelocityBC("top", v=lambda t, x, y: -1e-6 * t + 0 * x)],
                       substeps=5)
    st = IceState.uniform(mesh, cohesion_pa=1e12)
    step(s, st, 20.0)
    top = mesh.nodes_with_tag("top")
    assert np.allclose(st.velocity[top, 1], -2e-5, rtol=1e-14)
    assert np.abs(st.velocity[top, 0]).max() > 0  # u free (Poisson effect)


def first_peak(stress_c):
    return int(np.argmax(stress_c))


@pytest.fixture(scope="module")
def compression_pair(tmp_path_factory):
    # small mesh: one numba thread (fork/join of parallel kernels costs more than the
    # work here, and much more on a loaded machine)
    import numba

    nthreads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        return _run_compression_pair(tmp_path_factory.mktemp("pair"))
    finally:
        numba.set_num_threads(nthreads)


def _run_compression_pair(tmp):
    out = {}
    for solver in ("implicit", "explicit"):
        sim = scene_sim("uniaxial_compression", tmp / solver, compression_overrides(
            10, **{"solver.name": solver, "healing.law": "none", "run.duration": 3000 * 20.0}))
        sim.run()
        out[solver] = (-series(sim, "macro_stress"), sim.model)
    return out


def test_compression_stress_strain_agrees_with_implicit(compression_pair):
    """N = 10, Δt = td = 20 s (explicit: automatic sub-steps): the macroscopic
    stress–strain curves agree within 5 % of the peak up to the first
    macroscopic failure, and so do the peak stress and the strain where both
    curves reach 95 % of the lower peak."""
    a, sa = compression_pair["implicit"]
    b, sb = compression_pair["explicit"]
    assert sb.stepper.last_substeps >= 2
    ia, ib = first_peak(a), first_peak(b)
    assert 0 < ia < len(a) - 50 and 0 < ib < len(b) - 50, "no macroscopic failure"
    assert b[ib] == pytest.approx(a[ia], rel=0.05)
    # strain at which each curve first reaches 95 % of its peak (the peak itself sits
    # on a flat top and is a poor marker)
    level = 0.95 * min(a[ia], b[ib])
    ka, kb = int(np.argmax(a >= level)), int(np.argmax(b >= level))
    assert kb == pytest.approx(ka, rel=0.05)
    k = int(0.95 * min(ia, ib))
    assert np.abs(a[:k] - b[:k]).max() < 0.05 * a[ia]
    # both damaged after the failure
    assert sa.state.damage.max() > 0.5 and sb.state.damage.max() > 0.5


def test_stability_refusal_and_warning(tmp_path):
    explicit = compression_overrides(10, **{"solver.name": "explicit", "run.duration": 200.0})
    sim = scene_sim("uniaxial_compression", tmp_path / "a", {**explicit, "solver.substeps": 1})
    with pytest.raises(ConfigError, match=r"explicit sub-step dt_s = 20 s exceeds the measured "
                                          r"stability limit .* by a factor"):
        sim.run(n_steps=1)
    sim = scene_sim("uniaxial_compression", tmp_path / "b",
                    {**explicit, "solver.substeps": 1, "solver.allow_unstable": True})
    with pytest.warns(StabilityWarning, match="elastic-wave limit"):
        sim.run(n_steps=1)
    # automatic sub-steps respect the limit with the safety factor
    sim = scene_sim("uniaxial_compression", tmp_path / "c", explicit)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sim.run(n_steps=1)
    st = sim.model.stepper
    lim = explicit_substep_limit(st.dx_min, st.rheology.E0)
    assert sim.dt / st.last_substeps <= 0.7 * lim
    assert sim.dt / (st.last_substeps - 1) > 0.7 * lim
    assert load_limits()["explicit"]["C"] > 0


def test_bad_options(plate_mesh):
    rheo = MaxwellEB()
    with pytest.raises(ConfigError, match="substeps"):
        ExplicitSolver(rheo, plate_mesh, substeps=0)
    with pytest.raises(ConfigError, match="unknown boundary tag 'north'"):
        ExplicitSolver(rheo, plate_mesh, bcs=[VelocityBC("north", v=1.0)])
    s = ExplicitSolver(rheo, plate_mesh)
    with pytest.raises(ConfigError, match="dt"):
        step(s, IceState.uniform(plate_mesh, cohesion_pa=3e4), -1.0)


def test_implicit_limit_named_when_measured(monkeypatch):
    """If a limit for the implicit solver is ever shipped, a too-large Δt is refused
    (or warned about) naming the limit; today none is (stable to 1024 td)."""
    import lagice.stability as stab

    assert stab.implicit_step_limit(10e3) is None
    fake = {"explicit": {"C": 0.92}, "implicit": {"dt_over_td_max": 4.0}}
    monkeypatch.setattr(stab, "load_limits", lambda path=None: fake)
    with pytest.raises(ConfigError, match=r"implicit dt = 100 s exceeds .* limit 80 s by a factor 1.25"):
        stab.check_implicit_step(100.0, 10e3)
    with pytest.warns(StabilityWarning, match="dt <= 4 td"):
        stab.check_implicit_step(100.0, 10e3, allow_unstable=True)
    assert stab.check_implicit_step(50.0, 10e3) == pytest.approx(80.0)


def test_explicit_stepper_refuses_the_associated_correction():
    """The associated damage correction is in the implicit solver only; the explicit
    stepper must not silently correct towards the origin instead."""
    with pytest.raises(ConfigError, match="stress_correction = 'associated': the explicit CPU stepper .* implements "
                                          "origin, mean_stress only"):
        ExplicitSolver(MaxwellEB(stress_correction="associated"), mesh=None)
    # the CUDA stepper (which calls this before anything else once a GPU is found) has the CPU
    # stepper's paths and optional terms (since 2026-11-28), and not the associated path either
    with pytest.raises(ConfigError, match="stress_correction = 'associated': the CUDA explicit stepper .* implements "
                                          "origin, mean_stress only"):
        MaxwellEB(stress_correction="associated").require_stepper("explicit_cuda")
    MaxwellEB(stress_correction="mean_stress").require_stepper("explicit_cuda")
    # the optional terms: one table (maxwell_eb.OPTIONAL_TERMS) for the builder and every stepper
    for term in ({"max_pressure_pa": 10e3}, {"relax_mean_stress": False}, {"dilatancy_angle_deg": 20.0}):
        MaxwellEB(**term).require_stepper("explicit_cuda")  # implemented there
    from lagice.solvers.prescribed import PrescribedStepper
    mesh = generate_mesh(rectangle_domain(20e3, 20e3)[0], 10e3)
    for term in ({"max_pressure_pa": 10e3}, {"relax_mean_stress": False}, {"dilatancy_angle_deg": 20.0}):
        MaxwellEB(**term).require_stepper("explicit")
        with pytest.raises(ConfigError, match="the prescribed-velocity stepper .* does not implement it"):
            PrescribedStepper(MaxwellEB(**term), mesh=mesh, velocity=(0.1, 0.0))
    assert PrescribedStepper(MaxwellEB(), mesh=mesh, velocity=(0.1, 0.0)).rheology is not None


def test_elementwise_stability_bound(tmp_path):
    """``solver.substep_limit = "element"`` applies the sub-step limit element by element
    (lagice.stability.effective_dx): C min_e Δx_e / sqrt(E_e/ρ) instead of the default
    C Δx_min / sqrt(E_max/ρ). With the smaller half of the elements damaged to d = 0.9
    (E ten times lower) its automatic count is below the default's, and the run at that
    count stays bounded; with half that count (beyond the element-wise limit) the same
    run blows up, so the bound is what keeps it stable, not a margin. A bad value is
    refused before meshing, naming the key."""
    import math

    from lagice.stability import effective_dx, explicit_substep_limit

    def sim_with_damaged_small_elements(sub, overrides=None):
        sim = scene_sim("wind_square", tmp_path / sub,
                        {"domain.resolution_m": 25e3, "run.duration": "1h", "forcing.wind.params.ramp_h": 0.0,
                         "rheology.cohesion_min_pa": 1e12, "rheology.cohesion_max_pa": 2e12,
                         "lagrangian.enabled": False, "output.timeseries": None,
                         "solver.substep_limit": "element", **(overrides or {})})
        st = sim.model.state
        size = np.sqrt(2.0 * np.abs(st.mesh.areas()))
        d = np.where(size < np.median(size), 0.9, 0.0)
        st.damage = d
        return sim, size, d

    sim, size, d = sim_with_damaged_small_elements("auto")
    rh = sim.model.stepper.rheology
    E, _ = rh.moduli(d, np.ones_like(d))
    # the invariant: Δx_eff = min_e Δx_e sqrt(E_max/E_e), never below Δx_min
    area = np.abs(sim.model.mesh.areas())
    dx_eff = effective_dx(size.min(), E.max(), float((E / area).max()))
    assert dx_eff == pytest.approx((size * np.sqrt(E.max() / E)).min(), rel=1e-12)
    assert dx_eff > 1.05 * size.min()
    sim.run(n_steps=3)
    st = sim.model.stepper
    n_auto = st.last_substeps
    n_uniform = math.ceil(sim.dt / (0.7 * explicit_substep_limit(st.dx_min, E.max())))
    assert n_auto < n_uniform
    default, _, _ = sim_with_damaged_small_elements("default", {"solver.substep_limit": "mesh"})
    default.run(n_steps=1)
    assert default.model.stepper.last_substeps == n_uniform  # the default rule: whole-mesh Δx_min, E_max
    assert sim.dt / n_auto <= 0.7 * explicit_substep_limit(st.dx_eff, E.max())
    v = sim.model.state.velocity
    assert np.isfinite(v).all() and np.abs(v).max() < 1.0  # bounded: wind-driven ice, < 1 m/s

    # half the sub-steps: beyond the element-wise limit (by 2 × 0.7 = 1.4) -> unstable
    bad, _, _ = sim_with_damaged_small_elements("half", {"solver.substeps": max(1, n_auto // 2),
                                                         "solver.allow_unstable": True})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            bad.run(n_steps=3)
            vb = bad.model.state.velocity
            blew_up = not np.isfinite(vb).all() or np.abs(vb).max() > 1e3
        except LagiceError:
            blew_up = True
    assert blew_up
    with pytest.raises(ConfigError, match=r"solver.substep_limit = 'cell': expected one of \['mesh', 'element'\]"):
        scene_sim("wind_square", tmp_path / "bad", {"solver.substep_limit": "cell"})


def test_dilatant_viscous_flow_builds_pressure_analytically():
    """``rheology.dilatancy_angle_deg``: with no motion (uniform stress, boundary nodes
    coast) the deviator still decays by γ per sub-step, and the backward-Euler update
    σ ← γ σ − (1 − γ) k_ψ r I, k_ψ = sin ψ (1 + ν)/(1 − ν), r the relaxed Mohr radius,
    has the closed form m_N = γ^N (m_0 − N (1 − γ) k_ψ r_0) for the mean normal stress
    after N sub-steps. ψ = 0 is the default path bit for bit."""
    poly, _ = rectangle_domain(50e3, 50e3)
    mesh = generate_mesh(poly, 10e3)
    lam, dts, n_steps, nu = 900.0, 5.0, 40, 0.3
    dev = np.array([2e3, -2e3, 1e3])
    r0 = np.hypot(2e3, 1e3)
    m0 = -5e3

    def run(**kw):
        return stress_at_rest(MaxwellEB(relaxation_time_s=lam, healing_time_s=None, poisson=nu, **kw), mesh,
                              dev + [m0, m0, 0.0], n_steps, dts)

    g = lam / (lam + dts)
    n = 6 * n_steps
    k = np.sin(np.radians(20.0)) * (1 + nu) / (1 - nu)
    assert MaxwellEB(dilatancy_angle_deg=20.0).params.dilatancy_factor == pytest.approx(k, rel=1e-15)
    out = run(dilatancy_angle_deg=20.0)
    m_ref = g ** n * (m0 - n * (1 - g) * k * r0)
    assert np.allclose(out, dev * g ** n + [m_ref, m_ref, 0.0], rtol=1e-11, atol=1e-9)
    assert m_ref < 1.3 * m0 * g ** n  # the dilatant pressure is large enough to tell apart
    assert np.array_equal(run(dilatancy_angle_deg=0.0), run())


def test_sheared_broken_ice_opens_with_dilatancy():
    """Simple shear of broken ice (damage 0.99, so its Maxwell time is 10 s and the flow is
    viscous within seconds), bottom held, top driven along x with its v free, the sides
    free. The flow rule of ``dilatancy_angle_deg`` makes the divergence sin ψ times the
    viscous shear rate e1 − e2; the held bottom keeps the plate from widening, so a small
    pressure builds and the interior opens at 0.6-1 times that (0.29 at ψ = 20°, the median of
    the elements' ratios; 0.32, the interior's total divergence over its total shear; in
    proportion to sin ψ: ψ = 10° gives half), and at about 0 without dilatancy; the top rises."""
    poly, segs = rectangle_domain(20e3, 20e3)
    mesh = generate_mesh(poly, 2e3, segments=segs, exterior_tag="free")
    u_top = 0.05

    def sheared(psi, n_steps=60, parallel=None):
        rheo = MaxwellEB(healing_time_s=None, dilatancy_angle_deg=psi)
        s = ExplicitSolver(rheo, mesh, bcs=[VelocityBC("bottom", u=0.0, v=0.0), VelocityBC("top", u=u_top)],
                           substeps=20, parallel=parallel)
        st = IceState.uniform(mesh, cohesion_pa=1e12)
        st.damage[:] = 0.99
        for _ in range(n_steps):
            step(s, st, 60.0)
        return s, st

    def run(psi):
        s, st = sheared(psi)
        e = strain_rate(mesh.triangles, s.nodes.b, s.nodes.c, st.velocity)
        cen = mesh.nodes[mesh.triangles].mean(axis=1)
        inner = (np.abs(cen[:, 0] - 10e3) < 5e3) & (np.abs(cen[:, 1] - 10e3) < 5e3)
        div = e[inner, 0] + e[inner, 1]
        shear = np.sqrt((e[inner, 0] - e[inner, 1]) ** 2 + 4 * e[inner, 2] ** 2)
        top = mesh.nodes_with_tag("top")
        # the median of the element ratios, and the interior's total divergence over its total shear
        return (np.median(div / shear), div.sum() / shear.sum(), float(st.velocity[top, 1].mean()),
                float(np.median(shear)))

    s20, s10 = np.sin(np.radians(20.0)), np.sin(np.radians(10.0))
    ratio, total, v_top, shear = run(20.0)
    assert shear > 0.3 * u_top / 20e3  # the interior shears
    assert 0.6 * s20 < ratio < s20 and 0.6 * s20 < total < s20
    assert v_top > 0.0
    _, total10, _, _ = run(10.0)
    # on gmsh's meshes of this square at 1.8-2.2 km the totals' ratio is 0.48-0.54 (sin 10°/sin 20°
    # = 0.508; the medians' 0.45-0.56): the discretisation's part, not the flow rule's
    assert total10 / total == pytest.approx(s10 / s20, rel=0.10)
    ratio0, _, v_top0, _ = run(None)
    assert abs(ratio0) < 0.01 and v_top > 100 * abs(v_top0)
    # the parallel kernels (prange over elements, no races) give the serial ones' state bit for bit
    states = [sheared(20.0, n_steps=5, parallel=par)[1] for par in (False, True)]
    assert np.array_equal(states[0].velocity, states[1].velocity)
    assert np.array_equal(states[0].stress, states[1].stress)


def test_dilatancy_is_refused_where_it_is_not_implemented():
    from lagice.solvers.implicit import ImplicitSolver
    with pytest.raises(ConfigError, match="dilatancy_angle_deg = 20.0: the implicit solver .* does not implement it "
                                          ".implemented in the explicit CPU"):
        ImplicitSolver(MaxwellEB(dilatancy_angle_deg=20.0), mesh=None)
    with pytest.raises(ConfigError, match="dilatancy_angle_deg .ψ. = 50.0 .*45"):
        MaxwellEB(dilatancy_angle_deg=50.0)
    with pytest.raises(ConfigError, match="dilatancy_angle_deg = 20.0 is implemented with the whole stress relaxing"):
        MaxwellEB(dilatancy_angle_deg=20.0, relax_mean_stress=False)
    with pytest.raises(ConfigError, match="max_pressure_pa = 10000.0"):
        MaxwellEB(dilatancy_angle_deg=20.0, max_pressure_pa=10e3)


def test_bulk_shear_viscosity_ratio_relaxes_the_mean_stress_with_its_own_time():
    """``rheology.bulk_shear_viscosity_ratio`` ζ/η: on a motionless plate of damaged ice one
    sub-step relaxes the deviator by γ = λ/(λ + Δt_s) and the mean stress by
    γ_m = λ_m/(λ_m + Δt_s), λ_m = r λ with r = (ζ/η)(1 − ν)/(1 + ν), to round-off; the
    default (None) relaxes both by γ, and the kept mean (relax_mean_stress false) not at all.
    ζ/η = (1 + ν)/(1 − ν), the ratio of one λ, gives r = 1. With neXtSIM's compressive term
    both parts relax with Δt_s (1 − P̃). Steppers without it refuse it."""
    from lagice.solvers.explicit import mean_relaxation_ratio

    rng = np.random.default_rng(5)
    m = 200
    rheo = MaxwellEB(bulk_shear_viscosity_ratio=4.0)
    p = rheo.params
    r = mean_relaxation_ratio(p)
    assert r == pytest.approx(4.0 * 0.7 / 1.3, rel=1e-15)
    assert mean_relaxation_ratio(MaxwellEB(bulk_shear_viscosity_ratio=1.3 / 0.7).params) == pytest.approx(1.0)
    d = rng.uniform(0.5, 0.99, m)
    E, lam = rheo.moduli(d, np.ones(m))
    dt_s = 50.0
    g = lam / (lam + dt_s)
    sigma0 = rng.normal(0, 1e4, (m, 3))
    kc, kt = envelope_factors(rheo)
    tri = np.zeros((m, 3), np.int32)
    zeros3 = np.zeros((m, 3))

    def one(keep, pmax=None):
        sg, dm, flag = sigma0.copy(), d.copy(), np.zeros(m, np.int8)
        element_stress_damage_kernel_serial(
            tri, zeros3, zeros3, np.zeros((1, 2)), sg, dm, np.ones(m), np.full(m, 1e15), kc, kt,
            np.full(m, 20.0), np.zeros(m), dt_s * E, g, pmax, keep, None, None, None, None, dt_s, *rheo.K[0, :2],
            rheo.K[2, 2], rheo.q, rheo._denom, p.max_damage, p.E0, p.relaxation_time_s, 4.0, flag, None)
        assert np.array_equal(dm, d)
        return 0.5 * (sg[:, 0] + sg[:, 1]), np.column_stack([0.5 * (sg[:, 0] - sg[:, 1]), sg[:, 2]])

    m0 = 0.5 * (sigma0[:, 0] + sigma0[:, 1])
    s0 = np.column_stack([0.5 * (sigma0[:, 0] - sigma0[:, 1]), sigma0[:, 2]])
    lam_m = r * lam
    for keep, gm in ((None, g), (r, lam_m / (lam_m + dt_s)), (np.inf, np.ones(m))):
        mean, dev = one(keep)
        assert np.allclose(mean, gm * m0, rtol=1e-12, atol=1e-12 * np.abs(m0).max())
        assert np.allclose(dev, g[:, None] * s0, rtol=1e-12, atol=1e-12 * np.abs(s0).max())
    assert np.all(lam_m / (lam_m + dt_s) > g)  # the mean relaxes more slowly than the deviator
    # with neXtSIM's compressive term: where the previous mean stress is compressive, P̃ =
    # min(1, P_max/(−m)) and each part relaxes with Δt_s (1 − P̃), the deviator with λ, the mean
    # with λ_m; tensile elements as without the term
    pmax = np.abs(m0) * rng.uniform(0.0, 1.5, m)
    omp = np.where(m0 < 0, 1.0 - np.minimum(1.0, pmax / np.maximum(-m0, 1e-300)), 1.0)
    mean, dev = one(r, pmax)
    assert np.allclose(mean, lam_m / (lam_m + dt_s * omp) * m0, rtol=1e-12, atol=1e-12 * np.abs(m0).max())
    assert np.allclose(dev, (lam / (lam + dt_s * omp))[:, None] * s0, rtol=1e-12, atol=1e-12 * np.abs(s0).max())
    assert np.sum((m0 < 0) & (omp < 1.0)) > m // 4 and np.sum(omp == 0.0) > m // 10  # both cases occur
    mean_c, _ = one(None, pmax)  # the default with the term: one factor for the whole stress
    assert np.allclose(mean_c, lam / (lam + dt_s * omp) * m0, rtol=1e-12, atol=1e-12 * np.abs(m0).max())
    with pytest.raises(ConfigError, match="bulk_shear_viscosity_ratio = 4.0 is implemented with the whole stress"):
        MaxwellEB(bulk_shear_viscosity_ratio=4.0, relax_mean_stress=False)
    MaxwellEB(bulk_shear_viscosity_ratio=4.0, max_pressure_pa=10e3)  # allowed since the thirty-eighth session
    for stepper in ("implicit", "explicit_cuda"):
        with pytest.raises(ConfigError, match="bulk_shear_viscosity_ratio"):
            rheo.require_stepper(stepper)
