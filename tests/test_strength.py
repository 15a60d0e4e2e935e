"""Strength law scaled with element size (lagice/strength.py): the neXtSIM scaling,
the exact conversion of neXtSIM's criterion to lagice's, disorder, remeshing, and
parameter checks before any mesh work."""
import math

import numpy as np
import pytest

from lagice.errors import ConfigError
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.rheology import dcrit
from lagice.strength import StrengthLaw, element_size, element_uniforms, from_config, from_nextsim

from helpers import global_remesh, shear_inner_nodes


def _mesh(size):
    poly, segs = rectangle_domain(200e3, 200e3)
    return generate_mesh(poly, size, segments=segs)


def test_cohesion_follows_the_size_scaling():
    """Without disorder C·sqrt(Δx) is the same constant C_lab·sqrt(L_lab) on a 10 km and
    a 40 km mesh (every element, exactly), so C at 40 km is half of C at 10 km for
    elements 4 times as large."""
    law = StrengthLaw(lab_cohesion_pa=2.8e6, disorder=0.0)
    for size in (10e3, 40e3):
        m = _mesh(size)
        c = law.cohesion(m.nodes, m.triangles, np.arange(m.n_nodes))
        dx = element_size(m.nodes, m.triangles)
        np.testing.assert_allclose(c * np.sqrt(dx), 2.8e6 * math.sqrt(0.1), rtol=1e-12)
    assert law.cohesion(np.array([[0, 0], [4e4, 0], [0, 1e4]], float), np.array([[0, 1, 2]]), np.arange(3))[0] \
        == pytest.approx(0.5 * law.cohesion(np.array([[0, 0], [1e4, 0], [0, 2.5e3]], float), np.array([[0, 1, 2]]),
                                            np.arange(3))[0], rel=1e-12)


def test_nextsim_values():
    """neXtSIM: C_fix = C_lab sqrt(0.1/res) with C_lab = 2 MPa (options.cpp:319,
    finiteelement.cpp:6996-6997): 6.32 kPa at res = 10 km; in lagice's form with
    tanφ = 0.7 that is C = 6.32/sqrt(0.51) = 8.86 kPa and μ = 0.980."""
    c_n = 2e6 * math.sqrt(0.1 / 10e3)
    assert c_n == pytest.approx(6324.6, rel=1e-4)
    c, mu = from_nextsim(c_n, 0.7)
    assert c == pytest.approx(8856.2, rel=1e-4)
    assert mu == pytest.approx(0.98020, rel=1e-4)


def test_conversion_gives_the_same_envelope():
    """With (C, μ) = from_nextsim(C_N, tanφ), lagice's d_crit (Dansereau et al. 2016
    eq. 8) equals neXtSIM's C_N/(σ_s + tanφ σ_mean) for every stress state outside the
    envelope with σ2 ≤ 0 (compression–shear and uniaxial tension)."""
    rng = np.random.default_rng(4)
    c_n, tphi = 7.8e3, 0.7
    c, mu = from_nextsim(c_n, tphi)
    s1 = rng.uniform(-30e3, 15e3, 20000)
    s2 = s1 - rng.uniform(0.0, 80e3, 20000)
    keep = s2 <= 0.0
    s1, s2 = s1[keep], s2[keep]
    th = rng.uniform(0, np.pi, s1.size)  # rotate the principal axes: the criteria are isotropic
    cs, sn = np.cos(th), np.sin(th)
    sig = np.column_stack([s1 * cs**2 + s2 * sn**2, s1 * sn**2 + s2 * cs**2, (s1 - s2) * cs * sn])
    nx = c_n / (0.5 * (s1 - s2) + tphi * 0.5 * (s1 + s2))
    outside = (nx > 0) & (nx < 1)
    assert outside.sum() > 1000
    np.testing.assert_allclose(dcrit(sig[outside], c, mu), nx[outside], rtol=1e-9)
    # inside neXtSIM's envelope is inside lagice's
    inside = (nx >= 1) | (nx < 0)
    assert np.all(dcrit(sig[inside], c, mu) == 1.0)


