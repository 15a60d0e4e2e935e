"""Validation report: deformation statistics of Maxwell-EB and EVP against
observed sea-ice statistics (GitHub issues 7 and 12; Girard et al. 2011; Girard 2010; Dansereau et al. 2016).

Two experiments:

1. **winter basin**, 10 km, 28 days: the flagship ``examples/winter_basin_pack.toml``
   (closed; issue 12: wind climatology, size-scaled strength, neXtSIM healing, spun-up
   pack; docs/physics.md) and ``examples/winter_basin_pack_strait.toml`` (the same basin
   with an open strait), each run with Maxwell-EB (the scene's explicit solver) and with the EVP
   comparison rheology (``solver.name = "evp"``, ``rheology.law = "viscous_plastic"``, no
   healing) on the same mesh and forcing.
   The runs are ``lagice run`` subprocesses (scene builder + Simulation, two at a
   time). Deformation is Lagrangian, from the node displacements over back-to-back
   3-day windows after a 1-day spin-up (as RGPS; nodes are followed through
   remeshing by their ids), on the elements at least ``--coast-buffer-km`` from
   the coast (Girard et al. 2011 uses 150 km in the Arctic; the basin is ~3 times smaller,
   so the default is 100 km): :func:`lagice.diagnostics.window_statistics`, the
   function ``lagice diagnose RUN --window-days 3 --start-day 1`` uses. Per window: β
   of the spatial coarse-graining, ML tail exponents of the shear and |divergence|
   PDFs, localisation (area holding half of the shear), shear–|divergence| R²; the
   report gives medians and [min, max] over the windows, and the mean total
   deformation rate ⟨ε̇tot⟩ (median over the windows). ``--sensitivity`` adds
   Maxwell-EB runs of the closed basin with strength, air drag or wind scale ±50 %
   (``SENSITIVITY``, 10 km), reported apart.
2. **uniaxial compression** (Dansereau et al. 2016 §4–5, N = 40; scene builder + Simulation,
   recorded by a callback activity): the macroscopic stress of every step, the
   damage and the transport velocity averaged over blocks of N steps (an elastic
   shear wave crossing the plate width; Dansereau et al. 2016 §5.2).
   Reported: the angle between the faults and the compression axis against
   the Mohr–Coulomb prediction 45° − atan(μ)/2, the skewness of the
   macroscopic stress increments Δσ/Δt (Dansereau et al. 2016 §5.3: ≈ −6) and β at the
   macro-rupture (Dansereau et al. 2016 §5.2: 0.15 ± 0.02).

Observed ranges (``TARGETS``) come from the source papers; where a paper gives a single
value, the band around it is ours and is written next to it in the report. No
parameter is tuned per metric: the scenes run with their shipped settings.
``benchmarks/validation_discussion.md`` (hand-written summary and "where the
model misses") is placed into the report.

    python benchmarks/validate.py --sensitivity    # full: ~35 min + ~20 min sensitivity on 2 cores
    python benchmarks/validate.py --quick          # 4-day basins at 20 km, N = 20 compression (~3 min)
    python benchmarks/validate.py --analyse-only   # re-analyse the runs already in --out
    python benchmarks/validate.py --analyse-only --from-physics --evp-km 20
        # analyse the runs of benchmarks/physics_experiments.py (PHYSICS_RUNS: F10-1125, F10s-1125, E10/E20, X10-*)

Writes ``--out`` (default ``benchmarks/out/validate``: runs, logs, the full
``validation.json``), ``docs/validation.md``, ``docs/figures/validation_*.png``
and ``docs/figures/validation.json`` (the scalars).
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from scipy.stats import skew

from lagice.diagnostics import spatial_scaling, velocity_gradients, window_statistics
from lagice.diagnostics.drift import THORNDIKE_COLONY_WINTER
from lagice.diagnostics.faults import (
    angle_to_axis_deg,
    damage_mode_fault_angle_deg,
    fault_orientations,
    mohr_coulomb_fault_angle_deg,
)
from lagice.diagnostics.rgps import RGPS_CELL_M, RGPS_TRACKING_ERROR_M
from lagice.io.snapshots import read_index

ROOT = Path(__file__).resolve().parents[1]
#: basin scenes: the shipped closed basin and its variant with an open strait
SCENES = {"closed": ROOT / "examples" / "winter_basin_pack.toml",
          "strait": ROOT / "examples" / "winter_basin_pack_strait.toml"}
SCENE_LABELS = {"closed": "closed basin (winter_basin_pack)",
                "strait": "basin with an open strait (winter_basin_pack_strait)"}
DAY = 86400.0

#: observed values and the band counted as "inside"; (low, high, source, note)
TARGETS = {
    "beta_space": (0.17, 0.20, "RGPS, 3 days (Girard et al. 2011; Girard 2010 ch. 2: 0.18; Marsan et al. 2004: 0.2)",
                   "band from the issue; EB in Girard et al. 2011 gave 0.10"),
    "pdf_tail_exponent_divergence": (2.2, 2.8, "RGPS \\|divergence\\|, 10 km, 3 days: 2.5 (Girard et al. 2011)",
                                     "±0.3 is ours: the RGPS shear–divergence difference"),
    "pdf_tail_exponent_shear": (1.9, 2.5, "RGPS shear, 10 km, 3 days: 2.2 (Girard et al. 2011)", "±0.3 is ours"),
    "localisation_half_shear_area_fraction": (0.04, 0.08, "RGPS 10 km: 6 % (Girard et al. 2011; EB 4 %, VP > 20 %)",
                                              "±2 points is ours"),
    "shear_divergence_r2": (0.73, 0.93, "RGPS: 0.83 (Girard et al. 2011; EB 0.77, VP 0.58)", "±0.1 is ours"),
    "mean_total_deformation_rate_per_day": (0.01, 0.05, "RGPS winter, 10 km, 3 days: about 0.01–0.05 day⁻¹ "
                                            "(Girard 2010 ch. 2)", "band from the issue"),
}
#: β over nine box grids laid from different corners (lagice.diagnostics.grid_averaged_beta; a
#: window's β moves by 0.01-0.05 with the grid): reported next to β against β's band, not counted
#: among the six bands, so that the published count keeps its meaning
GRID_BETA = "beta_space_grid_mean"
GRID_BETA_LABEL = "β, mean over 9 box grids (not counted)"
#: β as observed β is computed (Marsan et al. 2004; Girard et al. 2011): one slope of the mean over every box of
#: every window (and of the nine grids), where the windows that deform most weigh most
#: (lagice.diagnostics.windows.pooled_window_scaling); reported next to β, not counted among the six bands
POOLED_BETA_LABEL = "β, one curve over every box of every window and grid (as observed β is computed; not counted)"
#: metrics window_statistics computes (the rate is its mean_total_s, converted to day⁻¹)
WINDOW_TARGETS = tuple(k for k in TARGETS if k != "mean_total_deformation_rate_per_day")
LABELS = {
    "beta_space": "β, ⟨ε̇tot⟩ ∝ L^−β (3-day window)",
    "pdf_tail_exponent_divergence": "PDF tail exponent, \\|divergence\\|",
    "pdf_tail_exponent_shear": "PDF tail exponent, shear",
    "localisation_half_shear_area_fraction": "area holding half of the shear",
    "shear_divergence_r2": "shear–\\|divergence\\| R²",
    "mean_total_deformation_rate_per_day": "⟨ε̇tot⟩ (day⁻¹)",
}
#: Maxwell-EB sensitivity runs (``--sensitivity``): the closed basin with one parameter
#: changed, reported apart from the headline and not used to pick any value
SENSITIVITY = {
    "base": ("closed", [], "recommended set at 10 km (the reference of the ±50 % runs)"),
    "strength-50": ("closed", ["rheology.strength_lab_pa=1.4e6"], "strength −50 % (C_lab 1.4 MPa)"),
    "strength+50": ("closed", ["rheology.strength_lab_pa=4.2e6"], "strength +50 % (C_lab 4.2 MPa)"),
    "drag-50": ("closed", ["forcing.drag.air_drag=1.0e-3"], "air drag −50 % (1.0e-3)"),
    "drag+50": ("closed", ["forcing.drag.air_drag=3.0e-3"], "air drag +50 % (3.0e-3)"),
    "wind-50": ("closed", ["forcing.wind.wind_scale=0.5"], "winds ×0.5"),
    "wind+50": ("closed", ["forcing.wind.wind_scale=1.5"], "winds ×1.5"),
}
#: resolution of the sensitivity runs [m]
SENSITIVITY_RESOLUTION_M = 10e3
#: the runs of benchmarks/physics_experiments.py that --from-physics analyses
#: (``{evp}``: E10/E20 by --evp-km). Since 2026-11-25 the flagship starts from the pack of
#: thick and thin ice (examples/winter_basin_spinup.toml; data_stubs/winter_basin_spinup.npz
#: is the same state as the experiments' spinup-H1125.npz): its Maxwell-EB runs are
#: F10-hthick-1125 / F10s-hthick-1125, EVP E10h / E10hs, the ±50 % runs X10h-*. The runs of
#: the pack shipped before (F10-1125, E10, X10-*...) keep their records in
#: docs/figures/physics_experiments.json
#: the winter wind factor of Thorndike and Colony (1982), about 0.008; the band is ours
WIND_FACTOR_BAND = THORNDIKE_COLONY_WINTER["factor"]
#: Since 2026-11-28 kept elements keep their strength at a remesh (rheology.strength_after_remesh =
#: "new", the default), and the shipped spin-up state is the one made so (spinup-H1125-newc.npz):
#: the Maxwell-EB runs are F10-hthick-newc / F10s-hthick-newc, EVP E10h-newc / E10hs-newc, the ±50 %
#: runs X10h-*-newc. A run whose folder is gone is carried from the previous report, labelled
#: (carry_sensitivity, carry_ensembles).
#: Since 2026-11-29 the basin is meshed at domain.resolution_m (20 726 elements, not the 28 048 that
#: gmsh made from the coast's pieces), and the shipped spin-up state is the one made so
#: (spinup-H1125-m10.npz): the runs are F10-hthick-m10 / F10s-hthick-m10, E10h-m10 / E10hs-m10 and
#: X10h-*-m10; the runs of the 8 km mesh keep their records (docs/figures/physics_experiments.json).
#: Since 2026-11-30 (forty-ninth session, rule NS of physics_experiments.py) the flagship turns the ocean drag by
#: neXtSIM's 25° and closes leads at neXtSIM's 0.25 m, and the shipped spin-up state is the one made so
#: (spinup-H1125-src-m10.npz): the runs are F10-hthick-src-m10 / F10s-hthick-src-m10, E10h-src-m10 /
#: E10hs-src-m10 and X10h-*-src-m10; the runs with 0° and 0.1 m are the comparison ensemble below.
PHYSICS_RUNS = {"closed_maxwell_eb": "F10-hthick-src-m10", "strait_maxwell_eb": "F10s-hthick-src-m10",
                "closed_evp": "E{evp}h-src-m10", "strait_evp": "E{evp}hs-src-m10",
                "sensitivity_base": "F10-hthick-src-m10",
                "sensitivity_strength-50": "X10h-str-50-src-m10", "sensitivity_strength+50": "X10h-str+50-src-m10",
                "sensitivity_drag-50": "X10h-drag-50-src-m10", "sensitivity_drag+50": "X10h-drag+50-src-m10",
                "sensitivity_wind-50": "X10h-wind-50-src-m10", "sensitivity_wind+50": "X10h-wind+50-src-m10"}
#: the weather ensemble of the flagship Maxwell-EB runs (--from-physics): the validation run
#: (wind seed 2026, the scene's) and the same set-up under the winds of seeds 2027-2033 for
#: the shipped pack (eight months since 2026-11-26), 2027-2029 for the pack shipped before
#: (benchmarks/physics_experiments.py ENSEMBLES). One 28-day run is one sample of the
#: weather: whether a metric is inside its band is read from how many members are inside.
#: The pack shipped before 2026-11-25 (F10-1125...) is the comparison.
PHYSICS_ENSEMBLE = {
    "closed": ["F10-hthick-src-m10"] + [f"F10-hthick-src-m10-w{y}" for y in range(2027, 2034)],
    "strait": ["F10s-hthick-src-m10"] + [f"F10s-hthick-src-m10-w{y}" for y in range(2027, 2034)],
    "closed, no ocean turning and leads closed at 0.1 m (before 2026-11-30)":
        ["F10-hthick-m10"] + [f"F10-hthick-m10-w{y}" for y in range(2027, 2034)],
    "strait, no ocean turning and leads closed at 0.1 m (before 2026-11-30)":
        ["F10s-hthick-m10"] + [f"F10s-hthick-m10-w{y}" for y in range(2027, 2034)],
    "closed, the 8 km mesh gmsh made from the coast's pieces (before 2026-11-29)":
        ["F10-hthick-newc"] + [f"F10-hthick-newc-w{y}" for y in range(2027, 2034)],
    "strait, the 8 km mesh gmsh made from the coast's pieces (before 2026-11-29)":
        ["F10s-hthick-newc"] + [f"F10s-hthick-newc-w{y}" for y in range(2027, 2034)],
    "closed, strength recomputed at every remesh (before 2026-11-28)":
        ["F10-hthick-1125"] + [f"F10-hthick-1125-w{y}" for y in range(2027, 2034)],
    "strait, strength recomputed at every remesh (before 2026-11-28)":
        ["F10s-hthick-1125"] + [f"F10s-hthick-1125-w{y}" for y in range(2027, 2034)],
    "closed, pack shipped before 2026-11-25": ["F10-1125"] + [f"F10-1125-w{y}" for y in (2027, 2028, 2029)],
    "strait, pack shipped before 2026-11-25": ["F10s-1125"] + [f"F10s-1125-w{y}" for y in (2027, 2028, 2029)]}
RHEOLOGIES = {
    "maxwell_eb": {"label": "Maxwell-EB", "overrides": []},
    "evp": {"label": "EVP (mEVP, Hibler ellipse)",
            "overrides": ["solver.name=evp", "rheology.law=viscous_plastic", "healing.law=none", "solver.dt=30min",
                          "solver.substeps=300"]},
}


# -- winter basin ---------------------------------------------------------------------
def _run_command(scene_path: Path, out_dir: Path, days: float, resolution_m: float | None, overrides):
    sets = [f"run.duration={days:g}d", "output.every=1d", *overrides]
    if resolution_m:
        sets.append(f"domain.resolution_m={resolution_m:g}")
    cmd = [sys.executable, "-m", "lagice.cli", "run", str(scene_path), "--out", str(out_dir)]
    for a in sets:
        cmd += ["--set", a]
    return cmd


def basin_commands(out: Path, days: float, resolution_m: float | None):
    """``lagice run`` command lines {(scene, rheology): argv} of the basin runs."""
    return {(scene, key): _run_command(path, out / f"{scene}_{key}", days, resolution_m, spec["overrides"])
            for scene, path in SCENES.items() for key, spec in RHEOLOGIES.items()}


def sensitivity_commands(out: Path, days: float, resolution_m: float | None):
    return {f"sensitivity_{name}": _run_command(SCENES[scene], out / f"sensitivity_{name}", days,
                                                resolution_m or SENSITIVITY_RESOLUTION_M, sets)
            for name, (scene, sets, _) in SENSITIVITY.items()}


def analyse_run(run: Path, days: float, buffer_m: float, window_days: float = 3.0, spinup_days: float = 1.0):
    """Window statistics of one basin run (:func:`lagice.diagnostics.window_statistics`:
    median, min and max over the windows) and the run's wall time, remeshing, outflow
    and mean speeds."""
    ws = window_statistics(run, window_days=window_days, coast_buffer_km=buffer_m / 1e3, start_day=spinup_days,
                           end_day=days, metrics=WINDOW_TARGETS + (GRID_BETA, "mean_total_s"), keep_arrays=True,
                           rgps_tracking_error_m=RGPS_TRACKING_ERROR_M)
    for part in ("median", "min", "max", "median_all_elements", "median_rgps", "median_rgps_cells"):
        v = ws[part].pop("mean_total_s")
        ws[part]["mean_total_deformation_rate_per_day"] = None if v is None else v * DAY
    cfg = _marker(run)
    for s in ws["skipped"]:
        print(f"validate: {run.name}: {s['reason']}", flush=True)
    idx = read_index(run)
    summary = json.loads((run / "summary.json").read_text()) if (run / "summary.json").exists() else {}
    return {"windows": ws["windows"], "skipped_windows": ws["skipped"],
            "mesh_epochs": sorted({e["mesh_epoch"] for e in idx}),
            "wall_s": summary.get("wall_s"), "remesh_events": idx[-1]["mesh_epoch"] - idx[0]["mesh_epoch"],
            "outflow_m3": summary.get("volume_budget", {}).get("outflow_m3"),
            "mean_speed_m_s": mean_speeds(run),
            "median": ws["median"], "min": ws["min"], "max": ws["max"],
            "median_all_elements": ws["median_all_elements"], "pooled": ws["pooled"],
            "mean_total_deformation_rate_per_day": ws["median"]["mean_total_deformation_rate_per_day"],
            "rgps_view": {"tracking_error_m": ws["rgps_tracking_error_m"], "cell_m": RGPS_CELL_M,
                          "median": ws["median_rgps"], "median_cells": ws["median_rgps_cells"],
                          "pooled": ws["pooled_rgps"], "pooled_cells": ws["pooled_rgps_cells"]},
            "resolution_m": run_resolution_m(run), "run_command": cfg.get("command"), "run_dir": str(run),
            "drift_km": drift_km(run, days), "drift_response": drift_response(run), **reuse_notice(run)}


def drift_response(run: Path) -> dict | None:
    """The drifters' wind factor against the geostrophic wind (docs/diagnostics.md §13, Thorndike
    and Colony 1982); None for a run without drifters or without the climatology wind (whose
    geostrophic wind is not known, so the observed factor does not apply)."""
    from lagice.diagnostics.drift import run_drift_response
    from lagice.errors import ConfigError

    try:
        r = run_drift_response(run)
    except ConfigError as e:
        print(f"validate: {run.name}: no drift response ({e})", flush=True)
        return None
    if r["wind"] != "geostrophic":
        print(f"validate: {run.name}: no drift response (the {r['wind']} wind, not the climatology's)", flush=True)
        return None
    return {"wind_factor": r["fit"]["factor"], "turning_deg": r["fit"]["angle_deg"], "r2": r["fit"]["r2"],
            "wind_factor_5_95_over_drifters": r["factor_5_95_over_drifters"], "drifter_days": r["fit"]["n"],
            "mean_ice_speed_m_s": r["fit"]["mean_ice_speed_m_s"]}


def run_resolution_m(run: Path):
    """The ``domain.resolution_m`` a run used (from its newest checkpoint's config; None if unknown)."""
    ck = sorted((run / "checkpoints").glob("*.npz")) if (run / "checkpoints").exists() else []
    if not ck:
        return None
    from lagice.simulation import load_checkpoint

    return load_checkpoint(ck[-1])[2]["config"]["domain"]["resolution_m"]


def drift_km(run: Path, days: float) -> dict:
    """Mean and largest displacement [km] over the run of the nodes present at its start
    and its end (followed through remeshing by their ids)."""
    from lagice.io.snapshots import load_window

    w = load_window(run, 0.0, days * DAY)
    d = np.hypot(*(w["xy1"] - w["xy0"]).T) / 1e3
    moving = d > 0
    return {"mean": float(d[moving].mean()) if moving.any() else 0.0, "max": float(d.max()) if d.size else 0.0}


def run_dir(out: Path, name: str, physics: Path | None = None, evp_km: float = 10.0) -> Path:
    """The folder of run ``name`` (``closed_maxwell_eb``, ``sensitivity_wind+50``...): in
    ``out``, or with ``physics`` the run of benchmarks/physics_experiments.py (PHYSICS_RUNS)."""
    if physics is None:
        return out / name
    return physics / PHYSICS_RUNS[name].format(evp=f"{evp_km:g}")


def analyse_basin(out: Path, scene: str, days: float, buffer_m: float, physics=None, evp_km=10.0):
    return {key: analyse_run(run_dir(out, f"{scene}_{key}", physics, evp_km), days, buffer_m) for key in RHEOLOGIES}


def git_commit() -> dict:
    """HEAD of the repository and whether its code differs from it (tracked files outside
    docs/, which this script writes)."""
    def git(*a):
        return subprocess.run(["git", *a], cwd=ROOT, capture_output=True, text=True, check=False).stdout.strip()

    changed = git("status", "--porcelain", "--untracked-files=no", "--", ".", ":(exclude)docs")
    return {"commit": git("rev-parse", "HEAD"), "dirty": bool(changed)}


#: the folders whose code decides a run's result (the model); a reused run made by another commit
#: is the same run as one made now only if none of them changed in between
MODEL_CODE = ("lagice", "forcing", "thermo")
#: folders of MODEL_CODE that only analyse a finished run's snapshots: no module of a run's time
#: stepping imports them (tests/test_bench_helpers.py runs ``lagice run`` and checks), and the
#: statistics are recomputed from the snapshots at every analysis, so a change there does not make
#: a reused run differ from one made now
ANALYSIS_CODE = ("lagice/diagnostics",)


def run_made_by(run: Path) -> str | None:
    """The commit of the code that made ``run``: the run folder's marker (``lagice_run.json``,
    ``git_commit``, since 2026-11-29), else the ``lagice_git_commit`` attribute of its first
    snapshot (every snapshot carries it); None where neither is known. A commit ending in
    ``-dirty`` was made from a modified work tree (the marker names the files since 2026-11-29)."""
    import xarray as xr

    c = _marker(run).get("git_commit")
    if c:
        return c
    idx = run / "snapshots" / "index.json"
    if not idx.exists():
        return None
    first = json.loads(idx.read_text())[0]["file"]
    with xr.open_dataset(run / "snapshots" / first, decode_times=False) as ds:
        return ds.attrs.get("lagice_git_commit")


def _marker(run: Path) -> dict:
    m = run / "lagice_run.json"
    return json.loads(m.read_text()) if m.exists() else {}


def model_code_changes(commit: str | None, modified=None) -> list | None:
    """The files of the model's code (:data:`MODEL_CODE`) that differ between the code that made a
    run and the work tree now (committed or not): [] where none does. For a run made from a
    modified work tree (``commit`` ending in ``-dirty``) the files it had modified are counted as
    changed, when ``modified`` names them; None where it cannot be told (an unknown commit, or a
    modified work tree whose files were not recorded, as before 2026-11-29)."""
    if not commit:
        return None
    base, dirty = commit.removesuffix("-dirty"), commit.endswith("-dirty")
    if dirty and modified is None:
        return None
    p = subprocess.run(["git", "diff", "--name-only", base, "--", *MODEL_CODE,
                        *(f":(exclude){a}" for a in ANALYSIS_CODE)], cwd=ROOT, capture_output=True,
                       text=True, check=False)
    if p.returncode != 0:
        return None
    own = [f for f in (modified or ()) if f.split("/")[0] in MODEL_CODE
           and not any(f.startswith(a + "/") for a in ANALYSIS_CODE)]
    return sorted(set(p.stdout.split()) | set(own))


def reuse_notice(run: Path) -> dict:
    """Who made a finished run that is about to be read, and which model files changed since
    (printed when any did, or when it cannot be told): ``{"made_by": ..., "model_code_changed":
    [files] or None}``. Whether those changes matter is for the reader: the files are named."""
    made = by = run_made_by(run)
    changed = model_code_changes(by, _marker(run).get("git_modified_files"))
    rep = run / "reproduced.json"   # benchmarks/rerun_check.py: made again, compared bit for bit
    rep = json.loads(rep.read_text()) if rep.exists() else None
    if rep is not None and rep.get("max_abs_difference") == 0:
        again = model_code_changes(rep.get("reproduced_by"), rep.get("modified_files"))
        # the reproduction names the code when it is closer to this commit's, or as close and made from a
        # clean checkout (the newer record, and no modified work tree to explain)
        clean = not str(rep.get("reproduced_by")).endswith("-dirty")
        if again is not None and (changed is None or len(again) < len(changed)
                                  or (len(again) == len(changed) and clean)):
            print(f"validate: {run.name}: made by {str(by)[:10]}, reproduced bit for bit by "
                  f"{str(rep['reproduced_by'])[:10]} on {rep.get('date')}", flush=True)
            made, by, changed = by, rep["reproduced_by"], again
    if changed != []:
        why = (f"the model code differs in {', '.join(changed)}" if changed else
               "made from a modified work tree whose files were not recorded" if str(by).endswith("-dirty") else
               "the code that made it is not known")
        print(f"validate: NOTE: reading {run.name}, made by commit {str(by)[:10]}: {why}; benchmarks/rerun_check.py "
              f"makes it again and compares, or delete the folder to replace it", flush=True)
    # made_by: the code that made the run, or the code that made it again bit for bit; then made_first_by
    # names the original maker
    return {"made_by": by, "model_code_changed": changed, **({"made_first_by": made} if made != by else {})}


def basin_imprint(run: Path, days: float, buffer_m: float) -> dict:
    """Mesh-imprint metric (lagice.diagnostics.imprint, docs/physics.md §3) of a basin run:
    the fracture directions of the top decile of the shear rate of the last 3-day window
    (Lagrangian, elements away from the coast) against the directions of the mesh at the
    window start; and of the damage ≥ 0.9 of the last snapshot."""
    from lagice.diagnostics.imprint import imprint_summary
    from lagice.io.snapshots import load_window

    w = load_window(run, (days - 3.0) * DAY, days * DAY)
    from lagice.diagnostics import lagrangian_velocity_gradients
    from lagice.diagnostics.faults import interior_triangles

    rates = lagrangian_velocity_gradients(w["xy0"], w["xy1"], w["triangles"], w["dt_s"])
    keep = interior_triangles(w["xy0"], w["triangles"], buffer_m)
    shear = np.where(keep, rates.shear_s, 0.0)
    out = {"shear_top_decile_last_window": _imprint_public(imprint_summary(w["xy0"], w["triangles"], shear,
                                                                           quantile=0.9))}
    import xarray as xr

    idx = read_index(run)
    with xr.open_dataset(run / "snapshots" / idx[-1]["file"], decode_times=False) as ds:
        nodes = np.column_stack([ds["mesh_node_x"].values, ds["mesh_node_y"].values])
        tri = ds["mesh_face_nodes"].values.astype(np.int64)
        d = ds["damage"].values[0].copy()
    out["damage_ge_0.9_last_snapshot"] = _imprint_public(imprint_summary(nodes, tri, d, threshold=0.9))
    out["damaged_fraction_ge_0.9"] = float(np.mean(d >= 0.9))
    return out


def _imprint_public(s: dict) -> dict:
    return {k: v for k, v in s.items() if not k.startswith("_")}


def mean_speeds(run_dir: Path) -> list:
    """Area-unweighted mean node speed (m s-1) of each daily snapshot."""
    import xarray as xr
    d = run_dir / "snapshots"
    out = []
    for e in read_index(run_dir):
        with xr.open_dataset(d / e["file"], decode_times=False) as ds:
            out.append(float(np.mean(np.hypot(ds["velocity_x"].values[0], ds["velocity_y"].values[0]))))
    return out


# -- uniaxial compression -------------------------------------------------------------
class BlockRecorder:
    """Callback after every step of the compression run: the macroscopic stress and the
    mean damage of the step, the transport velocity averaged over blocks of ``block``
    steps and the damage at the end of each block; a progress line every 15 s of wall time."""

    def __init__(self, sim, n_steps: int, block: int):
        from lagice.scenes.hooks.compression import macro_stress

        m = sim.model
        self.macro_stress, self.block = macro_stress, block
        self.area = m.mesh.areas()  # fixed mesh
        self.stress = np.empty(n_steps)
        self.mean_damage = np.empty(n_steps)
        self.vel_mean = np.zeros((n_steps // block, m.mesh.n_nodes, 2))
        self.damage_end = np.empty((n_steps // block, m.mesh.n_elements), np.float32)
        self.t0 = time.perf_counter()
        sim.add_callback(self, every="1 steps", name="blocks")
        sim.add_callback(self.progress, every="wall 15s", name="compression_progress")

    def __call__(self, sim):
        m = sim.model
        k = m.clock.iteration - 1
        self.stress[k] = -self.macro_stress(m)  # compressive positive [Pa]
        self.mean_damage[k] = np.average(m.state.damage, weights=self.area)
        b = k // self.block
        self.vel_mean[b] += m.transport_velocity
        if (k + 1) % self.block == 0:
            self.vel_mean[b] /= self.block
            self.damage_end[b] = m.state.damage

    def progress(self, sim):
        m = sim.model
        k = m.clock.iteration - 1
        print(f"  compression step {k + 1}/{sim.n_steps}  stress {self.stress[k] / 1e3:.1f} kPa  mean damage "
              f"{self.mean_damage[k]:.4f}  [{time.perf_counter() - self.t0:.0f} s]", flush=True)


def run_compression(out: Path, n_across: int, max_strain: float, seed: int = 0, overrides=None) -> Path:
    """Run the ``uniaxial_compression`` scene with N elements across the plate (scene builder
    + Simulation; ``overrides``: further scene keys, e.g. ``{"domain.jitter": 0.3}``) and keep
    the per-step macro stress and the block means."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from scene_runs import scene_config, scene_simulation, timed_run

    cfg = scene_config("uniaxial_compression")
    width, length = cfg["domain"]["width_m"], cfg["domain"]["height_m"]
    push = -float((overrides or {}).get("boundary.top.v", cfg["boundary"]["top"]["v"]))  # a variant may change it
    dx = width / n_across
    dt = dx / cfg["rheology"]["shear_wave_speed"]  # td
    block = n_across  # elastic shear wave across the width: (L/2)/(cs Δt) = N steps
    n_steps = (int(np.ceil(max_strain * length / push / dt)) // block) * block
    sim = scene_simulation("uniaxial_compression", {
        "domain.resolution_m": dx, "solver.dt": "td", "run.duration": n_steps * dt, "run.seed": seed,
        "output.timeseries": None, **(overrides or {})})
    rec = BlockRecorder(sim, n_steps, block)
    wall = timed_run(sim)
    if not sim.finished:  # stopped by a signal: a partial record must not pass for a finished run
        raise SystemExit(f"validate: compression N = {n_across} stopped at step {sim.model.clock.iteration} of "
                         f"{n_steps} ({sim.stop_reason}); nothing saved")
    m = sim.model
    path = out / f"compression_N{n_across}.npz"
    np.savez_compressed(path, stress_pa=rec.stress, mean_damage=rec.mean_damage, velocity_block_mean=rec.vel_mean,
                        damage_block_end=rec.damage_end, nodes=m.mesh.nodes, triangles=m.mesh.triangles,
                        dt_s=sim.dt, block_steps=block, n_across=n_across, length_m=length,
                        width_m=width, push_speed_m_s=push, friction=m.rheology.params.friction,
                        poisson=m.rheology.params.poisson,
                        stress_correction=str(m.rheology.params.stress_correction), wall_s=wall, seed=seed,
                        # the implicit solver's damage fixed point (solver.damage_iterations): passes over
                        # the run and steps that used every pass without converging (-1: not that solver)
                        damage_passes_total=getattr(m.stepper, "damage_passes_total", -1),
                        damage_unconverged_steps=getattr(m.stepper, "damage_unconverged_steps", -1))
    return path


def run_finished(run: Path) -> bool:
    """A run directory whose summary says the run reached its stop time (a run stopped by
    a signal writes a summary too, with ``finished = false``)."""
    summary = run / "summary.json"
    return summary.exists() and bool(json.loads(summary.read_text()).get("finished", False))


#: smallest stress drop between blocks, as a fraction of the peak compressive stress, that counts
#: as a macro-rupture (a calibration of this diagnostic, 2026-11-26). The plates that fail drop
#: 0.3-4 % of their peak in one block (origin path 3.8 of 117 kPa, the mean-stress path with
#: theta = 1 0.4 of 135 kPa); the plate that yields without failing (associated correction) wobbles
#: by 0.008 of 142 kPa (6e-5), which "any positive drop" used to call a rupture. 1e-3 lies a factor
#: 3 below the smallest failure and 17 above the wobble.
RUPTURE_MIN_DROP = 1e-3
#: the post-peak phase of the compression analysis: from the block of the peak stress until the
#: strain has grown by this fraction of the peak strain (2026-11-27; a choice of the diagnostic,
#: long enough to hold the first softening of a plate that does not drop at once)
POST_PEAK_STRAIN_FRACTION = 0.2


def load_npz(path: Path) -> dict:
    """Every array of an ``.npz`` read once. Indexing a ``numpy.lib.npyio.NpzFile`` reads and
    decompresses the whole array again at each access: ``z["velocity_block_mean"][b]`` in a loop
    over blocks read the 270 MB array of an N = 80 compression run 150 times (5-13 minutes on the 2-vCPU VM)."""
    with np.load(path) as z:
        return {k: z[k] for k in z.files}


def analyse_compression(path: Path) -> dict:
    z = load_npz(path)
    stress, dt, block = z["stress_pa"], float(z["dt_s"]), int(z["block_steps"])
    nodes, tri = z["nodes"], z["triangles"]
    n_blocks = z["velocity_block_mean"].shape[0]
    # block-mean stress and macro-rupture: the block with the largest stress drop
    s_block = stress[: n_blocks * block].reshape(n_blocks, block)
    s_end = s_block[:, -1]
    drop = np.concatenate([[0.0], s_end[:-1] - s_end[1:]])  # > 0 where the compressive stress fell
    k_rup = int(np.argmax(drop))
    k_peak = int(np.argmax(stress))
    # β from the block-mean velocity (Eulerian: fixed mesh), on ~150 blocks spread over the
    # run and on the rupture block and the next one
    betas, scale_curves = np.full(n_blocks, np.nan), {}
    chosen = set(np.linspace(0, n_blocks - 1, min(n_blocks, 150)).astype(int)) | {k_rup, min(k_rup + 1, n_blocks - 1)}
    for b in sorted(chosen):
        rates = velocity_gradients(nodes, tri, z["velocity_block_mean"][b])
        if not np.any(rates.total_s > 0):
            continue
        sp = spatial_scaling(rates)
        betas[b] = sp.fit.exponent
        if b in (k_rup, min(k_rup + 1, n_blocks - 1)):
            scale_curves[b] = (np.asarray(sp.scale_m), np.asarray(sp.mean_total_s), sp.fit)
    # faults: active ones (block-mean ε̇tot · area over the rupture block) and the damage the rupture made
    e1, e2 = nodes[tri[:, 1]] - nodes[tri[:, 0]], nodes[tri[:, 2]] - nodes[tri[:, 0]]
    area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    centroids = nodes[tri].mean(axis=1)
    dx = float(z["width_m"]) / int(z["n_across"])
    r_rate = velocity_gradients(nodes, tri, z["velocity_block_mean"][k_rup])
    f_rate = fault_orientations(centroids, r_rate.total_s * area, 2 * dx)
    d_before = z["damage_block_end"][k_rup - 1] if k_rup > 0 else np.zeros(tri.shape[0])
    d_gain = np.clip(z["damage_block_end"][k_rup].astype(float) - d_before, 0.0, None)  # healing lowers d
    f_dmg = fault_orientations(centroids, d_gain * area, 2 * dx) if d_gain.sum() > 0 else None
    # no macroscopic stress drop (at least RUPTURE_MIN_DROP of the peak), or a drop that made no
    # damage (an elastic wave: the explicit stepper rings before the plate damages at all): the
    # plate never failed, and the "faults" of the rate field would be its elastic or yielding
    # pattern; no fault angles then
    ruptured = bool(drop[k_rup] >= RUPTURE_MIN_DROP * abs(stress[k_peak]) and d_gain.sum() > 0.0)
    # the post-peak phase: the blocks from the peak's block until the strain has grown by a fifth
    # of the peak strain. Where the plate softens gradually (no one large drop right after the
    # peak), the block with the largest drop can be a small event late in the plateau; the
    # faults active while the plate first softens are then those of this phase.
    k_peak_block = min(k_peak // block, n_blocks - 1)
    k_post_end = min(n_blocks, k_peak_block + max(1, int(POST_PEAK_STRAIN_FRACTION * (k_peak_block + 1))))
    post_rate = np.zeros(tri.shape[0])
    for b in range(k_peak_block, k_post_end):
        post_rate += velocity_gradients(nodes, tri, z["velocity_block_mean"][b]).total_s
    f_post = fault_orientations(centroids, post_rate * area, 2 * dx) if post_rate.sum() > 0 else None
    d_post = np.clip(z["damage_block_end"][k_post_end - 1].astype(float)
                     - (z["damage_block_end"][k_peak_block - 1] if k_peak_block > 0 else 0.0), 0.0, None)
    f_post_dmg = fault_orientations(centroids, d_post * area, 2 * dx) if d_post.sum() > 0 else None
    post_peak = {"blocks": [k_peak_block, k_post_end],
                 "stress_drop_kpa": float((stress[k_peak] - s_end[k_post_end - 1]) / 1e3),
                 "fault_angles_rate_deg": None if f_post is None else angle_to_axis_deg(f_post.angles_deg).tolist(),
                 "fault_directions_rate_deg": None if f_post is None else f_post.angles_deg.tolist(),
                 "fault_angles_damage_deg": None if f_post_dmg is None
                 else angle_to_axis_deg(f_post_dmg.angles_deg).tolist(),
                 "fault_directions_damage_deg": None if f_post_dmg is None else f_post_dmg.angles_deg.tolist()}
    # intermittency: skewness of the macroscopic stress increments
    inc = np.diff(stress) / dt
    mc = mohr_coulomb_fault_angle_deg(float(z["friction"]))
    # the most unstable damage band (origin correction only; records before 2026-11-27 lack ν)
    origin = "poisson" in z and str(z["stress_correction"]) == "origin"
    mode = damage_mode_fault_angle_deg(float(z["friction"]), poisson_ratio=float(z["poisson"])) if origin else None
    return {
        "n_across": int(z["n_across"]), "steps": int(stress.size), "dt_s": dt, "block_steps": block,
        "wall_s": float(z["wall_s"]), "peak_stress_kpa": float(stress[k_peak] / 1e3),
        "peak_strain": float((k_peak + 1) * dt * float(z["push_speed_m_s"]) / float(z["length_m"])),
        "rupture_block": k_rup, "rupture_time_s": float((k_rup + 1) * block * dt),
        "rupture_drop_kpa": float(drop[k_rup] / 1e3), "ruptured": ruptured,
        "rupture_min_drop_fraction": RUPTURE_MIN_DROP,
        "rupture_blocks_after_peak": int(k_rup - k_peak_block), "post_peak": post_peak,
        "mohr_coulomb_angle_deg": mc, "damage_mode_angle_deg": mode,
        "fault_angles_rate_deg": angle_to_axis_deg(f_rate.angles_deg).tolist() if ruptured else None,
        "fault_directions_rate_deg": f_rate.angles_deg.tolist(), "fault_scores_rate": f_rate.scores.tolist(),
        "fault_angles_damage_deg": None if f_dmg is None else angle_to_axis_deg(f_dmg.angles_deg).tolist(),
        "fault_directions_damage_deg": None if f_dmg is None else f_dmg.angles_deg.tolist(),
        "skewness_increments_all": float(skew(inc)),
        "skewness_increments_from_peak": float(skew(inc[k_peak:])) if inc.size - k_peak > 10 else None,
        "beta_after_rupture": float(betas[min(k_rup + 1, n_blocks - 1)]),
        "beta_rupture_block": float(betas[k_rup]),
        "beta_blocks": betas.tolist(),
        "_plot": {"stress": stress, "betas": betas, "scale_curves": scale_curves, "centroids": centroids,
                  "tri": tri, "nodes": nodes, "rate": r_rate.total_s, "d_gain": d_gain, "f_rate": f_rate,
                  "f_dmg": f_dmg, "post_peak_rate": post_rate},
    }


# -- figures and report ---------------------------------------------------------------
def _fig(w, h):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    fig = Figure(figsize=(w, h))
    FigureCanvasAgg(fig)
    return fig


def figures_basin(basin: dict, fig_dir: Path, scene: str) -> list[Path]:
    colours = {"maxwell_eb": "tab:red", "evp": "tab:blue"}
    paths = []
    # scaling and PDFs of the last window
    fig = _fig(15, 4.6)
    ax1, ax2, ax3 = fig.subplots(1, 3)
    for key, r in basin.items():
        w = r["windows"][-1]["interior"]
        sc = w["scaling_space"]
        L = np.array(sc["scale_m"]) / 1e3
        m = np.array(sc["mean_total_s"]) * DAY
        ax1.loglog(L, m, "o-", color=colours[key], label=f"{RHEOLOGIES[key]['label']}: β = {w['beta_space']:.2f}")
        for ax, pdf_key, tail_key in ((ax2, "pdf_shear", "shear"), (ax3, "pdf_divergence", "divergence")):
            p = w[pdf_key]
            x, y = np.array(p["bin_centres_s"]) * DAY, np.array(p["density_s"])
            ok = y > 0
            if ok.any():
                ax.loglog(x[ok], y[ok] / y[ok].max(), ".-", color=colours[key],
                          label=f"{RHEOLOGIES[key]['label']}: tail {w[f'pdf_tail_exponent_{tail_key}']:.2f}")
            x0 = w[f"pdf_tail_fit_range_{tail_key}_s"][0]
            if x0:
                ax.axvline(x0 * DAY, color=colours[key], lw=0.6, ls=":")
    Lr = np.geomspace(10, 500, 10)
    ax1.loglog(Lr, 0.05 * (Lr / 10) ** -0.18, "k--", label="RGPS slope β = 0.18 (Girard 2010)")
    ax1.set(xlabel="scale L (km)", ylabel="⟨ε̇tot⟩ (day$^{-1}$)", title="spatial scaling, last 3-day window")
    ax2.set(xlabel="shear rate (day$^{-1}$)", ylabel="PDF / max", title="shear (10 km, 3 days; dotted: tail start)")
    ax3.set(xlabel="|divergence| rate (day$^{-1}$)", ylabel="PDF / max", title="|divergence| (10 km, 3 days)")
    for ax, slope in ((ax2, 2.2), (ax3, 2.5)):
        xs = np.geomspace(0.02, 0.3, 5)
        ax.loglog(xs, 0.3 * (xs / 0.02) ** -slope, "k--", label=f"RGPS tail exponent {slope}")
    from matplotlib.ticker import NullFormatter
    for ax in (ax1, ax2, ax3):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        ax.xaxis.set_minor_formatter(NullFormatter())
    fig.suptitle(SCENE_LABELS[scene], fontsize=10)
    fig.tight_layout()
    p = fig_dir / f"validation_{scene}_scaling_pdfs.png"
    fig.savefig(p, dpi=110)
    paths.append(p)
    # shear maps of the last window
    fig = _fig(12, 5.4)
    axes = fig.subplots(1, 2)
    for ax, (key, r) in zip(axes, basin.items()):
        xy, tri, shear = r["windows"][-1]["interior"]["_map"]
        v = np.log10(np.maximum(shear * DAY, 1e-4))
        tp = ax.tripcolor(xy[:, 0] / 1e3, xy[:, 1] / 1e3, tri, facecolors=v, cmap="magma", vmin=-4, vmax=0)
        w = r["windows"][-1]
        ax.set_title(f"{RHEOLOGIES[key]['label']}: log10 shear (day$^{{-1}}$), days "
                     f"{w['start_day']:.0f}–{w['end_day']:.0f}", fontsize=9)
        ax.set_aspect("equal")
        ax.set_xlabel("x (km)")
        fig.colorbar(tp, ax=ax, shrink=0.8)
    fig.suptitle(f"{SCENE_LABELS[scene]}: elements ≥ the coast buffer", fontsize=10)
    fig.tight_layout()
    p = fig_dir / f"validation_{scene}_shear_maps.png"
    fig.savefig(p, dpi=110)
    paths.append(p)
    # metrics per window against the observed bands, and the mean speed
    fig = _fig(18, 3.4)
    axes = fig.subplots(1, len(TARGETS) + 1)
    for ax, (k, (lo, hi, _, _)) in zip(axes, TARGETS.items()):
        ax.axhspan(lo, hi, color="0.85", label="observed band")
        for key, r in basin.items():
            days = [w["end_day"] for w in r["windows"]]
            vals = [w["interior"]["mean_total_s"] * DAY if k == "mean_total_deformation_rate_per_day"
                    else w["interior"][k] for w in r["windows"]]
            ax.plot(days, vals, "o-", color=colours[key], label=RHEOLOGIES[key]["label"])
        ax.set_title(LABELS[k].replace("\\|", "|"), fontsize=8)
        ax.set_xlabel("window end (day)")
        ax.grid(True, alpha=0.3)
    ax = axes[-1]
    for key, r in basin.items():
        ax.semilogy(np.arange(len(r["mean_speed_m_s"])), np.maximum(r["mean_speed_m_s"], 1e-6), "o-",
                    color=colours[key])
    ax.set_title("mean ice speed (m s$^{-1}$)", fontsize=8)
    ax.set_xlabel("day")
    ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle(SCENE_LABELS[scene], fontsize=10)
    fig.tight_layout()
    p = fig_dir / f"validation_{scene}_windows.png"
    fig.savefig(p, dpi=110)
    paths.append(p)
    return paths


def figure_ensemble_bands(ens: dict, basin: dict, fig_dir: Path) -> Path | None:
    """Every month of each weather ensemble analysed in this report (not those carried from an older
    report) against the observed bands, one panel per statistic: a dot per month (ringed: the validation
    month), a bar at the median over the months, the band shaded, and the EVP month of the same basin
    (×); the last panel is β as observed β is computed (one slope over every box of every window of the
    months, with its 90 % interval from resampling them). For the reader who looks rather than reads
    the tables of the section. None if no ensemble was analysed."""
    groups = [(g, e) for g, e in ens.items() if "carried_from" not in e]
    if not groups:
        return None
    keys = list(TARGETS) + ["wind_factor"]
    fig = _fig(4.0 * 4, 3.7 * 2)
    axes = fig.subplots(2, 4).ravel()
    rng = np.random.default_rng(0)   # the dots' horizontal jitter only

    def wind_factor(r):
        return (r.get("drift_response") or {}).get("wind_factor")

    def tick(g):   # "closed" / "strait"; an older set-up's group is faded, marked and named below the panels
        scene, _, note = g.partition(", ")
        return scene if not note else f"{scene}\n(older set)"

    def style(g):
        return {"color": "tab:red" if g.startswith("closed") else "tab:orange", "alpha": 1.0 if "," not in g else 0.45}

    for ax, k in zip(axes, keys):
        lo, hi = WIND_FACTOR_BAND if k == "wind_factor" else TARGETS[k][:2]
        ax.axhspan(lo, hi, color="0.85", zorder=0, label="observed band")
        for x, (g, e) in enumerate(groups):
            names = list(e["members"])
            vals = np.array([np.nan if v is None else v for v in
                             (wind_factor(e["members"][n]) if k == "wind_factor" else e["members"][n]["median"][k]
                              for n in names)], dtype=np.float64)
            st = style(g)
            xs = x + rng.uniform(-0.18, 0.18, vals.size)
            ax.plot(xs, vals, "o", ms=4, **st, label="a month (Maxwell-EB)" if x == 0 else None)
            ax.plot(xs[:1], vals[:1], "o", ms=9, mfc="none", color="k", alpha=st["alpha"],
                    label="validation month" if x == 0 else None)
            if np.isfinite(vals).any():
                med = float(np.nanmedian(vals))
                ax.plot([x - 0.3, x + 0.3], [med, med], "-", lw=2.5, **st,
                        label="median of the months" if x == 0 else None)
            evp = (basin.get(g) or {}).get("evp")
            if evp is not None:
                v = wind_factor(evp) if k == "wind_factor" else evp["median"].get(k)
                if v is not None:
                    ax.plot([x], [v], "x", ms=8, mew=2, color="tab:blue",
                            label="EVP, validation month" if x == 0 else None)
        title = ("wind factor |A| (Thorndike and Colony 1982, winter)" if k == "wind_factor"
                 else LABELS[k].replace("\\|", "|"))
        ax.set_title(title, fontsize=8)
        if k in ("mean_total_deformation_rate_per_day", "wind_factor"):
            ax.set_yscale("log")
    ax = axes[len(keys)]
    lo, hi = TARGETS["beta_space"][:2]
    ax.axhspan(lo, hi, color="0.85", zorder=0)
    for x, (g, e) in enumerate(groups):
        pc = e.get("pooled_curve") or {}
        b, iv = pc.get("beta_space_grids"), pc.get("beta_space_grids_interval_90")
        if b is not None:
            err = None if iv is None else [[b - iv[0]], [iv[1] - b]]
            ax.errorbar([x], [b], yerr=err, fmt="s", ms=6, capsize=4, **style(g))
    ax.set_ylim(0, max(0.22, ax.get_ylim()[1]))
    ax.set_title("β as observed β is computed: one slope over\nevery box of every window (90 % interval)",
                 fontsize=8)
    for ax in axes[:len(keys) + 1]:
        ax.set_xticks(range(len(groups)))
        ax.set_xticklabels([tick(g) for g, _ in groups], fontsize=7)
        ax.set_xlim(-0.6, len(groups) - 0.4)
        ax.grid(True, axis="y", alpha=0.3)
    axes[0].legend(fontsize=6, loc="upper right")
    fig.suptitle("Weather ensembles of the flagship (10 km, 28 days): each month's medians of its 3-day windows "
                 "against the observed bands (grey)", fontsize=10)
    older = sorted({g.partition(", ")[2] for g, _ in groups if ", " in g})
    if older:
        fig.text(0.5, 0.005, "older set (faded): " + "; ".join(older), ha="center", fontsize=8)
    fig.tight_layout(rect=(0, 0.025 if older else 0, 1, 1))
    p = fig_dir / "validation_ensemble_bands.png"
    fig.savefig(p, dpi=110)
    return p


def figure_compression(c: dict, fig_dir: Path) -> Path:
    d = c["_plot"]
    fig = _fig(15, 5.2)
    ax1, ax2, ax3 = fig.subplots(1, 3)
    t_h = np.arange(1, d["stress"].size + 1) * c["dt_s"] / 3600
    ax1.plot(t_h, d["stress"] / 1e3, "k-", lw=0.8)
    ax1.set(xlabel="time (h)", ylabel="macroscopic compressive stress (kPa)",
            title=f"skewness of Δσ/Δt: {c['skewness_increments_all']:.1f} (all), "
                  f"{c['skewness_increments_from_peak']:.1f} (from the peak on)")
    ax1.axvline(c["rupture_time_s"] / 3600, color="tab:red", lw=0.8, ls="--", label="macro-rupture block")
    axb = ax1.twinx()
    tb = (np.arange(d["betas"].size) + 1) * c["block_steps"] * c["dt_s"] / 3600
    ok = np.isfinite(d["betas"])
    axb.plot(tb[ok], d["betas"][ok], ".", color="tab:blue", ms=3)
    axb.set_ylabel("β of the block (blue)")
    ax1.legend(fontsize=8, loc="lower right")
    for b, (L, m, fit) in d["scale_curves"].items():
        ax2.loglog(L / 1e3, m / m[0], "o-", label=f"block {b}: β = {fit.exponent:.2f}")
    ax2.set(xlabel="scale L (km)", ylabel="⟨ε̇tot⟩ / ⟨ε̇tot⟩(L/N)", title="spatial scaling at the macro-rupture")
    from matplotlib.ticker import FormatStrFormatter, NullFormatter
    for axis in (ax2.xaxis, ax2.yaxis):
        axis.set_major_formatter(FormatStrFormatter("%g"))
        axis.set_minor_formatter(NullFormatter())
    ax2.set_xticks([2, 5, 10, 20, 50])
    ax2.set_yticks([0.5, 0.6, 0.7, 0.8, 0.9, 1.0])
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize=8)
    nodes, tri = d["nodes"], d["tri"]
    v = np.log10(np.maximum(d["rate"], d["rate"].max() * 1e-4))
    ax3.tripcolor(nodes[:, 0] / 1e3, nodes[:, 1] / 1e3, tri, facecolors=v, cmap="magma")
    s = np.array([-150.0, 150.0])
    for ang, off in zip(d["f_rate"].angles_deg, d["f_rate"].offsets_m):
        t = np.deg2rad(ang)  # the line −x sin t + y cos t = off (m)
        px = (-off * np.sin(t)) / 1e3 + s * np.cos(t)
        py = (off * np.cos(t)) / 1e3 + s * np.sin(t)
        ax3.plot(px, py, "c--", lw=1)
    ax3.set_xlim(nodes[:, 0].min() / 1e3, nodes[:, 0].max() / 1e3)
    ax3.set_ylim(nodes[:, 1].min() / 1e3, nodes[:, 1].max() / 1e3)
    ax3.set_aspect("equal")
    ax3.set_title(f"log10 ε̇tot over the rupture block\nfaults (dashed) "
                  f"{', '.join(f'{a:.1f}°' for a in (c['fault_angles_rate_deg'] or [])) or 'none (no rupture)'}"
                  f" from the y axis,\n"
                  f"Mohr–Coulomb {c['mohr_coulomb_angle_deg']:.1f}°", fontsize=9)
    ax3.set_xlabel("x (km)")
    ax3.set_ylabel("y (km), compression along y")
    fig.tight_layout()
    p = fig_dir / "validation_compression.png"
    fig.savefig(p, dpi=110)
    return p


def _inside(k, v):
    lo, hi = TARGETS[k][:2]
    if v is None or not np.isfinite(v):
        return "n/a"
    if lo <= v <= hi:
        return "inside"
    miss = lo - v if v < lo else v - hi
    if k == "localisation_half_shear_area_fraction":
        return f"misses by {100 * miss:.1f} points"
    if k == "mean_total_deformation_rate_per_day":
        return f"misses by {miss:.2g} ({v / (lo if v < lo else hi):.2g}× the band edge)"
    return f"misses by {miss:.2f}"


def _num(v):
    return "n/a" if v is None else f"{v:.3f}"


def _fmt(k, v):
    if v is None or not np.isfinite(v):
        return "n/a"
    if k == "localisation_half_shear_area_fraction":
        return f"{100 * v:.1f} %"
    if k == "mean_total_deformation_rate_per_day":
        return f"{v:.3g}"  # 3 digits: 0.00997 is outside a band that starts at 0.01
    return f"{v:.2f}"


def _fmt3(k, v):
    """:func:`_fmt` with three significant digits (values near a band edge: R² 0.728)."""
    if v is None or not np.isfinite(v) or k in ("localisation_half_shear_area_fraction",
                                                 "mean_total_deformation_rate_per_day"):
        return _fmt(k, v)
    return f"{v:.3g}"


def _res_km(r: dict) -> str:
    return "?" if r.get("resolution_m") is None else f"{r['resolution_m'] / 1e3:g} km"


def _basin_section(scene: str, b: dict, res: dict, figs: list[Path]) -> list[str]:
    keys = [k for k in RHEOLOGIES if k in b]
    labels = [f"{RHEOLOGIES[k]['label']} ({_res_km(b[k])})" for k in keys]
    lines = [f"## {SCENE_LABELS[scene][0].upper() + SCENE_LABELS[scene][1:]}: "
             + " against ".join(RHEOLOGIES[k]["label"] for k in keys), "",
             "| metric | observed | band used | " + " | ".join(labels) + " | " + " | ".join(labels) + " |",
             "|---|---|---|" + "---|" * (2 * len(keys))]
    for k, (lo, hi, src, note) in TARGETS.items():
        band = f"{_fmt(k, lo)}–{_fmt(k, hi)}"
        cells = [f"{_fmt(k, b[r]['median'][k])} [{_fmt(k, b[r]['min'][k])}, {_fmt(k, b[r]['max'][k])}]"
                 for r in keys]
        lines.append(f"| {LABELS[k]} | {src} | {band} ({note}) | " + " | ".join(cells) + " | "
                     + " | ".join(_inside(k, b[r]["median"][k]) for r in keys) + " |")
        if k == "beta_space" and all(b[r]["median"].get(GRID_BETA) is not None for r in keys):
            cells = [f"{_fmt(k, b[r]['median'][GRID_BETA])} [{_fmt(k, b[r]['min'][GRID_BETA])}, "
                     f"{_fmt(k, b[r]['max'][GRID_BETA])}]" for r in keys]
            lines.append(f"| {GRID_BETA_LABEL} | as β | {band} | " + " | ".join(cells) + " | "
                         + " | ".join(_inside(k, b[r]["median"][GRID_BETA]) for r in keys) + " |")
        if k == "beta_space" and all((b[r].get("pooled") or {}).get("beta_space_grids") is not None for r in keys):
            vals = [b[r]["pooled"]["beta_space_grids"] for r in keys]
            cells = [f"{_fmt(k, v)} (default grid {_fmt(k, b[r]['pooled']['beta_space'])})"
                     for v, r in zip(vals, keys)]
            lines.append(f"| {POOLED_BETA_LABEL} | Marsan et al. 2004; Girard et al. 2011 | {band} | "
                         + " | ".join(cells) + " | " + " | ".join(_inside(k, v) for v in vals) + " |")
    lines.append("")
    for r in keys:
        x = b[r]
        lines.append(f"* {RHEOLOGIES[r]['label']} at {_res_km(x)}: mean ice speed "
                     f"{np.mean(x['mean_speed_m_s'][1:]):.2g} m s⁻¹; drift of the nodes over the run "
                     f"{x['drift_km']['mean']:.0f} km on average, "
                     f"{x['drift_km']['max']:.0f} km at most; ice exported {(x['outflow_m3'] or 0) / 1e9:.3g} km³; "
                     f"remesh events {x['remesh_events']}; run wall time {x['wall_s'] or float('nan'):.0f} s "
                     f"(NUMBA_NUM_THREADS=1, two runs at a time on the shared 2-core host).")
        d = x.get("drift_response")
        if d is not None:
            sp = d["wind_factor_5_95_over_drifters"]
            side = "left" if d["turning_deg"] > 0 else "right"
            lines.append(f"  Drift against the wind ({d['drifter_days']} drifter-days; docs/diagnostics.md §13): wind "
                         f"factor {d['wind_factor']:.4f} (5–95 % over the drifters {sp[0]:.4f}–{sp[1]:.4f}; "
                         f"Thorndike and Colony 1982, winter: about 0.008), the ice "
                         f"{abs(d['turning_deg']):.0f}° to the {side} of the geostrophic wind (observed: about 5° "
                         f"to the right), R² {d['r2']:.2f} (about 0.7).")
    lines += ["", "The same statistics on all elements (coastal shear zones included), medians over the windows:", "",
              "| metric | " + " | ".join(labels) + " |", "|---|" + "---|" * len(keys)]
    for k in TARGETS:
        lines.append(f"| {LABELS[k]} | " + " | ".join(_fmt(k, b[r]['median_all_elements'][k]) for r in keys) + " |")
    lines += ["", "Per window (elements away from the coast; elements of remeshed patches left out):", "",
              "| rheology | days | elements (left out) | β | β, 9 grids (sd) | tail shear | tail \\|div\\| | "
              "half-shear area | R² | ⟨ε̇tot⟩ (day⁻¹) |", "|---|---|---|---|---|---|---|---|---|---|"]
    for key in keys:
        for w in b[key]["windows"]:
            i = w["interior"]
            lines.append(f"| {RHEOLOGIES[key]['label']} | {w['start_day']:.0f}–{w['end_day']:.0f} | "
                         f"{w['n_elements']} ({w['n_elements_lost']}) | {i['beta_space']:.3f} ± "
                         f"{i['beta_space_stderr']:.3f} | {_grid_beta_cell(i)} | {i['pdf_tail_exponent_shear']:.2f} "
                         f"(n={i['pdf_tail_n_shear']}) | "
                         f"{i['pdf_tail_exponent_divergence']:.2f} (n={i['pdf_tail_n_divergence']}) | "
                         f"{100 * i['localisation_half_shear_area_fraction']:.1f} % | "
                         f"{i['shear_divergence_r2']:.2f} | {i['mean_total_s'] * DAY:.2g} |")
    lines.append("")
    for p in figs:
        lines += [f"![{p.stem}](figures/{p.name})", ""]
    return lines


def _grid_beta_cell(i: dict) -> str:
    """A window's β over nine box grids and its standard deviation (– in records made before it)."""
    m, sd = i.get(GRID_BETA), i.get("beta_space_grid_sd")
    return "–" if m is None or sd is None else f"{m:.3f} ({sd:.3f})"


def headline(res: dict) -> list[str]:
    """The README headline table: the flagship Maxwell-EB runs (and EVP) against the bands."""
    cols = [(s, k) for s in SCENES for k in RHEOLOGIES if k in res["basin"].get(s, {})]
    head = [f"{RHEOLOGIES[k]['label']}, {s} ({_res_km(res['basin'][s][k])})" for s, k in cols]
    lines = ["| metric (median of 3-day windows) | observed | " + " | ".join(head) + " |",
             "|---|---|" + "---|" * len(cols)]
    for m, (lo, hi, _src, _n) in TARGETS.items():
        cells = []
        for s, k in cols:
            v = res["basin"][s][k]["median"][m]
            cells.append(_fmt(m, v) + (_inside_mark(m, v) or " ✗"))
        lines.append(f"| {LABELS[m]} | {_fmt(m, lo)}–{_fmt(m, hi)} | " + " | ".join(cells) + " |")
        if m == "beta_space" and all(res["basin"][s][k]["median"].get(GRID_BETA) is not None for s, k in cols):
            cells = [_fmt(m, res["basin"][s][k]["median"][GRID_BETA])
                     + (_inside_mark(m, res["basin"][s][k]["median"][GRID_BETA]) or " ✗") for s, k in cols]
            lines.append(f"| {GRID_BETA_LABEL} | {_fmt(m, lo)}–{_fmt(m, hi)} | " + " | ".join(cells) + " |")
        if m == "beta_space" and all((res["basin"][s][k].get("pooled") or {}).get("beta_space_grids") is not None
                                     for s, k in cols):
            vals = [res["basin"][s][k]["pooled"]["beta_space_grids"] for s, k in cols]
            lines.append(f"| {POOLED_BETA_LABEL} | {_fmt(m, lo)}–{_fmt(m, hi)} | "
                         + " | ".join(_fmt(m, v) + (_inside_mark(m, v) or " ✗") for v in vals) + " |")
    lo, hi = WIND_FACTOR_BAND
    cells = []
    for s, k in cols:
        d = res["basin"][s][k].get("drift_response")
        cells.append("–" if d is None else f"{d['wind_factor']:.4f}" + (" ✓" if lo <= d["wind_factor"] <= hi else " ✗"))
    lines.append(f"| wind factor \\|A\\| (daily drift / geostrophic wind; Thorndike and Colony 1982, winter) | "
                 f"about 0.008 ({lo}–{hi}) | " + " | ".join(cells) + " |")
    lines.append("| remesh events | | " + " | ".join(str(res["basin"][s][k]["remesh_events"]) for s, k in cols) + " |")
    lines.append("| mean / largest drift (km) | tens of km | " + " | ".join(
        f"{res['basin'][s][k]['drift_km']['mean']:.0f} / {res['basin'][s][k]['drift_km']['max']:.0f}"
        for s, k in cols) + " |")
    return lines


def runs_provenance(res) -> dict:
    """Every analysed run in ``res`` (a dict with ``run_dir`` and ``made_by``, at any depth):
    ``{commit: [run names]}``, and the runs whose model code changed since they were made or
    cannot be told (``"changed"``, ``"unknown"``)."""
    out = {"by_commit": {}, "changed": [], "unknown": []}

    def walk(o):
        if isinstance(o, dict):
            if "run_dir" in o and "made_by" in o:
                name = Path(o["run_dir"]).name
                out["by_commit"].setdefault(str(o["made_by"]), []).append(name)
                if o.get("model_code_changed") is None:
                    out["unknown"].append(name)
                elif o["model_code_changed"]:
                    out["changed"].append(name)
                    out.setdefault("files", set()).update(o["model_code_changed"])
            for v in o.values():
                walk(v)
        elif isinstance(o, list):
            for v in o:
                walk(v)

    walk(res)
    for k in out["by_commit"]:
        out["by_commit"][k] = sorted(set(out["by_commit"][k]))
    out["changed"], out["unknown"] = sorted(set(out["changed"])), sorted(set(out["unknown"]))
    out["files"] = sorted(out.get("files", ()))
    return out


def provenance_line(prov: dict) -> str:
    """The report's sentence on which code made the runs it reads."""
    if not prov["by_commit"]:
        return ""
    # where no run's model code changed or is unknown, every run made from a modified work tree had its files
    # recorded and none of them was model code: say so, rather than leave "modified" open
    same = not (prov["changed"] or prov["unknown"])
    tree = " (a work tree modified outside the model code)" if same else " (a modified work tree)"
    made = "; ".join(f"`{c[:10]}`{tree if c.endswith('-dirty') else ''} ({len(v)} "
                     f"run{'s' if len(v) > 1 else ''})" for c, v in prov["by_commit"].items())
    if not same:
        return (f"Runs made by the code of {made}. The model code (lagice/, forcing/, thermo/) of this commit differs "
                f"from that of {len(prov['changed'])} of the runs, in {', '.join(f'`{f}`' for f in prov['files'])}, "
                f"and is not known for {len(prov['unknown'])}: their figures describe the code that made them "
                f"(written by `benchmarks/validate.py` from `git diff`; whether the change matters is said in the "
                f"summary).")
    return (f"Runs made by the code of {made}; the model code (lagice/, forcing/, thermo/) is the same in this "
            f"commit, so every run read here is the run this code makes (checked by `git diff` at writing).")


def write_report(res: dict, md: Path, figs: dict):
    cmd = "python benchmarks/validate.py" + (" --quick" if res["quick"] else "") + (
        f" --analyse-only --from-physics --evp-km {res['evp_km']:g}" if res.get("from_physics") else " --sensitivity")
    lines = ["# Validation report: deformation statistics against observations (issues 7 and 12)", "",
             f"Written by `{cmd}` on {res['date']} from the code of commit `{res['git_commit']['commit'][:10]}`"
             f"{' (work tree modified)' if res['git_commit']['dirty'] else ''}. Method: `docs/diagnostics.md`, "
             f"physics: `docs/physics.md`; all numbers in `{res['json']}`.", "",
             *([provenance_line(res["runs_provenance"]), ""] if res.get("runs_provenance", {}).get("by_commit")
               else []),
             "## Headline (for README)", "", "Flagship scene `winter_basin_pack` (one parameter set, docs/physics.md "
             "§4), 28 days; ✓ inside the observed band, ✗ outside:", ""]
    lines += headline(res) + [""]
    lines += res.get("summary", []) + [""]
    lines += ["## Set-up", "",
              f"* Basin runs: `examples/winter_basin_pack.toml` (closed basin) and "
              f"`examples/winter_basin_pack_strait.toml` (the same basin with a 140 km open strait on the east coast), "
              f"{res['basin_days']:g} days, with the recommended parameter set of `docs/physics.md` §4: "
              f"Maxwell-EB with the explicit solver, the winter wind climatology with the air drag of ERA5-like winds "
              f"(2.0e-3), neXtSIM's strength scaled with each element's size (converted to lagice's criterion, "
              f"friction 0.98), neXtSIM's healing law, 25 cm of snow, starting from a spun-up pack. EVP on the same "
              f"scene (mesh generator, forcing, thermodynamics, mesh motion), `solver.name = \"evp\"`, Δt = 30 "
              f"min, 300 mEVP iterations (`docs/evp.md`). The wind climatology is drawn record by record from the "
              f"seed, so every run sees the same winds.",
              f"* Deformation as RGPS measures it: Lagrangian rates from the node displacements over back-to-back "
              f"3-day windows from day 1 on (the first day is spin-up), nodes followed through remeshing by their "
              f"ids (`load_window`), on the elements ≥ {res['coast_buffer_km']:g} km from the coast "
              f"(Girard et al. 2011 "
              f"used 150 km in the whole Arctic; this basin is about 3 times smaller).",
              "* Values in the tables: median over the windows, [min, max] in brackets. "
              "The bands are the source papers' "
              "observed values; where a paper gives one number, the width of the band is ours and is stated.",
              "* No parameter was tuned to any metric.", ""]
    for scene, b in res["basin"].items():
        lines += _basin_section(scene, b, res, figs.get(scene, []))
    if res.get("sensitivity"):
        lines += [f"## Sensitivity of Maxwell-EB to strength, air drag and wind scale (±50 %, closed basin, "
                  f"{SENSITIVITY_RESOLUTION_M / 1e3:g} km; not a calibration)", "",
                  "Each run changes one value of the recommended set by ±50 %; they are reported for what they show "
                  "and no value was chosen from them."
                  + "".join(f" Rows marked † were made on {c['date']} with the code of commit "
                            f"`{str(c['git_commit'])[:10]}` "
                            "and carried from that day's report; they were not remade with this code, so their "
                            "figures describe the code that made them (what differs is said in the summary)."
                            for c in {json.dumps(r["carried_from"], sort_keys=True): r["carried_from"]
                                      for r in res["sensitivity"].values() if r.get("carried_from")}.values()),
                  "", "| run | " + " | ".join(LABELS[k] for k in TARGETS)
                  + f" | {GRID_BETA_LABEL} | {POOLED_BETA_LABEL} | remesh events | mean speed (m s⁻¹) |",
                  "|---|" + "---|" * (len(TARGETS) + 4)]
        for n, r in res["sensitivity"].items():
            gb = r["median"].get(GRID_BETA)
            pb = (r.get("pooled") or {}).get("beta_space_grids")
            lines.append(f"| {r.get('label', SENSITIVITY[n][2])}{' †' if r.get('carried_from') else ''} | "
                         + " | ".join(
                f"{_fmt(k, r['median'][k])} ({_inside(k, r['median'][k])})" for k in TARGETS)
                + (" | –" if gb is None else f" | {_fmt('beta_space', gb)}")
                + (" | –" if pb is None else f" | {_fmt('beta_space', pb)}")
                + f" | {r['remesh_events']} | {np.mean(r['mean_speed_m_s'][1:]):.2g} |")
        lines.append("")
    lines += ensemble_lines(res.get("weather_ensemble") or {}, figs.get("ensemble"))
    lines += rgps_view_lines(res)
    mi = res.get("mesh_imprint") or {}
    if mi:
        lines += ["## Mesh imprint (docs/physics.md §3)", "",
                  "Imprint index (F − F0)/(1 − F0) of the fracture directions against the mesh's domain-wide "
                  "directions, and local index (F̄ − F0)/(F̄_max − F0) against the edges within three element "
                  "sizes of each band (0: chance, 1: every band along the mesh):", ""]
        for k, v in (mi.get("basin_closed_maxwell_eb") or {}).items():
            if isinstance(v, dict) and "index" in v:
                loc = v.get("local_index")
                lines.append(f"* flagship closed basin, {k.replace('_', ' ')}: index {v['index']:.2f}, local index "
                             f"{loc if loc is None else f'{loc:.2f}'} (mesh: "
                             f"{100 * v.get('mesh_lattice_fraction', float('nan')):.0f} % of the edge length in three "
                             f"15° bins, chance 25 %)")
        rt = mi.get("rotation_test")
        if rt:
            lines.append(f"* rotation test ({rt.get('source', '')}): {rt.get('summary', '')}")
        lines.append("")
    if res.get("compression") is not None:
        lines += compression_lines(res, figs)
    else:
        lines += ["## Uniaxial compression", "", "Not part of this report: the fault angles at N = 40 with and "
                  "without node jitter are in docs/physics.md §4 (compression test).", ""]
    lines += ["## Where the model misses, and why", ""] + res.get("discussion", ["(not written)"]) + [""]
    md.write_text("\n".join(lines))
    return md


def analyse_ensemble(physics: Path, days: float, buffer_m: float, basin: dict) -> dict:
    """Per basin of :data:`PHYSICS_ENSEMBLE` whose member runs have all finished: each
    member's window medians, and over the members the median, min, max and the number
    inside the band of every metric (the validation run itself from ``basin``)."""
    out = {}
    for scene, names in PHYSICS_ENSEMBLE.items():
        runs = [physics / n for n in names]
        if not all(run_finished(r) for r in runs):
            print(f"validate: weather ensemble {scene}: not every member has finished ({', '.join(names)})")
            continue
        members = {}
        for n, r in zip(names, runs):
            own = basin.get(scene, {}).get("maxwell_eb")
            a = own if own is not None and Path(own["run_dir"]).resolve() == r.resolve() else analyse_run(r, days,
                                                                                                         buffer_m)
            members[n] = {"median": a["median"], "remesh_events": a["remesh_events"], "drift_km": a["drift_km"],
                          "rgps_median": a["rgps_view"]["median"], "drift_response": a.get("drift_response"),
                          "windows_" + GRID_BETA: [w["interior"].get(GRID_BETA) for w in a["windows"]],
                          "window_curves": [{"interior": {k: w["interior"].get(k) for k in
                                                          ("scaling_space", "scaling_space_grids")}}
                                            for w in a["windows"]],
                          "pooled": a.get("pooled"),
                          **{k: a.get(k) for k in ("run_dir", "made_by", "model_code_changed")}}
        out[scene] = {"members": members, "metrics": _member_stats(members, "median"),
                      "rgps_metrics": _member_stats(members, "rgps_median"),
                      "pooled_" + GRID_BETA: pooled_windows(
                          [m["windows_" + GRID_BETA] for m in members.values()]),
                      "pooled_curve": pooled_months([m["window_curves"] for m in members.values()])}
    return out


def pooled_months(per_month: list) -> dict | None:
    """β of one curve over every box of every window of every month (default grid, and every grid),
    as observed β is computed over a winter (:func:`lagice.diagnostics.windows.pooled_window_scaling`),
    with a 90 % interval from resampling the months with replacement (:data:`POOLED_RESAMPLES`
    seeded resamples; the month is the unit, as in :func:`pooled_windows`). None if a month's windows
    lack their curves (records made before 2026-11-30)."""
    from lagice.diagnostics.windows import pooled_window_scaling

    if not per_month or any(not m or any(w["interior"].get("scaling_space") is None for w in m) for m in per_month):
        return None
    every = pooled_window_scaling([w for m in per_month for w in m])   # also checks that the curves pool
    rng = np.random.default_rng(POOLED_SEED)
    picks = rng.integers(0, len(per_month), size=(POOLED_RESAMPLES, len(per_month)))
    boot = {"beta_space": _resampled_betas([[w["interior"]["scaling_space"] for w in m] for m in per_month],
                                           picks)}
    grids = [[c for w in m for c in (w["interior"].get("scaling_space_grids") or [])] for m in per_month]
    boot["beta_space_grids"] = (_resampled_betas(grids, picks) if every["beta_space_grids"] is not None
                                else [None] * len(picks))
    out = {"n_windows": every["n_windows"], "n_months": len(per_month), "curve": every["curve"]}
    for k, v in boot.items():
        v = np.asarray([np.nan if x is None else x for x in v], dtype=np.float64)
        out[k] = every[k]
        out[k + "_interval_90"] = (None if every[k] is None or not np.all(np.isfinite(v)) else
                                   [float(np.quantile(v, 0.05)), float(np.quantile(v, 0.95))])
    return out


def _resampled_betas(per_month: list, picks) -> list:
    """β of :func:`lagice.diagnostics.scaling.pooled_spatial_scaling` over the curves of the months in
    each row of ``picks`` (month indices, with repeats), pooling each month's curves once into one curve
    (with its ``fewest_boxes``) and then the rows' month curves: the same β as pooling the rows' curves
    one by one, to round-off (the sums are added in another order), in a fraction of its time
    (``tests/test_bench_helpers.py``). The curves must pool (checked by the caller over every month)."""
    from lagice.diagnostics.scaling import pooled_spatial_scaling

    months = []
    for curves in per_month:
        p = pooled_spatial_scaling(curves)
        months.append({"box_size_m": list(curves[0]["box_size_m"])[:p.scale_m.size], "scale_m": p.scale_m,
                       "mean_total_s": p.mean_total_s, "n_boxes": p.n_boxes, "fewest_boxes": p.fewest_boxes})
    return [pooled_spatial_scaling([months[i] for i in row]).fit.exponent for row in picks]


#: resamples of the months in :func:`pooled_windows`' interval, and its seed
POOLED_RESAMPLES, POOLED_SEED = 2000, 0


def pooled_windows(per_month: list) -> dict | None:
    """The median of a window statistic pooled over every window of every month, with a 90 % interval
    from resampling the months with replacement (windows of one month share its weather and pack, so
    the month is the unit; :data:`POOLED_RESAMPLES` seeded resamples). None if a month lacks the
    statistic (records made before it)."""
    if not per_month or any(v is None for m in per_month for v in m):
        return None
    months = [np.asarray(m, dtype=np.float64) for m in per_month]
    rng = np.random.default_rng(POOLED_SEED)
    picks = rng.integers(0, len(months), size=(POOLED_RESAMPLES, len(months)))
    boot = np.array([np.median(np.concatenate([months[i] for i in row])) for row in picks])
    return {"median": float(np.median(np.concatenate(months))), "interval_90": [float(np.quantile(boot, 0.05)),
            float(np.quantile(boot, 0.95))], "n_windows": int(sum(m.size for m in months)),
            "n_months": len(months)}


def _carried(previous: dict) -> dict:
    return {"git_commit": previous.get("git_commit"), "date": previous.get("date")}


def carry_sensitivity(previous: dict, names: list) -> dict:
    """The sensitivity runs among ``names`` whose folders are gone, from the ``previous``
    report's JSON, each marked ``carried_from`` (its commit and date), so that the report says
    they were not remade. Printed, never silent."""
    out = {}
    for n in names:
        r = (previous.get("sensitivity") or {}).get(n)
        if r is not None:
            out[n] = {**r, "carried_from": r.get("carried_from") or _carried(previous)}
            print(f"validate: sensitivity run {n}: not in the runs folder; carried from the report of "
                  f"{out[n]['carried_from']['date']} (commit {str(out[n]['carried_from']['git_commit'])[:10]})")
        else:
            print(f"validate: sensitivity run {n}: not run and not in the previous report: left out")
    return out


def carry_ensembles(previous: dict, groups: list) -> dict:
    """The groups of :data:`PHYSICS_ENSEMBLE` among ``groups`` whose member runs are gone but
    whose members, by name, are a group of the ``previous`` report (under any group name), from
    that report, marked ``carried_from``."""
    out = {}
    old = previous.get("weather_ensemble") or {}
    for g in groups:
        hit = [e for e in old.values() if list(e.get("members", {})) == PHYSICS_ENSEMBLE[g]]
        if hit:
            out[g] = {**hit[0], "carried_from": hit[0].get("carried_from") or _carried(previous)}
            print(f"validate: weather ensemble {g}: carried from the report of {out[g]['carried_from']['date']}")
    return out


def _member_stats(members: dict, part: str) -> dict:
    """Per metric over the members' ``part`` medians: median, min, max and how many are inside the band
    (and β over nine grids against β's band, where every member has it)."""
    stats = {}
    bands = dict(TARGETS)
    if all(m[part].get(GRID_BETA) is not None for m in members.values()):
        bands[GRID_BETA] = TARGETS["beta_space"]
    for k, (lo, hi, _src, _n) in bands.items():
        v = np.array([np.nan if m[part][k] is None else m[part][k] for m in members.values()])
        ok = np.isfinite(v)
        some = bool(ok.any())
        stats[k] = {"median": float(np.median(v[ok])) if some else None,
                    "min": float(v[ok].min()) if some else None, "max": float(v[ok].max()) if some else None,
                    "n_inside": int(np.sum(ok & (v >= lo) & (v <= hi))), "n_members": len(v)}
    return stats


def ensemble_lines(ens: dict, figure: Path | None = None) -> list[str]:
    """Markdown: per basin, each member's medians and how many members are inside each band (and the
    figure of :func:`figure_ensemble_bands` first, where there is one)."""
    if not ens:
        return []
    months = sorted({len(e["members"]) for e in ens.values()})
    span = f"{months[0]}–{months[-1]}" if len(months) > 1 else str(months[0])
    lines = [f"## Weather ensemble of the flagship (Maxwell-EB, {span} months of winds)", "",
             "The validation run and the same set-up (spin-up state, strength disorder, parameters) under the "
             "winds of other seeds of the wind climatology (`python benchmarks/physics_experiments.py run "
             + " ".join(n for e in ens.values() for n in list(e["members"])[1:]) + "`; `PHYSICS_ENSEMBLE` of "
             "`benchmarks/validate.py`). Medians of the 3-day windows per member; the last columns give "
             "the median over the members and how many members are inside the band.", ""]
    if figure is not None:
        lines += [f"![every month against the observed bands](figures/{figure.name})", ""]
    for scene, e in ens.items():
        names = list(e["members"])
        c = e.get("carried_from")
        lines += [f"**{scene}**", ""] + ([f"(Numbers from the report of {c['date']}, commit "
                                          f"`{str(c['git_commit'])[:10]}`: the runs' folders are not kept, so they "
                                          "were not analysed again.)", ""] if c else []) + [
                  "| metric | observed | " + " | ".join(names)
                  + " | median of members | members inside |", "|---|---|" + "---|" * (len(names) + 2)]
        for k, (lo, hi, _src, _n) in TARGETS.items():
            st = e["metrics"][k]
            cells = [_fmt3(k, e["members"][n]["median"][k]) for n in names]
            med = st["median"]
            mark = "" if med is None else (" ✓" if lo <= med <= hi else " ✗")
            lines.append(f"| {LABELS[k]} | {_fmt(k, lo)}–{_fmt(k, hi)} | " + " | ".join(cells)
                         + f" | {_fmt3(k, med)}{mark} | {st['n_inside']} of {st['n_members']} |")
            gs = e["metrics"].get(GRID_BETA)
            if k == "beta_space" and gs is not None:
                med = gs["median"]
                lines.append(f"| {GRID_BETA_LABEL} | {_fmt(k, lo)}–{_fmt(k, hi)} | "
                             + " | ".join(_fmt3(k, e["members"][n]["median"][GRID_BETA]) for n in names)
                             + f" | {_fmt3(k, med)}{' ✓' if lo <= med <= hi else ' ✗'} | "
                             f"{gs['n_inside']} of {gs['n_members']} |")
        wf = [(e["members"][n].get("drift_response") or {}).get("wind_factor") for n in names]
        if all(v is not None for v in wf):
            lo, hi = WIND_FACTOR_BAND
            med = float(np.median(wf))
            lines.append("| wind factor \\|A\\| (Thorndike and Colony 1982, winter) | about 0.008 "
                         f"({lo}–{hi}) | " + " | ".join(f"{v:.4f}" for v in wf)
                         + f" | {med:.4f}{' ✓' if lo <= med <= hi else ' ✗'} | "
                         f"{sum(lo <= v <= hi for v in wf)} of {len(wf)} |")
        lines.append("| remesh events | | " + " | ".join(str(e["members"][n]["remesh_events"]) for n in names)
                     + " | | |")
        lines.append("")
        pw = e.get("pooled_" + GRID_BETA)
        if pw is not None:
            lo, hi = TARGETS["beta_space"][:2]
            a, b = pw["interval_90"]
            lines += [f"All {pw['n_windows']} windows of the {pw['n_months']} months pooled: the median of β over "
                      f"nine box grids is {pw['median']:.3f}, with a 90 % interval of {a:.3f}–{b:.3f} from "
                      f"resampling the months ({POOLED_RESAMPLES} resamples); the band is {lo}–{hi}.", ""]
        pc = e.get("pooled_curve")
        if pc is not None:
            lo, hi = TARGETS["beta_space"][:2]
            grids = ("" if pc.get("beta_space_grids") is None else
                     f", and over every box of the nine grids {pc['beta_space_grids']:.3f}"
                     f"{_interval_text(pc, 'beta_space_grids')}")
            lines += [f"As observed β is computed (Marsan et al. 2004; Girard et al. 2011): one slope of the mean "
                      f"over every box of every window of the {pc['n_months']} months, in which the windows that "
                      f"deform most weigh most, β is {pc['beta_space']:.3f}{_interval_text(pc, 'beta_space')} on "
                      f"the default box grid{grids}; the band is {lo}–{hi}. Not counted among the six bands.", ""]
    return lines


def _interval_text(pooled: dict, key: str) -> str:
    iv = pooled.get(key + "_interval_90")
    return "" if iv is None else f" (90 % interval {iv[0]:.3f}–{iv[1]:.3f})"


def rgps_view_lines(res: dict) -> list[str]:
    """Markdown: the basin runs' statistics as RGPS would see them (docs/diagnostics.md)."""
    cols = [(sc, k) for sc in res["basin"] for k in RHEOLOGIES if "rgps_view" in res["basin"][sc].get(k, {})]
    if not cols:
        return []
    err = res["basin"][cols[0][0]][cols[0][1]]["rgps_view"]["tracking_error_m"]
    lines = ["## The model as RGPS would see it", "",
             f"RGPS deformation comes from points tracked between SAR images on a grid of 10 km cells, each "
             f"displacement with an error of about {err:g} m (Lindsay and Stern 2003: 0.5 % day⁻¹ error standard "
             f"deviation in divergence and shear for a 10 km cell over 3 days). "
             f"`lagice.diagnostics.rgps` applies that to the model: 10 km cells of points that move with the ice, "
             f"a seeded Gaussian error of {err:g} m on each end position, the line integral around each cell "
             f"(docs/diagnostics.md). It changes no run. Per column: the model's elements (the headline) / the "
             f"same motion on 10 km cells without error / with the {err:g} m error; medians of the 3-day windows, "
             f"✓ inside the band:", "",
             "| metric | observed | " + " | ".join(f"{RHEOLOGIES[k]['label']}, {sc}" for sc, k in cols) + " |",
             "|---|---|" + "---|" * len(cols)]
    for m, (lo, hi, _src, _n) in TARGETS.items():
        cells = []
        for sc, k in cols:
            r = res["basin"][sc][k]
            cells.append(" / ".join(_fmt(m, v) + _inside_mark(m, v) for v in
                                    (r["median"][m], r["rgps_view"]["median_cells"][m], r["rgps_view"]["median"][m])))
        lines.append(f"| {LABELS[m]} | {_fmt(m, lo)}–{_fmt(m, hi)} | " + " | ".join(cells) + " |")
        if m == "beta_space" and all(res["basin"][sc][k].get("pooled")
                                     and res["basin"][sc][k]["rgps_view"].get("pooled") for sc, k in cols):
            cells = []
            for sc, k in cols:
                r = res["basin"][sc][k]
                vals = (r["pooled"]["beta_space_grids"], r["rgps_view"]["pooled_cells"]["beta_space_grids"],
                        r["rgps_view"]["pooled"]["beta_space_grids"])
                cells.append(" / ".join(_fmt(m, v) + _inside_mark(m, v) for v in vals))
            lines.append(f"| {POOLED_BETA_LABEL} | {_fmt(m, lo)}–{_fmt(m, hi)} | " + " | ".join(cells) + " |")
    lines.append("")
    ens = res.get("weather_ensemble") or {}
    if any("rgps_metrics" in e for e in ens.values()):
        lines += ["Weather ensemble (Maxwell-EB, the months of the section above), median over the members: "
                  "the model's elements / "
                  f"10 km cells with the {err:g} m error:", "",
                  "| metric | observed | " + " | ".join(ens) + " |", "|---|---|" + "---|" * len(ens)]
        for m, (lo, hi, _src, _n) in TARGETS.items():
            lines.append(f"| {LABELS[m]} | {_fmt(m, lo)}–{_fmt(m, hi)} | " + " | ".join(
                " / ".join(_fmt(m, v) + _inside_mark(m, v) for v in (e["metrics"][m]["median"],
                                                                     e["rgps_metrics"][m]["median"]))
                for e in ens.values()) + " |")
        lines.append("")
    return lines


def _inside_mark(k, v) -> str:
    lo, hi = TARGETS[k][:2]
    return "" if v is None or not np.isfinite(v) else (" ✓" if lo <= v <= hi else " ✗")


def compression_lines(res: dict, figs: dict) -> list[str]:
    lines = []
    c = res["compression"]
    lines += ["## Uniaxial compression (Dansereau et al. 2016 §4–5)", "",
              f"N = {c['n_across']} ({c['steps']} steps of {c['dt_s']:.1f} s, {c['wall_s']:.0f} s wall), seed 0, "
              f"implicit solver, healing on. Peak {c['peak_stress_kpa']:.0f} kPa at strain "
              f"{c['peak_strain']:.2e}; the macro-rupture (largest stress drop over one block of "
              f"{c['block_steps']} steps, the shear-wave crossing time of the width) drops "
              f"{c['rupture_drop_kpa']:.1f} kPa at t = {c['rupture_time_s'] / 3600:.2f} h.", "",
              "| metric | expected | lagice | verdict |", "|---|---|---|---|"]
    mc = c["mohr_coulomb_angle_deg"]
    ang = c["fault_angles_rate_deg"] or []  # None: the plate did not rupture
    angd = c["fault_angles_damage_deg"] or []
    lines.append(f"| fault angle to the compression axis (active faults: ε̇tot over the rupture block) | "
                 f"Mohr–Coulomb 45° − atan(μ)/2 = {mc:.1f}° (μ = 0.7) | "
                 f"{', '.join(f'{a:.1f}°' for a in ang)} | off by {', '.join(f'{a - mc:+.1f}°' for a in ang)} |")
    if angd:
        lines.append(f"| fault angle (damage created by the rupture) | {mc:.1f}° | "
                     f"{', '.join(f'{a:.1f}°' for a in angd)} | off by "
                     f"{', '.join(f'{a - mc:+.1f}°' for a in angd)} |")
    sk_a, sk_r = c["skewness_increments_all"], c["skewness_increments_from_peak"]
    lines.append("| skewness of Δσ/Δt, whole run | strongly negative, ≈ −6 (Dansereau et al. 2016 §5.3) | "
                 f"{sk_a:.1f} | "
                 f"{'negative' if sk_a < 0 else 'NOT negative'}; {abs(sk_a - (-6)):.1f} from −6 |")
    if sk_r is not None:
        lines.append("| skewness of Δσ/Δt, from the stress peak on (the regime of Dansereau et al. 2016 Fig. 7) "
                     "| ≈ −6 | "
                     f"{sk_r:.1f} | "
                     f"{'negative' if sk_r < 0 else 'NOT negative'}; {abs(sk_r - (-6)):.1f} from −6 |")
    lines.append(f"| β just after the macro-rupture (next block) | 0.15 ± 0.02 (Dansereau et al. 2016 §5.2, N = 100) | "
                 f"{c['beta_after_rupture']:.3f} | "
                 f"{'inside' if 0.13 <= c['beta_after_rupture'] <= 0.17 else 'outside'} 0.13–0.17 |")
    lines.append(f"| β of the rupture block | 0.15 ± 0.02 | {c['beta_rupture_block']:.3f} | "
                 f"{'inside' if 0.13 <= c['beta_rupture_block'] <= 0.17 else 'outside'} 0.13–0.17 |")
    lines += ["", f"![validation_compression](figures/{figs['compression'].name})", ""]
    return lines


#: arrays left out of the copy of validation.json kept in docs/figures (the full file
#: stays in --out)
BULKY = ("pdf_shear", "pdf_divergence", "scaling_space", "scaling_space_grids", "beta_blocks", "window_curves")


def _drop(obj, keys):
    if isinstance(obj, dict):
        return {k: _drop(v, keys) for k, v in obj.items() if k not in keys}
    if isinstance(obj, list):
        return [_drop(v, keys) for v in obj]
    return obj


def update_record_store(store: Path, seed: Path, update, publish=None) -> dict:
    """Read-modify-write of a JSON record store shared by runs that may finish together (two
    queues of physics runs): under an exclusive lock (``store`` with suffix ``.lock``), read
    ``store`` (in a fresh checkout, which has none, the published ``seed``, so that one new
    record does not drop every earlier one), apply ``update(records) -> records``, write it
    atomically, then call ``publish(records)`` (the copy under docs/) before the lock is
    released. Returns the records written."""
    import fcntl

    store.parent.mkdir(parents=True, exist_ok=True)
    with open(store.with_suffix(".lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        src = store if store.exists() else seed
        records = update(json.loads(src.read_text()) if src.exists() else {})
        tmp = store.with_suffix(".tmp")
        tmp.write_text(json.dumps(records, indent=1, default=float))
        tmp.replace(store)
        if publish is not None:
            publish(records)
    return records


def repo_relative(obj):
    """``obj`` with this checkout's absolute path taken out of every string (paths relative
    to the repository root), for the copies published under docs/: a record names files
    of the repository, not of the machine that wrote it."""
    if isinstance(obj, dict):
        return {k: repo_relative(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [repo_relative(v) for v in obj]
    if isinstance(obj, str):
        return obj.replace(f"{ROOT}/", "").replace(str(ROOT), ".")
    return obj


def _strip(obj):
    if isinstance(obj, dict):
        return {k: _strip(v) for k, v in obj.items() if not k.startswith("_")}
    if isinstance(obj, list):
        return [_strip(v) for v in obj]
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    if isinstance(obj, float) and not np.isfinite(obj):
        return None
    return obj


def _compression_job(out: Path, n_across: int, max_strain: float):
    print(f"validate: compression N = {n_across} to strain {max_strain:g}", flush=True)
    run_compression(out, n_across, max_strain)


def run_jobs(jobs: dict, out: Path, n_parallel: int):
    """Run {name: argv} as subprocesses, ``n_parallel`` at a time; logs in out/NAME.log."""
    pending, running = list(jobs.items()), {}
    while pending or running:
        while pending and len(running) < n_parallel:
            name, cmd = pending.pop(0)
            log = open(out / f"{name}.log", "w")
            print(f"validate: start {name}", flush=True)
            running[name] = (subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, cwd=ROOT), log,
                             time.perf_counter())
        time.sleep(2.0)
        for name, (p, log, t0) in list(running.items()):
            rc = p.poll()
            if rc is None:
                continue
            log.close()
            del running[name]
            if rc != 0:
                for q, _lg, _ in running.values():
                    q.kill()
                tail = (out / f"{name}.log").read_text()[-3000:]
                raise SystemExit(f"validate: {name} failed (exit {rc}); log {out / (name + '.log')}:\n{tail}")
            print(f"validate: {name} done in {time.perf_counter() - t0:.0f} s", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="4-day basins at 20 km, N = 20 compression")
    ap.add_argument("--analyse-only", action="store_true", help="re-analyse the runs in --out")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "out" / "validate")
    ap.add_argument("--days", type=float, default=None,
                    help="basin run length in days (default 28, the scene's own; quick 4)")
    ap.add_argument("--coast-buffer-km", type=float, default=100.0)
    ap.add_argument("--n-across", type=int, default=None, help="compression N (default 40, quick 20)")
    ap.add_argument("--max-strain", type=float, default=1e-3)
    ap.add_argument("--jobs", type=int, default=2, help="runs at a time (default 2)")
    ap.add_argument("--md", type=Path, default=ROOT / "docs" / "validation.md")
    ap.add_argument("--fig-dir", type=Path, default=ROOT / "docs" / "figures")
    ap.add_argument("--discussion", type=Path, default=ROOT / "benchmarks" / "validation_discussion.md",
                    help="hand-written summary and 'where the model misses' text, placed in the report")
    ap.add_argument("--sensitivity", action="store_true",
                    help="also run the Maxwell-EB sensitivity runs (SENSITIVITY: α = 5, 7 on the closed basin)")
    ap.add_argument("--only-sensitivity", action="store_true",
                    help="run only the sensitivity runs (the others are already in --out), then analyse all")
    ap.add_argument("--compression-job", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--from-physics", action="store_true",
                    help="with --analyse-only: analyse the runs of benchmarks/physics_experiments.py "
                         "(benchmarks/out/physics: PHYSICS_RUNS)")
    ap.add_argument("--evp-km", type=float, default=10.0, help="with --from-physics: the EVP runs' resolution")
    ap.add_argument("--physics-dir", type=Path, default=ROOT / "benchmarks" / "out" / "physics",
                    help="with --from-physics: where benchmarks/physics_experiments.py put its runs")
    ap.add_argument("--no-compression", action="store_true", help="leave the compression test out")
    args = ap.parse_args(argv)
    days = args.days or (4.0 if args.quick else 28.0)
    n_across = args.n_across or (20 if args.quick else 40)
    resolution = 20e3 if args.quick else None
    out = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    if args.compression_job:
        return _compression_job(out, n_across, args.max_strain)
    if args.from_physics and not args.analyse_only:
        raise SystemExit("validate: --from-physics analyses finished runs; add --analyse-only")
    physics = args.physics_dir.resolve() if args.from_physics else None
    args.fig_dir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    comp_path = out / f"compression_N{n_across}.npz"
    if not args.analyse_only:
        jobs = {} if args.no_compression else {
            "compression": [sys.executable, str(Path(__file__).resolve()), "--compression-job", "--out", str(out),
                            "--n-across", str(n_across), "--max-strain", str(args.max_strain)]}
        jobs.update({f"{s}_{k}": cmd for (s, k), cmd in basin_commands(out, days, resolution).items()})
        if args.only_sensitivity:
            jobs = {}
        if args.sensitivity or args.only_sensitivity:
            jobs.update(sensitivity_commands(out, days, resolution))
        run_jobs(jobs, out, max(1, args.jobs))

    done = run_finished

    basin = {}
    for s in SCENES:
        b = {}
        for key in RHEOLOGIES:
            run = run_dir(out, f"{s}_{key}", physics, args.evp_km)
            if done(run):
                b[key] = analyse_run(run, days, args.coast_buffer_km * 1e3)
            else:
                print(f"validate: {run} has not finished: left out", flush=True)
        if b:
            basin[s] = b
    sens = {}
    for name in SENSITIVITY:
        run = run_dir(out, f"sensitivity_{name}", physics, args.evp_km)
        if done(run):
            sens[name] = analyse_run(run, days, args.coast_buffer_km * 1e3)
    previous_json = args.fig_dir / "validation.json"
    previous = json.loads(previous_json.read_text()) if physics is not None and previous_json.exists() else None
    if previous is not None:
        sens.update(carry_sensitivity(previous, [n for n in SENSITIVITY if n not in sens]))
    if physics is not None and "base" in sens and PHYSICS_RUNS["sensitivity_base"] != PHYSICS_RUNS["closed_maxwell_eb"]:
        sens["base"]["label"] = (f"the set of the ±50 % runs at 10 km ({PHYSICS_RUNS['sensitivity_base']}: not the "
                                 f"validation run above)")
    comp = None if args.no_compression or not comp_path.exists() else analyse_compression(comp_path)
    figs = {s: figures_basin(basin[s], args.fig_dir, s) for s in basin}
    if comp is not None:
        figs["compression"] = figure_compression(comp, args.fig_dir)
    imprint = {}
    if "closed" in basin and "maxwell_eb" in basin["closed"]:
        imprint["basin_closed_maxwell_eb"] = basin_imprint(Path(basin["closed"]["maxwell_eb"]["run_dir"]), days,
                                                           args.coast_buffer_km * 1e3)
        figs.setdefault("closed", []).append(figure_rate_map(Path(basin["closed"]["maxwell_eb"]["run_dir"]), days,
                                                             args.fig_dir, "closed"))
    if "strait" in basin and "maxwell_eb" in basin["strait"]:
        figs.setdefault("strait", []).append(figure_rate_map(Path(basin["strait"]["maxwell_eb"]["run_dir"]), days,
                                                             args.fig_dir, "strait"))
    ensemble = analyse_ensemble(physics, days, args.coast_buffer_km * 1e3, basin) if physics is not None else {}
    if previous is not None:
        ensemble.update(carry_ensembles(previous, [g for g in PHYSICS_ENSEMBLE if g not in ensemble]))
    if ensemble:
        figs["ensemble"] = figure_ensemble_bands(ensemble, basin, args.fig_dir)
    mi_json = args.fig_dir / "mesh_imprint.json"
    if mi_json.exists():
        imprint["rotation_test"] = rotation_test_summary(json.loads(mi_json.read_text()))
    res = {"quick": args.quick, "date": time.strftime("%Y-%m-%d"), "wall_s": time.perf_counter() - t0,
           "git_commit": git_commit(), "from_physics": bool(physics), "evp_km": args.evp_km,
           "basin_days": days, "coast_buffer_km": args.coast_buffer_km,
           "basin": basin, "sensitivity": sens, "compression": comp, "mesh_imprint": imprint,
           "weather_ensemble": ensemble,
           "targets": {k: list(v) for k, v in TARGETS.items()},
           "json": str((args.fig_dir.resolve() / "validation.json").relative_to(ROOT))
           if args.fig_dir.resolve().is_relative_to(ROOT) else str(args.fig_dir / "validation.json")}
    res["runs_provenance"] = runs_provenance({k: res[k] for k in ("basin", "sensitivity", "weather_ensemble")})
    for name in res["runs_provenance"]["changed"] + res["runs_provenance"]["unknown"]:
        print(f"validate: WARNING: {name}: made by other model code than this commit's (or unknown)", flush=True)
    if args.discussion.exists():
        text = args.discussion.read_text()
        head, _, tail = text.partition("<!-- misses -->")
        res["summary"], res["discussion"] = head.strip().splitlines(), tail.strip().splitlines()
    full = _strip(res)
    full["git_commit"] = res["git_commit"]["commit"]
    full["git_dirty"] = res["git_commit"]["dirty"]
    (out / "validation.json").write_text(json.dumps(full, indent=1))
    (args.fig_dir / "validation.json").write_text(json.dumps(repo_relative(_drop(full, BULKY)), indent=1))
    md = write_report(res, args.md, figs)
    print(f"validate: report {md}")
    print("\n".join(headline(res)))
    if comp is not None:
        print(f"  compression: fault angles {comp['fault_angles_rate_deg']} (MC {comp['mohr_coulomb_angle_deg']:.1f}), "
              f"skewness {comp['skewness_increments_all']:.2f}, β after rupture {comp['beta_after_rupture']:.3f}")
    return res


def rotation_test_summary(mi: dict) -> dict:
    """The rotation test of benchmarks/mesh_imprint.py (docs/figures/mesh_imprint.json):
    per variant and field, the imprint index at each lattice rotation and the histogram
    correlation at no shift and at the rotation."""
    out = {"source": mi.get("source", "benchmarks/mesh_imprint.py cyclone"), "git_commit": mi.get("git_commit"),
           "variants": {}}
    parts = []
    for variant, fields in (mi.get("cyclone") or {}).items():
        v = {}
        for field, per in fields.items():
            v[field] = {rot: {"index": s.get("index"), "shift_vs_r0": s.get("shift_vs_r0")} for rot, s in per.items()}
            idx = " / ".join(f"{s.get('index', float('nan')):.2f}" for s in per.values())
            parts.append(f"{variant} {field}: index {idx} at rotations {', '.join(per)}°")
        out["variants"][variant] = v
    floor = mi.get("rotation_floor") or {}
    if floor:   # the same test against the noise of four disorder realisations (mesh_imprint.py floor)
        out["noise_floor"] = {}
        for variant, fields in floor.items():
            out["noise_floor"][variant] = {
                f: {k: r.get(k) for k in ("verdict", "test_stat_median", "null_stat_median", "null_stat_p90",
                                          "same_mesh_other_disorder_corr", "turns")}
                for f, r in fields.items() if isinstance(r, dict) and "verdict" in r}
            parts.append(f"{variant} against the noise of {len(fields.get('seeds', []))} disorder draws: "
                         + ", ".join(f"{f} {r['verdict']}" for f, r in out["noise_floor"][variant].items()))
    turn = mi.get("rotation_turn") or {}
    if turn:   # ensembles of 12 disjoint draws per rotation, judged at exactly the turn (mesh_imprint.py turn)
        out["ensemble_turn"] = {}
        for variant, fields in turn.items():
            out["ensemble_turn"][variant] = {
                f: {"verdict": r.get("verdict"),
                    "turns": {th: {k: t.get(k) for k in ("d", "d_low", "d_high", "corr_at_zero",
                                                         "corr_at_exact_rotation")}
                              for th, t in (r.get("turns") or {}).items()}}
                for f, r in fields.items() if isinstance(r, dict) and "verdict" in r}
            verdicts = ", ".join(f"{f} {r['verdict']}" for f, r in out["ensemble_turn"][variant].items())
            parts.append(f"{variant}, ensembles of {len((fields.get('seeds') or {}).get('0', []))} draws at exactly "
                         f"the turn: {verdicts}")
    out["summary"] = "; ".join(parts)
    return out


def figure_rate_map(run: Path, days: float, fig_dir: Path, scene: str) -> Path:
    """Total deformation rate (Lagrangian, over 3-day windows) of a basin run: the LKFs."""
    from matplotlib.colors import LogNorm

    from lagice.diagnostics import lagrangian_velocity_gradients
    from lagice.io.snapshots import load_window

    starts = [d for d in (7.0, 16.0, days - 3.0) if d + 3.0 <= days]
    fig = _fig(5.2 * len(starts), 5.0)
    axes = np.atleast_1d(fig.subplots(1, len(starts)))
    for ax, t0 in zip(axes, starts):
        w = load_window(run, t0 * DAY, (t0 + 3.0) * DAY)
        r = lagrangian_velocity_gradients(w["xy0"], w["xy1"], w["triangles"], w["dt_s"])
        v = np.maximum(r.total_s * DAY, 1e-4)
        xy = w["xy1"]
        tp = ax.tripcolor(xy[:, 0] / 1e3, xy[:, 1] / 1e3, w["triangles"], facecolors=v, cmap="magma",
                          norm=LogNorm(vmin=1e-3, vmax=0.3))
        ax.set_title(f"ε̇tot (day$^{{-1}}$), days {t0:.0f}–{t0 + 3:.0f}", fontsize=9)
        ax.set_aspect("equal")
        ax.set_xlabel("x (km)")
        fig.colorbar(tp, ax=ax, shrink=0.8)
    axes[0].set_ylabel("y (km)")
    fig.suptitle(f"{SCENE_LABELS[scene]}, Maxwell-EB: total deformation rate over 3-day windows (LKFs)", fontsize=10)
    fig.tight_layout()
    p = fig_dir / f"validation_{scene}_deformation_rate_map.png"
    fig.savefig(p, dpi=110)
    return p


if __name__ == "__main__":
    main()
