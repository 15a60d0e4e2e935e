"""The run workflow a modeller relies on (issue 13), through the CLI as a real
subprocess writing real files: run folders never mixed, extend and branch bit for
bit, clean stops on SIGTERM, every bad input a one-line error (exit 2) before any
work, dates and projections that agree, CF-clean outputs with provenance."""
import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

ROOT = Path(__file__).resolve().parents[1]

# a small moving-mesh run with remeshing and two drifters (60 steps, 4 mesh epochs)
BASE = ["run.duration=6000.0", "solver.dt=100.0", "output.every=1500.0", "checkpoint.every=3000.0",
        "domain.resolution_m=25e3", "run.progress=false", "output.plot=false",
        'boundary.top.u="20.0*minimum(1.0, t/600.0)"', "lagrangian.enabled=true", "remesh.enabled=true",
        "drifters.positions_m=[[50e3, 100e3], [150e3, 120e3]]", "run.max_speed_m_s=50.0",
        "output.grid_resolution_m=30e3", "output.vtu=true"]
# a quick fixed-mesh run (validation tests: they fail before any work)
QUICK = ["run.duration=800.0", "solver.dt=40.0", "output.every=400.0", "domain.resolution_m=50e3",
         "run.progress=false", "output.plot=false"]


def run_cli(*args, sets=(), cwd=None, env=None, timeout=600, **kw):
    """``lagice`` as a subprocess; ``sets`` like ``[*QUICK, "run.duration=1200.0"]``: a later
    value of a key replaces an earlier one here (``lagice`` itself refuses a key given twice
    with different values)."""
    merged = {}
    for s in sets:
        merged[s.split("=", 1)[0]] = s
    cmd = [sys.executable, "-m", "lagice.cli", *map(str, args)]
    for s in merged.values():
        cmd += ["--set", s]
    e = dict(os.environ, **(env or {}))
    return subprocess.run(cmd, capture_output=True, text=True, cwd=cwd, env=e, timeout=timeout, **kw)


def one_line_error(r, *fragments, strict=True):
    """Exit 2, one ``lagice: error:`` line on stderr naming every fragment, no traceback
    (``strict``: nothing else on stderr)."""
    assert r.returncode == 2, (r.returncode, r.stdout[-2000:], r.stderr[-3000:])
    assert "Traceback" not in r.stderr, r.stderr
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    if not strict:  # third-party libraries may warn on stderr too (numba cache writes under a size limit)
        lines = [ln for ln in lines if ln.startswith("lagice: error: ")]
    assert len(lines) == 1 and lines[0].startswith("lagice: error: "), r.stderr
    for f in fragments:
        assert f in lines[0], (f, lines[0])
    return lines[0]


def last_snapshot(run_dir):
    idx = json.loads((Path(run_dir) / "snapshots" / "index.json").read_text())
    return xr.load_dataset(Path(run_dir) / "snapshots" / idx[-1]["file"]), idx


STATE_VARS = ("mesh_node_x", "mesh_node_y", "mesh_face_nodes", "node_id", "thickness", "concentration", "damage",
              "cohesion", "stress_xx", "stress_yy", "stress_xy", "velocity_x", "velocity_y")


def assert_same_state(a_dir, b_dir):
    """The last snapshots (every variable) and the drifter tracks are equal bit for bit."""
    a, ia = last_snapshot(a_dir)
    b, ib = last_snapshot(b_dir)
    assert ia[-1]["step"] == ib[-1]["step"] and ia[-1]["mesh_epoch"] == ib[-1]["mesh_epoch"]
    assert set(a.variables) == set(b.variables) and set(STATE_VARS) <= set(a.variables)
    for v in a.variables:
        assert np.array_equal(a[v].values, b[v].values), f"{v} differs"
    ta = xr.load_dataset(Path(a_dir) / "drifters.nc", decode_times=False)
    tb = xr.load_dataset(Path(b_dir) / "drifters.nc", decode_times=False)
    assert np.array_equal(ta["x"].values, tb["x"].values) and np.array_equal(ta["y"].values, tb["y"].values)


@pytest.fixture(scope="module")
def base_run(tmp_path_factory):
    """The straight run every extend/branch/stop test compares with, bit for bit."""
    out = tmp_path_factory.mktemp("base") / "run"
    r = run_cli("run", "shear_box", "--out", out, sets=BASE)
    assert r.returncode == 0, r.stderr[-3000:]
    idx = json.loads((out / "snapshots" / "index.json").read_text())
    assert len({e["mesh_epoch"] for e in idx}) > 1, "the base run must remesh (mesh epochs) to mean something"
    return out


# -- 1. run folders are never mixed ------------------------------------------------
@pytest.mark.slow
def test_output_folder_reuse_is_refused(tmp_path):
    out = tmp_path / "run"
    assert run_cli("run", "shear_box", "--out", out, sets=QUICK).returncode == 0
    first = (out / "snapshots" / "index.json").read_text()
    r = run_cli("run", "shear_box", "--out", out, sets=QUICK)
    one_line_error(r, str(out), "not empty", "--overwrite", "--resume")
    assert (out / "snapshots" / "index.json").read_text() == first, "the refused run touched the folder"
    (out / "stray.txt").write_text("from the previous run")
    r = run_cli("run", "shear_box", "--out", out, "--overwrite", sets=[*QUICK, "run.seed=5"])
    assert r.returncode == 0, r.stderr
    assert not (out / "stray.txt").exists(), "--overwrite clears the folder first"
    ds, _ = last_snapshot(out)
    assert json.loads(ds.attrs["lagice_config"])["run"]["seed"] == 5
    # --resume continues the run in the folder (same physics), or says it is done
    r = run_cli("run", "shear_box", "--out", out, "--resume", sets=[*QUICK, "run.seed=5"])
    assert r.returncode == 0 and "already finished" in r.stdout, r.stdout + r.stderr
    r = run_cli("run", "shear_box", "--out", out, "--resume", sets=[*QUICK, "run.seed=5", "run.duration=1200.0"])
    assert r.returncode == 0, r.stderr
    assert last_snapshot(out)[1][-1]["step"] == 30
    other = tmp_path / "notes"
    other.mkdir()
    (other / "thesis.tex").write_text("precious")
    r = run_cli("run", "shear_box", "--out", other, "--overwrite", sets=QUICK)
    one_line_error(r, "not a lagice run folder", "refusing")
    assert (other / "thesis.tex").read_text() == "precious"


def test_resume_starts_a_run_killed_before_its_first_checkpoint_and_refuses_other_folders(tmp_path):
    """A batch queue requeues ``lagice run SCENE --out DIR --resume``: a run killed (SIGKILL)
    before its first checkpoint is started afresh in its folder; a folder of another run, or
    with files a run does not write, is refused and left as it is."""
    hook = tmp_path / "killhook.py"
    hook.write_text(textwrap.dedent("""
        import os, pathlib, time
        from lagice.io.timeseries import diagnostic

        @diagnostic("1", "pause (slows the run so the test can kill it mid-run)")
        def pause(model):
            if model.clock.iteration >= 3:
                pathlib.Path(os.environ["SENTINEL"]).touch()
                time.sleep(0.2)
            return 0.0
    """))
    out = tmp_path / "run"
    sentinel = tmp_path / "sentinel"
    env = {"PYTHONPATH": f"{tmp_path}{os.pathsep}{os.environ.get('PYTHONPATH', '')}", "SENTINEL": str(sentinel)}
    sets = [*QUICK, 'output.timeseries.every="1 steps"', 'output.timeseries.diagnostics=["killhook:pause"]']
    cmd = [sys.executable, "-m", "lagice.cli", "run", "shear_box", "--out", str(out), "--resume"]
    for s in sets:
        cmd += ["--set", s]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env={**os.environ, **env})
    t0 = time.time()
    while not sentinel.exists():
        assert p.poll() is None, p.communicate()
        assert time.time() - t0 < 120
        time.sleep(0.02)
    p.kill()
    p.communicate(timeout=60)
    assert (out / "lagice_run.json").exists() and (out / "snapshots").is_dir()
    assert not list(out.glob("checkpoints/checkpoint_*.npz")), "killed before its first checkpoint"
    one_line_error(run_cli("resume", out), f"no checkpoint in {out}", "lagice run", f"--out {out} --resume")
    before = sorted(p.name for p in out.rglob("*"))
    # another run (other physics) in the folder: refused, nothing touched
    r = run_cli("run", "shear_box", "--out", out, "--resume", sets=[*sets, "run.seed=5"], env=env)
    one_line_error(r, str(out), "other physics settings", "--overwrite")
    (out / "notes.txt").write_text("mine")
    r = run_cli("run", "shear_box", "--out", out, "--resume", sets=sets, env=env)
    one_line_error(r, str(out), "notes.txt", "a run does not write")
    assert sorted(p.name for p in out.rglob("*")) == sorted([*before, "notes.txt"])
    (out / "notes.txt").unlink()
    # the same run: started afresh, its partial outputs replaced, one line says so
    env["SENTINEL"] = str(tmp_path / "s2")
    r = run_cli("run", "shear_box", "--out", out, "--resume", sets=sets, env=env)
    assert r.returncode == 0, r.stderr[-3000:]
    assert sum("starting it afresh" in ln for ln in r.stdout.splitlines()) == 1, r.stdout
    assert json.loads((out / "summary.json").read_text())["finished"]
    assert last_snapshot(out)[1][-1]["step"] == 20 and list(out.glob("checkpoints/checkpoint_*.npz"))
    ts = xr.load_dataset(out / "timeseries.nc", decode_times=False)
    assert np.array_equal(ts["time"].values, np.arange(0.0, 801.0, 40.0)), "one row per step, no killed rows left"