def test_disorder_factor_distribution_and_ids():
    """U_e is uniform in [0, 1), depends only on the seed and the set of node ids
    (not their order or the element index)."""
    tri = np.random.default_rng(0).integers(0, 10**6, size=(20000, 3))
    ids = np.arange(10**6)
    u = element_uniforms(ids, tri, 3)
    assert 0.0 <= u.min() and u.max() < 1.0
    assert abs(u.mean() - 0.5) < 0.01 and abs(u.std() - math.sqrt(1 / 12)) < 0.005
    np.testing.assert_array_equal(u, element_uniforms(ids, tri[:, [2, 0, 1]], 3))
    np.testing.assert_array_equal(u[::-1], element_uniforms(ids, tri[::-1], 3))
    assert not np.allclose(u, element_uniforms(ids, tri, 4))


def test_after_a_remesh_every_element_carries_the_strength_of_its_size():
    """winter_basin_pack at 60 km (a coast-refined mesh whose element sizes vary),
    interior distorted, then a global remesh through the model's ``remeshing``
    component and its strength hook: afterwards every element has
    C = C_lab sqrt(L/Δx_e) f_e for its own current size, kept elements keep their
    disorder factor, and the new ones draw factors from the same distribution."""
    from lagice.scenes.builder import build_model
    from lagice.scenes.config import load_scene

    model = build_model(load_scene("winter_basin_pack", {"domain.resolution_m": 60e3, "run.duration": "1h",
                                                         "solver.dt": "1h"}))
    st = model.state
    law = from_config(model.config["rheology"], model.config["run"]["seed"])
    m = st.mesh
    f_before = st.cohesion / (law.lab_cohesion_pa * law.scale_factor(element_size(m.nodes, m.triangles)))
    shear_inner_nodes(m)
    rem = model.component("remeshing")
    assert any(getattr(f, "__self__", None) == law for f in rem.after_remesh)  # the scene's law is the hook
    ev = global_remesh(model)
    nm = st.mesh
    dx = element_size(nm.nodes, nm.triangles)
    f = law.disorder_factor(st.node_id, nm.triangles)
    np.testing.assert_allclose(st.cohesion, 2.8e6 * np.sqrt(0.1 / dx) * f, rtol=1e-12)
    assert dx.max() / dx.min() > 2.0  # sizes really differ
    k0 = len(ev.kept_elements)
    np.testing.assert_allclose(f[:k0], f_before[ev.kept_elements], rtol=1e-12)
    new = f[k0:]
    assert new.size > 100 and 1.0 <= new.min() and new.max() < 2.0
    assert abs(new.mean() - 1.5) < 0.06  # same distribution: mean 1.5, std 0.289
    assert abs(new.std() - math.sqrt(1 / 12)) < 0.04


def test_after_a_local_remesh_kept_elements_keep_their_strength_by_default():
    """``rheology.strength_after_remesh = "new"``: a local remesh of the flagship mesh (30 km,
    stretched by 10 %, one edge collapsed) gives its new elements C = C_lab sqrt(L/Δx_e) f_e of
    their own size, and every kept element keeps the C it had, bit for bit (through the
    renumbering the flagship applies after a remesh), although its size changed. "new" is the
    default (since 2026-11-28); "all" recomputes the kept elements too, so some of them differ
    by more than 1 %."""
    from lagice.scenes.builder import build_model
    from lagice.scenes.config import load_scene

    out = {}
    for mode in ("new", "all"):
        model = build_model(load_scene("winter_basin_pack", {
            "domain.resolution_m": 30e3, "run.duration": "1h", "solver.dt": "1h",
            **({"rheology.strength_after_remesh": mode} if mode == "all" else {})}))
        st = model.state
        law = from_config(model.config["rheology"], model.config["run"]["seed"])
        assert law.after_remesh == mode
        m = st.mesh
        x0 = np.median(m.nodes[:, 0])
        m.nodes[:, 0] = x0 + 1.1 * (m.nodes[:, 0] - x0)  # every element stretched by 10 % (sizes +4.9 %)
        interior = np.setdiff1d(np.arange(m.n_nodes), np.unique(m.boundary_edges))
        v = interior[np.argmin(np.hypot(*(m.nodes[interior] - m.nodes.mean(axis=0)).T))]
        nb = m.triangles[np.any(m.triangles == v, axis=1)]
        other = nb[nb != v][0]
        m.nodes[v] = 0.97 * m.nodes[other] + 0.03 * m.nodes[v]  # one edge nearly collapsed: a local remesh
        key = {tuple(sorted(t)): k for k, t in enumerate(st.node_id[m.triangles])}
        before = st.cohesion.copy()
        ev = model.component("remeshing").advance(model, 3600.0)
        assert ev is not None and ev.kind == "local" and ev.element_perm is not None  # renumbered after it
        nm = st.mesh
        ids = st.node_id[nm.triangles]
        kept = np.array([tuple(sorted(t)) in key for t in ids])
        assert 0 < (~kept).sum() < kept.sum()
        old = np.array([before[key[tuple(sorted(t))]] for t in ids[kept]])
        law_c = 2.8e6 * np.sqrt(0.1 / element_size(nm.nodes, nm.triangles)) * law.disorder_factor(st.node_id,
                                                                                                   nm.triangles)
        np.testing.assert_allclose(st.cohesion[~kept], law_c[~kept], rtol=1e-12)
        out[mode] = (st.cohesion[kept], old, law_c[kept])
    c_new, old_new, _ = out["new"]
    assert np.array_equal(c_new, old_new)
    c_all, old_all, law_all = out["all"]
    np.testing.assert_allclose(c_all, law_all, rtol=1e-12)
    assert np.abs(c_all / old_all - 1.0).max() > 0.01


