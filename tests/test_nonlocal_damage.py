"""Damage regularised over a physical length (``rheology.damage_nonlocal_radius_m``,
:mod:`lagice.solvers.nonlocal_damage`; issue 12 item 4): the weights, the damage rule
L̄ = Σ w L > 1 element by element, the local scheme as the limit of a small radius,
serial = parallel, bit-identical resume through remeshing, and clear refusals."""
import numpy as np
import pytest

from lagice.errors import ConfigError
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.rheology import MaxwellEB
from lagice.rheology.maxwell_eb import principal_stresses
from lagice.scenes.builder import build_simulation
from lagice.scenes.config import load_scene
from lagice.simulation import Simulation
from lagice.solvers import ExplicitSolver, VelocityBC
from lagice.solvers.nonlocal_damage import NonlocalWeights, nonlocal_average
from lagice.state import IceState

from helpers import step


@pytest.fixture(scope="module")
def plate():
    poly, segs = rectangle_domain(20e3, 20e3)
    return generate_mesh(poly, 1e3, segments=segs, exterior_tag="free")


def _area(mesh, nodes=None):
    p = (mesh.nodes if nodes is None else nodes)[mesh.triangles]
    return 0.5 * np.abs((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                        - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))


def _centroids(mesh):
    return mesh.nodes[mesh.triangles].mean(axis=1)


