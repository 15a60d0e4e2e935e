"""Drifters: advection by the P1-interpolated transport velocity (through Model),
loss outside the mesh."""
import numpy as np

from lagice.drifters import Drifters, locate
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.model import Model
from lagice.solvers import PrescribedStepper
from lagice.state import IceState


def _model(mesh, velocity, drifters, mover=None):
    st = IceState.uniform(mesh, cohesion_pa=3e4)
    return Model(st, solver=PrescribedStepper(mesh=mesh, velocity=velocity), drifters=drifters, mover=mover)


def test_drifters_follow_linear_velocity_exactly():
    poly, _ = rectangle_domain(200e3, 100e3)
    mesh = generate_mesh(poly, 15e3, exterior_tag="free")
    G = np.array([[1e-7, 2e-7], [-1e-7, 0.5e-7]])
    u0 = np.array([0.05, -0.02])

    def linear(t, x, y):  # a linear field: P1 interpolation is exact
        return u0[0] + G[0, 0] * x + G[0, 1] * y, u0[1] + G[1, 0] * x + G[1, 1] * y

    p0 = np.array([[50e3, 50e3], [120e3, 30e3]])
    dr = Drifters(p0)
    model = _model(mesh, linear, dr)
    model.step(600.0)
    expected = p0 + (u0 + p0 @ G.T) * 600.0
    assert np.allclose(dr.positions, expected, rtol=0, atol=1e-9)
    assert not dr.lost.any() and len(dr.trajectories()[0]) == 2
    assert np.allclose(dr.times_s(), [0.0, 600.0])


def test_drifters_keep_barycentric_position_in_the_moving_mesh():
    """Drifters and nodes move with the same transport velocity: after several steps of
    a (non-linear) prescribed field with mesh motion, every drifter sits at the same
    barycentric coordinates of the same triangle, to round-off."""
    from lagice.lagrangian import MeshMotion

    poly, _ = rectangle_domain(200e3, 100e3)
    mesh = generate_mesh(poly, 15e3, exterior_tag="free")
    p0 = np.array([[50e3, 50e3], [120e3, 30e3], [160e3, 70e3]])
    dr = Drifters(p0)
    model = _model(mesh, lambda t, x, y: (0.05 * np.sin(y / 3e4), 0.03 * np.cos(x / 5e4)), dr, MeshMotion())
    e0, w0 = locate(p0, mesh.nodes, mesh.triangles)
    for _ in range(5):
        model.step(3600.0)
    e1, w1 = locate(dr.positions, model.mesh.nodes, model.mesh.triangles)
    assert np.array_equal(e0, e1)
    assert np.abs(w1 - w0).max() < 1e-9
    assert np.abs(dr.positions - p0).max() > 500.0  # they did move (m)


def test_drifter_leaving_the_mesh_is_flagged_not_dropped():
    poly, _ = rectangle_domain(100e3, 100e3)
    mesh = generate_mesh(poly, 20e3, exterior_tag="free")
    dr = Drifters([[95e3, 50e3], [10e3, 50e3]])
    model = _model(mesh, (1.0, 0.0), dr)  # 1 m/s eastwards
    for _ in range(3):
        model.step(3600.0)
    assert dr.lost.tolist() == [True, False]
    assert len(dr.positions) == 2  # still reported, stopped where it left
    elem, w = locate(np.array([[50e3, 50e3]]), mesh.nodes, mesh.triangles)
    assert elem[0] >= 0 and np.isclose(w.sum(), 1.0) and (w >= -1e-12).all()