def test_correlated_factor_statistics():
    """g = 1 + a(2Φ(G) − 1): uniform on [1 − a, 1 + a] with mean 1 (the mean strength is
    kept), G's correlation at lag r follows exp(−r²/(2ℓ²)) and is gone at 4ℓ, and the
    field is a function of the seed."""
    law = StrengthLaw(correlation_m=50e3, correlated_amplitude=0.4, seed=7)
    x, y = np.meshgrid(np.linspace(-1.5e6, 1.5e6, 601), np.linspace(-1.5e6, 1.5e6, 601))
    g = law.correlated_factor(x, y)
    assert 0.6 <= g.min() and g.max() <= 1.4
    assert abs(g.mean() - 1.0) < 0.03 and abs(g.std() - 0.4 / math.sqrt(3)) < 0.02
    hist = np.histogram(g, bins=8, range=(0.6, 1.4))[0] / g.size
    assert np.all(np.abs(hist - 1 / 8) < 0.03)  # uniform
    G = law.gaussian_field(x, y)
    for lag in (5, 10, 20):  # grid spacing 5 km: 25, 50, 100 km
        r = np.corrcoef(G[:, :-lag].ravel(), G[:, lag:].ravel())[0, 1]
        assert r == pytest.approx(math.exp(-(lag * 5e3) ** 2 / (2 * 50e3 ** 2)), abs=0.05)
    assert abs(np.corrcoef(G[:, :-40].ravel(), G[:, 40:].ravel())[0, 1]) < 0.15
    np.testing.assert_array_equal(g, StrengthLaw(correlation_m=50e3, correlated_amplitude=0.4,
                                                 seed=7).correlated_factor(x, y))
    assert np.abs(g - StrengthLaw(correlation_m=50e3, correlated_amplitude=0.4, seed=8).correlated_factor(x, y)
                  ).max() > 0.5


def test_correlated_factor_is_carried_remapped_and_checkpointed(tmp_path):
    """winter_basin_pack at 60 km with a correlated factor over ℓ = 300 km: at the start
    C = C_lab sqrt(L/Δx) f g with g the field at the centroids; after a global remesh ∫ g da
    is conserved to round-off, every element has C from its own size, disorder and
    remapped g, g of the new elements is the field at their place (the ice moved less
    than ℓ/30) and its spread is kept; a checkpoint written and read back carries g."""
    from lagice.io.checkpoint import read_checkpoint, write_checkpoint
    from lagice.scenes.builder import build_model
    from lagice.scenes.config import load_scene

    over = {"domain.resolution_m": 60e3, "run.duration": "1h", "solver.dt": "1h",
            "rheology.strength_correlation_m": 300e3, "rheology.strength_correlated_amplitude": 0.5}
    model = build_model(load_scene("winter_basin_pack", over))
    st = model.state
    law = from_config(model.config["rheology"], model.config["run"]["seed"])
    m = st.mesh
    c = m.centroids()
    np.testing.assert_allclose(st.strength_factor, law.correlated_factor(c[:, 0], c[:, 1]), rtol=1e-12)
    np.testing.assert_allclose(st.cohesion, law.cohesion(m.nodes, m.triangles, st.node_id) * st.strength_factor,
                               rtol=1e-12)
    std_before = st.strength_factor.std()
    shear_inner_nodes(m)
    total = np.sum(st.strength_factor * m.areas())  # ∫ g da over the moved (Lagrangian) elements
    ev = global_remesh(model)
    nm = st.mesh
    assert np.sum(st.strength_factor * nm.areas()) == pytest.approx(total, rel=1e-12)
    dx = element_size(nm.nodes, nm.triangles)
    np.testing.assert_allclose(st.cohesion, 2.8e6 * np.sqrt(0.1 / dx) * law.disorder_factor(st.node_id, nm.triangles)
                               * st.strength_factor, rtol=1e-12)
    k0 = len(ev.kept_elements)
    nc = nm.centroids()[k0:]
    assert np.abs(st.strength_factor[k0:] - law.correlated_factor(nc[:, 0], nc[:, 1])).max() < 0.1
    assert st.strength_factor.std() > 0.9 * std_before
    write_checkpoint(tmp_path, 1, model.state_arrays(), model.state_meta())
    arrays, meta = read_checkpoint(next(tmp_path.glob("*.npz")))
    fresh = build_model(load_scene("winter_basin_pack", over))
    fresh.load_state(arrays, meta)
    np.testing.assert_array_equal(fresh.state.strength_factor, st.strength_factor)


