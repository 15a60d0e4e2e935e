"""Simulation API: schedules, bit-identical resume, damaged checkpoints, kill
during checkpoint writing, scene (TOML) validation."""
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest
import xarray as xr

from lagice.errors import ConfigError, RestartError
from lagice.io.checkpoint import latest_valid_checkpoint, list_checkpoints, read_checkpoint, write_checkpoint
from lagice.scenes.builder import build_simulation
from lagice.scenes.config import load_scene
from lagice.simulation import Simulation

FAST = {"run.duration": 1600.0, "solver.dt": 40.0, "output.every": 800.0, "checkpoint.every": 800.0,
        "domain.resolution_m": 25e3, "run.progress": False, "output.plot": False,
        "boundary.top.u": "5e-2*minimum(1.0, t/600.0)"}


def fields(model):
    st = model.state
    return {"nodes": st.mesh.nodes, "velocity": st.velocity, "stress": st.stress, "damage": st.damage,
            "thickness": st.thickness, "concentration": st.concentration, "cohesion": st.cohesion,
            "node_id": st.node_id}


def test_resume_is_bit_identical(tmp_path):
    cfg = load_scene("shear_box", FAST)
    full = build_simulation(cfg, tmp_path / "full")
    full.run()
    assert full.model.clock.iteration == 40
    assert full.model.state.damage.max() > 0, "the scene must crack for the test to mean something"

    cfg2 = load_scene("shear_box", FAST)
    part = build_simulation(cfg2, tmp_path / "part")
    part.run(n_steps=20)  # checkpoint at step 20 (t = 800 s)
    del part
    resumed = Simulation.resume(tmp_path / "part" / "checkpoints")
    assert resumed.model.clock.iteration == 20
    resumed.run()
    a, b = fields(full.model), fields(resumed.model)
    for k in a:
        assert np.array_equal(a[k], b[k]), f"{k} differs after resume"
    # the snapshot written after resume equals the uninterrupted one
    sa = xr.load_dataset(tmp_path / "full" / "snapshots" / "snapshot_00000040.nc")
    sb = xr.load_dataset(tmp_path / "part" / "snapshots" / "snapshot_00000040.nc")
    assert np.array_equal(sa["damage"].values, sb["damage"].values)


#: a moving mesh that remeshes (as tests/test_workflow.py BASE): 60 steps, several remesh events
REMESHING = {"run.duration": 6000.0, "solver.dt": 100.0, "output.every": 3000.0, "checkpoint.every": 3000.0,
             "domain.resolution_m": 25e3, "run.progress": False, "output.plot": False,
             "boundary.top.u": "20.0*minimum(1.0, t/600.0)", "lagrangian.enabled": True, "remesh.enabled": True,
             "run.max_speed_m_s": 50.0}


def test_resumed_run_carries_the_remesh_event_count(tmp_path):
    """components.remeshing.n_events of the final checkpoint counts the whole run: a run
    resumed after some remesh events ends with the uninterrupted run's count, and with its
    count of the events each trigger criterion fired in (summary ``remesh_triggers``). Each
    event was fired by at least one criterion and each criterion fired in no more events than
    there were, and the counts are those of the events' own logs."""
    def n_events(run):
        path = list_checkpoints(tmp_path / run / "checkpoints")[-1]
        return read_checkpoint(path)[1]["components"]["remeshing"]["n_events"]

    full = build_simulation(load_scene("shear_box", REMESHING), tmp_path / "full")
    full.run()
    part = build_simulation(load_scene("shear_box", REMESHING), tmp_path / "part")
    part.run(n_steps=30)  # checkpoint at step 30
    first = n_events("part")
    assert 0 < first < n_events("full"), "remesh events before and after the checkpoint"
    del part
    resumed = Simulation.resume(tmp_path / "part" / "checkpoints")
    assert resumed.model.component("remeshing").n_events == first
    resumed.run()
    assert n_events("part") == n_events("full")
    assert resumed.model.state.counters["remesh_count"] == full.model.state.counters["remesh_count"]
    trig, count = full.summary()["remesh_triggers"], full.summary()["remesh_count"]
    assert resumed.summary()["remesh_triggers"] == trig
    assert set(trig) == {"angle", "near_inversion", "edge_length"}
    assert max(trig.values()) <= count <= sum(trig.values())
    events = [ev for ev in full.model.component("remeshing").log.events if ev.kind != "failed"]
    assert len(events) == count
    assert trig == {k: sum(ev.trigger_counts[k] > 0 for ev in events) for k in trig}


