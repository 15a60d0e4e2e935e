"""The performance paths of the explicit stepper change nothing physical (issue 15):
Morton renumbering of nodes and elements (at mesh creation and after each remesh),
the sub-step loop in one compiled call, and the measured serial/parallel choice
(recorded, and overridden by ``solver.parallel``)."""
import copy
import logging

import numba
import numpy as np
import pytest

import lagice._numba as lnumba
import lagice.solvers.explicit as explicit
from lagice.errors import ConfigError
from lagice.mesh import morton_order
from lagice.remesh import remesh_global, totals

from helpers import scene_sim

#: a short damaging wind_square run on a coarse mesh (≈ 230 elements, moving mesh)
KW = {"domain.resolution_m": 50e3, "forcing.wind.params.ramp_h": 1.0, "forcing.wind.params.turn_h": 3.0,
      "run.seed": 3, "run.duration": "8h", "lagrangian.enabled": True}


def node_map(xy_from, xy_to):
    """Index in ``xy_to`` of each point of ``xy_from`` (the same points, permuted)."""
    oa = np.lexsort(xy_from.T[::-1])
    ob = np.lexsort(xy_to.T[::-1])
    assert np.array_equal(xy_from[oa], xy_to[ob])
    out = np.empty(len(xy_from), np.int64)
    out[oa] = ob
    return out


def element_map(tri_from, tri_to, nmap):
    """Index in ``tri_to`` of each element of ``tri_from`` (element id = its sorted node triple)."""
    ka = np.sort(nmap[tri_from], axis=1)
    kb = np.sort(tri_to, axis=1)
    oa = np.lexsort(ka.T[::-1])
    ob = np.lexsort(kb.T[::-1])
    assert np.array_equal(ka[oa], kb[ob])
    out = np.empty(len(tri_from), np.int64)
    out[oa] = ob
    return out


def test_renumbering_leaves_a_damaging_run_unchanged(tmp_path):
    """domain.renumber = false (gmsh order) and true (Morton order, the default) on the same
    scene: the same cohesion per element (drawn in gmsh order), and after 8 h of wind with
    damage and a moving mesh every field matches, mapped by node position / node triple,
    to round-off (only the order of floating-point sums differs)."""
    one = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        a = scene_sim("wind_square", tmp_path / "a", {**KW, "domain.renumber": False})
        b = scene_sim("wind_square", tmp_path / "b", KW)
        ma, mb = a.model, b.model
        nm = node_map(ma.mesh.nodes, mb.mesh.nodes)
        assert not np.array_equal(nm, np.arange(len(nm))), "the test needs a renumbered mesh"
        assert np.array_equal(morton_order(mb.mesh.nodes), np.arange(mb.mesh.n_nodes))
        em = element_map(ma.mesh.triangles, mb.mesh.triangles, nm)
        assert np.array_equal(ma.state.cohesion, mb.state.cohesion[em])
        a.run()
        b.run()
    finally:
        numba.set_num_threads(one)
    sa, sb = ma.state, mb.state
    assert sa.damage.max() > 0.1, "the test should include damage"
    assert np.abs(mb.mesh.nodes[nm] - ma.mesh.nodes).max() < 1e-6  # m (nodes moved ~km)
    assert np.abs(ma.mesh.nodes - a.model.state.mesh.nodes).max() == 0.0
    uscale = np.abs(sa.velocity).max()
    assert np.abs(sb.velocity[nm] - sa.velocity).max() < 1e-9 * uscale
    assert np.abs(sb.damage[em] - sa.damage).max() < 1e-9
    sscale = np.abs(sa.stress).max()
    assert np.abs(sb.stress[em] - sa.stress).max() < 1e-9 * sscale
    ta, tb = totals(ma.mesh, sa), totals(mb.mesh, sb)
    for k in ta:
        assert tb[k] == pytest.approx(ta[k], rel=1e-12)