@pytest.mark.parametrize("key,value,fragment", [
    ("strength_correlation_m", 10.0, "rheology.strength_correlation_m = 10.0 m is out of range; expected a value "
                                     "in [1000, 1e+07]"),
    ("strength_correlated_amplitude", 1.5, "rheology.strength_correlated_amplitude = 1.5 is set but "
                                           "rheology.strength_correlation_m is 0"),
    ("strength_lab_pa", 5.0, "rheology.strength_lab_pa = 5.0 Pa is out of range; expected a value in [10000, 1e+08]"),
    ("strength_disorder", -0.5, "rheology.strength_disorder = -0.5 is out of range; expected a value in [0, 10]"),
    ("strength_lab_scale_m", 100.0, "rheology.strength_lab_scale_m = 100.0 m is out of range"),
    ("strength_law", "weird", "rheology.strength_law = 'weird': expected one of ['uniform', 'scaled']"),
])
def test_bad_strength_parameters_fail_before_meshing(monkeypatch, key, value, fragment):
    from lagice.scenes import builder, config

    def boom(*a, **k):
        raise AssertionError("meshing must not start")

    monkeypatch.setattr(builder, "generate_mesh", boom)
    cfg = config.load_scene("winter_basin_pack", {f"rheology.{key}": value})
    with pytest.raises(ConfigError) as exc:
        builder.build_model(cfg)
    assert fragment in str(exc.value)


def test_bad_correlated_strength_fails_before_meshing(monkeypatch):
    """An amplitude out of range, and a correlated field with the cohesion set by hand."""
    from lagice.scenes import builder, config

    def boom(*a, **k):
        raise AssertionError("meshing must not start")

    monkeypatch.setattr(builder, "generate_mesh", boom)
    for over, fragment in (({"rheology.strength_correlated_amplitude": 1.5},
                            "rheology.strength_correlated_amplitude = 1.5 is out of range; expected a value in "
                            "[0, 0.95]"),
                           ({"initial.cohesion_pa": 2e4},
                            "rheology.strength_correlation_m = 50000 m needs the cohesion from the strength law, "
                            "but initial.cohesion_pa = 20000.0")):
        cfg = config.load_scene("winter_basin_pack", {"rheology.strength_correlation_m": 5e4, **over})
        with pytest.raises(ConfigError) as exc:
            builder.build_model(cfg)
        assert fragment in str(exc.value)


def test_unknown_law_and_orphan_keys():
    with pytest.raises(ConfigError, match="strength_law = 'weird'"):
        from_config({"strength_law": "weird"}, 0)
    with pytest.raises(ConfigError, match="strength_disorder is set but rheology.strength_law = 'uniform'"):
        from_config({"strength_law": "uniform", "strength_disorder": 0.5}, 0)
    assert from_config({"strength_law": "uniform"}, 0) is None
    with pytest.raises(ConfigError, match="strength_correlation_m is set but rheology.strength_law = 'uniform'"):
        from_config({"strength_law": "uniform", "strength_correlation_m": 5e4}, 0)
    from lagice.scenes import builder, config

    # the scene schema's defaults (every key present, unset ones None) leave a uniform law valid
    cfg = config.load_scene("uniaxial_compression")
    assert cfg["rheology"]["strength_law"] == "uniform" and cfg["rheology"]["strength_correlation_m"] is None
    builder.validate_config(cfg)


