"""EVP comparison rheology (issue 7): Hibler VP stress with an elliptical
yield curve by mEVP iterations. Plastic regime on the ellipse, viscous regime
linear, free drift through ``Model(solver="evp")``, stability of the adaptive
iteration, TOML selection."""
import numpy as np
import pytest

from lagice.errors import ConfigError
from lagice.forces import Coriolis, OceanDrag, WindStress, free_drift_velocity
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.model import Model
from lagice.params import RHO_AIR, coriolis_from_latitude
from lagice.rheology import ViscousPlastic, principal_stresses
from lagice.scenes.builder import build_model
from lagice.scenes.config import load_scene
from lagice.solvers import SOLVERS, VelocityBC
from lagice.solvers.evp import DELTA_MIN, EVPSolver, ice_strength, vp_stress_of
from lagice.state import IceState

from helpers import step

E = 2.0  # ellipse ratio
SIDES = ("bottom", "right", "top", "left")


def run_uniform(mesh, G, steps=6, dt=600.0, **opts):
    """All boundary nodes prescribed with u = G·x (uniform strain rate); returns
    the state, the solver and the (exact) strain rate."""
    bcs = [VelocityBC(t, u=lambda t_, x, y: G[0, 0] * x + G[0, 1] * y,
                      v=lambda t_, x, y: G[1, 0] * x + G[1, 1] * y) for t in SIDES]
    s = EVPSolver(ViscousPlastic(), mesh, bcs=bcs, **opts)
    st = IceState.uniform(mesh, thickness_m=1.5, concentration=0.95)
    st.velocity = mesh.nodes @ G.T
    for _ in range(steps):
        step(s, st, dt)
    eps = np.array([G[0, 0], G[1, 1], 0.5 * (G[0, 1] + G[1, 0])])
    return st, s, eps


def invariants(eps):
    div = eps[0] + eps[1]
    shear = np.sqrt((eps[0] - eps[1]) ** 2 + 4 * eps[2] ** 2)
    return div, shear


@pytest.mark.parametrize("G", [np.array([[-1e-6, 0.4e-6], [0.2e-6, -0.5e-6]]),   # convergence + shear
                               np.array([[-2e-7, 1.5e-6], [0.0, 0.1e-6]])],       # shear dominated
                         ids=["convergent", "sheared"])
def test_plastic_stress_on_ellipse(plate_mesh, G):
    st, s, eps = run_uniform(plate_mesh, G, substeps=500)
    div, shear = invariants(eps)
    assert np.hypot(div, shear / E) > 100 * DELTA_MIN  # plastic regime
    # the velocity stays the prescribed linear field (uniform stress: interior forces cancel)
    ref = plate_mesh.nodes @ G.T
    assert np.abs(st.velocity - ref).max() < 1e-9 * np.abs(ref).max()
    assert np.allclose(s.last_strain_rate, eps, rtol=1e-8, atol=1e-8 * np.abs(eps).max())
    S = st.stress * st.thickness[:, None]  # state.stress is S/h
    assert np.allclose(S, s.last_stress_integrated)
    P = ice_strength(st.thickness, st.concentration)
    assert np.allclose(P, 27.5e3 * 1.5 * np.exp(-20 * 0.05))
    s1, s2 = principal_stresses(S)
    F = ((s1 + s2) / P + 1) ** 2 + (E * (s1 - s2) / P) ** 2 - 1.0
    assert np.abs(F).max() < 0.01
    # shear over (pressure offset) follows e: τ/(σm + P/2) = ε̇II/(e² ε̇I)
    tau = 0.5 * (s1 - s2)
    offset = 0.5 * (s1 + s2) + 0.5 * P
    assert np.allclose(tau / offset, shear / (E * E * div), rtol=0.01)
    # the converged mEVP stress is the VP stress of the strain rate
    ref_S, _ = vp_stress_of(np.tile(eps, (len(S), 1)), P)
    assert np.abs(S - ref_S).max() < 1e-3 * np.abs(ref_S).max()
    assert np.all(st.damage == 0.0)  # damage untouched


