"""Drifters: advection by P1-interpolated velocity, loss outside the mesh."""
import numpy as np

from lagice.drifters import Drifters, locate
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.state import IceState


def test_drifters_follow_linear_velocity_exactly():
    poly, _ = rectangle_domain(200e3, 100e3)
    mesh = generate_mesh(poly, 15e3)
    st = IceState.uniform(mesh, cohesion_pa=3e4)
    G = np.array([[1e-7, 2e-7], [-1e-7, 0.5e-7]])
    u0 = np.array([0.05, -0.02])
    st.velocity = u0 + mesh.nodes @ G.T  # linear field: P1 interpolation is exact
    p0 = np.array([[50e3, 50e3], [120e3, 30e3]])
    dr = Drifters(p0)
    dr.advance(st, 600.0)
    expected = p0 + (u0 + p0 @ G.T) * 600.0
    assert np.allclose(dr.positions, expected, rtol=0, atol=1e-9)
    assert not dr.lost.any() and len(dr.trajectories()[0]) == 2


def test_drifter_leaving_the_mesh_is_flagged_not_dropped():
    poly, _ = rectangle_domain(100e3, 100e3)
    mesh = generate_mesh(poly, 20e3)
    st = IceState.uniform(mesh, cohesion_pa=3e4)
    st.velocity[:] = [1.0, 0.0]  # 1 m/s eastwards
    dr = Drifters([[95e3, 50e3], [10e3, 50e3]])
    for _ in range(3):
        dr.advance(st, 3600.0)
    assert dr.lost.tolist() == [True, False]
    assert len(dr.positions) == 2  # still reported, stopped where it left
    elem, w = locate(np.array([[50e3, 50e3]]), mesh.nodes, mesh.triangles)
    assert elem[0] >= 0 and np.isclose(w.sum(), 1.0) and (w >= -1e-12).all()