def test_remesh_renumbers_and_keeps_fields_and_ids(tmp_path):
    """A global remesh with and without the renumbering: the same new mesh and fields up to
    the permutation (node ids follow their nodes), the renumbered one in Morton order, and
    the volume/area totals conserved as by the remesh alone."""
    sim = scene_sim("wind_square", tmp_path, {**KW, "run.duration": "2h", "solver.parallel": False})
    sim.run()
    st0 = sim.model.state
    sa, sb = copy.deepcopy(st0), copy.deepcopy(st0)
    size = 50e3
    ea = remesh_global(sa, size, renumber=False)
    eb = remesh_global(sb, size, renumber=True)
    assert ea.kind == eb.kind == "global"
    assert eb.node_perm is not None and ea.node_perm is None
    assert np.array_equal(morton_order(sb.mesh.nodes), np.arange(sb.mesh.n_nodes))
    assert not np.array_equal(eb.node_perm, np.arange(len(eb.node_perm)))
    # node ids follow their nodes
    ida = np.argsort(sa.node_id)
    idb = np.argsort(sb.node_id)
    assert np.array_equal(sa.node_id[ida], sb.node_id[idb])
    assert np.array_equal(sa.mesh.nodes[ida], sb.mesh.nodes[idb])
    assert np.array_equal(sa.velocity[ida], sb.velocity[idb])
    nm = node_map(sa.mesh.nodes, sb.mesh.nodes)
    em = element_map(sa.mesh.triangles, sb.mesh.triangles, nm)
    for name in ("thickness", "concentration", "damage", "stress", "cohesion"):
        assert np.array_equal(getattr(sb, name)[em], getattr(sa, name)), name
    t0, tb = totals(st0.mesh, st0), totals(sb.mesh, sb)
    for k in t0:
        assert tb[k] == pytest.approx(t0[k], rel=1e-10)
    assert eb.rel_change == pytest.approx(ea.rel_change, abs=1e-14)


def test_compiled_substep_loop_matches_python_loop(tmp_path):
    """The whole sub-step loop in one numba call (default) and the Python loop over the two
    kernels (profile_kernels) give bit-identical results on a damaging run, serial and
    parallel builds alike (tolerance 0)."""
    res = {}
    for par in (False, True):
        for prof in (False, True):
            sim = scene_sim("wind_square", tmp_path / f"{par}{prof}", {**KW, "solver.parallel": par})
            sim.model.stepper.profile_kernels = prof
            sim.run()
            res[par, prof] = sim.model.state
    ref = res[False, False]
    assert ref.damage.max() > 0.1
    for k, s in res.items():
        assert np.array_equal(s.velocity, ref.velocity), k
        assert np.array_equal(s.stress, ref.stress), k
        assert np.array_equal(s.damage, ref.damage), k
    kt = sim.model.stepper.kernel_timings
    assert kt["node_velocity"] > 0 and kt["element_stress_damage"] > 0  # profiled split recorded


@pytest.mark.parametrize("setting, parallel", [(True, True), (False, False)])
def test_forced_kernel_choice_is_obeyed_and_logged(tmp_path, caplog, setting, parallel):
    sim = scene_sim("wind_square", tmp_path, {**KW, "run.duration": "1h", "solver.parallel": setting})
    with caplog.at_level(logging.INFO, logger="lagice"):
        sim.run()
    ch = sim.model.stepper.kernel_choice
    assert ch["parallel"] is parallel and ch["method"] == f"solver.parallel = {str(setting).lower()}"
    assert sim.model.stepper.nodes.parallel is parallel
    assert any("explicit kernels: " + ("parallel" if parallel else "serial") in r.getMessage()
               for r in caplog.records)