def test_viscous_regime_linear(plate_mesh):
    """Δ < Δmin: ζ = P/(2Δmin) is constant, the deviatoric stress is linear in
    the strain rate (doubling it doubles the deviator)."""
    G1 = 1e-11 * np.array([[-1.0, 0.4], [0.2, -0.5]])
    dev = []
    for G in (G1, 2 * G1):
        # fixed α, β: with uniform strain rate every element relaxes alike (no stability issue)
        st, s, eps = run_uniform(plate_mesh, G, substeps=500, adaptive=False)
        div, shear = invariants(eps)
        assert np.hypot(div, shear / E) < DELTA_MIN
        S = st.stress * st.thickness[:, None]
        m = 0.5 * (S[:, 0] + S[:, 1])
        d = np.stack([S[:, 0] - m, S[:, 1] - m, S[:, 2]], axis=1)
        P = ice_strength(st.thickness, st.concentration)
        eta = P / (2 * DELTA_MIN) / E**2
        epsd = np.array([eps[0] - 0.5 * div, eps[1] - 0.5 * div, eps[2]])
        assert np.allclose(d, 2 * eta[:, None] * epsd, rtol=0.01, atol=0.01 * np.abs(2 * eta[0] * epsd).max())
        dev.append(d)
    assert np.allclose(dev[1], 2 * dev[0], rtol=0.01, atol=0.01 * np.abs(dev[1]).max())


@pytest.fixture(scope="module")
def free_mesh():
    poly, _ = rectangle_domain(60e3, 60e3)
    return generate_mesh(poly, 20e3, exterior_tag="free")


@pytest.mark.parametrize("repl", [False, True], ids=["hibler", "replacement_pressure"])
def test_selectable_by_name_free_drift(free_mesh, repl):
    assert SOLVERS["evp"] is EVPSolver and EVPSolver.name == "evp"
    wind, lat = (10.0, 5.0), 80.0
    st = IceState.uniform(free_mesh, thickness_m=1.0)
    forces = [WindStress(wind), OceanDrag(), Coriolis(latitude_deg=lat)]
    model = Model(st, ViscousPlastic(replacement_pressure=repl), solver="evp", forces=forces,
                  solver_options={"substeps": 200})
    assert isinstance(model.solver, EVPSolver)
    for _ in range(72):
        model.step(1200.0)
    ua = complex(*wind)
    u_fd = free_drift_velocity(RHO_AIR * 1.2e-3 * abs(ua) * ua, coriolis_from_latitude(lat), 900.0)
    assert np.all(np.isfinite(st.velocity)) and np.all(np.isfinite(st.stress))
    speed = np.hypot(st.velocity[:, 0], st.velocity[:, 1])
    assert speed.max() <= 1.01 * abs(u_fd)
    assert speed.min() >= 0.99 * abs(u_fd)
    if repl:  # no stress at rest or in rigid motion: exactly free drift
        u = st.velocity[:, 0] + 1j * st.velocity[:, 1]
        assert np.abs(u - u_fd).max() < 1e-6 * abs(u_fd)
        assert np.abs(st.stress).max() < 1e-6


def test_coast_box_wind_adaptive_stable():
    """Coast-locked box under a sheared wind, long steps: the adaptive
    iteration converges, ice stays (nearly) at rest, coast nodes are no-slip and
    the stress never leaves the yield ellipse."""
    poly, segs = rectangle_domain(200e3, 200e3)
    mesh = generate_mesh(poly, 20e3, segments={"top": segs["top"]}, exterior_tag="coast")
    wind = WindStress(lambda t, x, y: (15 * np.sin(np.pi * y / 2e5), 0 * x))
    s = EVPSolver(ViscousPlastic(), mesh, forces=[wind, OceanDrag()], substeps=300,
                  bcs=[VelocityBC("top", v=0.0)])
    st = IceState.uniform(mesh, thickness_m=0.5, concentration=0.9)
    for _ in range(12):
        info = step(s, st, 1800.0)
    assert info.iterations == 300 and info.residual < 1e-6
    assert np.all(np.isfinite(st.velocity))
    coast = mesh.coast_nodes()
    top = np.setdiff1d(mesh.nodes_with_tag("top"), coast)
    assert np.all(st.velocity[coast] == 0.0)
    assert np.all(st.velocity[top, 1] == 0.0) and np.abs(st.velocity[top, 0]).max() > 0
    S = st.stress * st.thickness[:, None]
    P = ice_strength(st.thickness, st.concentration)
    s1, s2 = principal_stresses(S)
    F = ((s1 + s2) / P + 1) ** 2 + (E * (s1 - s2) / P) ** 2 - 1.0
    assert F.max() < 1e-6


