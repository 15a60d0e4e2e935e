"""Implicit solver: elastic patch test, Maxwell relaxation, boundary conditions."""
import numpy as np
import pytest

from lagice.errors import ConfigError
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.rheology import MaxwellEB
from lagice.solvers import ImplicitSolver, VelocityBC
from lagice.state import IceState

from helpers import step

G = np.array([[2e-8, 0.7e-8], [-0.3e-8, -1.1e-8]])  # velocity gradient [s-1]


def linear_velocity(comp):
    return lambda t, x, y: G[comp, 0] * x + G[comp, 1] * y


@pytest.mark.parametrize("linear_solver", ["superlu", "cg", "amg"])
def test_elastic_patch_uniform_stress(plate_mesh, linear_solver):
    """Uniform strain rate on the boundary of an irregular mesh: the stress is
    uniform and equals the plane-stress backward-Euler value to 1e-8."""
    mesh = plate_mesh
    rheo = MaxwellEB(cohesion_min_pa=1e12, cohesion_max_pa=1e12)
    bcs = [VelocityBC(tag, u=linear_velocity(0), v=linear_velocity(1))
           for tag in ("bottom", "right", "top", "left")]
    solver = ImplicitSolver(rheo, mesh, bcs=bcs, linear_solver=linear_solver, linear_rtol=1e-13)
    st = IceState.uniform(mesh, cohesion_pa=1e12)
    dt = 20.0
    eps = np.array([G[0, 0], G[1, 1], 0.5 * (G[0, 1] + G[1, 0])])
    E, lam = rheo.E0, rheo.params.relaxation_time_s
    gamma = lam / (lam + dt)
    sigma = np.zeros(3)
    st.velocity = mesh.nodes @ G.T
    for _ in range(4):
        step(solver, st, dt)
        sigma = gamma * (sigma + dt * E * rheo.K @ eps)
    assert np.allclose(st.velocity, mesh.nodes @ G.T, rtol=0, atol=1e-10 * np.abs(mesh.nodes @ G.T).max())
    scale = np.abs(sigma).max()
    assert np.abs(st.stress - sigma).max() / scale < 1e-8
    # plane stress: sigma_xx = E/(1-nu^2) (eps_xx + nu eps_yy) accumulated
    nu = rheo.params.poisson
    assert sigma[0] == pytest.approx(E / (1 - nu**2) * (eps[0] + nu * eps[1]) * dt
                                     * sum(gamma ** k for k in range(1, 5)), rel=1e-12)


def test_maxwell_relaxation_backward_euler_factor():
    poly, _ = rectangle_domain(50e3, 50e3)
    mesh = generate_mesh(poly, 10e3)  # all edges coast: no-slip, fixed
    rheo = MaxwellEB(relaxation_time_s=900.0, healing_time_s=None)
    solver = ImplicitSolver(rheo, mesh, linear_solver="superlu")
    st = IceState.uniform(mesh, cohesion_pa=1e12)
    s0 = np.array([-3e4, 1e4, 5e3])
    st.stress[:] = s0
    dt = 60.0
    for n in range(1, 6):
        step(solver, st, dt)
        expected = s0 * (900.0 / (900.0 + dt)) ** n
        assert np.allclose(st.stress, expected, rtol=1e-12, atol=0)
    assert np.abs(st.velocity).max() < 1e-15


def test_damaged_relaxation_uses_damaged_lambda():
    poly, _ = rectangle_domain(50e3, 50e3)
    mesh = generate_mesh(poly, 10e3)
    rheo = MaxwellEB(relaxation_time_s=1e5, healing_time_s=None)
    solver = ImplicitSolver(rheo, mesh, linear_solver="superlu")
    st = IceState.uniform(mesh, cohesion_pa=1e12, damage=0.5)
    st.stress[:] = [-1e3, 0.0, 0.0]
    step(solver, st, 10.0)
    lam = 1e5 * 0.5 ** 3
    assert np.allclose(st.stress[:, 0], -1e3 * lam / (lam + 10.0), rtol=1e-12)


def test_bad_bc_tag_and_dt(plate_mesh):
    rheo = MaxwellEB()
    with pytest.raises(ConfigError, match="unknown boundary tag 'north'"):
        ImplicitSolver(rheo, plate_mesh, bcs=[VelocityBC("north", v=1.0)])
    with pytest.raises(ConfigError, match="neither u nor v"):
        ImplicitSolver(rheo, plate_mesh, bcs=[VelocityBC("top")])
    with pytest.raises(ConfigError, match="linear_solver = 'lu'"):
        ImplicitSolver(rheo, plate_mesh, linear_solver="lu")
    s = ImplicitSolver(rheo, plate_mesh)
    with pytest.raises(ConfigError, match="dt"):
        step(s, IceState.uniform(plate_mesh, cohesion_pa=3e4), 0.0)