@pytest.mark.slow
def test_default_folders_never_collide_and_latest_follows(tmp_path):
    a = run_cli("run", "shear_box", sets=QUICK, cwd=tmp_path)
    b = run_cli("run", "shear_box", sets=QUICK, cwd=tmp_path)
    assert a.returncode == 0 and b.returncode == 0, a.stderr + b.stderr
    runs = sorted(p for p in (tmp_path / "runs").iterdir() if not p.is_symlink())
    assert len(runs) == 2 and all(p.name.startswith("shear_box-20") for p in runs)
    link = tmp_path / "runs" / "shear_box-latest"
    assert link.is_symlink() and link.resolve().parent == (tmp_path / "runs").resolve()
    assert link.resolve().name in b.stdout and link.resolve().name not in a.stdout, "latest is the newest run"
    assert (link / "snapshots" / "index.json").exists()


# -- 1b. one process per run folder: the run-folder lock ----------------------------------
HOLD_HOOK = """
import os, pathlib, time
from lagice.io.timeseries import diagnostic

@diagnostic("1", "hold (the run waits at step HOLD_AT until the file GO exists)")
def hold(model):
    if model.clock.iteration == int(os.environ.get("HOLD_AT", "-1")):
        pathlib.Path(os.environ["SENTINEL"]).touch()
        go = pathlib.Path(os.environ["GO"])
        t0 = time.time()
        while not go.exists() and time.time() - t0 < 300:
            time.sleep(0.02)
    return 0.0
"""
HELD = ['output.timeseries.every="1 steps"', 'output.timeseries.diagnostics=["holdhook:hold"]']


def _held_run(tmp_path, out, sets, hold_at):
    """``lagice run shear_box --out out`` as a background process, held at step ``hold_at``
    (until ``tmp_path/go`` exists) once it has written its first outputs; returns the
    process and the environment of its hook."""
    (tmp_path / "holdhook.py").write_text(HOLD_HOOK)
    env = {"PYTHONPATH": f"{tmp_path}{os.pathsep}{os.environ.get('PYTHONPATH', '')}",
           "SENTINEL": str(tmp_path / "held"), "GO": str(tmp_path / "go"), "HOLD_AT": str(hold_at)}
    cmd = [sys.executable, "-m", "lagice.cli", "run", "shear_box", "--out", str(out)]
    for s in sets:
        cmd += ["--set", s]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env={**os.environ, **env})
    t0 = time.time()
    while not (tmp_path / "held").exists():
        assert p.poll() is None, p.communicate()
        assert time.time() - t0 < 180, "the run did not reach its hold step"
        time.sleep(0.02)
    return p, env


def _tree(folder):
    """Every file under ``folder`` with its size and modification time."""
    return {str(q.relative_to(folder)): (q.stat().st_size, q.stat().st_mtime_ns) for q in sorted(folder.rglob("*"))}


def assert_same_snapshot(a_dir, b_dir):
    a, ia = last_snapshot(a_dir)
    b, ib = last_snapshot(b_dir)
    assert ia[-1]["step"] == ib[-1]["step"] and set(STATE_VARS) <= set(a.variables)
    for v in a.variables:
        assert np.array_equal(a[v].values, b[v].values), f"{v} differs"


def test_a_second_process_on_a_running_run_folder_fails_at_once(tmp_path):
    """The process that runs a simulation into a folder holds its lock (DIR/.lock, flock) for
    the whole run: a new run, --overwrite, --resume, `lagice resume` and `lagice branch --out`
    on that folder each fail at once (exit 2, one line naming the folder and the holder's pid,
    host and start time) and touch nothing; the held run then finishes as a straight run does."""
    import socket

    sets = [*QUICK, "checkpoint.every=80.0"]
    ref = tmp_path / "ref"
    r = run_cli("run", "shear_box", "--out", ref, sets=sets)
    assert r.returncode == 0, r.stderr[-3000:]
    out = tmp_path / "run"
    p, env = _held_run(tmp_path, out, [*sets, *HELD], hold_at=3)
    try:
        holder = json.loads((out / ".lock").read_text())
        assert holder["pid"] == p.pid and holder["host"] == socket.gethostname() and holder["started"]
        assert list(out.glob("checkpoints/checkpoint_*.npz")), "held after its first checkpoint"
        before = _tree(out)
        parent = sorted((ref / "checkpoints").glob("checkpoint_*.npz"))[0]
        for args in (["run", "shear_box", "--out", out], ["run", "shear_box", "--out", out, "--overwrite"],
                     ["run", "shear_box", "--out", out, "--resume"], ["resume", out],
                     ["branch", parent, "--out", out, "--overwrite"]):
            t0 = time.time()
            r = run_cli(*args, sets=[*sets, *HELD] if args[0] == "run" else (), env=env)
            took = time.time() - t0
            one_line_error(r, f"run folder {out} is in use by another lagice process", f"pid {p.pid}",
                           f"host {holder['host']}", f"since {holder['started']}")
            assert took < 60, f"{args}: {took:.0f} s"
            assert _tree(out) == before, f"{args} touched the folder of the running run"
    finally:
        (tmp_path / "go").touch()
        stdout, stderr = p.communicate(timeout=300)
    assert p.returncode == 0, stderr[-3000:]
    assert json.loads((out / "summary.json").read_text())["finished"]
    assert_same_snapshot(ref, out)
    assert (out / ".lock").read_text() == "", "released: the lock file stays, empty"


def test_a_lock_left_by_a_killed_run_does_not_block_its_resume(tmp_path):
    """SIGKILL leaves DIR/.lock (with the dead process's pid) behind; the kernel dropped its
    lock, so `lagice resume` and `lagice run --resume` take it and continue the run bit for bit."""
    sets = [*QUICK, "checkpoint.every=200.0"]
    ref = tmp_path / "ref"
    assert run_cli("run", "shear_box", "--out", ref, sets=sets).returncode == 0
    for how in ("resume", "run --resume"):
        out = tmp_path / how.replace(" ", "")
        for f in ("held", "go"):
            (tmp_path / f).unlink(missing_ok=True)
        p, env = _held_run(tmp_path, out, [*sets, *HELD], hold_at=12)
        p.kill()
        p.communicate(timeout=60)
        assert json.loads((out / ".lock").read_text())["pid"] == p.pid, "the killed run's lock file is left"
        env.pop("HOLD_AT")
        if how == "resume":
            r = run_cli("resume", out, env=env)
        else:
            r = run_cli("run", "shear_box", "--out", out, "--resume", sets=[*sets, *HELD], env=env)
        assert r.returncode == 0, r.stderr[-3000:]
        assert "resuming" in r.stdout and "checkpoint_0000000010" in r.stdout, r.stdout
        assert json.loads((out / "summary.json").read_text())["finished"]
        assert_same_snapshot(ref, out)
        assert (out / ".lock").read_text() == ""


def test_run_lock_in_one_process(tmp_path):
    """flock locks an open file: a second lock of the same folder is refused in the same
    process too; a released lock is taken again; a lock that made its folder removes it
    again when nothing else was written (a run that failed its checks on the mesh), and
    leaves no lock file in a folder where no run started."""
    from lagice.errors import ConfigError, RunFolderLocked
    from lagice.rundir import LOCK, RunLock, claim, is_empty

    out = tmp_path / "new" / "run"
    with RunLock(out) as lock:
        assert lock.held and lock.created and (out / LOCK).exists() and is_empty(out)
        with pytest.raises(RunFolderLocked, match=rf"run folder {out} is in use .*pid {os.getpid()} on host "):
            RunLock(out).acquire()
    assert not out.exists(), "the lock made the folder and nothing else was written: removed"
    with RunLock(out):
        (out / "lagice_run.json").write_text("{}")
    assert (out / LOCK).read_text() == "" and (out / "lagice_run.json").exists(), "kept, the lock file emptied"
    with RunLock(out):  # taken again
        pass
    (tmp_path / "file").write_text("x")
    with pytest.raises(ConfigError, match="exists and is not a folder"):
        RunLock(tmp_path / "file").acquire()
    # a folder that is not a run folder: a refused start leaves no trace; a .lock of its own is not taken over
    notes = tmp_path / "notes"
    notes.mkdir()
    (notes / "thesis.tex").write_text("precious")
    with RunLock(notes), pytest.raises(ConfigError, match="not empty"):
        claim(notes)
    assert sorted(q.name for q in notes.iterdir()) == ["thesis.tex"]
    (notes / LOCK).write_text("another tool's lock")
    with pytest.raises(ConfigError, match=rf"holds a {LOCK} file and other files but is not a lagice run folder"):
        RunLock(notes).acquire()
    assert (notes / LOCK).read_text() == "another tool's lock"


