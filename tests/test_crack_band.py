"""A crack band for the Maxwell viscous flow (``rheology.crack_band_length_m`` = ℓ, docs/physics.md
§4, "A crack band for the viscous flow"): each element's relaxation time is λ Δx/ℓ, Δx = √(2 A), in
the stepper's set-up and wherever the element kernel refreshes λ after a damage change; through a
remesh; refused with a clear error where it is not implemented; off by default."""
import numpy as np
import pytest

from lagice.errors import ConfigError
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.rheology import MaxwellEB
from lagice.solvers import ExplicitSolver
from lagice.solvers.explicit import (
    element_stress_damage_kernel_a4,
    element_stress_damage_kernel_serial,
    envelope_factors,
)
from lagice.state import IceState

from helpers import global_remesh, shear_inner_nodes, step


def test_relaxation_scale_against_the_element_size():
    """Off by default (None: the kernels take λ unchanged); with ℓ set, Δx/ℓ per element."""
    sizes = np.array([2e3, 9.3e3, 18.6e3, 55e3])
    assert MaxwellEB().relaxation_scale(sizes) is None
    assert MaxwellEB(crack_band_length_m=0.0).relaxation_scale(sizes) is None
    np.testing.assert_allclose(MaxwellEB(crack_band_length_m=20e3).relaxation_scale(sizes), sizes / 20e3,
                               rtol=1e-15)
    assert MaxwellEB(crack_band_length_m=20e3).params.optional_terms() == {"crack_band_length_m": 20e3}


@pytest.mark.parametrize("bad", [-5e3, 2e6, float("nan")])
def test_bad_crack_band_length_is_refused_by_name(bad):
    with pytest.raises(ConfigError, match="crack_band_length_m"):
        MaxwellEB(crack_band_length_m=bad)


def test_crack_band_is_refused_with_the_nonlocal_damage_and_where_it_is_not_implemented():
    with pytest.raises(ConfigError, match="crack_band_length_m = 20000.0 is implemented with the local damage"):
        MaxwellEB(crack_band_length_m=20e3, damage_nonlocal_radius_m=30e3)
    rh = MaxwellEB(crack_band_length_m=20e3)
    rh.require_stepper("explicit")
    for stepper in ("implicit", "explicit_cuda", "prescribed"):
        with pytest.raises(ConfigError, match=r"rheology.crack_band_length_m = 20000.0: .* does not implement it"):
            rh.require_stepper(stepper)


def test_relaxation_time_carries_the_scale_in_the_stepper():
    """The stepper's scale is √(2 A)/ℓ per element (on a gmsh mesh whose elements differ in
    size). Under a uniform stress on a strip of equal elements, all coast (no node moves), each
    element relaxes by λ s/(λ s + Δt_s) per sub-step, s = √(2 A)/ℓ, to 1e-12; without the option by
    λ/(λ + Δt_s)."""
    lam, dts, ell = 900.0, 5.0, 12e3
    poly, _ = rectangle_domain(50e3, 50e3)
    mixed = generate_mesh(poly, 10e3)
    solver = ExplicitSolver(MaxwellEB(crack_band_length_m=ell), mixed, substeps=6)
    scale = np.sqrt(2.0 * solver.nodes.area) / ell
    assert scale.max() / scale.min() > 1.2  # the elements' sizes differ
    np.testing.assert_allclose(solver.lam_scale, scale, rtol=1e-14)

    poly, _ = rectangle_domain(100e3, 10e3)
    strip = generate_mesh(poly, 10e3)  # 40 equal right triangles, 7.07 km
    s0 = np.array([-3e4, 1e4, 5e3])

    def relaxed(**kw):
        rheo = MaxwellEB(relaxation_time_s=lam, healing_time_s=None, **kw)
        solver = ExplicitSolver(rheo, strip, substeps=6)
        st = IceState.uniform(strip, cohesion_pa=1e12)
        st.stress[:] = s0
        for _ in range(3):
            step(solver, st, 6 * dts)
        assert np.abs(st.velocity).max() < 1e-12
        return solver, st.stress

    solver, sigma = relaxed(crack_band_length_m=ell)
    scale = np.sqrt(2.0 * solver.nodes.area) / ell
    ref = s0[None, :] * ((lam * scale / (lam * scale + dts)) ** 18)[:, None]
    np.testing.assert_allclose(sigma, ref, rtol=1e-12, atol=0)
    _, plain = relaxed()
    np.testing.assert_allclose(plain, np.tile(s0 * (lam / (lam + dts)) ** 18, (strip.n_elements, 1)), rtol=1e-12)
    assert np.abs(sigma - plain).max() > 0.05 * np.abs(s0).max()  # the scale (0.59) acted