def test_numba_pcg_matches_scipy_cg(plate_mesh):
    """The numba Jacobi-PCG gives scipy's answer on an assembled SPD system."""
    import scipy.sparse.linalg as spla

    from lagice.solvers.linear import jacobi_pcg

    rheo = MaxwellEB()
    solver = ImplicitSolver(rheo, plate_mesh, linear_solver="cg")
    from lagice.fem import assemble_elasticity
    data = assemble_elasticity(solver.pattern.entry_map, solver.b, solver.c, solver.area * 1e3,
                               0.3, solver.pattern.nnz)
    data[solver.pattern.diag_pos] += 1e6
    A = solver.pattern.matrix(data)
    b = np.random.default_rng(0).standard_normal(A.shape[0])
    x = np.zeros_like(b)
    its, res = jacobi_pcg(A.indptr, A.indices, A.data, b, x, 1e-12, 5000)
    assert its > 0 and res <= 1e-12 * np.linalg.norm(b)
    ref = spla.spsolve(A.tocsc(), b)
    assert np.abs(x - ref).max() <= 1e-9 * np.abs(ref).max()


def test_damage_fixed_point_is_consistent_and_default_is_one_pass(tmp_path, caplog):
    """solver.damage_iterations (Dansereau et al. 2016's fixed point): on a step of the N = 10
    compression where the plate damages, the fixed point's damage d* is the damage that the
    stress solved with d* gives again (to 10 × damage_tol = 1e-9), in more than one pass; the
    one-pass damage is not (it is computed from the stress solved with the old damage: here it
    is off by about 1e-6), so the check can fail. A step that uses every pass without settling is
    counted and logged. Bad values fail before any work, naming the key."""
    import copy

    from lagice.solvers.base import StepInfo

    from helpers import compression_overrides, scene_sim

    sim = scene_sim("uniaxial_compression", tmp_path / "a", compression_overrides(
        10, **{"healing.law": "none", "run.duration": 2600 * 20.0}))
    m = sim.model
    dt = sim.dt
    while m.state.damage.max() == 0.0:  # to the onset of damage
        sim.run(n_steps=50)
    for _ in range(400):  # on to a step with many damaging elements
        before = copy.deepcopy(m.state)
        sim.run(n_steps=1)
        if np.sum(m.state.damage > before.damage) >= 10:
            break
    t_s = m.clock.time_s - dt
    st = m.stepper
    rheo = st.rheology

    def damage_from(state0, d_use):
        vel, sigma, _ = st._solve(state0, d_use, t_s, dt, StepInfo())
        d = state0.damage.copy()
        rheo.damage_update(sigma, d, state0.cohesion, dt, st.td, rheo.constant_heal_rate(len(d)))
        return d

    one = copy.deepcopy(before)
    st.damage_iterations = 1
    st.step(one, t_s, dt)
    assert np.array_equal(one.damage, m.state.damage)  # the run itself took one pass (the default)
    st.damage_tol = tol = 1e-10  # one pass is already consistent to about 1e-6 here
    gap_one = np.abs(damage_from(before, one.damage) - one.damage).max()
    fixed = copy.deepcopy(before)
    st.damage_iterations = 30
    unconverged = st.damage_unconverged_steps
    st.step(fixed, t_s, dt)
    assert st.last_damage_passes > 1 and st.damage_unconverged_steps == unconverged
    gap_fixed = np.abs(damage_from(before, fixed.damage) - fixed.damage).max()
    assert gap_fixed < 10 * tol < gap_one
    # too few passes for the tolerance: counted and logged, the last pass kept
    st.damage_iterations, st.damage_tol = 2, 1e-15
    with caplog.at_level("WARNING", logger="lagice"):
        st.step(copy.deepcopy(before), t_s, dt)
    assert st.damage_unconverged_steps == unconverged + 1
    assert "damage_iterations = 2 passes without the damage settling" in caplog.text
    for bad in ({"solver.damage_iterations": 0}, {"solver.damage_tol": 0.0}):
        with pytest.raises(ConfigError, match=list(bad)[0].split(".")[1]):
            scene_sim("uniaxial_compression", tmp_path / "b", compression_overrides(10, **bad))
    with pytest.raises(ConfigError, match="damage_iterations does not apply to solver 'explicit'"):
        scene_sim("uniaxial_compression", tmp_path / "c",
                  compression_overrides(10, **{"solver.name": "explicit", "solver.damage_iterations": 5}))