def test_run_folder_marker_names_the_code_that_made_the_run(tmp_path, monkeypatch):
    """The marker of a run folder records the commit of the code (what a benchmark reads before
    it reuses a finished run instead of making it again), and the command shell-quoted, so that
    it can be run again word for word (benchmarks/rerun_check.py)."""
    import shlex

    from lagice.io.cf import git_commit, git_modified_files
    from lagice.rundir import MARKER, prepare

    argv = ["lagice", "run", "shear_box", "--set", 'output.timeseries.every="1 steps"', "--out", "a b"]
    monkeypatch.setattr(sys, "argv", argv)
    prepare(tmp_path / "run")
    info = json.loads((tmp_path / "run" / MARKER).read_text())
    assert shlex.split(info["command"]) == argv
    assert info.get("git_commit") == git_commit()
    # a modified work tree: "-dirty", and the marker names the modified files
    assert bool(info.get("git_modified_files")) == str(info.get("git_commit")).endswith("-dirty")
    assert info.get("git_modified_files", []) == git_modified_files()
    if (Path(__file__).resolve().parents[1] / ".git").exists():   # a checkout: the commit is known
        assert info["git_commit"].split("-")[0] == subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=Path(__file__).resolve().parents[1], capture_output=True,
            text=True).stdout.strip()


def test_a_run_waits_out_the_probe_of_plot_beside_it(tmp_path):
    """``lagice plot`` / ``diagnose`` probe a run folder's lock with a shared flock
    (``running_holder``) that they release at once. A run that starts in that moment is not
    refused: it tries the lock again for 0.2 s. Here a shared lock is held for 50 ms (far
    longer than a probe) while the run lock is taken: it is taken once the probe lets go.
    A lock held for longer than the retries is still refused, naming the holder."""
    import fcntl
    import threading

    from lagice.errors import RunFolderLocked
    from lagice.rundir import LOCK, LOCK_RETRIES, LOCK_RETRY_S, RunLock, running_holder

    out = tmp_path / "run"
    with RunLock(out):
        (out / "lagice_run.json").write_text("{}")
    assert running_holder(out) is None
    fd = os.open(out / LOCK, os.O_RDONLY)
    fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)  # the probe, held long
    threading.Timer(0.05, lambda: fcntl.flock(fd, fcntl.LOCK_UN)).start()
    t0 = time.perf_counter()
    with RunLock(out) as lock:
        assert lock.held
        assert time.perf_counter() - t0 >= 0.04  # it waited for the probe
    fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)  # held past the retries: refused
    t0 = time.perf_counter()
    with pytest.raises(RunFolderLocked, match=rf"run folder {out} is in use"):
        RunLock(out).acquire()
    assert time.perf_counter() - t0 >= (LOCK_RETRIES - 1) * LOCK_RETRY_S
    os.close(fd)


def test_a_file_system_without_flock_is_refused_not_run_unlocked(tmp_path, monkeypatch):
    """No file system here lacks flock: flock is made to fail as it does there (EOPNOTSUPP /
    ENOLCK) to show the message; the run does not go on unlocked."""
    import errno
    import fcntl

    from lagice.errors import RunFolderLocked
    from lagice.rundir import RunLock

    def no_flock(fd, op):
        raise OSError(errno.ENOLCK, os.strerror(errno.ENOLCK))

    monkeypatch.setattr(fcntl, "flock", no_flock)
    out = tmp_path / "run"
    with pytest.raises(RunFolderLocked, match=rf"cannot lock the run folder {out}: .*does not support file locks"):
        RunLock(out).acquire()
    assert not out.exists()


# -- 2. extend and branch ------------------------------------------------------------
@pytest.mark.slow
def test_extend_is_bit_identical_and_bookkeeping_is_whole_run(base_run, tmp_path):
    part = tmp_path / "part"
    r = run_cli("run", "shear_box", "--out", part, sets=[s for s in BASE if not s.startswith("run.duration")]
                + ["run.duration=3000.0"])
    assert r.returncode == 0, r.stderr
    s1 = json.loads((part / "summary.json").read_text())
    # resuming a finished run changes nothing and says how to extend it
    before = (part / "summary.json").read_bytes()
    r = run_cli("resume", part)
    assert r.returncode == 0 and "already finished" in r.stdout and "run.duration" in r.stdout, r.stdout
    assert (part / "summary.json").read_bytes() == before
    # a killed write left temporaries behind: they are cleaned when the run starts again
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True).stdout.strip()
    stale = [part / "checkpoints" / f"checkpoint_0000000031.npz.tmp-{dead}", part / "snapshots" / "snapshot_x.nc.tmp"]
    for p in stale:
        p.write_bytes(b"half a file")
    # a physics change is refused on resume, naming the key
    r = run_cli("resume", part, sets=["run.duration=6000.0", "rheology.alpha=5.0"])
    one_line_error(r, "rheology.alpha", "lagice branch")
    r = run_cli("resume", part, sets=["run.duration=6000.0"])
    assert r.returncode == 0, r.stderr
    assert not any(p.exists() for p in stale), "stale temporary files were left behind"
    assert_same_state(base_run, part)
    s2 = json.loads((part / "summary.json").read_text())
    assert s2["steps"] == 60 and s2["finished"] and s2["wall_s"] > s1["wall_s"], "wall time covers the whole run"
    assert s2["timings"]["dynamics"] > s1["timings"]["dynamics"]


@pytest.mark.slow
def test_branch_same_physics_is_bit_identical_and_records_its_parent(base_run, tmp_path):
    parent = base_run / "checkpoints" / "checkpoint_0000000030.npz"
    assert parent.exists()
    sha = hashlib.sha256(parent.read_bytes()).hexdigest()
    same = tmp_path / "same"
    r = run_cli("branch", parent, "--out", same, sets=["output.every=1000.0"])
    assert r.returncode == 0, r.stderr
    assert_same_state(base_run, same)
    ds, idx = last_snapshot(same)
    assert idx[0]["step"] == 30, "the branch starts with a snapshot of its parent's state"
    assert ds.attrs["lagice_parent_checkpoint"] == str(parent.resolve())
    assert ds.attrs["lagice_parent_checkpoint_sha256"] == sha
    assert json.loads((same / "lagice_run.json").read_text())["parent"]["sha256"] == sha
    info = run_cli("info", sorted((same / "checkpoints").glob("*.npz"))[-1])
    assert info.returncode == 0 and sha in info.stdout
    # changed physics: explicit, allowed, and it changes the trajectory
    soft = tmp_path / "soft"
    r = run_cli("branch", parent, "--out", soft, sets=["rheology.alpha=5.0"])
    assert r.returncode == 0, r.stderr
    a, _ = last_snapshot(base_run)
    b, _ = last_snapshot(soft)
    assert json.loads(b.attrs["lagice_config"])["rheology"]["alpha"] == 5.0
    assert a["mesh_face_nodes"].shape != b["mesh_face_nodes"].shape or not np.array_equal(a["damage"], b["damage"])
    r = run_cli("branch", parent, "--out", tmp_path / "geo", sets=["domain.resolution_m=10e3"])
    one_line_error(r, "domain.resolution_m", "cannot change")


@pytest.mark.slow
def test_extending_length_dependent_forcing_is_refused_unless_its_horizon_is_fixed(tmp_path):
    """Random winds are drawn over the whole run: extending would change the forcing
    already used, so it is refused with the two ways out; with a fixed ``horizon`` the
    run extends bit for bit."""
    out = tmp_path / "random"
    r = run_cli("run", "shear_box", "--out", out, sets=[*QUICK, 'forcing.wind={kind="random"}'])
    assert r.returncode == 0, r.stderr
    r = run_cli("resume", out, sets=["run.duration=1600.0"])
    one_line_error(r, "forcing.wind", "horizon", "lagice branch")
    wind = 'forcing.wind={kind="random", horizon="1d"}'
    short, straight = tmp_path / "short", tmp_path / "straight"
    assert run_cli("run", "shear_box", "--out", short, sets=[*QUICK, wind]).returncode == 0
    assert run_cli("resume", short, sets=["run.duration=1600.0"]).returncode == 0
    assert run_cli("run", "shear_box", "--out", straight, sets=[*QUICK, wind, "run.duration=1600.0"]).returncode == 0
    a, _ = last_snapshot(short)
    b, _ = last_snapshot(straight)
    assert a.attrs["step"] == 40 and all(np.array_equal(a[v].values, b[v].values) for v in a.data_vars)


