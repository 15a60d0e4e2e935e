"""Persistent node ids through remeshing, and Lagrangian windows that span a
remesh event (lagice.io.snapshots.load_window, issue 7 diagnostics)."""
import numpy as np
import pytest

from lagice.diagnostics import lagrangian_velocity_gradients
from lagice.errors import LagiceError
from lagice.io.snapshots import SnapshotWriter, load_window
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.model import Model
from lagice.remesh import remesh_if_needed
from lagice.state import IceState


def _state(size=40e3, h=5e3):
    poly, _ = rectangle_domain(size, size)
    mesh = generate_mesh(poly, h)
    return IceState.uniform(mesh, thickness_m=1.0, concentration=1.0, cohesion_pa=25e3)


def test_remesh_keeps_ids_of_kept_nodes_and_gives_new_ones():
    st = _state()
    n0 = st.mesh.n_nodes
    assert np.array_equal(st.node_id, np.arange(n0))
    pos_by_id = {int(i): p.copy() for i, p in zip(st.node_id, st.mesh.nodes)}
    for k in range(3):  # three local events, each on a different element
        ev = remesh_if_needed(st, 5e3, flagged=[(k + 1) * st.mesh.n_elements // 4])
        assert ev is not None and ev.kind == "local"
        ids = st.node_id
        assert ids.shape == (st.mesh.n_nodes,) and np.unique(ids).size == ids.size
        kept = ids[:len(ev.kept_nodes)]
        new = ids[len(ev.kept_nodes):]
        # kept nodes did not move and kept their ids; new ids were never used before
        for i, p in zip(kept, st.mesh.nodes[:len(kept)]):
            assert np.array_equal(pos_by_id[int(i)], p)
        assert new.size == ev.n_nodes_added and (new.size == 0 or new.min() >= max(pos_by_id) + 1)
        assert st.counters["next_node_id"] == max(pos_by_id) + 1 + new.size
        for i, p in zip(ids, st.mesh.nodes):
            pos_by_id.setdefault(int(i), p.copy())


def test_window_across_a_remesh_follows_nodes(tmp_path):
    """Snapshot, remesh, affine motion x1 = x0 + Δt (G x0 + c), snapshot: the
    window across the remesh pairs every surviving node with itself, so the
    start-geometry Lagrangian gradient equals G exactly on the kept elements;
    the remeshed elements are left out and counted."""
    st = _state()
    model = Model(st)
    w = SnapshotWriter(tmp_path / "snaps", crs=None)
    w.write(model)
    ev = remesh_if_needed(st, 5e3, flagged=[st.mesh.n_elements // 2])
    st.counters["mesh_epoch"] = 1
    G = np.array([[2e-7, -1e-7], [3e-7, -0.5e-7]])
    dt = 86400.0
    st.mesh.nodes = st.mesh.nodes + dt * (st.mesh.nodes @ G.T + np.array([0.01, -0.02]))
    model.clock.time_s, model.clock.iteration = dt, 10
    w.write(model)
    win = load_window(tmp_path / "snaps", 0.0, dt)
    assert win["remesh_events"] == 1 and win["dt_s"] == dt
    assert win["n_elements_lost"] == ev.n_patch_old
    assert win["triangles"].shape[0] == len(ev.kept_elements)
    r = lagrangian_velocity_gradients(win["xy0"], win["xy1"], win["triangles"], dt, geometry="start")
    np.testing.assert_allclose(r.gradient_s, np.broadcast_to(G, r.gradient_s.shape), rtol=0, atol=1e-18)
    # the coast mask is taken on the start mesh, not on the holes left by the patch
    xy_s, tri_s = win["start_mesh"]
    assert tri_s.shape[0] == win["triangles"].shape[0] + win["n_elements_lost"]
    # every start node's end position: the affine motion where it survived, NaN where it was replaced
    end = win["start_nodes_at_end"]
    gone = np.isnan(end[:, 0])
    assert 0 < gone.sum() < len(end)
    np.testing.assert_allclose(end[~gone], (xy_s + dt * (xy_s @ G.T + np.array([0.01, -0.02])))[~gone],
                               rtol=1e-15, atol=1e-6)


def test_window_without_ids_across_remesh_is_refused(tmp_path):
    st = _state()
    st.node_id = None
    model = Model(st)
    w = SnapshotWriter(tmp_path, crs=None)
    w.write(model)
    remesh_if_needed(st, 5e3, flagged=[3])
    st.node_id = None
    st.counters["mesh_epoch"] = 1
    model.clock.time_s, model.clock.iteration = 100.0, 1
    w.write(model)
    with pytest.raises(LagiceError, match="spans a remesh .* no node_id"):
        load_window(tmp_path, 0.0, 100.0)
    with pytest.raises(LagiceError, match="no window"):
        load_window(tmp_path, 100.0, 100.0)
