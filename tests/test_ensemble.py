"""Ensembles on dask.distributed (lagice.ensemble, `lagice ensemble`).

One small ensemble of the shear box at 40 km (66 elements, 1 h, 90 steps) runs
once on a real 2-worker LocalCluster (module fixture); the tests compare it with
the same members run one by one, rerun it after simulated interruptions,
branch members from a checkpoint and check the specs that must be refused.
"""
from __future__ import annotations

import contextlib
import hashlib
import io
import json
import os
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from lagice.ensemble import Ensemble, load_spec, open_grids, spread
from lagice.ensemble.cluster import local_cluster_kwargs, machine_cores, make_cluster, uses_member_resource
from lagice.errors import ConfigError
from lagice.io.checkpoint import read_checkpoint
from lagice.scenes.builder import build_simulation
from lagice.scenes.config import load_scene

COMMON = {"domain.resolution_m": 40e3, "run.duration": "1h", "output.every": "20min",
          "checkpoint.every": "20min", "output.plot": False, "output.grid_resolution_m": 50e3}
MEMBERS = {"a": {"rheology.friction": 0.6},
           "b": {"rheology.friction": 0.8, "run.seed": 5},
           "c": {"rheology.healing_time_s": 1e6, "run.seed": 9},
           # NaN velocities on the top edge after t = 1200 s: the member fails at run time, naming the key
           "bad": {"boundary.top.u": "1e-2*sqrt(1200.0 - t)"}}
GOOD = ("a", "b", "c")


def spec_dict(members=MEMBERS, common=COMMON, **extra):
    return {"ensemble": {"name": "tiny", "base": "shear_box"}, "set": dict(common),
            "member": [{"id": k, "set": v} for k, v in members.items()], **extra}


def last_snapshot(run_dir: Path) -> Path:
    idx = json.loads((run_dir / "snapshots" / "index.json").read_text())
    return run_dir / "snapshots" / idx[-1]["file"]


def assert_same_snapshot(p: Path, q: Path):
    a, b = xr.load_dataset(p, decode_times=False), xr.load_dataset(q, decode_times=False)
    assert set(a.variables) == set(b.variables)
    for v in a.variables:
        assert np.array_equal(a[v].values, b[v].values), f"{v} differs between {p} and {q}"


@pytest.fixture(scope="module")
def ensemble_run(tmp_path_factory):
    """The 4-member ensemble (one failing member) on a 2-worker LocalCluster."""
    from distributed import Client, LocalCluster

    out = tmp_path_factory.mktemp("ens") / "out"
    ens = Ensemble(spec_dict(), out)
    kw = local_cluster_kwargs(machine_cores(), n_members=4, workers=2)
    buf = io.StringIO()
    with LocalCluster(**kw) as cluster, Client(cluster) as client, contextlib.redirect_stdout(buf):
        resources = uses_member_resource(client)
        summary = ens.run(client=client)
    return {"out": out, "summary": summary, "screen": buf.getvalue(), "ens": ens,
            "threads": int(kw["env"]["NUMBA_NUM_THREADS"]), "resources": resources}


@pytest.fixture(scope="module")
def references(tmp_path_factory):
    """The good members run one by one with the plain scene API (no ensemble code)."""
    root = tmp_path_factory.mktemp("ref")
    out = {}
    for mid in GOOD:
        cfg = load_scene("shear_box", {**COMMON, **MEMBERS[mid]})
        sim = build_simulation(cfg, root / mid, progress=False)
        sim.run()
        out[mid] = root / mid
    return out


