"""External forces (issue 3): wind, ocean drag, Coriolis, for both solvers.

Free drift against the analytic steady state; inertial oscillation period and
speed; the linearisation the implicit solver uses against the exact force.
"""
import cmath
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from lagice.errors import ConfigError, ForcingError
from lagice.forces import Coriolis, OceanDrag, WindStress, evaluate_vector, explicit_terms, free_drift_velocity
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.params import RHO_AIR, RHO_WATER, coriolis_from_latitude
from lagice.rheology import MaxwellEB
from lagice.solvers import ExplicitSolver, ImplicitSolver
from lagice.state import IceState

from helpers import step

RHO_H = 900.0  # ρi h [kg m-2] for h = 1 m
WIND = (10.0, 5.0)  # m s-1
TURN = 25.0  # deg
LAT = 75.0


@pytest.fixture(autouse=True)
def one_thread():
    """Tiny meshes: one numba thread (parallel fork/join dominates otherwise)."""
    import numba

    n = numba.get_num_threads()
    numba.set_num_threads(1)
    yield
    numba.set_num_threads(n)


@pytest.fixture(scope="module")
def free_mesh():
    """A small square with traction-free edges (no coast): uniform fields stay uniform."""
    poly, _ = rectangle_domain(60e3, 60e3)
    return generate_mesh(poly, 20e3, exterior_tag="free")


def free_rheology_state(mesh):
    """Fully damaged ice (d = 1 − 1e-6): E ≈ 600 Pa, λ ≈ 1e-11 s, no internal stress."""
    rheo = MaxwellEB(healing_time_s=None)
    st = IceState.uniform(mesh, cohesion_pa=3e4, damage=rheo.params.max_damage)
    return rheo, st


def analytic_free_drift(tau, f, rho_h, theta_deg):
    """Steady state of τa + τw(u) − ρh f k×u = 0 with the ocean at rest.

    Complex form (k× ≡ i): τa = u (c|u| e^{iθ} + i ρh f), c = ρw Cw. Taking the
    modulus gives a scalar equation for the speed s: s |c s e^{iθ} + iρh f| = |τa|.
    """
    c = RHO_WATER * 5.5e-3
    rot = cmath.exp(1j * math.radians(theta_deg))
    s = brentq(lambda s: s * abs(c * s * rot + 1j * rho_h * f) - abs(tau), 0.0, 10.0, xtol=1e-15)
    return tau / (c * s * rot + 1j * rho_h * f)


def forces_list():
    return [WindStress(WIND), OceanDrag(turning_angle_deg=TURN), Coriolis(latitude_deg=LAT)]


@pytest.mark.parametrize("solver", ["implicit", "explicit"])
def test_free_drift_reaches_analytic_steady_state(free_mesh, solver):
    rheo, st = free_rheology_state(free_mesh)
    if solver == "implicit":
        s = ImplicitSolver(rheo, free_mesh, forces=forces_list(), linear_solver="superlu", tol=1e-12)
    else:
        s = ExplicitSolver(rheo, free_mesh, forces=forces_list(), substeps=4)
    dt = 600.0
    for _ in range(int(1.5 * 86400 / dt)):
        step(s, st, dt)
    ua = complex(*WIND)
    tau = RHO_AIR * 1.2e-3 * abs(ua) * ua
    u_exact = analytic_free_drift(tau, coriolis_from_latitude(LAT), RHO_H, TURN)
    u_num = st.velocity[:, 0] + 1j * st.velocity[:, 1]
    err = np.abs(u_num - u_exact).max() / abs(u_exact)
    assert err < 5e-3, f"{solver}: free drift {u_num.mean():.5f} vs analytic {u_exact:.5f}"
    # the library helper solves the same equation
    assert free_drift_velocity(tau, coriolis_from_latitude(LAT), RHO_H,
                               turning_angle_deg=TURN) == pytest.approx(u_exact, rel=1e-10)
    # ice drifts to the right of the wind in the northern hemisphere
    assert np.angle(u_exact / ua) < 0


def test_explicit_inertial_oscillation_period_and_speed(free_mesh):
    """Coriolis only: u rotates clockwise (f > 0) with period 2π/f; the
    Crank–Nicolson Coriolis keeps the speed (a Cayley rotation)."""
    rheo, st = free_rheology_state(free_mesh)
    f = 1.4e-4
    s = ExplicitSolver(rheo, free_mesh, forces=[Coriolis(f=f)], substeps=5)
    st.velocity[:] = (0.1, 0.0)
    period = 2 * math.pi / f
    dt = 300.0
    n = int(round(2 * period / dt))
    ang, speed = np.zeros(n + 1), np.zeros(n + 1)
    for k in range(1, n + 1):
        step(s, st, dt)
        u = st.velocity[:, 0] + 1j * st.velocity[:, 1]
        assert np.ptp(u.real) < 1e-12 and np.ptp(u.imag) < 1e-12  # stays uniform
        ang[k] = np.angle(u[0])
        speed[k] = abs(u[0])
    speed[0] = 0.1
    t = dt * np.arange(n + 1)
    omega = np.polyfit(t, np.unwrap(ang), 1)[0]
    assert omega < 0, "northern hemisphere: clockwise"
    assert 2 * math.pi / abs(omega) == pytest.approx(period, rel=1e-2)
    assert np.abs(speed / 0.1 - 1).max() < 1e-10


