"""Lagrangian mesh motion: volume/area kept per element, ridging, inversion guard, outflow."""
import numpy as np
import pytest

from lagice.errors import ConfigError
from lagice.lagrangian import fixed_node_mask, move_mesh, new_budget
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.state import IceState

from helpers import compression_overrides, scene_sim, step


def _state(mesh, rng, conc=(0.5, 0.9)):
    st = IceState.uniform(mesh, thickness_m=1.0, concentration=0.8)
    m = mesh.n_elements
    st.thickness = rng.uniform(0.5, 2.0, m)
    st.concentration = rng.uniform(*conc, m)
    st.snow = rng.uniform(0.0, 0.3, m)
    return st


@pytest.fixture(scope="module")
def box_mesh():
    poly, segs = rectangle_domain(100e3, 100e3)
    return generate_mesh(poly, 10e3)  # all coast


@pytest.fixture(scope="module")
def channel_mesh():
    poly, segs = rectangle_domain(100e3, 50e3)
    return generate_mesh(poly, 8e3, segments={"open": segs["right"], "inflow": segs["left"],
                                              "top": segs["top"]}, exterior_tag="coast")


def _swirl(x, amp):
    return amp * np.column_stack([np.sin(np.pi * x[:, 1] / 100e3), np.sin(np.pi * x[:, 0] / 100e3)])


def test_volume_and_ice_area_kept_per_element(box_mesh, rng):
    mesh = box_mesh.copy()
    st = _state(mesh, rng)
    a0 = mesh.areas()
    v0, ia0, s0 = st.thickness * a0, st.concentration * a0, st.snow * a0
    st.velocity = _swirl(mesh.nodes, 0.1)
    b = new_budget()
    rep = move_mesh(st, st.velocity, 3600.0, b)
    a1 = mesh.areas()
    assert rep.limited_nodes == 0
    np.testing.assert_allclose(st.thickness * a1, v0, rtol=1e-14)
    np.testing.assert_allclose(st.concentration * a1, ia0, rtol=1e-14)
    np.testing.assert_allclose(st.snow * a1, s0, rtol=1e-14)
    assert not np.allclose(a1, a0)  # the mesh did move


def test_coast_nodes_fixed_and_segment_nodes_move(channel_mesh, rng):
    mesh = channel_mesh.copy()
    st = _state(mesh, rng)
    st.velocity[:] = (0.05, 0.0)
    x0 = mesh.nodes.copy()
    move_mesh(st, st.velocity, 600.0)
    fixed = fixed_node_mask(mesh)
    assert np.array_equal(mesh.nodes[fixed], x0[fixed])
    top = np.setdiff1d(mesh.nodes_with_tag("top"), np.flatnonzero(fixed))
    np.testing.assert_allclose(mesh.nodes[top, 0] - x0[top, 0], 30.0)
    interior = ~fixed
    assert np.all(mesh.nodes[interior, 0] > x0[interior, 0])


def test_ridging_caps_concentration_and_keeps_volume(box_mesh, rng):
    mesh = box_mesh.copy()
    st = _state(mesh, rng, conc=(0.95, 1.0))
    c = mesh.nodes - 50e3
    st.velocity = -2e-6 * c  # uniform convergence
    b = new_budget()
    V0 = st.ice_volume_m3
    IA0 = float(np.sum(st.concentration * mesh.areas()))
    move_mesh(st, st.velocity, 3 * 86400.0, b)
    assert st.concentration.max() <= 1.0
    assert b["ridged_elements"] > 0 and b["ridged_ice_area_m2"] > 0
    assert abs(st.ice_volume_m3 - V0) <= 1e-12 * V0
    IA1 = float(np.sum(st.concentration * mesh.areas()))
    assert IA1 + b["ridged_ice_area_m2"] == pytest.approx(IA0, rel=1e-12)


def test_inversion_guard_never_inverts(box_mesh, rng):
    mesh = box_mesh.copy()
    st = _state(mesh, rng)
    st.velocity = rng.normal(0.0, 1.0, (mesh.n_nodes, 2))  # wild: would invert many elements
    a0 = mesh.areas()
    V0 = st.ice_volume_m3
    b = new_budget()
    rep = move_mesh(st, st.velocity, 5000.0, b, min_area_ratio=0.05)
    a1 = mesh.areas()
    assert np.all(a1 > 0.05 * a0)
    assert rep.limited_nodes > 0 and b["limited_nodes"] == rep.limited_nodes
    assert len(rep.flagged_elements) > 0
    assert abs(st.ice_volume_m3 - V0) <= 1e-12 * V0