def test_toml_scene_selects_evp():
    vp = {"solver.name": "evp", "rheology.law": "viscous_plastic", "healing.law": "none"}
    cfg = load_scene("shear_box", {**vp, "solver.substeps": 50, "solver.dt": 600.0,
                                   "domain.resolution_m": 40e3, "run.progress": False})
    model = build_model(cfg)
    assert isinstance(model.solver, EVPSolver) and model.solver.substeps == 50
    for _ in range(3):
        model.step(600.0)
    assert np.all(np.isfinite(model.state.velocity)) and np.all(np.isfinite(model.state.stress))
    with pytest.raises(ConfigError, match="linear_solver"):
        build_model(load_scene("shear_box", {**vp, "solver.linear_solver": "cg"}))
    m = build_model(load_scene("shear_box", {**vp, "solver.tol": 1e-6, "domain.resolution_m": 40e3}))
    assert m.solver.tol == 1e-6
    # what is solved must match how: a Maxwell-EB scene cannot use the mEVP stepper, nor keep healing
    with pytest.raises(ConfigError, match="rheology.law"):
        build_model(load_scene("shear_box", {"solver.name": "evp"}))
    with pytest.raises(ConfigError, match="healing.law"):
        build_model(load_scene("shear_box", {"solver.name": "evp", "rheology.law": "viscous_plastic"}))


def test_tolerance_stops_iterations_early():
    """With ``tol`` the iteration stops once the velocity change is below it
    (here from the fifth step on, as the flow settles); the velocity stays
    within 0.1 % of the fixed-N result (the mEVP error is about
    tol/(1 − contraction), larger than tol), and a tolerance never met gives
    all N iterations, bit for bit the fixed-N result."""
    poly, segs = rectangle_domain(200e3, 200e3)
    mesh = generate_mesh(poly, 20e3, segments={"top": segs["top"]}, exterior_tag="coast")
    wind = WindStress(lambda t, x, y: (15 * np.sin(np.pi * y / 2e5), 0 * x))
    runs = {}
    for tol in (None, 1e-6, 1e-300):
        s = EVPSolver(ViscousPlastic(), mesh, forces=[wind, OceanDrag()], substeps=300, tol=tol,
                      bcs=[VelocityBC("top", v=0.0)])
        st = IceState.uniform(mesh, thickness_m=0.5, concentration=0.9)
        its = [step(s, st, 1800.0) for _ in range(8)]
        runs[tol] = (st.velocity.copy(), [i.iterations for i in its], [i.residual for i in its])
    assert runs[None][1] == [300] * 8 and runs[1e-300][1] == [300] * 8
    np.testing.assert_array_equal(runs[None][0], runs[1e-300][0])
    it, res = runs[1e-6][1], runs[1e-6][2]
    assert it[:4] == [300] * 4 and max(it[4:]) < 300 and sum(it) < 0.7 * 8 * 300
    assert all(r < 1e-6 for r, n in zip(res, it) if n < 300)
    assert np.abs(runs[1e-6][0] - runs[None][0]).max() < 1e-3 * np.abs(runs[None][0]).max()