def test_implicit_inertial_oscillation_backward_euler(free_mesh):
    """Implicit solver: backward Euler rotation u_{n+1} = (I + fΔt J)^{-1} u_n
    (period 2π/f to 1 % at fΔt = 0.042; speed damped by the BE factor)."""
    rheo, st = free_rheology_state(free_mesh)
    f = 1.4e-4
    s = ImplicitSolver(rheo, free_mesh, forces=[Coriolis(f=f)], linear_solver="superlu", tol=1e-13)
    st.velocity[:] = (0.1, 0.0)
    dt = 300.0
    z = 0.1 + 0j
    ang = [0.0]
    n = int(round(2 * 2 * math.pi / f / dt))
    for _ in range(n):
        step(s, st, dt)
        z = z / (1 + 1j * f * dt)
        ang.append(np.angle(st.velocity[0, 0] + 1j * st.velocity[0, 1]))
    assert np.allclose(st.velocity[:, 0] + 1j * st.velocity[:, 1], z, rtol=0, atol=1e-9 * abs(z))
    omega = np.polyfit(dt * np.arange(n + 1), np.unwrap(ang), 1)[0]
    assert 2 * math.pi / abs(omega) == pytest.approx(2 * math.pi / f, rel=1e-2)


def test_linearisation_matches_force_at_iterate():
    rng = np.random.default_rng(3)
    nodes = rng.uniform(0, 1e5, (7, 2))
    vel = rng.normal(0, 0.2, (7, 2))
    cur = lambda t, x, y: (0.05 + 0 * x, -0.02 + 1e-7 * y)  # noqa: E731
    drag = OceanDrag(cur, turning_angle_deg=20.0)
    A, b = drag.linearise(0.0, nodes, vel, 900.0)
    lin = b - np.einsum("nij,nj->ni", A, vel)
    assert np.allclose(lin, drag.stress(0.0, nodes, vel), rtol=1e-13, atol=0)
    # Coriolis: b − A u = −ρh f k×u = ρh f (v, −u)
    cor = Coriolis(f=1.3e-4)
    A, b = cor.linearise(0.0, nodes, vel, 900.0)
    got = b - np.einsum("nij,nj->ni", A, vel)
    assert np.allclose(got, 900.0 * 1.3e-4 * np.c_[vel[:, 1], -vel[:, 0]], rtol=1e-14)
    # wind: A = 0, b = ρa Ca |Ua| Ua
    A, b = WindStress((3.0, 4.0)).linearise(0.0, nodes, vel, 900.0)
    assert np.all(A == 0) and np.allclose(b, RHO_AIR * 1.2e-3 * 5.0 * np.array([3.0, 4.0]))
    # explicit terms carry the same data
    terms = explicit_terms([WindStress((3.0, 4.0)), drag, cor], 0.0, nodes)
    assert np.allclose(terms.tau, b) and np.allclose(terms.coriolis, 1.3e-4)
    assert terms.sin_turn == pytest.approx(math.sin(math.radians(20.0)))


def test_vector_field_conventions():
    nodes = np.array([[0.0, 0.0], [1.0, 2.0], [3.0, 1.0]])
    pair = evaluate_vector(lambda t, x, y: (x, 2 * y), 0.0, nodes)
    arr = evaluate_vector(lambda t, x, y: np.vstack([x, 2 * y]), 0.0, nodes)  # forcing: (2, n)
    const = evaluate_vector((1.5, -2.0), 0.0, nodes)
    assert np.array_equal(pair, arr) and np.array_equal(pair[:, 1], 2 * nodes[:, 1])
    assert np.array_equal(const, np.tile([1.5, -2.0], (3, 1)))
    with pytest.raises(ForcingError, match="wind"):
        evaluate_vector(lambda t, x, y: (x, y, x), 0.0, nodes, "wind")
    with pytest.raises(ForcingError, match="non-finite"):
        evaluate_vector(lambda t, x, y: (np.nan * x, y), 0.0, nodes)
    with pytest.raises(ConfigError, match="wind"):
        WindStress("strong")
    with pytest.raises(ConfigError, match="exactly one"):
        Coriolis()
    with pytest.raises(ConfigError, match="turning_angle_deg"):
        OceanDrag(turning_angle_deg=120.0)


def test_forcing_package_fields_plug_in():
    """Fields of the ``forcing`` package (``(2, n)`` arrays) work as wind/current."""
    forcing = pytest.importorskip("forcing")
    nodes = np.array([[0.0, 0.0], [5e3, 1e3], [2e4, 3e4]])
    func = lambda t, x, y: (5.0 + 1e-4 * x, -1.0 + 0 * y)  # noqa: E731
    field = forcing.as_field(func, "vector", "m s-1")
    a = WindStress(field).stress(0.0, nodes)
    b = WindStress(func).stress(0.0, nodes)
    assert np.array_equal(a, b)
    drag = OceanDrag(forcing.as_field((0.1, 0.05), "vector"))
    assert np.allclose(drag.current_at(0.0, nodes), [[0.1, 0.05]] * 3)