def test_open_boundary_outflow_booked(channel_mesh, rng):
    mesh = channel_mesh.copy()
    st = _state(mesh, rng)
    fixed = fixed_node_mask(mesh)
    V0 = st.ice_volume_m3
    b = new_budget()
    for _ in range(10):
        st.velocity[:] = (0.02, 0.0)
        st.velocity[fixed & np.isin(np.arange(mesh.n_nodes), mesh.coast_nodes())] = 0.0
        move_mesh(st, st.velocity, 1800.0, b)
    V1 = st.ice_volume_m3
    assert b["outflow_volume_m3"] > 0
    assert V1 + b["outflow_volume_m3"] == pytest.approx(V0, rel=1e-12)
    assert st.concentration.max() <= 1.0 and st.concentration.min() >= 0.0


def test_open_edge_owners_found_once_per_mesh(channel_mesh, rng):
    # the owners of the open edges are kept on the mesh (its topology never changes while its
    # nodes move): the kept ones are the search's, and a copy (a new mesh) searches again
    from lagice.lagrangian import _edge_owner

    mesh = channel_mesh.copy()
    st = _state(mesh, rng)
    sel = mesh.boundary_tags == mesh.tag_id("open")
    st.velocity[:] = (0.02, 0.0)
    st.velocity[fixed_node_mask(mesh)] = 0.0
    move_mesh(st, st.velocity, 1800.0)
    kept = mesh._topology_cache["open_edge_owner"]
    np.testing.assert_array_equal(kept, _edge_owner(mesh, mesh.boundary_edges[sel]))
    tri = mesh.triangles[kept]  # each owner holds its edge
    for (a, b), t in zip(mesh.boundary_edges[sel], tri):
        assert a in t and b in t
    move_mesh(st, st.velocity, 1800.0)
    assert mesh._topology_cache["open_edge_owner"] is kept
    assert "open_edge_owner" not in mesh.copy()._topology_cache


def test_bad_arguments(box_mesh, rng):
    st = _state(box_mesh.copy(), rng)
    with pytest.raises(ConfigError, match="dt_s"):
        move_mesh(st, st.velocity, 0.0)
    with pytest.raises(ConfigError, match="min_area_ratio"):
        move_mesh(st, st.velocity, 1.0, min_area_ratio=1.5)


def test_solver_move_remesh_step_cycle(tmp_path):
    """ImplicitSolver + mesh motion + a forced local remesh: the solver keeps
    stepping on the new mesh, boundary conditions still act on the tagged nodes."""
    from lagice.remesh import RemeshLog, remesh_if_needed

    sim = scene_sim("uniaxial_compression", tmp_path, compression_overrides(
        8, **{"run.seed": 3, "boundary.top.v": -0.05, "solver.dt": 600.0, "run.duration": "1d", "output.every": "1d"}))
    st, solver = sim.model.state, sim.model.stepper
    b = new_budget()
    log = RemeshLog()
    V0 = st.ice_volume_m3
    for k in range(6):
        step(solver, st, 600.0)
        rep = move_mesh(st, solver.transport_velocity, 600.0, b, solver=solver)
        flagged = np.union1d(rep.flagged_elements, [k * 7])  # force a remesh event every step
        ev = remesh_if_needed(st, 12.5e3, solver=solver, flagged=flagged, log=log)
        assert ev is not None and ev.kind == "local"
        assert solver.mesh is st.mesh
        assert len(st.velocity) == st.mesh.n_nodes and len(st.stress) == st.mesh.n_elements
    info = step(solver, st, 600.0)
    assert np.all(np.isfinite(st.velocity)) and info.iterations >= 1
    top = st.mesh.nodes_with_tag("top")
    np.testing.assert_allclose(st.velocity[top, 1], -0.05)
    assert abs(st.ice_volume_m3 - V0) < 1e-12 * V0
    assert len(log) == 6