@pytest.mark.parametrize("kernel", [element_stress_damage_kernel_serial, element_stress_damage_kernel_a4])
def test_refreshed_relaxation_after_a_damage_event_carries_the_scale(kernel):
    """Elements pushed beyond the envelope damage in the sub-step; the kernel then refreshes
    γ from the new damage: λ0 ((1 − d) g)³ s/(λ0 ((1 − d) g)³ s + Δt_s) with the element's scale s,
    to 1e-14, and without the scale as before (the default path, the argument omitted). Both start
    from the same γ, so the damage is the same and only the refresh differs."""
    rng = np.random.default_rng(7)
    m = 300
    rheo = MaxwellEB()
    p = rheo.params
    d0 = rng.uniform(0.0, 0.8, m)
    cf = np.exp(-p.concentration_c * (1.0 - rng.uniform(0.9, 1.0, m)))
    scale = rng.uniform(0.3, 2.0, m)
    dt_s = 20.0
    sigma0 = np.column_stack([rng.uniform(-8e5, -4e5, m), rng.uniform(-1e4, 1e4, m), rng.uniform(1e5, 3e5, m)])
    kc, kt = envelope_factors(rheo)
    tri = np.zeros((m, 3), np.int32)
    zeros3 = np.zeros((m, 3))
    E, lam = rheo.moduli(d0, np.ones(m), cf)

    def one(lam_scale):
        sg, dm, flag = sigma0.copy(), d0.copy(), np.zeros(m, np.int8)
        g = lam / (lam + dt_s)  # the same starting γ: the stress update and the damage are the same
        args = (tri, zeros3, zeros3, np.zeros((1, 2)), sg, dm, cf, np.full(m, 20e3), kc, kt, np.full(m, 40.0),
                np.zeros(m), dt_s * E, g, None, None, None, None, None, None, dt_s, *rheo.K[0, :2], rheo.K[2, 2],
                rheo.q, rheo._denom, p.max_damage, p.E0, p.relaxation_time_s, 4.0, flag, None)
        kernel(*args) if lam_scale is None else kernel(*args, lam_scale)
        return dm, g

    d_plain, g_plain = one(None)
    d_band, g_band = one(scale)
    assert (d_band > d0).all()  # every element damaged in the sub-step
    np.testing.assert_array_equal(d_band, d_plain)
    x = (1.0 - d_band) * cf
    lam_new = p.relaxation_time_s * x ** 3
    np.testing.assert_allclose(g_band, lam_new * scale / (lam_new * scale + dt_s), rtol=1e-14)
    np.testing.assert_allclose(g_plain, lam_new / (lam_new + dt_s), rtol=1e-14)


def test_crack_band_scale_holds_on_every_element_through_a_remesh():
    """winter_basin_pack at 60 km through the scene builder: the stepper's scale is √(2 A)/ℓ on
    every element before and after a global remesh (which makes new elements)."""
    from lagice.scenes.builder import build_model
    from lagice.scenes.config import load_scene

    ov = {"domain.resolution_m": 60e3, "run.duration": "1h", "solver.dt": "1h", "rheology.crack_band_length_m": 30e3}
    model = build_model(load_scene("winter_basin_pack", ov))
    assert model.stepper.lam_scale is not None
    np.testing.assert_allclose(model.stepper.lam_scale, np.sqrt(2.0 * model.stepper.nodes.area) / 30e3, rtol=1e-14)
    assert build_model(load_scene("winter_basin_pack", {k: v for k, v in ov.items()
                                                        if k != "rheology.crack_band_length_m"})).stepper.lam_scale \
        is None
    m = model.state.mesh
    shear_inner_nodes(m)
    global_remesh(model)
    assert model.state.mesh is not m
    assert len(model.stepper.lam_scale) == model.state.mesh.n_elements
    np.testing.assert_allclose(model.stepper.lam_scale, np.sqrt(2.0 * model.stepper.nodes.area) / 30e3, rtol=1e-14)