def _as_written_without(path, keys):
    """Rewrite checkpoint ``path`` as a version of lagice without the dotted ``keys``
    would have written it: its stored configuration lacks them and its fingerprint is
    the hash of the physics without them (the hash of :meth:`Model.fingerprint`)."""
    import hashlib
    import json

    from lagice.scenes.config import physics_view

    arrays, meta = read_checkpoint(path)
    cfg = meta["config"]
    for key in keys:
        table, _, name = key.partition(".")
        del cfg[table][name]
    view = {k: v for k, v in physics_view(cfg).items() if not k.startswith("_")}
    meta["scene_fingerprint"] = hashlib.sha256(json.dumps(view, sort_keys=True, default=str).encode()).hexdigest()[:16]
    meta["lagice_version"] = "0.1.0"
    for k in ("format_version", "sha256", "step"):
        meta.pop(k)
    write_checkpoint(path.parent, int(path.name[11:21]), arrays, meta, keep=10)


def test_checkpoint_of_an_earlier_version_resumes_bit_identically(tmp_path):
    """A checkpoint written before keys were added (its configuration lacks them, its
    fingerprint was hashed without them) resumes when their values do what that version
    did (LEGACY_VALUES), and continues bit for bit; one lacking a key whose default does
    not (domain.renumber) is refused, naming it."""
    full = build_simulation(load_scene("shear_box", FAST), tmp_path / "full")
    full.run()
    part = build_simulation(load_scene("shear_box", FAST), tmp_path / "part")
    part.run(n_steps=20)
    ck = list_checkpoints(tmp_path / "part" / "checkpoints")[-1]
    old_keys = ["solver.substep_limit", "rheology.stress_correction", "rheology.stress_correction_mean_fraction",
                "domain.jitter"]
    _as_written_without(ck, old_keys)
    assert Simulation.resume(ck).model.fingerprint() != read_checkpoint(ck)[1]["scene_fingerprint"]
    resumed = Simulation.resume(ck)
    assert resumed.model.clock.iteration == 20
    resumed.run()
    a, b = fields(full.model), fields(resumed.model)
    for k in a:
        assert np.array_equal(a[k], b[k]), f"{k} differs after resume"
    # the same through the CLI path (resume_simulation normalises the stored configuration)
    from lagice.scenes.builder import resume_simulation

    assert resume_simulation(ck).model.clock.iteration == 20
    # a key whose default does not reproduce the earlier code is not accepted silently
    _as_written_without(ck, ["domain.renumber"])
    with pytest.raises(RestartError, match=r"no domain\.renumber"):
        Simulation.resume(ck)


def _one_checkpoint(tmp_path):
    cfg = load_scene("shear_box", FAST)
    sim = build_simulation(cfg, tmp_path / "run")
    sim.run(n_steps=20)
    return sim, list_checkpoints(tmp_path / "run" / "checkpoints")[-1]