def test_scene_uses_the_law():
    """winter_basin at 40 km with strength_law = "scaled": the initial cohesion is the
    law's, element by element."""
    from lagice.scenes import builder, config

    cfg = config.load_scene("winter_basin", {"rheology.strength_law": "scaled", "rheology.strength_disorder": 0.5,
                                             "domain.resolution_m": 40e3, "run.duration": "6h"})
    model = builder.build_model(cfg)
    st = model.state
    law = from_config(cfg["rheology"], cfg["run"]["seed"])
    np.testing.assert_allclose(st.cohesion, law.cohesion(st.mesh.nodes, st.mesh.triangles, st.node_id), rtol=1e-12)
    dx = element_size(st.mesh.nodes, st.mesh.triangles)
    c = st.cohesion / law.disorder_factor(st.node_id, st.mesh.triangles)
    np.testing.assert_allclose(c * np.sqrt(dx), law.lab_cohesion_pa * math.sqrt(0.1), rtol=1e-12)
    assert dx.max() / dx.min() > 2.0  # a non-uniform mesh: each element has its own C


def test_strength_law_is_a_maxwell_eb_key():
    """The EVP comparison of the flagship scene: the viscous-plastic rheology has no
    cohesion, so the scene's strength law is not used (as cohesion_min/max_pa), but its
    values are still checked."""
    from lagice.scenes import builder, config

    evp = {"rheology.law": "viscous_plastic", "solver.name": "evp", "healing.law": "none", "solver.dt": "30min"}
    cfg = config.load_scene("winter_basin_pack", evp)
    builder.validate_config(cfg)
    assert builder.strength_law(cfg) is None
    assert builder.strength_law(config.load_scene("winter_basin_pack")) is not None
    with pytest.raises(ConfigError, match="rheology.strength_lab_pa = 5.0 Pa is out of range"):
        builder.validate_config(config.load_scene("winter_basin_pack", {**evp, "rheology.strength_lab_pa": 5.0}))


def test_nextsim_healing_rate():
    """neXtSIM healing: H = e^(−20(1 − A)) ΔT/(th0 ΔT0), ΔT = (Tf − Ta)/(1 + ki hs/(ks h)):
    th0 = 25 d at ΔT = 20 K for compact snow-free ice; snow and low concentration slow it;
    none at or above freezing."""
    from lagice.strength import NextsimHealing

    h = NextsimHealing(-21.8)
    day = 86400.0
    r = h.rate(np.array([-21.8, -21.8, -21.8, 0.0]), np.array([1.0, 1.0, 1.0, 1.0]), np.array([1.0, 1.0, 0.9, 1.0]),
               np.array([0.0, 0.31, 0.0, 0.0]))
    assert r[0] == pytest.approx(1.0 / (25 * day), rel=1e-12)
    assert r[1] == pytest.approx(1.0 / (25 * day) / (1.0 + 2.0), rel=1e-12)  # ki hs/(ks h) = 2
    assert r[2] == pytest.approx(np.exp(-2.0) / (25 * day), rel=1e-12)
    assert r[3] == 0.0
    with pytest.raises(ConfigError, match="healing.params.th0_s"):
        NextsimHealing(-20.0, th0_s=-1.0)


