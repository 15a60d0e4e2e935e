"""Trigger, local patches, stitching, fallbacks, and conservation over many remesh events."""
import numpy as np
import pytest

import lagice.remesh as rm
from lagice.errors import MeshError
from lagice.lagrangian import move_mesh
from lagice.mesh import angles_deg, generate_mesh, rectangle_domain
from lagice.remesh import RemeshLog, TriggerParams, check_trigger, remesh_if_needed, totals
from lagice.state import IceState


def _random_state(mesh, rng):
    m = mesh.n_elements
    st = IceState.uniform(mesh, thickness_m=1.0, concentration=1.0, cohesion_pa=25e3)
    st.thickness = rng.uniform(0.0, 3.0, m)
    st.concentration = rng.uniform(0.0, 1.0, m)
    st.concentration[rng.random(m) < 0.2] = 1.0
    st.damage = rng.uniform(0.0, 1.0 - 1e-6, m)
    st.damage[rng.random(m) < 0.2] = 0.0
    st.cohesion = rng.uniform(20e3, 30e3, m)
    st.stress = rng.normal(0.0, 1e4, (m, 3))
    st.snow = rng.uniform(0.0, 0.5, m)
    st.velocity = rng.normal(0.0, 0.1, (mesh.n_nodes, 2))
    return st


@pytest.fixture(scope="module")
def small_mesh():
    poly, segs = rectangle_domain(40e3, 40e3)
    return generate_mesh(poly, 5e3, segments={"open": segs["right"], "top": segs["top"]})


def test_trigger_quiet_on_fresh_mesh_and_fires_on_distortion(small_mesh):
    mesh = small_mesh.copy()
    assert not check_trigger(mesh, 5e3).any
    interior = np.setdiff1d(np.arange(mesh.n_nodes), np.unique(mesh.boundary_edges))
    v = interior[0]
    nb = mesh.triangles[np.any(mesh.triangles == v, axis=1)]
    other = nb[nb != v][0]
    mesh.nodes[v] = 0.97 * mesh.nodes[other] + 0.03 * mesh.nodes[v]  # nearly collapse an edge
    tr = check_trigger(mesh, 5e3)
    assert tr.any and tr.counts["angle"] + tr.counts["edge_length"] + tr.counts["near_inversion"] > 0
    assert np.all(tr.seeds[tr.bad]) and tr.seeds.sum() >= tr.bad.sum()
    wide = check_trigger(mesh, 5e3, TriggerParams(seed_margin_deg=30.0))
    assert wide.seeds.sum() > tr.seeds.sum() and np.array_equal(wide.bad, tr.bad)
    tr2 = check_trigger(small_mesh, 5e3, TriggerParams(length_factor=1.01))
    assert tr2.counts["edge_length"] > 0