# -- 3. stop cleanly -----------------------------------------------------------------
@pytest.mark.slow
def test_sigterm_writes_a_checkpoint_and_the_run_resumes_bit_identically(base_run, tmp_path):
    hook = tmp_path / "slowhook.py"
    hook.write_text(textwrap.dedent("""
        import os, pathlib, time
        from lagice.io.timeseries import diagnostic

        @diagnostic("1", "pause (slows the run so the test can signal it mid-run)")
        def pause(model):
            if model.clock.iteration == 12:
                pathlib.Path(os.environ["SENTINEL"]).touch()
            if model.clock.iteration >= 12:
                time.sleep(0.1)
            return 0.0
    """))
    out = tmp_path / "stopped"
    sentinel = tmp_path / "sentinel"
    env = dict(os.environ, PYTHONPATH=f"{tmp_path}{os.pathsep}{os.environ.get('PYTHONPATH', '')}",
               SENTINEL=str(sentinel))
    cmd = [sys.executable, "-m", "lagice.cli", "run", "shear_box", "--out", str(out)]
    for s in [*BASE, 'output.timeseries.every="1 steps"', 'output.timeseries.diagnostics=["slowhook:pause"]']:
        cmd += ["--set", s]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    t0 = time.time()
    while not sentinel.exists():
        assert p.poll() is None, p.communicate()
        assert time.time() - t0 < 120
        time.sleep(0.02)
    p.send_signal(signal.SIGTERM)
    stdout, stderr = p.communicate(timeout=120)
    assert p.returncode == 0, stderr
    assert "SIGTERM" in stdout and f"lagice resume {out}" in stdout, stdout
    ck = sorted((out / "checkpoints").glob("checkpoint_*.npz"))
    step = int(ck[-1].stem.split("_")[1])
    assert 12 <= step < 60 and step != 30, "a checkpoint at the step the signal arrived"
    assert not json.loads((out / "summary.json").read_text())["finished"]
    r = run_cli("resume", out, env={"PYTHONPATH": env["PYTHONPATH"], "SENTINEL": str(tmp_path / "s2")})
    assert r.returncode == 0, r.stderr
    assert_same_state(base_run, out)
    ts = xr.load_dataset(out / "timeseries.nc", decode_times=False)
    assert np.array_equal(ts["time"].values, np.arange(0.0, 6001.0, 100.0)), "one time-series row per step"


# -- 4. every bad input: one line, exit 2, before any work ---------------------------
@pytest.mark.parametrize("setting,fragments", [
    ('forcing.wind.n="six"', ["forcing.wind.n", "'six'", "integer"]),
    ("forcing.wind.background_m_s=5", ["forcing.wind.background_m_s", "5", "[x, y] pair"]),
    ("forcing.wind.max_speed_range_m_s=[30,10]", ["forcing.wind.max_speed_range_m_s", "[30, 10]", "low <= high"]),
    ('forcing.air_temperature.mean_c="cold"', ["forcing.air_temperature.mean_c", "'cold'", "number"]),
    ("remesh.params.foo=1", ["remesh.params.foo", "known keys"]),
    ('remesh.params.rings="two"', ["remesh.params.rings", "'two'", "integer"]),
    ("thermo.params.latent_heat_j_kg=-1.0", ["latent_heat_j_kg", "-1", "out of range"]),
    ("drifters.count=-3", ["drifters.count", "-3", ">= 0"]),
    ('forcing.crs="EPSG:3413"', ["forcing.crs", "[domain] crs"]),
    ("output.crs_epsg=3031", ["output.crs_epsg", "[domain] crs"]),
    ('forcing.ocean.colour="blue"', ["forcing.ocean.colour", "takes no keys"]),
    ('forcing.wind={kind="file", path="no/such/era5.nc"}', ["no/such/era5.nc", "file not found"]),
    ('output.timeseries={every="1h", diagnostics=["mean_damagee"]}',
     ["unknown diagnostic 'mean_damagee'", "did you mean 'mean_damage'?", "known: [", "'mean_damage'",
      "'module:function' hook"]),
    ("domain.resolution_m=2000e3", ["domain.resolution_m = 2e+06 m", "larger than the domain", "942.7 km"]),
])
def test_bad_setting_is_one_line_before_any_work(setting, fragments, tmp_path):
    out = tmp_path / "run"
    t0 = time.time()
    r = run_cli("run", "winter_basin", "--out", out, sets=["run.duration=1h", setting])
    one_line_error(r, *fragments)
    assert not out.exists(), "nothing is written (and no mesh made) before the settings are checked"
    assert time.time() - t0 < 60


@pytest.mark.parametrize("shift_km", [4500.0, 150.0])
def test_spinup_state_that_does_not_cover_the_domain_is_refused_before_meshing(shift_km, tmp_path):
    """The bundled winter-basin spin-up state moved east: its nearest-centroid lookup would
    fill the domain (all of it, or its western part) from ice far away."""
    z = dict(np.load(ROOT / "data_stubs" / "winter_basin_spinup.npz"))
    z["centroid_x_m"] = (z["centroid_x_m"] + shift_km * 1e3).astype(np.float32)
    state = tmp_path / "moved.npz"
    np.savez(state, **z)
    out = tmp_path / "run"
    r = run_cli("run", "winter_basin_pack", "--out", out,
                sets=["run.duration=1h", "domain.resolution_m=80e3", f'initial.state_file="{state}"'])
    from lagice.spinup import footprint_tolerance_m

    # five times the state's centroid spacing (about 4.7 km on the 9.3 km mesh it was made on)
    tol_m = footprint_tolerance_m(str(state))
    assert 15e3 < tol_m < 35e3
    tol_text = f"tolerance {tol_m / 1e3:.1f} km"
    line = one_line_error(r, "initial.state_file", str(state), "outside the spin-up state's footprint",
                          tol_text, "km from the nearest state centroid")
    far = float(line.split(" km from the nearest")[0].rsplit(" ", 1)[1])
    assert far > 100.0 and (shift_km < 1000 or far > 3000.0), line
    assert not out.exists(), "refused before the output folder and the mesh"


def test_resolution_larger_than_the_domain_is_refused_before_meshing(tmp_path):
    from lagice.errors import ConfigError
    from lagice.scenes.builder import validate_config
    from lagice.scenes.config import load_scene

    out = tmp_path / "run"
    r = run_cli("run", "shear_box", "--out", out, sets=[*QUICK, "domain.resolution_m=500e3"])
    one_line_error(r, "domain.resolution_m = 500000 m", "larger than the domain", "smallest extent is 200.0 km")
    assert not out.exists()
    validate_config(load_scene("shear_box", {"domain.resolution_m": 200e3}))  # one element across: allowed
    with pytest.raises(ConfigError, match="smallest extent is 200.0 km"):
        validate_config(load_scene("shear_box", {"domain.resolution_m": 200.001e3}))


@pytest.mark.parametrize("setting,fragments", [
    ("initial.thickness_m=-1", ["initial.thickness_m = -1 m", "out of range", "[0, inf] m"]),
    ("initial.concentration=1.5", ["initial.concentration = 1.5", "out of range", "[0, 1]"]),
    ("initial.damage=1.5", ["initial.damage = 1.5", "out of range", "[0, 1)"]),
    ("initial.damage=1.0", ["initial.damage = 1.0", "out of range", "[0, 1)"]),
    ("initial.thickness_m=nan", ["initial.thickness_m = nan", "out of range"]),
])
def test_initial_constant_out_of_range_is_refused_before_meshing(setting, fragments, tmp_path):
    out = tmp_path / "run"
    one_line_error(run_cli("run", "shear_box", "--out", out, sets=[*QUICK, setting]), *fragments)
    assert not out.exists(), "refused before the output folder (and the mesh)"


def test_initial_expression_out_of_range_names_the_key_and_leaves_no_folder(tmp_path):
    """An expression is checked on the mesh (its values at the element centroids); the
    failed start leaves no folder, so the corrected command may use the same --out."""
    out = tmp_path / "run"
    r = run_cli("run", "shear_box", "--out", out, sets=[*QUICK, 'initial.concentration="0.5 + x / 2e5"'])
    one_line_error(r, "initial.concentration = '0.5 + x / 2e5' gives values in [", "elements outside",
                   "expected values in [0, 1]")
    assert not out.exists(), "the failed start left its folder behind"
    r = run_cli("run", "shear_box", "--out", out, sets=[*QUICK, 'initial.concentration="0.5 + x / 4e5"'])
    assert r.returncode == 0, r.stderr[-3000:]
    ds, _ = last_snapshot(out)
    assert 0.5 < float(ds["concentration"].min()) and float(ds["concentration"].max()) < 1.0


@pytest.mark.parametrize("setting,fragments", [
    ('output.every="50s"', ["output.every = '50s' (50 s)", "solver.dt = 40 s", "40 s or 80 s", "'1 steps'"]),
    ("checkpoint.every=100.0", ["checkpoint.every = 100.0 (100 s)", "solver.dt = 40 s", "80 s or 120 s"]),
    ("output.every=10.0", ["output.every = 10.0 (10 s)", "whole number (>= 1) of steps", "40 s"]),
    ('output.timeseries={every="1min", diagnostics=["mean_damage"]}',
     ["output.timeseries.every = '1min' (60 s)", "solver.dt = 40 s"]),
])
def test_output_and_checkpoint_intervals_must_be_whole_steps(setting, fragments, tmp_path):
    """As run.duration: an interval that is not a whole number of steps would fall due at
    irregular steps (every 40 or 80 s for 50 s)."""
    out = tmp_path / "run"
    one_line_error(run_cli("run", "shear_box", "--out", out, sets=[*QUICK, setting]), *fragments)
    assert not out.exists()