def test_compliance_healing_form():
    """form = "compliance" (neXtSIM before 2017): the rate is −K times the damage form's,
    and damage_step then heals χ = 1/(1 − d) linearly in time, exactly over any number of
    sub-steps: nearly broken ice heals slowly, lightly damaged ice fast."""
    from lagice.rheology import damage_step
    from lagice.strength import NextsimHealing

    args = (np.array([-21.8, -11.8]), np.array([1.0, 2.0]), np.array([1.0, 0.95]), np.array([0.0, 0.3]))
    lin = NextsimHealing(-21.8).rate(*args)
    com = NextsimHealing(-21.8, form="compliance").rate(*args)
    np.testing.assert_allclose(com, -1000.0 * lin, rtol=1e-15)
    h = -1000.0 / (25 * 86400.0)  # |H| = K/th0 at ΔT = ΔT0
    dt, n = 600.0, 144  # one day in 10-minute steps
    for d0 in (0.999, 0.99):
        d = d0
        for _ in range(n):
            d = damage_step(d, 1.0, dt, 1.0, h, 1.0 - 1e-6)[0]
        assert 1.0 / (1.0 - d) == pytest.approx(1.0 / (1.0 - d0) + h * n * dt, rel=1e-9)
    # d = 0.999 is still 0.9990 after a day; d = 0.5 (χ = 2) is fully healed after 1/|H| = 36 min
    assert damage_step(0.5, 1.0, 1.0 / -h, 1.0, h, 1.0 - 1e-6)[0] == 0.0
    assert damage_step(0.5, 1.0, 0.5 / -h, 1.0, h, 1.0 - 1e-6)[0] == pytest.approx(1.0 / 3.0, rel=1e-12)
    # the damage form with the same |H| would take d = 0.999 to 0.0 within that day
    assert damage_step(0.999, 1.0, n * dt, 1.0, -h, 1.0 - 1e-6)[0] == 0.0


@pytest.mark.parametrize("params,fragment", [
    ({"form": "exponential"}, "healing.params.form = 'exponential'; expected one of ['damage', 'compliance']"),
    ({"form": "compliance", "compliance_factor": 0.5}, "healing.params.compliance_factor = 0.5 is out of range"),
    ({"th0_s": -1.0}, "healing.params.th0_s = -1.0 s is out of range"),
    ({"concentration_c": 500.0}, "healing.params.concentration_c = 500.0 is out of range; expected a value in "
                                 "[0, 100]"),
    ({"half_life": 3.0}, "unknown key healing.params.half_life for healing.law = 'nextsim'"),
])
def test_bad_nextsim_healing_fails_before_meshing(monkeypatch, params, fragment):
    from lagice.scenes import builder, config

    def boom(*a, **k):
        raise AssertionError("meshing must not start")

    monkeypatch.setattr(builder, "generate_mesh", boom)
    cfg = config.load_scene("winter_basin_pack", {"healing.params": params})
    with pytest.raises(ConfigError) as exc:
        builder.build_model(cfg)
    assert fragment in str(exc.value)


def test_nextsim_healing_component_in_the_model():
    """[healing] law = "nextsim": the model's healing component gives the stepper
    NextsimHealing's rate at the element centroids (air temperature, thickness,
    concentration and snow of the state)."""
    from lagice.scenes import builder, config
    from lagice.strength import NextsimHealingComponent

    model = builder.build_model(config.load_scene("winter_basin_pack", {"domain.resolution_m": 60e3,
                                                                        "run.duration": "1h", "solver.dt": "1h"}))
    comp = model.component("healing")
    assert isinstance(comp, NextsimHealingComponent)
    st = model.state
    c = st.mesh.centroids()
    ta = comp.law.air_temperature.evaluate(3600.0, np.ascontiguousarray(c[:, 0]), np.ascontiguousarray(c[:, 1]))
    assert np.all(ta < -1.8)  # January air: every element heals
    r = comp.rate(st, 3600.0)
    hs = st.snow
    expect = (np.exp(-20.0 * (1.0 - st.concentration)) * (-1.8 - ta) / (1.0 + 2.0 * hs / (0.31 * st.thickness))
              / (25 * 86400.0 * 20.0))
    np.testing.assert_allclose(r, expect, rtol=1e-12)
    assert model.stepper.heal_rate == comp.rate