def test_auto_kernel_choice_is_measured_and_recorded(tmp_path, caplog, monkeypatch):
    """solver.parallel = "auto": serial and every parallel thread count are timed on the run's
    own arrays at the first step; the fastest is kept, recorded and logged. Below the
    size floor the serial build is chosen without measuring."""
    n = numba.get_num_threads()
    monkeypatch.setattr(lnumba, "AUTOTUNE_MIN_SIZE", 0)
    sim = scene_sim("wind_square", tmp_path / "a", {**KW, "run.duration": "2h", "solver.parallel": "auto"})
    with caplog.at_level(logging.INFO, logger="lagice"):
        sim.run(n_steps=6)
    ch = sim.model.stepper.kernel_choice
    if n < 2:
        assert ch["method"].startswith("rule") and not ch["parallel"]
    else:
        assert ch["method"] == "measured"
        names = set(ch["timings_ms"])
        assert names == {"serial"} | {f"parallel_{t}" for t in range(2, n + 1)}
        best = min(ch["timings_ms"], key=ch["timings_ms"].get)
        if ch["parallel"]:
            assert best == f"parallel_{ch['threads']}" and numba.get_num_threads() == ch["threads"]
            assert ch["timings_ms"][best] * lnumba.AUTOTUNE_MARGIN < ch["timings_ms"]["serial"]
        else:
            assert ch["threads"] == 1
    assert sim.model.stepper.nodes.parallel is ch["parallel"] and ch["n_measurements"] == 1
    assert any("explicit kernels:" in r.getMessage() and f"{sim.model.mesh.n_elements} elements" in r.getMessage()
               for r in caplog.records)
    # measured again once AUTOTUNE_FIRST_INTERVAL_S of wall time has passed (a start-up trial can be
    # disturbed), then every AUTOTUNE_INTERVAL_S (the load changes)
    monkeypatch.setattr(explicit, "AUTOTUNE_FIRST_INTERVAL_S", 0.0)
    monkeypatch.setattr(explicit, "AUTOTUNE_INTERVAL_S", 1e9)
    sim.run(n_steps=2)
    assert sim.model.stepper.kernel_choice["n_measurements"] == 2
    monkeypatch.setattr(explicit, "AUTOTUNE_INTERVAL_S", 0.0)
    sim.run(n_steps=2)
    assert sim.model.stepper.kernel_choice["n_measurements"] == 4
    numba.set_num_threads(n)
    monkeypatch.setattr(lnumba, "AUTOTUNE_MIN_SIZE", 10**9)
    sim = scene_sim("wind_square", tmp_path / "b", {**KW, "run.duration": "1h"})
    sim.run()
    ch = sim.model.stepper.kernel_choice
    assert not ch["parallel"] and ch["method"] == f"rule: below {10**9} elements" and ch["timings_ms"] == {}
    # numba limited to one thread (as the ensemble workers are): serial without measuring
    monkeypatch.setattr(lnumba, "AUTOTUNE_MIN_SIZE", 0)
    numba.set_num_threads(1)
    try:
        sim = scene_sim("wind_square", tmp_path / "c", {**KW, "run.duration": "1h"})
        sim.run()
    finally:
        numba.set_num_threads(n)
    ch = sim.model.stepper.kernel_choice
    assert not ch["parallel"] and ch["method"] == "rule: one numba thread available"


def test_bad_parallel_setting_names_the_key(tmp_path):
    with pytest.raises(ConfigError, match=r"solver.parallel = 'fast'.*true, false or \"auto\""):
        scene_sim("wind_square", tmp_path, {**KW, "solver.parallel": "fast"})


def test_import_makes_openmp_workers_spin_briefly_unless_the_user_chose():
    """`import lagice` sets a short libgomp spin (GOMP_SPINCOUNT=10000, ~0.1 ms) and
    OMP_WAIT_POLICY=PASSIVE before numba's OpenMP runtime loads: workers spin between the
    sub-step kernels of a quiet machine, then sleep (libgomp's default 3-ms spin made the
    parallel kernels 4-5x slower on shared cores, docs/benchmarks.md). A user's own
    OMP_WAIT_POLICY or GOMP_SPINCOUNT is kept, and a wait policy of theirs is not
    overridden by our spin count (libgomp lets GOMP_SPINCOUNT win)."""
    import os
    import subprocess
    import sys

    code = ("import os, lagice; print(os.environ['OMP_WAIT_POLICY'], "
            "os.environ.get('GOMP_SPINCOUNT', 'unset'))")
    env = {k: v for k, v in os.environ.items() if k not in ("OMP_WAIT_POLICY", "GOMP_SPINCOUNT")}

    def run(**extra):
        return subprocess.run([sys.executable, "-c", code], env={**env, **extra}, capture_output=True,
                              text=True, check=True).stdout.split()

    assert run() == ["PASSIVE", "10000"]
    assert run(OMP_WAIT_POLICY="ACTIVE") == ["ACTIVE", "unset"]
    assert run(GOMP_SPINCOUNT="0") == ["PASSIVE", "0"]