def test_damaged_checkpoints_raise_restart_error(tmp_path):
    sim, ck = _one_checkpoint(tmp_path)
    data = ck.read_bytes()
    trunc = tmp_path / "trunc.npz"
    trunc.write_bytes(data[: len(data) // 2])
    with pytest.raises(RestartError, match="trunc.npz"):
        read_checkpoint(trunc)
    corrupt = tmp_path / "corrupt.npz"
    b = bytearray(data)
    for k in range(len(b) // 3, len(b) // 3 + 64):
        b[k] ^= 0xFF
    corrupt.write_bytes(bytes(b))
    with pytest.raises(RestartError, match="corrupt"):
        read_checkpoint(corrupt)
    garbage = tmp_path / "garbage.npz"
    garbage.write_text("not a checkpoint")
    with pytest.raises(RestartError):
        Simulation.resume(garbage)
    # compatibility is keyed on the checkpoint format version, not on the package version
    arrays, meta = read_checkpoint(ck)
    meta["lagice_version"] = "0.0.0"
    other_version = write_checkpoint(tmp_path / "other_version", 20, arrays, meta)
    assert Simulation.resume(other_version).model.clock.iteration == 20
    import lagice.io.checkpoint as ckmod
    monkey = ckmod.FORMAT_VERSION
    try:
        ckmod.FORMAT_VERSION = monkey + 1  # a checkpoint of a newer format
        newer = write_checkpoint(tmp_path / "newer", 20, arrays, meta)
    finally:
        ckmod.FORMAT_VERSION = monkey
    with pytest.raises(RestartError, match=f"format version {monkey + 1}"):
        Simulation.resume(newer)
    # incompatible: another scene configuration (different seed)
    other = build_simulation(load_scene("shear_box", {**FAST, "run.seed": 99}), tmp_path / "other")
    with pytest.raises(RestartError, match="another scene"):
        Simulation.resume(ck, model=other.model)


def test_damaged_newest_checkpoint_falls_back_to_older(tmp_path):
    sim, _ = _one_checkpoint(tmp_path)
    sim.run()  # checkpoints at steps 20 and 40
    d = tmp_path / "run" / "checkpoints"
    files = list_checkpoints(d)
    assert [int(f.stem.split("_")[1]) for f in files] == [20, 40]
    files[-1].write_bytes(files[-1].read_bytes()[:1000])
    path, _, meta, skipped = latest_valid_checkpoint(d)
    assert path == files[0] and meta["step"] == 20 and len(skipped) == 1
    res = Simulation.resume(d)
    assert res.model.clock.iteration == 20


def test_keep_last_k(tmp_path):
    cfg = load_scene("shear_box", {**FAST, "checkpoint.every": 200.0, "checkpoint.keep": 2})
    sim = build_simulation(cfg, tmp_path)
    sim.run()
    steps = [int(f.stem.split("_")[1]) for f in list_checkpoints(tmp_path / "checkpoints")]
    assert steps == [35, 40]


KILL_SCRIPT = textwrap.dedent("""
    import sys, numpy as np
    from lagice.io.checkpoint import write_checkpoint
    d = sys.argv[1]
    write_checkpoint(d, 1, {"a": np.arange(10.0)}, {"lagice_version": "x"}, keep=5)
    print("first", flush=True)
    big = np.random.default_rng(0).random(40_000_000)  # 320 MB: slow to write
    step = 2
    while True:
        write_checkpoint(d, step, {"a": big}, {"lagice_version": "x"}, keep=5)
        step += 1
""")


def test_sigkill_during_checkpoint_keeps_previous(tmp_path):
    d = tmp_path / "ck"
    p = subprocess.Popen([sys.executable, "-c", KILL_SCRIPT, str(d)], stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "first"
    t0 = time.time()
    while not any(".tmp-" in f.name for f in d.iterdir()):
        assert time.time() - t0 < 60, "checkpoint writing never started"
        time.sleep(0.005)
    time.sleep(0.05)
    os.kill(p.pid, signal.SIGKILL)
    p.wait()
    assert any(".tmp-" in f.name for f in d.iterdir()), "killed mid-write: a temp file is left"
    path, arrays, meta, skipped = latest_valid_checkpoint(d)
    assert np.array_equal(arrays["a"], np.arange(10.0)) or arrays["a"].size == 40_000_000
    assert skipped == []  # no half-written file carries a checkpoint name


@pytest.mark.parametrize("override,match", [
    ({"domain.colour": "blue"}, "unknown key domain.colour"),
    ({"physics.x": 1}, r"unknown table \[physics\]"),
    ({"domain.resolution_m": True}, "domain.resolution_m = True: expected"),
    ({"run.seed": "abc"}, "run.seed = 'abc': expected integer"),
    ({"rheology.poisson": 0.5}, "poisson"),
    ({"rheology.alpha": 0.9}, "alpha"),
    ({"solver.dt": "-5s"}, "solver.dt"),
    ({"run.duration": "soon"}, "run.duration"),
    ({"boundary.north.u": 1.0}, "unknown boundary tag 'north'"),
    ({"initial.thickness_m": "1 + undefined_name*x"}, "initial.thickness_m"),
    ({"domain.kind": "file", "domain.file": "no/such/coast.geojson"}, "file not found"),
    ({"healing.law": "magic"}, "healing.law = 'magic'"),
    ({"solver.name": "magic"}, "solver.name = 'magic'"),
    ({"solver.substeps": 5}, "solver.substeps does not apply to solver 'implicit'"),
])
def test_bad_scene_fails_before_work_naming_key(override, match, tmp_path, monkeypatch):
    import lagice.scenes.builder as ts

    calls = []
    real = ts.generate_mesh
    monkeypatch.setattr(ts, "generate_mesh", lambda *a, **k: calls.append(1) or real(*a, **k))
    with pytest.raises(ConfigError, match=match):
        cfg = load_scene("shear_box", {**FAST, **override})
        build_simulation(cfg, tmp_path)
    assert not calls, "meshing started before the scene was validated"
    assert not (tmp_path / "snapshots").exists()


def test_missing_scene_file():
    with pytest.raises(ConfigError, match="does not exist"):
        load_scene("nowhere/scene.toml")
    with pytest.raises(ConfigError, match="unknown scene 'nope'"):
        load_scene("nope")


REMESH = {"run.duration": 6000.0, "solver.dt": 100.0, "output.every": 3000.0, "checkpoint.every": 3000.0,
          "domain.resolution_m": 25e3, "run.progress": False, "output.plot": False,
          "boundary.top.u": "20.0*minimum(1.0, t/600.0)", "lagrangian.enabled": True,
          "remesh.enabled": True, "drifters.count": 3, "run.max_speed_m_s": 50.0}


def test_resume_bit_identical_across_remeshing(tmp_path):
    """Moving mesh + local remeshing: N steps vs N/2, checkpoint, resume, N/2."""
    full = build_simulation(load_scene("shear_box", REMESH), tmp_path / "full")
    full.run()
    n_events = full.model.state.counters.get("remesh_count", 0)
    part = build_simulation(load_scene("shear_box", REMESH), tmp_path / "part")
    part.run(n_steps=30)
    first_half = part.model.state.counters.get("remesh_count", 0)
    assert 0 < first_half < n_events, "remesh events on both sides of the checkpoint"
    resumed = Simulation.resume(tmp_path / "part" / "checkpoints")
    resumed.run()
    assert resumed.model.state.counters["remesh_count"] == n_events
    a, b = fields(full.model), fields(resumed.model)
    for k in a:
        assert a[k].shape == b[k].shape and np.array_equal(a[k], b[k]), f"{k} differs after resume"
    assert np.array_equal(full.model.mesh.triangles, resumed.model.mesh.triangles)
    assert full.summary()["n_elements"] == resumed.summary()["n_elements"] == full.model.mesh.n_elements
    assert np.array_equal(np.array(full.model.drifters.track), np.array(resumed.model.drifters.track))
    assert (full.model.component("mesh_motion").budget == resumed.model.component("mesh_motion").budget)
    # mass: the moving mesh and every remap conserve ice volume
    assert full.model.state.ice_volume_m3 == pytest.approx(full.model.ledger.initial_m3, rel=1e-10)
    assert abs(resumed.model.volume_budget()["relative_residual"]) < 1e-12