def test_spinup_state_carries_the_correlated_factor(tmp_path, monkeypatch):
    """A spin-up made with a correlated strength factor saves g with its ℓ and a; a run
    from that state carries the spin-up's g on (nearest spin-up centroid, like damage),
    not a fresh draw of its own seed; a run without the same ℓ and a is refused before
    any mesh work, naming the file and the values."""
    from lagice.scenes import builder, config
    from lagice.spinup import field_from_spinup, save_spinup

    from helpers import scene_sim

    cor = {"rheology.strength_correlation_m": 300e3, "rheology.strength_correlated_amplitude": 0.4}
    sim = scene_sim("winter_basin_pack", tmp_path / "run", {"domain.resolution_m": 80e3, "run.duration": "1h",
                                                            "solver.dt": "1h", "output.every": "1h",
                                                            "drifters.count": 0, **cor})
    sim.run()
    sim.write_checkpoint()
    npz = save_spinup(tmp_path / "run", tmp_path / "s.npz")
    z = np.load(npz)
    assert float(z["strength_correlation_m"]) == 300e3 and float(z["strength_correlated_amplitude"]) == 0.4
    np.testing.assert_allclose(np.sort(z["strength_factor"]), np.sort(sim.model.state.strength_factor), rtol=1e-6)
    over = {"domain.resolution_m": 60e3, "run.duration": "1h", "solver.dt": "1h", "initial.state_file": str(npz),
            "run.seed": 99}
    model = builder.build_model(config.load_scene("winter_basin_pack", {**over, **cor}))
    st = model.state
    c = st.mesh.centroids()
    g = field_from_spinup(npz, "strength_factor", c[:, 0], c[:, 1])
    np.testing.assert_array_equal(st.strength_factor, g)
    law = from_config(model.config["rheology"], 99)
    np.testing.assert_allclose(st.cohesion, law.cohesion(st.mesh.nodes, st.mesh.triangles, st.node_id) * g,
                               rtol=1e-12)
    assert np.abs(g - law.correlated_factor(c[:, 0], c[:, 1])).max() > 0.2  # not the run seed's own draw

    def boom(*a, **k):
        raise AssertionError("meshing must not start")

    monkeypatch.setattr(builder, "generate_mesh", boom)
    for extra, fragment in (({}, "carries a correlated strength factor (ℓ = 300000 m, a = 0.4) but "
                                 "rheology.strength_correlation_m is not set"),
                            ({**cor, "rheology.strength_correlated_amplitude": 0.5},
                             "strength_correlated_amplitude = 0.5, but initial.state_file")):
        with pytest.raises(ConfigError) as exc:
            builder.build_model(config.load_scene("winter_basin_pack", {**over, **extra}))
        assert fragment in str(exc.value)


def test_a_branch_applies_its_strength_law_at_the_branch_point(tmp_path):
    """A branch that changes the strength law (here: a correlated factor on a checkpoint
    without one, then none on a checkpoint with one) sets the cohesion of every element
    from its own law at the branch point, instead of keeping the parent's until the first
    remesh (which, with a factor the state lacked, would have failed mid-run); a branch
    that leaves the law alone keeps the checkpoint's fields bit for bit."""
    from lagice.scenes.builder import branch_simulation

    from helpers import scene_sim

    base = {"domain.resolution_m": 80e3, "run.duration": "1h", "solver.dt": "1h", "output.every": "1h",
            "drifters.count": 0}
    sim = scene_sim("winter_basin_pack", tmp_path / "parent", base)
    sim.run()
    ck = sim.write_checkpoint()
    parent_c = sim.model.state.cohesion.copy()
    cor = {"rheology.strength_correlation_m": 300e3, "run.duration": "2h"}
    br = branch_simulation(ck, tmp_path / "cor", cor)
    st = br.model.state
    law = from_config(br.model.config["rheology"], br.model.config["run"]["seed"])
    c = st.mesh.centroids()
    np.testing.assert_allclose(st.strength_factor, law.correlated_factor(c[:, 0], c[:, 1]), rtol=1e-12)
    np.testing.assert_allclose(st.cohesion, law.cohesion(st.mesh.nodes, st.mesh.triangles, st.node_id)
                               * st.strength_factor, rtol=1e-12)
    assert np.abs(st.cohesion / parent_c - 1.0).max() > 0.3
    br.run()  # steps (and would remesh) with the factor it carries
    ck2 = br.write_checkpoint()
    same = branch_simulation(ck2, tmp_path / "same", {"run.duration": "3h"})
    np.testing.assert_array_equal(same.model.state.strength_factor, br.model.state.strength_factor)
    np.testing.assert_array_equal(same.model.state.cohesion, br.model.state.cohesion)
    off = branch_simulation(ck2, tmp_path / "off", {"rheology.strength_correlation_m": 0.0, "run.duration": "3h"})
    so = off.model.state
    assert so.strength_factor is None
    np.testing.assert_allclose(so.cohesion, law.cohesion(so.mesh.nodes, so.mesh.triangles, so.node_id), rtol=1e-12)