def test_weights_are_a_partition_of_unity_with_the_bell_shape(plate):
    """Rows sum to 1; each weight is A_j (1 − r²/R²)² over the row's sum (checked against a
    brute-force computation over all pairs); no pair beyond R has weight; the element itself
    is in its row."""
    R = 2.5e3
    nw = NonlocalWeights(R)
    area = _area(plate)
    ptr, idx, w = nw.update(plate.triangles, plate.nodes, area)
    rows = np.repeat(np.arange(plate.n_elements), np.diff(ptr))
    assert np.allclose(np.bincount(rows, weights=w), 1.0, rtol=0, atol=1e-14)
    c = _centroids(plate)
    for e in (0, 17, plate.n_elements // 2, plate.n_elements - 1):
        r2 = ((c - c[e]) ** 2).sum(axis=1)
        phi = np.where(r2 < R * R, (1 - r2 / R**2) ** 2, 0.0) * area
        dense = np.zeros(plate.n_elements)
        dense[idx[ptr[e]:ptr[e + 1]]] = w[ptr[e]:ptr[e + 1]]
        assert np.allclose(dense, phi / phi.sum(), rtol=1e-13, atol=1e-17)
        assert e in idx[ptr[e]:ptr[e + 1]]
    assert 10 < nw.mean_neighbours() < 40   # ~π R² / A with the bell's tails at zero weight
    # a constant field is its own average, a spike spreads to exactly its column of weights
    assert np.allclose(nonlocal_average(ptr, idx, w, np.full(plate.n_elements, 3.0)), 3.0, rtol=1e-14)
    spike = np.zeros(plate.n_elements)
    spike[40] = 1.0
    avg = nonlocal_average(ptr, idx, w, spike)
    assert np.count_nonzero(avg) == np.count_nonzero(w[idx == 40])


def test_weights_do_not_depend_on_when_the_candidates_were_found(plate):
    """The candidate pairs are kept while centroids move less than R·margin/2 and found again
    beyond that; the average is bit-identical to that of weights found afresh on the same
    geometry (what makes a resumed run reproduce an uninterrupted one)."""
    R = 2.5e3
    area0 = _area(plate)
    moved = plate.nodes.copy()
    rng = np.random.default_rng(3)
    # a shear and noise: every centroid moves by at most 0.005·√2·20 km + 60·√2 m = 226 m < R/8 = 312 m
    moved += rng.uniform(-1, 1, moved.shape) * 60.0 + 0.005 * moved[:, ::-1]
    old = NonlocalWeights(R)
    old.update(plate.triangles, plate.nodes, area0)
    field = rng.uniform(0, 2, plate.n_elements)
    tri = plate.triangles
    area1 = _area(plate, moved)
    a = nonlocal_average(*old.update(tri, moved, area1), field)
    assert old.n_searches == 1   # the candidates of the first geometry were reused
    fresh = NonlocalWeights(R)
    b = nonlocal_average(*fresh.update(tri, moved, area1), field)
    assert np.array_equal(a, b)
    assert not np.array_equal(b, nonlocal_average(*fresh.update(tri, plate.nodes, area0), field))
    far = plate.nodes + np.where(plate.nodes[:, :1] > 10e3, 1e3, 0.0)   # beyond the margin: searched again
    old.update(tri, far, _area(plate))
    assert old.n_searches == 2


def _load_ratio(rheo, sigma, cohesion):
    """L = max(0, s1/σT, (q s1 − s2)/σc) (module doc) from the envelope of the rheology."""
    s1, s2 = principal_stresses(sigma)
    sc = 2.0 * cohesion / rheo._denom
    return np.maximum.reduce([np.zeros_like(s1), s1 / (sc / rheo.q), (rheo.q * s1 - s2) / sc])


def test_an_element_damages_exactly_where_its_neighbourhood_is_overloaded():
    """A uniform stress at rest (all-coast plate, no motion) over a field of cohesion with a
    weak disk of radius 2.5 km and one weak element far from it. One sub-step: with the local
    scheme every weak element damages (its own load ratio 1.3); with R = 3 km the damaged set
    is exactly {e : Σ_j w_ej L_j > 1}, computed here with numpy from the weights: the disk's
    core only, never the isolated weak element, and each damaged element's stress is scaled
    by f = 1 − (Δt/td)(1 − 1/L̄) (the local rule with L̄ in place of L)."""
    poly, _ = rectangle_domain(20e3, 20e3)
    mesh = generate_mesh(poly, 1e3)
    c = _centroids(mesh)
    sigma0 = np.array([-30e3, -2e3, 8e3])   # shear under compression: q s1 − s2 > 0
    R, dts = 3e3, 0.5

    def run(radius):
        rheo = MaxwellEB(healing_time_s=None, relaxation_time_s=1e12, damage_nonlocal_radius_m=radius)
        s = ExplicitSolver(rheo, mesh, substeps=1)
        st = IceState.uniform(mesh, cohesion_pa=1.0)
        load_strong = _load_ratio(rheo, sigma0[None], 1.0)[0]
        coh = np.full(mesh.n_elements, load_strong / 0.6)            # L = 0.6 everywhere ...
        weak = np.hypot(c[:, 0] - 7e3, c[:, 1] - 10e3) < 2.5e3      # ... 1.3 in the disk
        lone = int(np.argmin(np.hypot(c[:, 0] - 16e3, c[:, 1] - 10e3)))
        weak[lone] = True
        coh[weak] = load_strong / 1.3
        st.cohesion[:] = coh
        st.stress[:] = sigma0
        step(s, st, dts)
        assert np.abs(st.velocity).max() < 1e-12
        return rheo, s, st, weak, lone, coh

    _, _, st_loc, weak, lone, _ = run(None)
    assert np.array_equal(st_loc.damage > 0, weak)
    rheo, s, st, weak, lone, coh = run(R)
    ptr, idx, w = s.nonlocal_weights.ptr, s.nonlocal_weights.idx, s.nonlocal_weights.w
    lbar = nonlocal_average(ptr, idx, w, _load_ratio(rheo, np.broadcast_to(sigma0, (mesh.n_elements, 3)), coh))
    damaged = st.damage > 0
    assert np.array_equal(damaged, lbar > 1.0)
    assert 3 <= damaged.sum() <= weak.sum() - 6      # the disk without its rim, not the lone element
    assert not damaged[lone] and weak[damaged].all()
    f = 1.0 - min(1.0, dts / s.td[damaged][0]) * (1.0 - 1.0 / lbar[damaged][0])
    assert np.allclose(st.stress[damaged][0], sigma0 * f, rtol=1e-12)


def _sheared(mesh, radius, parallel=False, n_steps=30, **rheology):
    rheo = MaxwellEB(healing_time_s=None, damage_nonlocal_radius_m=radius, **rheology)
    s = ExplicitSolver(rheo, mesh, bcs=[VelocityBC("bottom", u=0.0, v=0.0), VelocityBC("top", u=0.02)],
                       parallel=parallel)
    st = IceState.uniform(mesh, cohesion_pa=2e3)
    st.cohesion[:] = np.random.default_rng(0).uniform(1e3, 2e3, mesh.n_elements)
    for _ in range(n_steps):
        step(s, st, 20.0)
    return st


def test_a_radius_below_the_element_spacing_is_the_local_scheme(plate):
    """A sheared plate that cracks (most of it above damage 0.5): with R = 1 m every row is
    the element alone, and the run equals the local kernels' to round-off (1/L against
    σc/(q s1 − s2): 1e-10 after 30 steps of ~25 sub-steps; a wrong factor is ≥ 1e-3 off).
    With R = 3 km it differs; the parallel build equals the serial one bit for bit."""
    local = _sheared(plate, None)
    assert (local.damage > 0.5).mean() > 0.3
    tiny = _sheared(plate, 1.0)
    assert np.abs(tiny.damage - local.damage).max() < 1e-10
    assert np.abs(tiny.stress - local.stress).max() < 1e-10 * np.abs(local.stress).max()
    wide = _sheared(plate, 3e3)
    assert np.abs(wide.damage - local.damage).max() > 0.1
    par = _sheared(plate, 3e3, parallel=True)
    assert np.array_equal(par.damage, wide.damage) and np.array_equal(par.stress, wide.stress)


@pytest.mark.parametrize("failure_stress", ["effective", "energy"])
def test_the_nonlocal_ratio_judges_the_effective_stress_where_asked(plate, failure_stress):
    """``failure_stress`` other than nominal with the nonlocal damage (2026-12-02): the ratio
    averaged is the effective stress's, L/(1 − d)^p. With R = 1 m the run equals the local
    kernel's with the same failure stress to round-off, and differs from the nominal
    nonlocal run (so the damage of the sub-step's start does enter the ratio); with
    R = 3 km it differs from the local run, and parallel equals serial bit for bit."""
    cap = {"failure_stress": failure_stress, "max_damage": 0.97}
    local = _sheared(plate, None, **cap)
    assert (local.damage > 0.5).mean() > 0.15
    tiny = _sheared(plate, 1.0, **cap)
    assert np.abs(tiny.damage - local.damage).max() < 1e-10
    assert np.abs(tiny.stress - local.stress).max() < 1e-10 * np.abs(local.stress).max()
    nominal = _sheared(plate, 1.0, max_damage=0.97)
    assert np.abs(nominal.damage - local.damage).max() > 0.05
    wide = _sheared(plate, 3e3, **cap)
    assert np.abs(wide.damage - local.damage).max() > 0.1
    par = _sheared(plate, 3e3, parallel=True, **cap)
    assert np.array_equal(par.damage, wide.damage) and np.array_equal(par.stress, wide.stress)


REMESH = {"run.duration": 6000.0, "solver.dt": 100.0, "output.every": 3000.0, "checkpoint.every": 3000.0,
          "domain.resolution_m": 25e3, "run.progress": False, "output.plot": False,
          "boundary.top.u": "20.0*minimum(1.0, t/600.0)", "lagrangian.enabled": True,
          "remesh.enabled": True, "run.max_speed_m_s": 50.0, "solver.name": "explicit",
          "rheology.damage_nonlocal_radius_m": 60e3}


def test_resume_is_bit_identical_with_nonlocal_damage_through_remeshing(tmp_path):
    """shear_box on the explicit stepper with R = 60 km, moving mesh and remeshing: a run
    stopped at its checkpoint and resumed ends bit for bit where the uninterrupted run ends
    (the weights are recomputed from the geometry alone), with remesh events on both sides
    and damage made."""
    full = build_simulation(load_scene("shear_box", REMESH), tmp_path / "full")
    full.run()
    n_events = full.model.state.counters.get("remesh_count", 0)
    assert full.model.state.damage.max() > 0.1
    part = build_simulation(load_scene("shear_box", REMESH), tmp_path / "part")
    part.run(n_steps=30)
    assert 0 < part.model.state.counters.get("remesh_count", 0) < n_events
    resumed = Simulation.resume(tmp_path / "part" / "checkpoints")
    resumed.run()
    for k in ("velocity", "stress", "damage", "thickness"):
        a, b = getattr(full.model.state, k), getattr(resumed.model.state, k)
        assert a.shape == b.shape and np.array_equal(a, b), f"{k} differs after resume"


def test_nonlocal_damage_is_refused_where_it_is_not_implemented(tmp_path):
    from lagice.solvers.implicit import ImplicitSolver
    with pytest.raises(ConfigError, match="damage_nonlocal_radius_m = 5000.0: the implicit solver .* does not "
                                          "implement it .implemented in the explicit CPU stepper"):
        ImplicitSolver(MaxwellEB(damage_nonlocal_radius_m=5e3), mesh=None)
    with pytest.raises(ConfigError, match="CUDA explicit stepper .* does not implement it"):
        MaxwellEB(damage_nonlocal_radius_m=5e3).require_stepper("explicit_cuda")
    with pytest.raises(ConfigError, match="damage_nonlocal_radius_m .R. = -1.0"):
        MaxwellEB(damage_nonlocal_radius_m=-1.0)
    with pytest.raises(ConfigError, match="implemented with the default stress path only"):
        MaxwellEB(damage_nonlocal_radius_m=5e3, max_pressure_pa=1e4)
    with pytest.raises(ConfigError, match="implemented with the default stress path only"):
        MaxwellEB(damage_nonlocal_radius_m=5e3, stress_correction="mean_stress")
    # a scene asks for it on the implicit solver: refused before meshing, naming the key
    with pytest.raises(ConfigError, match="rheology.damage_nonlocal_radius_m"):
        build_simulation(load_scene("shear_box", {"rheology.damage_nonlocal_radius_m": 5e3}), tmp_path / "run")