def test_local_remesh_fixes_patch_keeps_outside_bit_identical(small_mesh, rng):
    mesh = small_mesh.copy()
    st = _random_state(mesh, rng)
    old = {k: np.array(getattr(st, k), copy=True) for k in ("thickness", "concentration", "damage",
                                                            "stress", "cohesion", "snow", "velocity")}
    old_mesh = mesh.copy()
    ev = remesh_if_needed(st, 5e3, flagged=[mesh.n_elements // 2])
    assert ev is not None and ev.kind == "local"
    k = len(ev.kept_elements)
    assert 0 < ev.n_patch_old < mesh.n_elements // 2
    nm = st.mesh
    assert np.array_equal(nm.nodes[nm.triangles[:k]], old_mesh.nodes[old_mesh.triangles[ev.kept_elements]])
    for name in ("thickness", "concentration", "damage", "stress", "cohesion", "snow"):
        assert np.array_equal(getattr(st, name)[:k], old[name][ev.kept_elements]), name
    assert np.array_equal(st.velocity[:len(ev.kept_nodes)], old["velocity"][ev.kept_nodes])
    assert np.array_equal(nm.nodes[:len(ev.kept_nodes)], old_mesh.nodes[ev.kept_nodes])
    # domain boundary: same edges (renumbered), same tags, same coordinates
    assert np.array_equal(nm.nodes[nm.boundary_edges], old_mesh.nodes[old_mesh.boundary_edges])
    assert np.array_equal(nm.boundary_tags, old_mesh.boundary_tags) and nm.tag_names == old_mesh.tag_names
    from lagice.mesh import boundary_edges_of
    be = boundary_edges_of(nm.triangles)
    assert {tuple(e) for e in be.tolist()} == {tuple(e) for e in nm.boundary_edges.tolist()}
    assert np.all(nm.areas() > 0)
    assert ev.t_gmsh_s > 0 and ev.t_remap_s > 0 and ev.extrema_after and ev.totals_after


def test_global_remesh_keeps_domain_boundary_nodes(small_mesh, rng):
    mesh = small_mesh.copy()
    st = _random_state(mesh, rng)
    bnodes = mesh.nodes[np.unique(mesh.boundary_edges)]
    ev = rm.remesh_global(st, 4e3)
    assert ev.kind == "global" and ev.n_patch_old == mesh.n_elements
    nm = st.mesh
    nb = nm.nodes[np.unique(nm.boundary_edges)]
    assert {tuple(p) for p in bnodes.tolist()} == {tuple(p) for p in nb.tolist()}
    assert np.array_equal(nm.nodes[nm.coast_nodes()], mesh.nodes[mesh.coast_nodes()])
    assert nm.n_elements > mesh.n_elements  # finer target size
    assert abs(ev.rel_change["ice_volume_m3"]) < 1e-12


def test_gmsh_failure_falls_back_then_keeps_run(small_mesh, rng, monkeypatch):
    real = rm.mesh_patch
    calls = []

    def fail_local(mesh, bnd, size, algorithm=6):
        calls.append(len(bnd.loops))
        if len(calls) <= 3:
            raise MeshError("simulated gmsh failure")
        return real(mesh, bnd, size, algorithm=algorithm)

    monkeypatch.setattr(rm, "mesh_patch", fail_local)
    st = _random_state(small_mesh.copy(), rng)
    ev = remesh_if_needed(st, 5e3, flagged=[3], max_patch_fraction=1.0)
    assert ev.kind == "global" and len(ev.attempts) == 4 and "simulated" in ev.attempts[0]

    def always_fail(*a, **k):
        raise MeshError("simulated gmsh failure")

    monkeypatch.setattr(rm, "mesh_patch", always_fail)
    st = _random_state(small_mesh.copy(), rng)
    before = st.mesh
    log = RemeshLog()
    ev = remesh_if_needed(st, 5e3, flagged=[3], log=log)
    assert ev.kind == "failed" and st.mesh is before and len(log) == 1


def test_deterministic(small_mesh):
    outs = []
    for _ in range(2):
        rng = np.random.default_rng(7)
        st = _random_state(small_mesh.copy(), rng)
        for _k in range(5):
            st.velocity = rng.normal(0.0, 1.0, (st.mesh.n_nodes, 2))
            rep = move_mesh(st, st.velocity, 1500.0)
            remesh_if_needed(st, 5e3, flagged=rep.flagged_elements)
        outs.append((st.mesh.nodes.copy(), st.mesh.triangles.copy(), st.thickness.copy(), st.damage.copy()))
    for a, b in zip(*outs):
        assert np.array_equal(a, b)


def test_hundreds_of_events_conserve_totals_and_bounds(rng):
    """Random fields on randomly distorted small meshes: every remesh event
    keeps total ice volume, ice area and snow volume to 1e-12 (relative),
    A and d in [0, 1] without clipping, and the target size field."""
    poly, segs = rectangle_domain(30e3, 30e3)
    n_events = 0
    worst = 0.0
    size = lambda x, y: 3e3 + 2e3 * x / 30e3  # noqa: E731 - graded size field, fixed in space
    for _trial in range(4):
        mesh = generate_mesh(poly, size, segments={"open": segs["right"]})
        st = _random_state(mesh, rng)
        for _k in range(60):
            st.velocity = rng.normal(0.0, 1.0, (st.mesh.n_nodes, 2))
            rep = move_mesh(st, st.velocity, 300.0 + 300.0 * rng.random())
            flagged = np.union1d(rep.flagged_elements, rng.integers(0, st.mesh.n_elements, 2))
            before = totals(st.mesh, st)
            ev = remesh_if_needed(st, size, flagged=flagged, rings=int(rng.integers(1, 3)))
            assert ev is not None and ev.kind in ("local", "global")
            n_events += 1
            after = totals(st.mesh, st)
            for key in before:
                rel = abs(after[key] - before[key]) / before[key]
                worst = max(worst, rel)
                assert rel <= 1e-12, (key, rel)
            assert st.concentration.min() >= 0.0 and st.concentration.max() <= 1.0
            assert st.damage.min() >= 0.0 and st.damage.max() < 1.0
            assert np.all(st.mesh.areas() > 0)
    assert n_events >= 200
    print(f"{n_events} events, worst relative change of a total {worst:.2e}")


def test_remeshed_patch_has_good_angles(small_mesh, rng):
    mesh = small_mesh.copy()
    st = _random_state(mesh, rng)
    for _ in range(4):
        st.velocity = rng.normal(0.0, 2.0, (st.mesh.n_nodes, 2))
        move_mesh(st, st.velocity, 2000.0)
    tr = check_trigger(st.mesh, 5e3)
    assert tr.any
    ev = remesh_if_needed(st, 5e3)
    k = len(ev.kept_elements)
    assert angles_deg(st.mesh.nodes, st.mesh.triangles[k:]).min() >= 10.0 or ev.kind == "global"


def test_patch_with_hole_and_island_domain(rng, tmp_path):
    """A patch that encloses unpatched elements (a hole), and a global remesh
    of a domain with an island (the annulus of the shear_channel scene)."""
    from lagice.remesh import apply_remesh, remesh_region
    from lagice.remesh.patch import make_manifold, patch_boundary

    from helpers import scene_sim

    st = scene_sim("shear_channel", tmp_path, {"domain.resolution_m": 12e3}).model.state
    mesh = st.mesh
    interior = np.setdiff1d(np.arange(mesh.n_nodes), np.unique(mesh.boundary_edges))
    r = np.hypot(*mesh.nodes[interior].T)
    v = interior[np.argmin(np.abs(r - 65e3))]
    around = np.any(mesh.triangles == v, axis=1)
    mask = rm.grow_patch(mesh, around, 2) & ~around
    mask = make_manifold(mesh, mask)
    assert not mask[around].any()
    bnd = patch_boundary(mesh, mask)
    assert sum(not o for o in bnd.outer) == 1  # one hole
    before = totals(mesh, st)
    old_d = st.damage[around].copy()
    nm, fields, vel, stt, _ = remesh_region(st, mask, 12e3)
    apply_remesh(st, nm, fields, vel, None)
    new_index = np.searchsorted(stt.kept_elements, np.flatnonzero(around))
    assert np.array_equal(st.damage[new_index], old_d)
    after = totals(st.mesh, st)
    assert abs(after["ice_volume_m3"] / before["ice_volume_m3"] - 1) < 1e-12
    ev = rm.remesh_global(st, 10e3)
    assert ev.kind == "global" and abs(ev.rel_change["ice_volume_m3"]) < 1e-12
    rc = np.hypot(*st.mesh.nodes[st.mesh.coast_nodes()].T)
    assert np.all((np.abs(rc - 100e3) < 1e-6) | (np.abs(rc - 30e3) < 1e-6))
    assert np.all(st.mesh.areas() > 0)


def test_a_snapshot_on_a_remesh_step_has_the_steps_transport_velocity_and_rates(tmp_path):
    """A remesh at the end of a step drops the stepper's transport velocity and strain rate
    with the old mesh. The model carries them onto the new mesh (kept nodes keep theirs, new
    nodes interpolated), so a snapshot written on that step has the deformation rates, and its
    velocity is the step's transport velocity, not the state's end-of-step velocity."""
    from lagice.fem import shape_gradients, strain_rate
    from lagice.io.snapshots import snapshot_dataset

    from helpers import scene_sim

    sim = scene_sim("winter_basin_pack", tmp_path, {"domain.resolution_m": 40e3, "run.duration": "1d"})
    sim.run(n_steps=2)
    model = sim.model
    tv = model.transport_velocity.copy()
    assert not np.allclose(tv, model.state.velocity)  # the two velocities differ
    m = model.mesh
    ids_before = {int(i): k for k, i in enumerate(model.state.node_id)}
    interior = np.setdiff1d(np.arange(m.n_nodes), np.unique(m.boundary_edges))
    v = interior[np.argmin(np.hypot(*(m.nodes[interior] - m.nodes.mean(axis=0)).T))]
    nb = m.triangles[np.any(m.triangles == v, axis=1)]
    other = nb[nb != v][0]
    m.nodes[v] = 0.97 * m.nodes[other] + 0.03 * m.nodes[v]  # one edge nearly collapsed
    ev = model.component("remeshing").advance(model, sim.dt)
    assert ev is not None and ev.kind == "local"
    assert model.stepper.transport_velocity is None  # dropped with the old mesh
    nm = model.mesh
    out = model.transport_velocity
    assert out.shape == (nm.n_nodes, 2)
    kept = np.array([int(i) in ids_before for i in model.state.node_id])
    assert 0 < (~kept).sum() < kept.sum()
    old_index = np.array([ids_before[int(i)] for i in model.state.node_id[kept]])
    assert np.array_equal(out[kept], tv[old_index])
    b, c, _ = shape_gradients(nm.nodes, nm.triangles)
    np.testing.assert_array_equal(model.strain_rate, strain_rate(nm.triangles, b, c, out))
    ds = snapshot_dataset(model)
    for name in ("divergence_rate", "shear_rate", "total_deformation_rate"):
        assert name in ds and np.isfinite(ds[name].values).all()
    np.testing.assert_array_equal(ds["velocity_x"].values[0], out[:, 0])
    sim.run(n_steps=1)  # the next step replaces both
    assert model.stepper.transport_velocity is not None and model.transport_velocity is model.stepper.transport_velocity