def test_nan_boundary_constant_is_refused_before_meshing(tmp_path):
    out = tmp_path / "run"
    one_line_error(run_cli("run", "shear_box", "--out", out, sets=[*QUICK, "boundary.top.v=nan"]),
                   "boundary.top.v = nan", "finite")
    assert not out.exists()


def test_keys_of_the_other_rheology_law(tmp_path):
    """A viscous-plastic key set under maxwell_eb is refused before meshing (nothing reads it, and
    its value is not even range-checked there); Maxwell-EB keys of a scene run with
    law = 'viscous_plastic' (the EVP comparison) are named once as ignored, and the run goes on."""
    out = tmp_path / "run"
    one_line_error(run_cli("run", "shear_box", "--out", out, sets=[*QUICK, "rheology.p_star=-5"]),
                   "rheology.p_star = -5", "rheology.law = 'maxwell_eb' does not use it")
    assert not out.exists()
    r = run_cli("run", "shear_box", "--out", tmp_path / "evp",
                sets=[*QUICK, "rheology.law=viscous_plastic", "solver.name=evp", "healing.law=none",
                      "rheology.friction=0.9"])
    assert r.returncode == 0, r.stderr[-2000:]
    warned = [ln for ln in r.stderr.splitlines() if "ignores these Maxwell-EB keys" in ln]
    assert len(warned) == 1 and "rheology.friction = 0.9" in warned[0], r.stderr


def test_keys_of_components_that_are_off_are_named_once_and_change_nothing(tmp_path):
    """Keys that only a component that is off (or another kind) reads, set away from their
    defaults, are named in one warning (key, value, why) and the run goes on: the same result
    as without them. A scene file carries such keys legitimately when a --set switches their
    component off (the EVP comparison, tests that switch remeshing off)."""
    sets = [*QUICK, "healing.law=none"]
    plain = tmp_path / "plain"
    assert run_cli("run", "shear_box", "--out", plain, sets=sets).returncode == 0
    out = tmp_path / "run"
    r = run_cli("run", "shear_box", "--out", out,
                sets=[*sets, "remesh.min_angle_deg=25.0", "lagrangian.max_halvings=4", "rheology.healing_time_s=2e5",
                      'domain.file="data_stubs/winter_basin_coast.geojson"'])
    assert r.returncode == 0, r.stderr[-2000:]
    warned = [ln for ln in r.stderr.splitlines() if "ignores these keys of the scene" in ln]
    assert len(warned) == 1 and warned[0].startswith("lagice: warning: this run ignores these keys of the scene: "), \
        r.stderr
    for part in ("remesh.min_angle_deg = 25.0 (remeshing is off: remesh.enabled = false)",
                 "lagrangian.max_halvings = 4 (the mesh does not move: lagrangian.enabled = false)",
                 "rheology.healing_time_s = 200000.0 (healing.law = 'none': no healing)",
                 "domain.file = 'data_stubs/winter_basin_coast.geojson' (domain.kind = 'rectangle'; it is a key of "
                 "kind 'file')"):
        assert part in warned[0], (part, warned[0])
    assert_same_snapshot(plain, out)
    assert "ignores these keys" not in run_cli("run", "shear_box", "--out", tmp_path / "p2", sets=QUICK).stderr


@pytest.mark.parametrize("scene,override,expected", [
    ("shear_box", {"lagrangian.min_area_ratio": 0.1},
     [("lagrangian.min_area_ratio", 0.1, "the mesh does not move: lagrangian.enabled = false")]),
    ("winter_basin_pack", {"rheology.healing_time_s": 2e5},
     [("rheology.healing_time_s", 2e5, "healing.law = 'nextsim' sets the healing rate; healing_time_s is the "
                                       "constant law's")]),
    ("winter_basin_pack", {"rheology.cohesion_max_pa": 6e4},
     [("rheology.cohesion_max_pa", 6e4, "rheology.strength_law = 'scaled' gives the cohesion")]),
    ("winter_basin", {"initial.cohesion_pa": 3e4},  # its cohesion_min/max_pa (10 and 20 kPa) are not drawn
     [("rheology.cohesion_min_pa", 10e3, "initial.cohesion_pa = 30000.0 gives the cohesion"),
      ("rheology.cohesion_max_pa", 20e3, "initial.cohesion_pa = 30000.0 gives the cohesion")]),
    ("shear_box", {"rheology.max_pressure_thickness_exponent": 2.0},
     [("rheology.max_pressure_thickness_exponent", 2.0, "no compressive term: rheology.max_pressure_pa is not set")]),
    ("shear_box", {"rheology.max_pressure_thickness_exponent": 2.0, "rheology.max_pressure_pa": 1e4,
                   "solver.name": "explicit"}, []),
    ("winter_basin", {"domain.kind": "rectangle", "domain.width_m": 500e3, "domain.height_m": 500e3},
     [("domain.file", "data_stubs/winter_basin_coast.geojson", "domain.kind = 'rectangle'; it is a key of kind "
                                                               "'file'")]),
    ("wind_square", {"domain.kind": "polygon", "domain.vertices": [[0, 0], [4e5, 0], [0, 4e5]]},
     [("domain.width_m", 500e3, "domain.kind = 'polygon'; it is a key of kind 'rectangle'"),
      ("domain.height_m", 500e3, "domain.kind = 'polygon'; it is a key of kind 'rectangle'")]),
    ("shear_channel", {"domain.kind": "rectangle", "domain.width_m": 200e3, "domain.height_m": 200e3},
     [("domain.function", "lagice.scenes.hooks.shear_channel:annulus", "domain.kind = 'rectangle'; it is a key "
                                                                        "of kind 'function'"),
      ("domain.params", {"radius_m": 100e3, "inner_radius_m": 30e3, "vertex_spacing_m": 10e3},
       "domain.kind = 'rectangle'; it is a key of kind 'function'")]),
    ("shear_box", {"forcing.grid_spacing_m": 10e3, "forcing.wind": {"kind": "expression", "u": 5.0}},
     [("forcing.grid_spacing_m", 10e3, "no [forcing.*] table has a kind drawn on the forcing grid; expression, "
                                       "function, file, constant and rest are not")]),
    ("shear_box", {"forcing.grid_spacing_m": 10e3, "forcing.wind": {"kind": "uniform"}}, []),
    ("shear_box", {"forcing.drag": {"water_drag": 4e-3}},
     [("forcing.drag.water_drag", 4e-3, "no external forces: no [forcing.wind], [forcing.ocean] or "
                                        "[forcing.coriolis]")]),
    ("winter_basin_pack", {"forcing.wind": None, "forcing.drag": {"air_drag": 2e-3, "coriolis_f": 1e-4}},
     [("forcing.drag.air_drag", 2e-3, "no wind stress: no [forcing.wind]"),
      ("forcing.drag.coriolis_f", 1e-4, "[forcing.coriolis] sets the Coriolis parameter")]),
    ("winter_basin", {"thermo.enabled": False, "healing.law": "constant"},
     [("forcing.air_temperature", {"kind": "synthetic", "start_day_of_year": 15.0},
       "nothing reads it: thermo.enabled = false, and healing.law = 'constant' is not one of the laws that do, "
       "'thermodynamic', 'fdd', 'nextsim'")]),
    ("winter_basin", {"thermo.enabled": False}, []),  # thermodynamic healing reads the air temperature
    # the flagship switched to fewer components: its [remesh.params] and a [thermo.params] are named, not refused
    ("winter_basin_pack", {"remesh.enabled": False},
     [("remesh.params", {"algorithm": 5}, "remeshing is off: remesh.enabled = false")]),
    ("winter_basin_pack", {"thermo.enabled": False, "healing.law": "constant", "forcing.air_temperature": None,
                           "thermo.params": {"new_ice_thickness_m": 0.2}},
     [("thermo.params", {"new_ice_thickness_m": 0.2}, "thermodynamics is off: thermo.enabled = false")]),
    # a scene's undamaged new ice with thermodynamics switched off by --set: named, not refused; so is the
    # flagship's own [thermo.params] (neXtSIM's lead-closing thickness, since 2026-11-30)
    ("winter_basin_pack", {"thermo.enabled": False, "healing.law": "constant", "forcing.air_temperature": None,
                           "thermo.new_ice_undamaged": True},
     [("thermo.params", {"new_ice_thickness_m": 0.25}, "thermodynamics is off: thermo.enabled = false"),
      ("thermo.new_ice_undamaged", True, "thermodynamics is off (thermo.enabled = false): no new ice forms")]),
    # a scene's [healing.params] with its law switched to one that takes none
    ("winter_basin_pack", {"healing.law": "none", "healing.params": {"time_scale_days": 10.0}},
     [("healing.params", {"time_scale_days": 10.0}, "healing.law = 'none' takes no parameters")]),
    ("winter_basin_pack", {"healing.law": "constant", "healing.params": {"time_scale_days": 10.0}},
     [("healing.params", {"time_scale_days": 10.0},
       "healing.law = 'constant' takes no parameters (it uses rheology.healing_time_s)")]),
])
def test_unused_keys_of_each_component_and_kind(scene, override, expected, caplog, monkeypatch):
    from lagice.scenes import builder
    from lagice.scenes.builder import unused_keys, validate_config
    from lagice.scenes.config import load_scene

    cfg = load_scene(scene, {"run.duration": "1h", **override})
    assert unused_keys(cfg) == expected
    monkeypatch.setattr(builder, "_LOGGED_UNUSED", set())  # what earlier tests in this process logged
    caplog.clear()
    validate_config(cfg)
    validate_config(cfg)  # the checks run twice per run (CLI, builder): one warning
    warned = [r.getMessage() for r in caplog.records if "ignores these keys of the scene" in r.getMessage()]
    assert len(warned) == (1 if expected else 0), warned