def test_nextsim_healing_takes_the_models_freezing_point_conductivities_and_c_star():
    """The nextsim healing law's ΔT across the ice uses Tf, ki, ks and its e^(−c*(1−A)) uses c*:
    where ``[healing.params]`` does not set them they are the model's own (``[thermo.params]``,
    ``rheology.concentration_c``), so the healing and the ice it heals agree; a key set in
    ``[healing.params]`` wins; under the defaults the values are the law's defaults."""
    from lagice.scenes.builder import build_model
    from lagice.scenes.config import load_scene

    base = {"domain.resolution_m": 120e3, "run.duration": "1h", "solver.dt": "1h"}
    law = build_model(load_scene("winter_basin_pack", base)).healing.law
    assert (law.freezing_point_c, law.concentration_c) == (-1.8, 20.0)
    k_default = law.ki
    law = build_model(load_scene("winter_basin_pack", {
        **base, "thermo.params": {"conductivity_ice_w_m_k": 1.5, "freezing_point_c": -1.9},
        "rheology.concentration_c": 15.0})).healing.law
    assert (law.ki, law.freezing_point_c, law.concentration_c) == (1.5, -1.9, 15.0)
    assert k_default != 1.5
    law = build_model(load_scene("winter_basin_pack", {
        **base, "thermo.params": {"conductivity_ice_w_m_k": 1.5},
        "healing.params": {"conductivity_ice_w_m_k": 2.2}})).healing.law
    assert law.ki == 2.2


def _after_remesh_of(sim) -> str:
    """The ``after_remesh`` of the strength law hooked into a simulation's remeshing."""
    laws = [f.__self__ for f in sim.model.component("remeshing").after_remesh
            if isinstance(getattr(f, "__self__", None), StrengthLaw)]
    assert len(laws) == 1
    return laws[0].after_remesh


def test_checkpoints_of_the_code_before_the_new_default_resume_recomputing_every_element(tmp_path):
    """``strength_after_remesh`` became "new" by default on 2026-11-28. A new run stores "new";
    a checkpoint of the code before (its configuration holds None, or lacks the key, with the
    fingerprint hashed without it) resumes with "all", what that code did, through both resume
    paths and a branch; a resume that asked for "new" would change the physics and is refused."""
    from lagice.errors import RestartError
    from lagice.io.checkpoint import list_checkpoints, read_checkpoint, write_checkpoint
    from lagice.scenes.builder import branch_simulation, build_simulation, resume_simulation
    from lagice.scenes.config import load_scene, physics_view
    from lagice.simulation import Simulation
    from tests.test_simulation import _as_written_without

    sim = build_simulation(load_scene("winter_basin_pack", {
        "domain.resolution_m": 80e3, "run.duration": "4h", "solver.dt": "1h", "checkpoint.every": "1h",
        "output.every": "4h", "output.plot": False}), tmp_path / "run")
    assert _after_remesh_of(sim) == "new"
    sim.run(n_steps=2)
    ck = list_checkpoints(tmp_path / "run" / "checkpoints")[-1]
    assert read_checkpoint(ck)[1]["config"]["rheology"]["strength_after_remesh"] == "new"
    assert _after_remesh_of(Simulation.resume(ck)) == "new"

    # the code of 2026-11-28 before the switch stored None (its default, meaning "all")
    import hashlib
    import json

    arrays, meta = read_checkpoint(ck)
    meta["config"]["rheology"]["strength_after_remesh"] = None
    view = {k: v for k, v in physics_view(meta["config"]).items() if not k.startswith("_")}
    meta["scene_fingerprint"] = hashlib.sha256(json.dumps(view, sort_keys=True, default=str).encode()).hexdigest()[:16]
    for k in ("format_version", "sha256", "step"):
        meta.pop(k)
    none_ck = write_checkpoint(tmp_path / "none", 2, arrays, meta, keep=10)
    assert _after_remesh_of(Simulation.resume(none_ck)) == "all"
    assert _after_remesh_of(resume_simulation(none_ck)) == "all"

    # older code had no such key at all
    _as_written_without(ck, ["rheology.strength_after_remesh"])
    assert "strength_after_remesh" not in read_checkpoint(ck)[1]["config"]["rheology"]
    assert _after_remesh_of(Simulation.resume(ck)) == "all"
    assert _after_remesh_of(resume_simulation(ck)) == "all"
    assert _after_remesh_of(branch_simulation(ck, tmp_path / "branch", ["run.duration=5h"])) == "all"
    with pytest.raises(RestartError, match="strength_after_remesh"):
        resume_simulation(ck, ["rheology.strength_after_remesh=new"])