@pytest.mark.slow
def test_members_on_local_cluster_are_bit_identical_to_serial_runs(ensemble_run, references):
    out = ensemble_run["out"]
    assert ensemble_run["resources"] == (True, 2)            # 2 workers, one member slot each
    for mid in GOOD:
        mdir = out / "members" / mid
        assert_same_snapshot(last_snapshot(mdir), last_snapshot(references[mid]))
        info = json.loads((mdir / "member.json").read_text())
        assert info["worker"].startswith("tcp://")          # it really ran on a dask worker
        assert info["numba_threads"] == ensemble_run["threads"] == max(1, machine_cores() // 2)
        assert info["overrides"] == MEMBERS[mid]
        # provenance in every output file (lagice.io.cf.provenance), the run-folder marker and the checkpoints
        files = sorted((mdir / "snapshots").glob("*.nc"))
        assert any(f.name.startswith("grid_") for f in files) and any(f.name.startswith("snapshot_") for f in files)
        for f in files:
            with xr.open_dataset(f, decode_times=False) as ds:
                assert ds.attrs["lagice_ensemble"] == "tiny" and ds.attrs["lagice_ensemble_member"] == mid, f
                assert json.loads(ds.attrs["lagice_ensemble_member_overrides"]) == MEMBERS[mid]
        assert json.loads((mdir / "lagice_run.json").read_text())["ensemble"]["member"] == mid
        _, meta = read_checkpoint(max((mdir / "checkpoints").glob("*.npz")))
        assert meta["config"]["_ensemble"] == {"ensemble": "tiny", "member": mid, "overrides": MEMBERS[mid]}


@pytest.mark.slow
def test_failing_member_is_reported_and_others_finish(ensemble_run):
    s, screen = ensemble_run["summary"], ensemble_run["screen"]
    status = dict(zip(s["member"].values, s["status"].values))
    assert status == {"a": "done", "b": "done", "c": "done", "bad": "failed"}
    err = str(s["error"].sel(member="bad").values)
    assert "ConfigError: boundary.top.u = '1e-2*sqrt(1200.0 - t)' gives nan at t = 1240 s" in err
    assert "bad: FAILED" in screen and "boundary.top.u" in screen
    assert "[4/4]" in screen and "ETA" in screen
    failed = json.loads((ensemble_run["out"] / "members" / "bad" / "failed.json").read_text())
    assert "boundary.top.u" in failed["error"] and "Traceback" in failed["traceback"]
    assert not (ensemble_run["out"] / "members" / "bad" / "done.json").exists()


@pytest.mark.slow
def test_summary_has_member_dimension_and_diagnostics(ensemble_run, tmp_path):
    out = ensemble_run["out"]
    with xr.open_dataset(out / "ensemble_summary.nc") as s:
        assert s.sizes == {"member": 4}
        assert list(s["member"].values) == list(MEMBERS)
        done = s.sel(member=list(GOOD))
        assert np.all(done["steps"] == 90) and np.all(done["time_s"] == 3600.0)
        assert np.all(np.abs(done["volume_relative_residual"]) < 1e-12)  # fixed mesh, no thermodynamics
        assert np.all(done["diag_status"] == "ok")
        assert np.all(np.isfinite(done["beta_space"]))
        bad = s.sel(member="bad")
        assert np.isnan(bad["beta_space"]) and str(bad["diag_status"].values).startswith("not_computed")
        assert float(s["set_rheology_friction"].sel(member="b")) == 0.8
        base_friction = load_scene("shear_box")["rheology"]["friction"]
        assert float(s["set_rheology_friction"].sel(member="c")) == base_friction  # c runs with the base value
        # the same statistics as `lagice diagnose` on the member folder (last two snapshots)
        from lagice.cli import main
        with contextlib.redirect_stdout(io.StringIO()):
            assert main(["diagnose", str(out / "members" / "b"), "--out", str(tmp_path / "d")]) == 0
        ref = json.loads((tmp_path / "d" / "diagnostics.json").read_text())
        for k in ("beta_space", "mean_total_s", "pdf_tail_exponent_shear", "shear_divergence_r2"):
            assert float(s[k].sel(member="b")) == pytest.approx(ref[k], rel=1e-12)
    png = out / "ensemble_spread.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.slow
def test_grids_combine_lazily_along_member(ensemble_run):
    import dask.array as da

    out = ensemble_run["out"]
    g = open_grids(out)
    assert list(g["member"].values) == list(GOOD)                   # finished members only
    assert g["thickness"].dims == ("member", "time", "y", "x") and g.sizes["time"] == 4
    assert isinstance(g["thickness"].data, da.Array)                # lazy
    for mid in GOOD:
        last = max((out / "members" / mid / "snapshots").glob("grid_*.nc"))
        with xr.open_dataset(last) as ref:
            np.testing.assert_array_equal(g["damage"].sel(member=mid).isel(time=-1).values, ref["damage"].values[0])
    sp = spread(out)
    stack = g["damage"].isel(time=-1).values
    np.testing.assert_allclose(sp["damage_mean"].values, np.mean(stack, axis=0), rtol=1e-14)
    np.testing.assert_allclose(sp["damage_std"].values, np.std(stack, axis=0), rtol=1e-12, atol=1e-15)
    assert float(sp["damage_std"].max()) > 0      # the members differ


@pytest.mark.slow
def test_rerun_completes_only_what_is_missing(ensemble_run, tmp_path):
    first = ensemble_run["out"]
    out = tmp_path / "out"
    shutil.copytree(first, out)
    spec = tmp_path / "tiny.toml"
    spec.write_text(_toml(spec_dict()))
    a_done = (out / "members" / "a" / "done.json").stat().st_mtime_ns
    a_last = last_snapshot(out / "members" / "a").stat().st_mtime_ns
    # b was interrupted after its 40-minute checkpoint; c never started
    b = out / "members" / "b"
    (b / "done.json").unlink()
    (b / "checkpoints" / "checkpoint_0000000090.npz").unlink()
    shutil.rmtree(out / "members" / "c")
    bad_failed = (out / "members" / "bad" / "failed.json").stat().st_mtime_ns
    # the same command again, on the default embedded LocalCluster (sized to the machine)
    r = subprocess.run([sys.executable, "-m", "lagice.cli", "ensemble", str(spec), "--out", str(out), "--no-plot"],
                       check=False, capture_output=True, text=True, env={**os.environ, "NUMBA_NUM_THREADS": "1"})
    assert r.returncode == 1, r.stderr           # one member still fails
    assert "1 done, 1 to resume, 1 to start, 1 failed to retry" in r.stdout
    assert (out / "members" / "a" / "done.json").stat().st_mtime_ns == a_done         # skipped
    assert last_snapshot(out / "members" / "a").stat().st_mtime_ns == a_last
    info = json.loads((b / "member.json").read_text())
    assert info["resumed_from"].endswith("checkpoint_0000000060.npz")
    workers = min(machine_cores(), 3)                     # 3 members to run
    assert f"LocalCluster: {workers} worker processes" in r.stdout
    assert info["worker"].startswith("tcp://") and info["numba_threads"] == max(1, machine_cores() // workers)
    assert json.loads((out / "members" / "c" / "member.json").read_text())["resumed_from"] is None
    assert (out / "members" / "bad" / "failed.json").stat().st_mtime_ns > bad_failed  # retried
    for mid in ("b", "c"):
        assert_same_snapshot(last_snapshot(out / "members" / mid), last_snapshot(first / "members" / mid))
    s = xr.open_dataset(out / "ensemble_summary.nc")
    assert list(s["status"].values) == ["done", "done", "done", "failed"]
    assert str(s["resumed_from"].sel(member="b").values).endswith("checkpoint_0000000060.npz")
    # a changed member configuration is refused before anything runs
    changed = spec_dict(members={**MEMBERS, "a": {"rheology.friction": 0.65}})
    with pytest.raises(ConfigError, match=r"member 'a' was started with other physics \(rheology.friction: 0.6 -> "
                                          r"0.65\).*may only change run.duration"):
        Ensemble(changed, out).run(serial=True)
    assert (out / "members" / "a" / "done.json").stat().st_mtime_ns == a_done
    # a longer run.duration extends every member from its last checkpoint (lagice resume's rules)
    longer = Ensemble(spec_dict(common={**COMMON, "run.duration": "80min"}), out)
    assert longer.plan() == {"a": "resume", "b": "resume", "c": "resume", "bad": "retry"}
    s = longer.run(serial=True, plot=False, retry_failed=False)
    assert list(s["status"].values) == ["done", "done", "done", "failed"]
    assert list(s["steps"].sel(member=list(GOOD)).values) == [120, 120, 120]
    assert all(str(s["resumed_from"].sel(member=m).values).endswith("checkpoint_0000000090.npz") for m in GOOD)


def _toml(d: dict) -> str:
    def val(v):
        return json.dumps(v) if not isinstance(v, bool) else str(v).lower()
    lines = ["[ensemble]"] + [f"{k} = {val(v)}" for k, v in d["ensemble"].items()]
    lines += ["[set]"] + [f'"{k}" = {val(v)}' for k, v in d["set"].items()]
    for m in d["member"]:
        sets = ", ".join(f'"{k}" = {val(v)}' for k, v in m["set"].items())
        lines += ["[[member]]", f'id = "{m["id"]}"', f"set = {{ {sets} }}"]
    return "\n".join(lines) + "\n"


# -- branching from a checkpoint --------------------------------------------------------------
@pytest.fixture(scope="module")
def parent_checkpoint(tmp_path_factory):
    """A 40-minute shear-box run with checkpoints every 20 minutes, and the 1 h straight run."""
    root = tmp_path_factory.mktemp("parent")
    base = {k: v for k, v in COMMON.items() if k != "output.grid_resolution_m"}
    cfg = load_scene("shear_box", {**base, "run.duration": "40min"})
    sim = build_simulation(cfg, root / "parent", progress=False)
    sim.run()
    straight = build_simulation(load_scene("shear_box", base), root / "straight", progress=False)
    straight.run()
    return root / "parent" / "checkpoints" / "checkpoint_0000000060.npz", root / "straight"


def test_branch_members_start_from_the_checkpoint(parent_checkpoint, tmp_path):
    ck, straight = parent_checkpoint
    spec = {"ensemble": {"name": "branch", "branch_from": str(ck)}, "set": {"run.duration": "1h"},
            "member": [{"id": "same", "set": {}}, {"id": "weak", "set": {"rheology.friction": 0.3}}]}
    summary = Ensemble(spec, tmp_path / "out").run(serial=True, plot=False)
    assert list(summary["status"].values) == ["done", "done"]
    same = tmp_path / "out" / "members" / "same"
    # the same physics as the straight run: bit for bit
    assert_same_snapshot(last_snapshot(same), last_snapshot(straight))
    # the branch's first snapshot is the parent state
    arrays, _ = read_checkpoint(ck)
    first = xr.load_dataset(same / "snapshots" / "snapshot_00000060.nc", decode_times=False)
    for name in ("thickness", "damage", "cohesion"):
        np.testing.assert_array_equal(first[name].values[0], arrays[name])
    np.testing.assert_array_equal(first["velocity_x"].values[0], arrays["velocity"][:, 0])
    # provenance: the parent path and SHA-256, in member.json, output files and the summary
    sha = hashlib.sha256(ck.read_bytes()).hexdigest()
    info = json.loads((same / "member.json").read_text())
    assert info["parent_checkpoint_sha256"] == sha and Path(info["parent_checkpoint"]) == ck.resolve()
    assert first.attrs["lagice_parent_checkpoint_sha256"] == sha and first.attrs["lagice_ensemble_member"] == "same"
    assert summary.attrs["ensemble_parent_checkpoint_sha256"] == sha
    weak_ck = max((tmp_path / "out" / "members" / "weak" / "checkpoints").glob("*.npz"))
    _, wmeta = read_checkpoint(weak_ck)
    assert wmeta["config"]["rheology"]["friction"] == 0.3 and wmeta["config"]["_parent"]["sha256"] == sha
    w = xr.load_dataset(last_snapshot(tmp_path / "out" / "members" / "weak"))
    assert not np.array_equal(w["damage"].values, xr.load_dataset(last_snapshot(same))["damage"].values)


# -- specs ----------------------------------------------------------------------------------
def test_grid_spec_expands_to_the_cartesian_product():
    spec = load_spec(textwrap.dedent("""
        [ensemble]
        base = "shear_box"
        [set]
        run.duration = "1h"
        [grid]
        "rheology.alpha" = [3.0, 5.0]
        rheology.friction = [0.5, 0.6, 0.7]
        """))
    assert [m.id for m in spec.members] == [f"alpha={a}__friction={f}" for a in (3, 5) for f in (0.5, 0.6, 0.7)]
    pairs = [(m.config["rheology"]["alpha"], m.config["rheology"]["friction"]) for m in spec.members]
    assert pairs == [(a, f) for a in (3.0, 5.0) for f in (0.5, 0.6, 0.7)]
    assert spec.members[4].overrides == {"rheology.alpha": 5.0, "rheology.friction": 0.6}
    assert all(m.config["run"]["duration"] == "1h" for m in spec.members)
    assert all(m.config["solver"]["dt"] == 40.0 for m in spec.members)          # the base scene's value
    assert len({m.config_hash for m in spec.members}) == 6
    # two keys with the same leaf name keep their full dotted keys in the ids
    two = load_spec({"ensemble": {"base": "winter_basin"},
                     "grid": {"forcing.wind.seed": [1, 2], "run.seed": [3]}})
    assert [m.id for m in two.members] == ["forcing.wind.seed=1__run.seed=3", "forcing.wind.seed=2__run.seed=3"]


def test_seed_spec_members_are_reproducible_and_perturbed():
    from lagice.ensemble.spec import seed_members

    rule = {"n": 3, "seed": 11, "keys": ["run.seed", "forcing.wind.seed"],
            "perturb": {"rheology.cohesion_max_pa": {"relative": 0.05}}}
    small = load_spec({"ensemble": {"base": "winter_basin"}, "seeds": rule})   # every member config validated
    assert [m.id for m in small.members] == ["s000", "s001", "s002"]
    for m in small.members:
        assert m.config["run"]["seed"] == m.overrides["run.seed"]
        assert m.config["forcing"]["wind"]["seed"] == m.overrides["forcing.wind.seed"]
        assert m.config["rheology"]["cohesion_max_pa"] == m.overrides["rheology.cohesion_max_pa"]
    # 200 members (overrides only: the same rule, without building 200 configs)
    big = seed_members({**rule, "n": 200}, "<test>", {}, load_spec({"ensemble": {"base": "winter_basin"},
                                                                   "seeds": {"n": 1}}).base, None)
    assert [own for _, own in big[:3]] == [m.overrides for m in small.members]       # member k does not depend on n
    seeds = [own["run.seed"] for _, own in big]
    assert len(set(seeds)) == 200 and all(0 <= s < 2**31 - 1 for s in seeds)
    vals = np.array([own["rheology.cohesion_max_pa"] for _, own in big])
    assert np.mean(vals) == pytest.approx(20e3, rel=0.02)                    # winter_basin: 20 kPa
    assert np.std(vals) == pytest.approx(0.05 * 20e3, rel=0.15)


BAD_SPECS = [
    ('[ensemble]\nbase = "shear_box"\n[members]\nn = 2\n', r"unknown table \[members\]"),
    ('[ensemble]\nbsae = "shear_box"\n[grid]\n"run.seed" = [1]\n', "unknown key ensemble.bsae"),
    ('[ensemble]\nbase = "shear_box"\n[grid]\n"run.seed" = []\n', "grid.run.seed is an empty list"),
    ('[ensemble]\nbase = "shear_box"\n[grid]\n', r"\[grid\] is empty"),
    ('[ensemble]\nbase = "shear_box"\n[[member]]\nid = "x"\n[[member]]\nid = "x"\n', "duplicate member id 'x'"),
    ('[ensemble]\nbase = "shear_box"\n[[member]]\n[[member]]\nset = {"rheology.alpah" = 3.0}\n',
     r"member 'm001' \(rheology.alpah=3\): .*unknown key rheology.alpah"),
    ('[ensemble]\nbase = "shear_box"\n[[member]]\nset = {"rheolgy.alpha" = 3.0}\n', r"unknown table \[rheolgy\]"),
    ('[ensemble]\nbase = "shear_box"\n[grid]\n"run.duration" = ["1h", "2x"]\n',
     "member 'duration=2x'.*run.duration = '2x'"),
    # forcing generator keywords are checked for every member too (lagice.scenes.builder.validate_config)
    ('[ensemble]\nbase = "winter_basin"\n[grid]\n"forcing.wind.n" = [4, "six"]\n',
     r"member 'n=six' \(forcing.wind.n=six\): forcing.wind.n = 'six': expected an integer"),
    ('[ensemble]\nbase = "winter_basin"\n[[member]]\n[[member]]\n'
     'set = {"forcing.wind.max_speed_range_m_s" = [30, 10]}\n',
     r"member 'm001'.*forcing.wind.max_speed_range_m_s = \[30, 10\]: expected \[low, high\] with low <= high"),
    ('[ensemble]\nbase = "shear_box"\n[grid]\n"run.seed" = [1]\n[seeds]\nn = 2\n', "exactly one of"),
    ('[ensemble]\nbase = "shear_box"\n[seeds]\nn = 0\n', "seeds.n = 0"),
    ('[ensemble]\nbase = "shear_box"\n[seeds]\nn = 2\nperturb = {"solver.name" = {relative = 0.1}}\n',
     "perturb.solver.name: the base value 'implicit' is not a number"),
    ('[ensemble]\nbase = "no_such_scene"\n[seeds]\nn = 2\n', "unknown scene 'no_such_scene'"),
    ('[ensemble]\nbase = "shear_box"\n[[member]]\nid = "a/b"\n', "member id 'a/b'"),
    ('[ensemble]\nbase = "shear_box"\n[seeds]\nn = 2\n[cluster]\nkind = "kubernetes"\n', "cluster.kind"),
    ('[ensemble]\nbase = "shear_box"\n[seeds]\nn = 2\n[analysis]\nwindow = "-1d"\n', "analysis.window"),
]


@pytest.mark.parametrize("text,message", BAD_SPECS)
def test_invalid_spec_fails_before_anything_starts(text, message, tmp_path):
    spec = tmp_path / "bad.toml"
    spec.write_text(text)
    with pytest.raises(ConfigError, match=message):
        Ensemble.from_file(spec, tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_invalid_branch_overrides_are_refused(parent_checkpoint, tmp_path):
    ck = parent_checkpoint[0]
    for sets, message in (({"domain.resolution_m": 20e3}, "member 'x'.*domain.resolution_m: a branch starts from"),
                          ({"solver.dt": 20.0}, "member 'x'.*solver.dt: a branch starts from"),
                          ({"run.duration": "30min"}, "member 'x'.*checkpoint is at t = 2400 s")):
        spec = {"ensemble": {"branch_from": str(ck)}, "member": [{"id": "x", "set": sets}]}
        with pytest.raises(ConfigError, match=message):
            Ensemble(spec, tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_cli_refuses_a_bad_spec_with_exit_2(tmp_path):
    spec = tmp_path / "bad.toml"
    spec.write_text('[ensemble]\nbase = "shear_box"\n[[member]]\nid = "x"\n[[member]]\nid = "x"\n')
    r = subprocess.run([sys.executable, "-m", "lagice.cli", "ensemble", str(spec), "--out", str(tmp_path / "o")],
                       check=False, capture_output=True, text=True)
    assert r.returncode == 2 and "duplicate member id 'x'" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "o").exists()


# -- clusters ---------------------------------------------------------------------------------
def test_local_cluster_sizing_never_oversubscribes():
    assert local_cluster_kwargs(16, n_members=3)["n_workers"] == 3
    kw = local_cluster_kwargs(16, n_members=3)
    assert kw["env"]["NUMBA_NUM_THREADS"] == "5" and kw["resources"] == {"member": 1}
    kw = local_cluster_kwargs(16, n_members=100)
    assert (kw["n_workers"], kw["env"]["NUMBA_NUM_THREADS"]) == (16, "1")
    kw = local_cluster_kwargs(16, n_members=100, threads_per_member=4)
    assert (kw["n_workers"], kw["env"]["NUMBA_NUM_THREADS"]) == (4, "4")
    kw = local_cluster_kwargs(2, n_members=4, workers=2)
    assert (kw["n_workers"], kw["env"]["NUMBA_NUM_THREADS"], kw["threads_per_worker"]) == (2, "1", 1)


@pytest.mark.parametrize("kind", ["slurm", "pbs"])
def test_jobqueue_cluster_job_script_asks_for_the_right_resources(kind):
    cfg = {"kind": kind, "cores": 8, "memory": "16GiB", "walltime": "02:00:00", "queue": "normal",
           "account": "proj", "threads_per_member": 2, "jobs": 3}
    cluster, desc = make_cluster(cfg, n_members=10)
    try:
        script = cluster.job_script()
    finally:
        cluster.close()
    assert "4 workers per job x 2 numba thread(s)" in desc
    if kind == "slurm":
        for line in ("#SBATCH --cpus-per-task=8", "#SBATCH --mem=16G", "#SBATCH -t 02:00:00",
                     "#SBATCH -p normal", "#SBATCH -A proj"):
            assert line in script
    else:
        for line in ("#PBS -l walltime=02:00:00", "#PBS -q normal", "#PBS -A proj", "ncpus=8"):
            assert line in script
    assert "export NUMBA_NUM_THREADS=2" in script            # 8 cores / 4 workers
    assert "--nworkers 4" in script and "--resources member=1" in script  # one member per worker
    with pytest.raises(ConfigError, match="needs cluster.memory"):
        make_cluster({"kind": kind, "cores": 8}, n_members=1)


def test_example_specs_are_valid():
    specs = sorted((Path(__file__).resolve().parents[1] / "examples" / "ensembles").glob("*.toml"))
    assert len(specs) >= 3
    for p in specs:
        spec = load_spec(p)
        assert spec.members and all(m.config["run"]["duration"] for m in spec.members)
    slurm = load_spec(Path(__file__).resolve().parents[1] / "examples" / "ensembles" / "winter_basin_alpha_slurm.toml")
    cluster, _ = make_cluster(slurm.cluster, len(slurm.members))
    try:
        script = cluster.job_script()
    finally:
        cluster.close()
    assert "#SBATCH --exclusive" in script and "--nworkers 8" in script and "NUMBA_NUM_THREADS=1" in script


@pytest.mark.slow
def test_sigterm_stops_cleanly_and_the_same_command_resumes(tmp_path):
    import signal
    import time

    spec = tmp_path / "long.toml"
    spec.write_text(_toml(spec_dict(members={"m0": {"rheology.friction": 0.6},
                                             "m1": {"rheology.friction": 0.8, "run.duration": "1h"}},
                                    common={**COMMON, "run.duration": "6h", "checkpoint.every": "30min",
                                            "output.every": "1h"})))
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "lagice.cli", "ensemble", str(spec), "--out", str(out), "--workers", "1",
           "--no-plot"]
    env = {**os.environ, "NUMBA_NUM_THREADS": "1"}
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                         start_new_session=True)
    ck = out / "members" / "m0" / "checkpoints"
    t0 = time.time()
    while not (ck.exists() and len(list(ck.glob("checkpoint_*.npz"))) >= 2) and time.time() - t0 < 60:
        time.sleep(0.05)
    # what a batch system sends at the walltime, to every process of the job: the command and its workers
    os.killpg(p.pid, signal.SIGTERM)
    stdout, stderr = p.communicate(timeout=120)
    # a clean stop, as `lagice run`: exit 0, the running member checkpoints where it stopped, m1 never started
    assert p.returncode == 0, stdout + stderr
    assert "SIGTERM received" in stdout and "resume with: lagice ensemble" in stdout
    assert "Traceback" not in stderr and "died" not in stderr    # the workers were not killed
    with xr.open_dataset(out / "ensemble_summary.nc") as s:
        assert list(s["status"].values) == ["stopped", "not_run"]
        why = str(s["error"].sel(member="m0").values)
    step = int(re.search(r"stopped at step (\d+)", why).group(1))
    assert max(ck.glob("checkpoint_*.npz")).name == f"checkpoint_{step:010d}.npz"   # written at the stop
    # m0 runs 540 steps (6 h of 40 s); the signal comes after its second checkpoint (step 45),
    # far from the end even on a fast machine (with 2 h, 180 steps, a run could finish first)
    assert 0 < step < 540 and not (out / "members" / "m1").exists()
    assert not (out / "ensemble.lock").exists() and not (out / "STOP").exists()
    r = subprocess.run(cmd, check=False, capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "1 to resume, 1 to start" in r.stdout
    info = json.loads((out / "members" / "m0" / "member.json").read_text())
    assert info["status"] == "done" and info["resumed_from"].endswith(f"checkpoint_{step:010d}.npz")
    with xr.open_dataset(out / "ensemble_summary.nc") as s:
        assert list(s["status"].values) == ["done", "done"] and list(s["steps"].values) == [540, 90]


@pytest.mark.slow
def test_a_second_ensemble_on_the_same_folder_is_refused(ensemble_run, tmp_path):
    from lagice.errors import LagiceError

    out = tmp_path / "out"
    shutil.copytree(ensemble_run["out"], out)
    lock = out / "ensemble.lock"
    # another process holds the folder's lock (flock), as a running `lagice ensemble` does
    holder = subprocess.Popen([sys.executable, "-c", "import sys; from pathlib import Path; "
                               "from lagice.ensemble.core import _FolderLock; "
                               "_FolderLock(Path(sys.argv[1])).__enter__(); "
                               "print('held', flush=True); sys.stdin.read()", str(lock)],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        with pytest.raises(LagiceError, match=rf"another lagice ensemble is running in this folder \(pid "
                                              rf"{holder.pid} on "):
            Ensemble(spec_dict(), out).run(serial=True, retry_failed=False)
    finally:
        holder.communicate("")  # its end drops the lock, as a killed process's does
    assert lock.exists()  # left by the holder, which never released it: it blocks nothing
    # a file naming a live pid but not locked (pid reuse, or a file copied from elsewhere) blocks nothing either
    lock.write_text(json.dumps({"host": __import__("socket").gethostname(), "pid": os.getppid()}))
    s = Ensemble(spec_dict(), out).run(serial=True, retry_failed=False, plot=False)
    assert list(s["status"].values) == ["done", "done", "done", "failed"] and not lock.exists()


def test_a_member_folder_another_process_writes_is_left_alone(tmp_path):
    """A member holds the lock of its run folder (lagice.rundir.RunLock) while it runs: when
    another process holds it (a `lagice resume` of the member folder), the member fails at
    once, naming the folder and that process, and writes nothing there; the next run of the
    ensemble continues it."""
    spec = spec_dict(members={"a": {"rheology.friction": 0.6}}, common={**COMMON, "run.duration": "20min"})
    out = tmp_path / "out"
    assert list(Ensemble(spec, out).run(serial=True, plot=False)["status"].values) == ["done"]
    mdir = out / "members" / "a"
    longer = spec_dict(members={"a": {"rheology.friction": 0.6}}, common={**COMMON, "run.duration": "40min"})
    holder = subprocess.Popen([sys.executable, "-c", "import sys; from lagice.rundir import RunLock; "
                               "RunLock(sys.argv[1]).acquire(); print('held', flush=True); sys.stdin.read()",
                               str(mdir)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        before = {q: q.stat().st_mtime_ns for q in mdir.rglob("*")}
        s = Ensemble(longer, out).run(serial=True, plot=False)
        assert list(s["status"].values) == ["failed"]
        err = str(s["error"].sel(member="a").values)
        assert f"run folder {mdir} is in use by another lagice process (pid {holder.pid} on host" in err, err
        assert {q: q.stat().st_mtime_ns for q in mdir.rglob("*")} == before, "the member wrote into the folder"
    finally:
        holder.communicate(input="", timeout=60)
    s = Ensemble(longer, out).run(serial=True, plot=False)
    assert list(s["status"].values) == ["done"] and int(s["steps"].sel(member="a")) == 60


def test_gmsh_start_keeps_the_sigterm_handler():
    """gmsh's first initialisation resets SIGTERM to the default action at the C level;
    lagice.mesh.generate puts the Python handler back (else a clean stop on SIGTERM
    installed before the first mesh, as by `lagice ensemble` and its workers, kills)."""
    code = textwrap.dedent("""
        import os, signal, time
        signal.signal(signal.SIGTERM, lambda *a: print("handler ran", flush=True))
        from lagice.scenes.builder import build_mesh
        from lagice.scenes.config import load_scene
        build_mesh(load_scene("shear_box", {"domain.resolution_m": 40e3}))
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(0.2)
        print("alive", flush=True)
        """)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert r.returncode == 0 and r.stdout.split() == ["handler", "ran", "alive"], (r.returncode, r.stderr[-500:])


def test_members_start_largest_first(tmp_path, monkeypatch):
    """Members start in the order of their estimated cost (elements × steps × sub-steps), largest
    first, spec order among equals: run one by one, the finer and the longer members start
    before the coarse short one listed first; the estimate scales as the physics says (area /
    resolution² elements; explicit sub-steps ∝ 1/resolution; steps ∝ duration)."""
    from lagice.ensemble.core import estimated_cost, largest_first

    common = {**COMMON, "domain.resolution_m": 80e3, "run.duration": "20min"}
    spec = load_spec(spec_dict({"coarse": {}, "fine": {"domain.resolution_m": 40e3},
                                "long": {"run.duration": "40min"}, "coarse2": {"run.seed": 3}}, common))
    cost = {m.id: estimated_cost(m.config) for m in spec.members}
    assert cost["fine"] == pytest.approx(4 * cost["coarse"], rel=1e-9)  # implicit: elements only
    assert cost["long"] == pytest.approx(2 * cost["coarse"], rel=1e-9) and cost["coarse2"] == cost["coarse"]
    assert [m.id for m in largest_first(spec.members)] == ["fine", "long", "coarse", "coarse2"]
    ex = {"solver.name": "explicit", "solver.dt": 600.0}  # many sub-steps per step: the ceil hardly matters
    explicit = load_scene("shear_box", {**ex, "domain.resolution_m": 40e3})
    finer = load_scene("shear_box", {**ex, "domain.resolution_m": 20e3})
    assert 7.5 < estimated_cost(finer) / estimated_cost(explicit) < 8.5  # 2² elements × 2× the sub-steps
    # an implicit member counts its steps at IMPLICIT_STEP_SUBSTEPS element-sub-steps each, not one
    from lagice.ensemble.core import IMPLICIT_STEP_SUBSTEPS
    from lagice.scenes.builder import domain_polygon
    from lagice.schedule import parse_duration

    implicit = load_scene("shear_box", {"solver.name": "implicit", "solver.dt": 600.0, "domain.resolution_m": 40e3})
    elements = domain_polygon(implicit).area / (3 ** 0.5 / 4 * 40e3 ** 2)
    steps = parse_duration(implicit["run"]["duration"], "run.duration") / 600.0
    assert estimated_cost(implicit) == pytest.approx(IMPLICIT_STEP_SUBSTEPS * elements * steps, rel=1e-9)
    broken = load_scene("shear_box", {})
    broken["domain"]["resolution_m"] = "not a number"
    assert estimated_cost(broken) == float("inf")
    from lagice.ensemble import core

    order, real = [], core.run_member

    def spy(task):  # the real member run, its start recorded
        order.append(task["id"])
        return real(task)

    monkeypatch.setattr(core, "run_member", spy)
    said = io.StringIO()
    with contextlib.redirect_stdout(said):
        summary = Ensemble(spec, tmp_path / "ens").run(serial=True, plot=False)
    assert order == ["fine", "long", "coarse", "coarse2"]
    assert "members start largest first (estimated elements x steps x sub-steps): fine, long, coarse, coarse2" \
        in said.getvalue()
    assert list(summary["member"].values) == ["coarse", "fine", "long", "coarse2"]  # the summary keeps spec order
    assert set(summary["status"].values) == {"done"}