def test_cpu_threading_on_the_gpu_is_named():
    from lagice.scenes.builder import unused_keys
    from lagice.scenes.config import load_scene

    cfg = load_scene("wind_square", {"solver.name": "explicit", "solver.device": "cuda", "solver.parallel": True})
    assert unused_keys(cfg) == [("solver.parallel", True, "solver.device = 'cuda': the CPU kernels' threading does "
                                                         "not apply on the GPU")]
    cfg = load_scene("wind_square", {"solver.name": "explicit", "solver.device": "cuda", "solver.parallel": "auto"})
    assert unused_keys(cfg) == []


def test_no_bundled_scene_or_ensemble_member_sets_an_unused_key():
    from lagice.ensemble import Ensemble, load_spec
    from lagice.scenes.builder import unused_keys
    from lagice.scenes.config import list_scenes, load_scene

    for name in list_scenes():
        assert unused_keys(load_scene(name)) == [], name
    for spec in sorted((ROOT / "examples" / "ensembles").glob("*.toml")):
        for m in Ensemble(load_spec(spec), ROOT / "runs" / "never-made").members:
            assert unused_keys(m.config) == [], (spec.name, m.id)


def test_a_refused_setting_leaves_no_run_folder(tmp_path):
    """A key that can never be read is refused (exit 2) before the run folder (and its lock)
    is made, so the corrected command may use the same --out."""
    out = tmp_path / "run"
    one_line_error(run_cli("run", "shear_box", "--out", out, sets=[*QUICK, "rheology.p_star=30000"]),
                   "rheology.p_star = 30000")
    assert not out.exists()
    r = run_cli("run", "shear_box", "--out", out, "--resume", sets=[*QUICK, 'domain.file_crs="EPSG:3413"'])
    one_line_error(r, "domain.file_crs applies to domain.kind = 'file' only")
    assert not out.exists()


@pytest.mark.parametrize("expr,fragments", [
    ("1.0/(t-400.0)", ["cannot evaluate the expression at t = 400 s", "ZeroDivisionError"]),
    ("0.01*sqrt(360.0 - t)", ["gives nan at t = 400 s", "finite"]),
])
def test_boundary_expression_failing_mid_run_is_one_line_with_a_summary(expr, fragments, tmp_path):
    """A prescribed velocity that cannot be evaluated, or is not finite, at some time: the
    error names the key, the expression and the time (not 'cg did not converge' or a
    traceback), exit 2, and the run leaves summary.json and its last checkpoint."""
    out = tmp_path / "run"
    r = run_cli("run", "shear_box", "--out", out, sets=[*QUICK, f'boundary.top.u="{expr}"', "checkpoint.every=200.0"])
    one_line_error(r, f"boundary.top.u = '{expr}'", *fragments)
    s = json.loads((out / "summary.json").read_text())
    assert not s["finished"] and s["stop_reason"].startswith("error: boundary.top.u") and s["steps"] == 9
    assert s["checkpoint"].endswith("checkpoint_0000000005.npz") and Path(s["checkpoint"]).exists()


def test_wind_file_with_missing_records_is_refused_before_meshing(tmp_path):
    """The bundled 6-hourly ERA5 stub without records 1-3 (a 24 h gap)."""
    ds = xr.open_dataset(ROOT / "data_stubs" / "era5_stub_arctic.nc")[["u10", "v10"]].load()
    gap = tmp_path / "gap.nc"
    ds.isel(time=[0, 4, 5, 6, 7, 8]).to_netcdf(gap)
    out = tmp_path / "run"
    r = run_cli("run", "winter_basin", "--out", out,
                sets=["run.duration=12h", f'forcing.wind={{kind="file", path="{gap}"}}'])
    one_line_error(r, str(gap), "not evenly spaced", "1 d apart", "the records are 6 h apart")
    assert not out.exists()


def test_info_on_a_file_that_is_not_netcdf(tmp_path):
    bad = tmp_path / "notes.nc"
    bad.write_text("not netCDF at all")
    one_line_error(run_cli("info", bad), str(bad), "neither a netCDF file nor a lagice checkpoint")
    one_line_error(run_cli("info", tmp_path), "is a folder")


@pytest.fixture
def read_only_dir(tmp_path):
    d = tmp_path / "ro"
    d.mkdir()
    if os.geteuid() == 0:  # root ignores permissions: make the folder immutable instead
        if subprocess.run(["chattr", "+i", str(d)], capture_output=True).returncode != 0:
            pytest.skip("running as root without chattr: cannot make a read-only folder")
        yield d
        subprocess.run(["chattr", "-i", str(d)])
    else:
        d.chmod(0o555)
        yield d
        d.chmod(0o755)


def test_read_only_output_folder_is_one_line_before_meshing(read_only_dir):
    r = run_cli("run", "shear_box", "--out", read_only_dir, sets=QUICK)
    one_line_error(r, "cannot write in the output folder", str(read_only_dir))
    r = run_cli("run", "shear_box", "--out", read_only_dir / "sub", sets=QUICK)
    one_line_error(r, "cannot create the output folder", "sub")


def _file_size_limit(nbytes):
    def limit():
        import resource

        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG
        resource.setrlimit(resource.RLIMIT_FSIZE, (nbytes, nbytes))
    return limit


def test_disk_full_is_one_line_and_leaves_no_partial_file(tmp_path):
    """A file-size limit (RLIMIT_FSIZE) stands in for a full disk: the write fails with
    an OS error half-way through a real file."""
    out = tmp_path / "run"
    r = run_cli("run", "shear_box", "--out", out, sets=QUICK, preexec_fn=_file_size_limit(20_000))
    one_line_error(r, "cannot write", "snapshot_00000000.nc", "disk full", strict=False)
    assert not [p for p in out.rglob("*") if ".tmp" in p.name], "no temporary file is left behind"
    # a checkpoint write that fails keeps the previous checkpoint and leaves nothing partial
    script = textwrap.dedent("""
        import sys, numpy as np
        from lagice.errors import OutputError
        from lagice.io.checkpoint import write_checkpoint
        write_checkpoint(sys.argv[1], 1, {"a": np.arange(10.0)}, {"x": 1})
        try:
            write_checkpoint(sys.argv[1], 2, {"a": np.zeros(100_000)}, {"x": 1})
        except OutputError as exc:
            print(exc)
    """)
    ck = tmp_path / "ck"
    r = subprocess.run([sys.executable, "-c", script, str(ck)], capture_output=True, text=True,
                       preexec_fn=_file_size_limit(200_000))
    assert r.returncode == 0, r.stderr
    assert "cannot write" in r.stdout and "checkpoint_0000000002.npz" in r.stdout and "File too large" in r.stdout
    assert sorted(p.name for p in ck.iterdir()) == ["checkpoint_0000000001.npz"]


# -- 5. dates and projections ------------------------------------------------------------
def _wind_file(path, start="2020-01-01T00:00", n=17):
    """Uniform x/y wind on a projected grid over the shear box: record k blows at 1 + k m/s."""
    times = np.datetime64(start, "ns") + np.arange(n) * np.timedelta64(6, "h")
    x = np.linspace(-200e3, 400e3, 7)
    y = np.linspace(-200e3, 400e3, 7)
    u = (1.0 + np.arange(n))[:, None, None] * np.ones((n, y.size, x.size))
    xr.Dataset({"u": (("time", "y", "x"), u, {"units": "m s-1"}), "v": (("time", "y", "x"), 0 * u, {"units": "m s-1"})},
               coords={"time": times, "x": ("x", x, {"units": "m"}), "y": ("y", y, {"units": "m"})}).to_netcdf(path)
    return path


WIND_HOOK = """
import numpy as np
from lagice.forces import WindStress
from lagice.io.timeseries import diagnostic

@diagnostic("m s-1", "x wind at node 0 (from the wind stress the model applies)")
def wind_u(model):
    ws = [f for f in model.forces if isinstance(f, WindStress)][0]
    tau = ws.stress(model.clock.time_s, model.mesh.nodes[:1])[0, 0]
    return float(np.sqrt(abs(tau) / (ws.rho_air * ws.drag)))
"""


