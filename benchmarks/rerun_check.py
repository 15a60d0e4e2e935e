r"""Make a finished run again with this checkout's code and compare it bit for bit.

A benchmark that reuses a finished run (``benchmarks/validate.py``, ``physics_experiments.py``)
reads which commit made it (``validate.run_made_by``). Where that commit's work tree was modified,
or its model code differs from today's, the run may not be the run today's code makes. This
script settles it: it takes the run's own command from its folder's marker (``lagice_run.json``),
runs it into a temporary folder through ``lagice run`` (one numba thread unless
``NUMBA_NUM_THREADS`` says otherwise), and compares every numeric variable of every snapshot
with the stored run's. The outcome goes to ``RUN/reproduced.json`` (commit, modified files of the
work tree, snapshots compared, the largest absolute difference, the variables that differ), which
``validate.reuse_notice`` reads: a run reproduced with zero difference counts as made by the
reproducing commit.

    python benchmarks/rerun_check.py benchmarks/out/physics/F10-hthick-m10 \
        benchmarks/out/physics/F10s-hthick-m10 --jobs 2
"""
from __future__ import annotations

import argparse
import json
import os
import shlex
import subprocess
import sys
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RECORD = "reproduced.json"


def rerun_command(run: Path, out: Path) -> list:
    """The run's ``lagice run`` command (from its marker) with ``--out`` pointing at ``out``. A scene
    file of the checkout's examples/ is read as the commit that made the run had it (:func:`scene_files_of`,
    in a folder beside ``out``): a scene file changed since would otherwise make another run, and the
    comparison would blame the code."""
    marker = run / "lagice_run.json"
    if not marker.exists():
        raise SystemExit(f"rerun_check: {run} has no lagice_run.json: not a lagice run folder")
    info = json.loads(marker.read_text())
    argv = shlex.split(info.get("command") or "")
    if len(argv) < 3 or argv[1] != "run" or "--out" not in argv:
        raise SystemExit(f"rerun_check: {marker}: its command is not a 'lagice run ... --out ...' command: {argv}")
    argv = [sys.executable, "-m", "lagice.cli", *argv[1:]]
    argv[argv.index("--out") + 1] = str(out)
    scene = Path(argv[4])
    commit, modified = str(info.get("git_commit") or ""), info.get("git_modified_files")
    if scene.suffix == ".toml" and scene.parent.resolve() == (ROOT / "examples").resolve() and commit:
        if any(f.startswith("examples/") for f in modified or ()) or (modified is None and commit.endswith("-dirty")):
            print(f"rerun_check: {run.name}: made from a work tree whose scene files were modified; today's "
                  f"{scene.name} is read", flush=True)
        else:
            argv[4] = str(scene_files_of(commit.removesuffix("-dirty"), out.parent / "examples") / scene.name)
    return [a for a in argv if a not in ("--overwrite", "--resume")]


def scene_files_of(commit: str, folder: Path) -> Path:
    """The scene files (``examples/*.toml``) of ``commit`` from git, written into ``folder`` (together, so
    that ``extends`` finds its base; their relative paths to data are read from the checkout's root)."""
    names = subprocess.run(["git", "ls-tree", "--name-only", commit, "examples/"], cwd=ROOT, capture_output=True,
                           text=True, check=False)
    if names.returncode != 0:
        raise SystemExit(f"rerun_check: commit {commit} is not in this checkout's git history "
                         f"({names.stderr.strip()}); its scene files cannot be read")
    folder.mkdir(parents=True, exist_ok=True)
    for f in names.stdout.split():
        if f.endswith(".toml"):
            blob = subprocess.run(["git", "show", f"{commit}:{f}"], cwd=ROOT, capture_output=True, check=True)
            (folder / Path(f).name).write_bytes(blob.stdout)
    return folder


#: netCDF4/HDF5 is not safe to call from two threads at once: with ``--jobs 2`` two comparisons that
#: overlapped ended one of them in "NetCDF: HDF error" (2026-11-29), so they take turns.
_NETCDF_LOCK = threading.Lock()


def compare_runs(a: Path, b: Path) -> dict:
    """Every numeric variable of every snapshot of ``a`` against ``b`` (same index order)."""
    with _NETCDF_LOCK:
        return _compare_runs(a, b)


def _compare_runs(a: Path, b: Path) -> dict:
    import xarray as xr

    ia = json.loads((a / "snapshots" / "index.json").read_text())
    ib = json.loads((b / "snapshots" / "index.json").read_text())
    worst, differ = 0.0, set()
    if len(ia) != len(ib):
        return {"snapshots": [len(ia), len(ib)], "max_abs_difference": float("inf"), "differ": ["snapshot count"]}
    for ea, eb in zip(ia, ib):
        with (xr.open_dataset(a / "snapshots" / ea["file"], decode_times=False) as da,
              xr.open_dataset(b / "snapshots" / eb["file"], decode_times=False) as db):
            for v in da.data_vars:
                if not np.issubdtype(da[v].dtype, np.number):
                    continue
                if v not in db or da[v].shape != db[v].shape:
                    worst = float("inf")
                    differ.add(v)
                    continue
                x, y = da[v].values.astype(float), db[v].values.astype(float)
                if not np.array_equal(np.isnan(x), np.isnan(y)):
                    worst = float("inf")
                    differ.add(v)
                    continue
                d = float(np.nanmax(np.abs(x - y))) if x.size and not np.all(np.isnan(x)) else 0.0
                if d > 0:
                    worst = max(worst, d)
                    differ.add(v)
    return {"snapshots": len(ia), "max_abs_difference": worst, "differ": sorted(differ)}


def check(run: Path) -> dict:
    run = run.resolve()
    with tempfile.TemporaryDirectory(prefix=f"rerun-{run.name}-") as tmp:
        out = Path(tmp) / run.name
        cmd = rerun_command(run, out)
        env = {**os.environ, "NUMBA_NUM_THREADS": os.environ.get("NUMBA_NUM_THREADS", "1")}
        t0 = time.perf_counter()
        print(f"rerun_check: {run.name}: " + " ".join(cmd[3:]), flush=True)
        p = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
        if p.returncode != 0:
            raise SystemExit(f"rerun_check: {run.name} failed:\n{p.stderr[-2000:]}")
        res = compare_runs(run, out)
        # the code that made the run again: its own marker (the checkout may have moved on since it began)
        made = json.loads((out / "lagice_run.json").read_text())
    res.update({"run": run.name, "reproduced_by": made.get("git_commit"),
                "modified_files": made.get("git_modified_files", []),
                "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
                "numba_threads": env["NUMBA_NUM_THREADS"], "wall_s": time.perf_counter() - t0})
    (run / RECORD).write_text(json.dumps(res, indent=1) + "\n")
    same = res["max_abs_difference"] == 0
    which = "" if same else "; " + ", ".join(res["differ"])
    print(f"rerun_check: {run.name}: {'bit for bit the same' if same else 'DIFFERS'} over {res['snapshots']} "
          f"snapshots (largest difference {res['max_abs_difference']:g}{which}); {res['wall_s']:.0f} s", flush=True)
    return res


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", type=Path)
    ap.add_argument("--jobs", type=int, default=1, help="runs made at a time")
    args = ap.parse_args(argv)
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        results = list(pool.map(check, args.runs))
    if any(r["max_abs_difference"] != 0 for r in results):
        raise SystemExit(1)


if __name__ == "__main__":
    main()