def test_coriolis_crank_nicolson_keeps_inertial_oscillations(free_mesh):
    """Free, strengthless ice, no wind, no drag: Coriolis alone turns the velocity by 2 atan(fΔt/2) per step
    (Crank–Nicolson) and keeps the speed; backward Euler would have lost
    1 − (1 + (fΔt)²)^(−24) ≈ 79 % of it in 24 h of 30-min steps."""
    lat, dt = 80.0, 1800.0
    f = coriolis_from_latitude(lat)
    st = IceState.uniform(free_mesh, thickness_m=1.0)
    st.velocity[:] = (0.2, 0.0)
    # strengthless ice (P* → 0, so mEVP is stable with small α, β) and uniform,
    # non-adaptive α, β: every node follows the same iteration, which with β = 1
    # contracts by 1/2 per iteration, so 100 iterations converge to round-off
    s = EVPSolver(ViscousPlastic(replacement_pressure=True, p_star=1e-20), free_mesh,
                  forces=[Coriolis(latitude_deg=lat)], substeps=100, adaptive=False, alpha=2.0, beta=1.0)
    for _ in range(48):
        step(s, st, dt)
    u = st.velocity[:, 0] + 1j * st.velocity[:, 1]
    expect = 0.2 * np.exp(-1j * 48 * 2 * np.arctan(f * dt / 2))  # clockwise in the northern hemisphere
    assert np.abs(np.abs(u) - 0.2).max() < 1e-9
    assert np.abs(u - expect).max() < 1e-9


def test_bad_options(plate_mesh):
    with pytest.raises(ConfigError):
        EVPSolver(ViscousPlastic(), plate_mesh, substeps=0)
    with pytest.raises(ConfigError):
        EVPSolver(ViscousPlastic(), plate_mesh, alpha=0.5)
    with pytest.raises(ConfigError, match="tol"):
        EVPSolver(ViscousPlastic(), plate_mesh, tol=-1.0)
    s = EVPSolver(ViscousPlastic(), plate_mesh)
    with pytest.raises(ConfigError):
        step(s, IceState.uniform(plate_mesh), 0.0)


def test_adaptive_converges_where_fixed_alpha_beta_stall():
    """Thick compact ice at rest in a coast-locked box, 30 min steps: the viscous
    regime (ζ = P/2Δmin) makes αβ = 300² too small for the mEVP stability
    condition; the adaptive α_e, β_i (aEVP) converge."""
    poly, _ = rectangle_domain(200e3, 200e3)
    mesh = generate_mesh(poly, 10e3)
    wind = WindStress(lambda t, x, y: (15 * np.sin(np.pi * y / 2e5), 0 * x))
    res = {}
    for adaptive in (True, False):
        s = EVPSolver(ViscousPlastic(), mesh, forces=[wind, OceanDrag()], substeps=300, adaptive=adaptive)
        st = IceState.uniform(mesh, thickness_m=2.0)
        for _ in range(24):
            info = step(s, st, 1800.0)
        res[adaptive] = (info.residual, np.hypot(st.velocity[:, 0], st.velocity[:, 1]).max())
    assert res[True][0] < 1e-6 and res[True][1] < 2e-4  # converged; strong ice nearly at rest
    assert res[False][0] > 10 * res[True][0]


@pytest.mark.slow
def test_parallel_kernels_match_serial():
    """The prange kernels give the same result as their serial copies (each
    iteration is a pure gather; no reductions except the residual max)."""
    poly, _ = rectangle_domain(200e3, 200e3)
    mesh = generate_mesh(poly, 25e3)
    wind = WindStress(lambda t, x, y: (15 * np.sin(np.pi * y / 2e5), 0 * x))
    out = []
    for par in (False, True):
        s = EVPSolver(ViscousPlastic(), mesh, forces=[wind, OceanDrag(), Coriolis(latitude_deg=80.0)],
                      substeps=50, parallel=par)
        st = IceState.uniform(mesh, thickness_m=0.5, concentration=0.9)
        for _ in range(2):
            info = step(s, st, 1800.0)
        out.append((st.velocity, st.stress, info.residual))
    assert np.array_equal(out[0][0], out[1][0]) and np.array_equal(out[0][1], out[1][1])
    assert out[0][2] == out[1][2]