@pytest.mark.slow
def test_a_run_inside_a_gridded_file_uses_the_records_of_its_date(tmp_path):
    path = _wind_file(tmp_path / "wind.nc")
    (tmp_path / "windhook.py").write_text(WIND_HOOK)
    env = {"PYTHONPATH": f"{tmp_path}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    wind = [f'forcing.wind={{kind="file", path="{path}", u="u", v="v"}}', "solver.dt=1800.0",
            "run.duration=21600.0", "output.every=21600.0", "domain.resolution_m=50e3", "run.progress=false",
            "output.plot=false", 'output.timeseries={every="1 steps", diagnostics=["windhook:wind_u"]}',
            "checkpoint.every=21600.0"]
    out = tmp_path / "run"
    r = run_cli("run", "shear_box", "--out", out, sets=[*wind, 'run.start_date="2020-01-03 06:00:00"'], env=env)
    assert r.returncode == 0, r.stderr
    ts = xr.load_dataset(out / "timeseries.nc")
    # 2020-01-03 06:00 is record 9 (1 + 9 = 10 m/s); 6 h later record 10; linear in between
    assert str(ts["time"].values[0]).startswith("2020-01-03T06:00")
    t_s = (ts["time"].values - ts["time"].values[0]) / np.timedelta64(1, "s")
    np.testing.assert_allclose(ts["wind_u"].values, 10.0 + t_s / 21600.0, rtol=1e-12)
    # a run outside the file's dates is an error naming both spans (hold is opt-in)
    r = run_cli("run", "shear_box", "--out", tmp_path / "late", sets=[*wind, 'run.start_date="2026-01-15 00:00:00"'],
                env=env)
    one_line_error(r, "2020-01-01T00:00 .. 2020-01-05T00:00", "2026-01-15T00:00", "time_extrapolation = 'hold'")


def test_lonlat_coastline_is_projected_and_degrees_as_metres_are_refused(tmp_path):
    from pyproj import Transformer
    from shapely.geometry import Polygon

    lonlat = [[-150.0, 75.0], [-140.0, 75.0], [-140.0, 80.0], [-150.0, 80.0], [-150.0, 75.0]]
    coast = tmp_path / "coast.geojson"
    coast.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [lonlat]}}]}))
    scene = tmp_path / "coast.toml"
    scene.write_text(textwrap.dedent(f"""
        [scene]
        name = "coast"
        [domain]
        kind = "file"
        file = "{coast}"
        resolution_m = 100e3
        [solver]
        dt = 40.0
        [run]
        duration = 80.0
        progress = false
        [output]
        every = 80.0
        plot = false
    """))
    r = run_cli("run", scene, "--out", tmp_path / "m")
    one_line_error(r, "look like longitude/latitude degrees", "domain.file_crs = 'EPSG:4326'")
    out = tmp_path / "ll"
    r = run_cli("run", scene, "--out", out, sets=['domain.file_crs="EPSG:4326"'])
    assert r.returncode == 0, r.stderr
    ds, _ = last_snapshot(out)
    xy = np.column_stack([ds["mesh_node_x"].values, ds["mesh_node_y"].values])
    t = ds["mesh_face_nodes"].values
    a, b, c = xy[t[:, 0]], xy[t[:, 1]], xy[t[:, 2]]
    area = 0.5 * np.abs((b - a)[:, 0] * (c - a)[:, 1] - (c - a)[:, 0] * (b - a)[:, 1]).sum()
    tr = Transformer.from_crs("EPSG:4326", "EPSG:3413", always_xy=True)
    expected = Polygon([tr.transform(lo, la) for lo, la in lonlat]).area
    assert area == pytest.approx(expected, rel=1e-9) and expected > 1e11  # ~ 240 km x 560 km, not 10 m x 5 m


def test_lonlat_shapefile_is_projected_with_its_prj(tmp_path):
    """A shapefile declares its CRS in its .prj: a lon/lat one is projected into domain.crs."""
    import shapefile
    from pyproj import CRS, Transformer
    from shapely.geometry import Polygon

    from lagice.scenes.builder import domain_polygon
    from lagice.scenes.config import load_scene

    ring = [[10.0, 78.0], [10.0, 80.0], [30.0, 80.0], [30.0, 78.0], [10.0, 78.0]]  # Svalbard-like box
    with shapefile.Writer(str(tmp_path / "coast"), shapeType=shapefile.POLYGON) as w:
        w.field("name", "C")
        w.poly([ring])
        w.record("box")
    (tmp_path / "coast.prj").write_text(CRS("EPSG:4326").to_wkt("WKT1_ESRI"))
    cfg = load_scene("winter_basin", {"domain.file": str(tmp_path / "coast.shp"), "run.duration": "1h"})
    poly = domain_polygon(cfg)
    tr = Transformer.from_crs("EPSG:4326", "EPSG:3413", always_xy=True)
    expected = Polygon([tr.transform(lo, la) for lo, la in ring])
    assert poly.symmetric_difference(expected).area < 1e-9 * expected.area and expected.area > 1e10


@pytest.mark.slow
def test_one_crs_labels_the_output_and_rejects_forcing_from_elsewhere(tmp_path):
    out = tmp_path / "south"
    r = run_cli("run", "shear_box", "--out", out, sets=[*QUICK, 'domain.crs="EPSG:3031"'])
    assert r.returncode == 0, r.stderr
    ds, _ = last_snapshot(out)
    assert ds["crs"].attrs["latitude_of_projection_origin"] == -90.0
    assert "Antarctic" in ds["crs"].attrs["crs_wkt"]
    # Arctic ERA5-like records cannot drive a scene whose CRS puts it at the South Pole
    era5 = ROOT / "data_stubs" / "era5_stub_arctic.nc"
    r = run_cli("run", "shear_box", "--out", tmp_path / "mixed",
                sets=[*QUICK, 'domain.crs="EPSG:3031"', f'forcing.wind={{kind="file", path="{era5}"}}',
                      'run.start_date="2020-01-02 00:00:00"'])
    one_line_error(r, "outside the forcing grid")
    assert not (tmp_path / "mixed").exists()


def test_coriolis_latitude_from_the_crs_per_node():
    from lagice.forces import Coriolis
    from lagice.params import OMEGA_EARTH

    c = Coriolis(crs="EPSG:3413")
    nodes = np.array([[0.0, 0.0], [1.0e6, 0.0], [0.0, -2.0e6]])
    from pyproj import Transformer

    lat = Transformer.from_crs("EPSG:3413", "EPSG:4326", always_xy=True).transform(nodes[:, 0], nodes[:, 1])[1]
    assert lat[0] == pytest.approx(90.0) and lat[2] < lat[1] < 90.0
    np.testing.assert_allclose(c.f_at(nodes), 2 * OMEGA_EARTH * np.sin(np.deg2rad(lat)), rtol=1e-12)
    assert c.f_at(nodes + 1.0e5)[0] < c.f_at(nodes)[0], "f follows the nodes as they move"


# -- 6. CF and provenance ------------------------------------------------------------------
UGRID_ROLES = ("mesh_topology is not a valid cf_role", "face_node_connectivity is not a valid cf_role")


def _cf_errors(path):
    from compliance_checker.runner import CheckSuite, ComplianceChecker

    CheckSuite.load_all_available_checkers()
    report = path.with_suffix(".cf.json")
    ComplianceChecker.run_checker(str(path), ["cf:1.8"], verbose=0, criteria="normal",
                                  output_filename=str(report), output_format="json")
    res = json.loads(report.read_text())["cf:1.8"]
    return [m for sec in res.get("high_priorities", []) for m in sec.get("msgs", [])]


def test_outputs_pass_the_cf_checker_and_carry_provenance(base_run, tmp_path):
    pytest.importorskip("compliance_checker")
    snap = tmp_path / "snapshot.nc"
    shutil.copy(sorted((base_run / "snapshots").glob("snapshot_*.nc"))[-1], snap)
    errors = _cf_errors(snap)
    assert errors and all(any(role in e for role in UGRID_ROLES) for e in errors), errors
    for name in ("grid_00000060.nc",):
        p = tmp_path / name
        shutil.copy(base_run / "snapshots" / name, p)
        assert _cf_errors(p) == []
    traj = tmp_path / "drifters.nc"
    shutil.copy(base_run / "drifters.nc", traj)
    assert _cf_errors(traj) == []
    for f in (snap, tmp_path / "grid_00000060.nc", traj):
        ds = xr.open_dataset(f)
        assert ds.attrs["title"] and ds.attrs["history"] and ds.attrs["lagice_version"]
        assert json.loads(ds.attrs["lagice_config"])["scene"]["name"] == "shear_box"
    d = xr.open_dataset(traj)
    assert d.attrs["featureType"] == "trajectory" and d["trajectory"].attrs["cf_role"] == "trajectory_id"


def test_vtu_carries_every_snapshot_field_and_the_pvd_its_times(base_run):
    import meshio

    idx = json.loads((base_run / "snapshots" / "index.json").read_text())
    pvd = (base_run / "snapshots" / "snapshots.pvd").read_text()
    for e in idx:
        assert f'timestep="{float(e["time_s"])!r}"' in pvd and e["file"].replace(".nc", ".vtu") in pvd
    e = idx[-1]
    ds = xr.load_dataset(base_run / "snapshots" / e["file"])
    m = meshio.read(base_run / "snapshots" / e["file"].replace(".nc", ".vtu"))
    assert float(m.field_data["TimeValue"][0]) == e["time_s"]
    data = {**m.point_data, **{k: v[0] for k, v in m.cell_data.items()}}
    for name, var in ds.data_vars.items():
        if "location" not in var.attrs or name in ("mesh",):
            continue
        base = name.rsplit("_", 1)[0] if name.startswith(("stress_", "velocity_")) else name
        assert base in data, f"{name} missing in the VTU"
        vals = data[base]
        if vals.ndim == 2:
            k = {"xx": 0, "yy": 1, "xy": 2, "x": 0, "y": 1}[name.rsplit("_", 1)[1]]
            vals = vals[:, k]
        np.testing.assert_array_equal(vals, np.squeeze(var.values), err_msg=name)


def test_open_run_gives_time_series_across_mesh_epochs(base_run):
    import lagice

    run = lagice.open_run(base_run)
    idx = json.loads((base_run / "snapshots" / "index.json").read_text())
    assert len(run.epochs) == len({e["mesh_epoch"] for e in idx})
    assert sum(ep.sizes["time"] for ep in run.epochs) == len(idx)
    for ep in run.epochs:  # topology shared inside an epoch, positions per time
        assert ep["node_x"].dims == ("time", "mesh_node") and ep.ugrid.grid.n_face == ep.sizes["mesh_face"]
    damage = run.area_mean("damage")
    assert damage.sizes["time"] == len(idx) and str(damage["time"].values[0]).startswith("2000-01-01T00:00")
    for k, e in enumerate(idx):
        ds = xr.load_dataset(base_run / "snapshots" / e["file"])
        xy = np.column_stack([ds["mesh_node_x"].values, ds["mesh_node_y"].values])
        t = ds["mesh_face_nodes"].values
        a, b, c = xy[t[:, 0]], xy[t[:, 1]], xy[t[:, 2]]
        area = 0.5 * np.abs((b - a)[:, 0] * (c - a)[:, 1] - (c - a)[:, 0] * (b - a)[:, 1])
        assert damage.values[k] == pytest.approx(np.sum(ds["damage"].values[0] * area) / area.sum(), rel=1e-12)
        # the regular-grid time series keeps the ice volume of every snapshot
        g = run.grid.isel(time=k)
        vol_grid = float((g["thickness"].fillna(0) * g["coverage"]).sum()) * 30e3 * 30e3
        assert vol_grid == pytest.approx(float(np.sum(ds["thickness"].values[0] * area)), rel=1e-10)
    traj = run.drifters
    assert traj.sizes["trajectory"] == 2 and traj.sizes["obs"] == 61


# -- 7. feedback ---------------------------------------------------------------------------
def test_version_log_level_and_numba_notice(tmp_path, capsys):
    import lagice

    r = run_cli("--version")
    assert r.returncode == 0 and r.stdout.strip() == f"lagice {lagice.__version__}"
    quiet = run_cli("run", "shear_box", "--out", tmp_path / "q", "--log-level", "warning",
                    sets=[s for s in QUICK if s != "run.progress=false"])
    assert quiet.returncode == 0 and "running scene" not in quiet.stdout and "sim-days" not in quiet.stdout
    r = run_cli("run", "shear_box", "--out", tmp_path / "d", "--log-level", "debug", sets=["drifters.count=-3"])
    assert r.returncode == 2 and "Traceback" in r.stderr and "drifters.count" in r.stderr.splitlines()[-1]
    from numba import njit

    from lagice.cli import _announce_numba_compilation, setup_logging

    setup_logging("info")
    _announce_numba_compilation()

    @njit
    def fresh(x):  # not cached: numba compiles it now
        return x + 1

    assert fresh(1) == 2
    assert "numba is compiling" in capsys.readouterr().out


def test_progress_bar_after_resume(tmp_path):
    import io

    from lagice.activities import Progress
    from lagice.simulation import Simulation

    from helpers import scene_sim

    sim = scene_sim("shear_box", tmp_path, {"run.duration": 1600.0, "solver.dt": 40.0, "checkpoint.every": 800.0,
                                            "domain.resolution_m": 50e3})
    sim.run(n_steps=20)
    res = Simulation.resume(tmp_path / "checkpoints", progress=False)
    stream = io.StringIO()
    res.add(Progress(stream=stream, bar=True))
    res.run()
    text = stream.getvalue()
    assert "20/40" in text and "40/40" in text and "100%" in text, text
    assert "step/s" in text or "s/step" in text  # the rate (tqdm), over this session's steps


@pytest.mark.slow
def test_diagnose_warns_when_the_window_is_shortened(base_run, tmp_path):
    r = run_cli("diagnose", base_run, "--window-steps", "10", "--out", tmp_path / "diag")
    assert r.returncode == 0, r.stderr
    assert "warning: --window-steps 10: the run has 5 snapshots; the window was shortened to 4" in r.stderr
    res = json.loads((tmp_path / "diag" / "diagnostics.json").read_text())
    assert res["dt_s"] == 4 * 1500.0


def test_plot_draws_the_drifters_of_the_drifter_file(base_run, tmp_path, monkeypatch):
    import lagice.plotting as plotting
    from lagice.io.drifters import read_trajectories
    from lagice.scenes.builder import plot_scene

    run = tmp_path / "run"
    shutil.copytree(base_run, run)
    seen = {}
    real = plotting.plot_run

    def spy(snap_dir, png, summary=None, trajectories=None):
        seen["trajectories"] = trajectories
        return real(snap_dir, png, summary, trajectories)

    monkeypatch.setattr(plotting, "plot_run", spy)
    ds, _ = last_snapshot(run)
    cfg = json.loads(ds.attrs["lagice_config"])
    cfg["output"]["plot"] = True
    png = plot_scene(cfg, run)
    assert png.stat().st_size > 10_000
    d = xr.load_dataset(run / "drifters.nc", decode_times=False)
    assert len(seen["trajectories"]) == 2
    for k, tr in enumerate(seen["trajectories"]):
        assert np.array_equal(tr[:, 0], d["x"].values[k]) and tr.shape == (61, 2)
    assert all(np.array_equal(a, b) for a, b in zip(seen["trajectories"], read_trajectories(run / "drifters.nc")))


def test_coriolis_from_the_crs_is_applied_once_beside_a_drag_coriolis_f(tmp_path, caplog):
    """``[forcing.coriolis] latitude_deg = "crs"`` with ``forcing.drag.coriolis_f`` set: the
    Coriolis term was added twice (the table's per-node f and the drag's constant f). The table
    decides, once, and the drag key is named as unused."""
    import logging

    from lagice.forces import Coriolis

    from helpers import scene_sim

    with caplog.at_level(logging.WARNING, logger="lagice"):
        sim = scene_sim("wind_square", tmp_path / "a",
                        {"domain.resolution_m": 100e3, "domain.crs": "EPSG:3413",
                         "forcing.coriolis": {"latitude_deg": "crs"}, "forcing.drag.coriolis_f": 1.0e-4})
    cor = [f for f in sim.model.forces if isinstance(f, Coriolis)]
    assert len(cor) == 1 and cor[0].crs is not None
    assert "forcing.drag.coriolis_f = 0.0001 ([forcing.coriolis] sets the Coriolis parameter)" in caplog.text


@pytest.mark.parametrize("coriolis,warned", [({"latitude_deg": -70.0}, True), ({"f_s": -1.4e-4}, True),
                                             ({"latitude_deg": 80.0}, False)])
def test_a_counter_clockwise_ocean_turning_in_the_southern_hemisphere_is_named(coriolis, warned, caplog):
    """``turning_angle_deg`` is counter-clockwise positive everywhere (the Northern Hemisphere's
    Ekman turning); a positive value with a negative Coriolis parameter turns the drag the wrong
    way for the Southern Hemisphere, and the warning says so, with the value to use."""
    import logging

    from lagice.scenes.builder import validate_config
    from lagice.scenes.config import load_scene

    cfg = load_scene("winter_basin_pack", {"run.duration": "1h", "forcing.coriolis": coriolis,
                                           "forcing.drag": {"air_drag": 2e-3, "turning_angle_deg": 25.0}})
    with caplog.at_level(logging.WARNING, logger="lagice"):
        validate_config(cfg)
    assert ("turning_angle_deg = 25 turns the ocean drag counter-clockwise" in caplog.text
            and "use turning_angle_deg = -25" in caplog.text) is warned


@pytest.mark.parametrize("coriolis_lat,warned", [(70.0, True), (80.0, False)])
def test_the_wind_climatologys_latitude_against_the_ices_is_named(coriolis_lat, warned, caplog):
    """The climatology builds its geostrophic wind with f of its own ``latitude_deg`` (80° by
    default); a ``[forcing.coriolis]`` latitude that differs is named in a warning."""
    import logging

    from lagice.scenes.builder import validate_config
    from lagice.scenes.config import load_scene

    cfg = load_scene("winter_basin_pack", {"run.duration": "1h", "forcing.coriolis": {"latitude_deg": coriolis_lat}})
    with caplog.at_level(logging.WARNING, logger="lagice"):
        validate_config(cfg)
    assert ("forcing.wind.latitude_deg = 80 (the climatology's geostrophic wind) differs from "
            f"forcing.coriolis.latitude_deg = {coriolis_lat:g}" in caplog.text) is warned
