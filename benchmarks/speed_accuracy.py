"""Speed–accuracy chart of the implicit and explicit solvers (issue 3).

Runs ``uniaxial_compression`` and ``wind_square`` (scene builder + Simulation, the
path of ``lagice run``: ``--set``-style overrides of the resolution, solver, Δt and
sub-step safety) over a grid of (solver, Δt, sub-step size, resolution) and
measures, for every run:

* cost: wall time of the time loop ``sim.run()`` [s] (numba compilation excluded by
  warm-up runs);
* L2 velocity error, ‖u − u_ref‖/‖u_ref‖ of the velocity averaged over a final
  window (compression: last 10 % of the run, the mean of the transport velocity
  (``model.transport_velocity``: the sub-step mean of the explicit stepper, u^{n+1}
  of the implicit one); wind_square: last 3 h, from the node displacements), on a
  regular 60×60 grid (linear interpolation from the nodes, so different
  resolutions compare). Instantaneous velocities are not used: the explicit
  solver resolves elastic waves that ring in undamaged ice (Maxwell λ0 = 1e7 s)
  and dominate the instantaneous field; the implicit solver damps them;
  against the reference of the **same** solver family and against the reference
  of the **other** family. The reference of a family is its run on the finest
  mesh (``--full``: ≥ 20 000 elements) at its reference step (implicit Δt = td,
  explicit Δt = td (compression) or 60 s (wind_square) with sub-steps at 0.35 × the
  stability limit); the same configuration on the coarser meshes gives the
  convergence series (error against the number of elements), and one run at a
  smaller Δt checks that the reference step is converged in time;
* mean damage and damaged-area fraction (d > 0.5) at the end;
* compression only: the macroscopic stress–strain curve, error = RMS difference
  from the reference curve divided by the reference peak stress.

Everything recorded during a run (stress curve, window displacement, sub-steps)
is recorded by callback activities after each step.

Writes ``benchmarks/out/speed_accuracy.json``, ``docs/figures/speed_accuracy.png``
(log–log error vs cost, Pareto front of each scene marked; error vs elements),
``docs/figures/speed_accuracy.json`` and ``docs/speed_accuracy.md`` (tables).

    python benchmarks/speed_accuracy.py --quick      # < 10 min on 2 cores (meshes up to ~2k elements)
    python benchmarks/speed_accuracy.py --full       # fine end >= 20 000 elements (hours on 2 shared cores)
"""
from __future__ import annotations

import argparse
import json
import time
import warnings
from pathlib import Path

import numba
import numpy as np
from scene_runs import Recorder, area_weighted, scene_simulation, timed_run, whole_steps
from scipy.interpolate import LinearNDInterpolator

from lagice.scenes.hooks.compression import macro_stress
from lagice.stability import StabilityWarning

GRID_N = 60
#: velocities are compared as means over a final window (displacement / time), which
#: filters the elastic waves that the explicit sub-steps resolve and the implicit
#: solver damps: compression, the last 10 % of the run; wind_square, the last 3 h
WINDOW_FRACTION = 0.1
WIND_WINDOW_S = 3 * 3600.0
PLATE_WIDTH_M, PLATE_LENGTH_M, PUSH_SPEED_M_S = 100e3, 200e3, 1e-3  # uniaxial_compression
WIND_DOMAIN_M = 500e3  # wind_square
CS = 500.0  # shear wave speed [m s-1]: td = Δx/cs
DAY = 86400.0


# -- runs ------------------------------------------------------------------------------
def velocity_on_grid(nodes, vel, box):
    x0, y0, x1, y1 = box
    gx, gy = np.meshgrid(np.linspace(x0, x1, GRID_N), np.linspace(y0, y1, GRID_N))
    out = np.empty((GRID_N * GRID_N, 2))
    for k in range(2):
        f = LinearNDInterpolator(nodes, vel[:, k], fill_value=np.nan)
        out[:, k] = f(gx.ravel(), gy.ravel())
    return out


class WindowMean:
    """Callback: Σ Δt · transport velocity over the steps ending after ``t_start_s``
    (the displacement of a fixed-mesh run over the window)."""

    def __init__(self, sim, t_start_s):
        self.t_start_s = t_start_s
        self.disp = np.zeros_like(sim.model.state.velocity)
        sim.add_callback(self, every="1 steps", name="window_mean")

    def __call__(self, sim):
        if sim.model.clock.time_s > self.t_start_s:
            self.disp += sim.dt * sim.model.transport_velocity


class WindowStart:
    """Callback: the node positions and time at the first step end at or after ``t_start_s``."""

    def __init__(self, sim, t_start_s):
        self.t_start_s = t_start_s
        self.xy = self.time_s = None
        sim.add_callback(self, every="1 steps", name="window_start")
        if sim.model.clock.time_s >= t_start_s - 1e-6:
            self(sim)

    def __call__(self, sim):
        m = sim.model
        if self.xy is None and m.clock.time_s >= self.t_start_s - 1e-6:
            self.xy, self.time_s = m.mesh.nodes.copy(), m.clock.time_s


def _explicit_options(solver, safety):
    return {"solver.safety": safety} if solver == "explicit" else {}


def run_compression(n_across, solver, dt_factor, safety, max_strain):
    dx = PLATE_WIDTH_M / n_across
    dt = dt_factor * dx / CS
    n_steps = whole_steps(max_strain * PLATE_LENGTH_M / PUSH_SPEED_M_S, dt)
    sim = scene_simulation("uniaxial_compression", {
        "domain.resolution_m": dx, "solver.name": solver, "solver.dt": dt, "run.duration": n_steps * dt,
        "run.seed": 0, "output.timeseries": None, **_explicit_options(solver, safety)})
    model = sim.model
    t_win = (1.0 - WINDOW_FRACTION) * n_steps * dt
    win = WindowMean(sim, t_win)
    rec = Recorder(sim, stress=lambda m: -macro_stress(m),
                   substeps=lambda m: m.last_report["solver"].iterations)
    wall = timed_run(sim)
    strain = PUSH_SPEED_M_S * np.asarray(rec.time_s) / PLATE_LENGTH_M
    stress = rec["stress"]
    vel = win.disp / (model.clock.time_s - t_win)
    st = model.state
    area = model.mesh.areas()
    return {
        "scene": "uniaxial_compression", "solver": solver, "resolution_m": dx, "n_across": n_across,
        "dt_s": dt, "dt_over_td": dt_factor, "safety": safety if solver == "explicit" else None,
        "substeps": float(np.mean(rec["substeps"])) if solver == "explicit" else None,
        "n_elements": model.mesh.n_elements, "wall_s": wall, "steps": n_steps,
        "mean_damage": area_weighted(model, st.damage),
        "damaged_fraction": float(area[st.damage > 0.5].sum() / area.sum()),
        "peak_stress_pa": float(stress.max()), "strain_at_peak": float(strain[np.argmax(stress)]),
        "_grid_vel": velocity_on_grid(model.mesh.nodes, vel, (0, 0, PLATE_WIDTH_M, PLATE_LENGTH_M)),
        "_curve": (strain, stress),
    }


def run_wind(resolution_m, solver, dt_s, safety, days):
    n_steps = whole_steps(days * DAY, dt_s)
    t_end = n_steps * dt_s
    sim = scene_simulation("wind_square", {
        "domain.resolution_m": resolution_m, "solver.name": solver, "solver.dt": dt_s, "run.duration": t_end,
        "run.seed": 0, "output.timeseries": None, **_explicit_options(solver, safety)})
    model = sim.model
    start = WindowStart(sim, days * DAY - WIND_WINDOW_S)
    rec = Recorder(sim, substeps=lambda m: m.last_report["solver"].iterations)
    wall = timed_run(sim)
    vel = (model.mesh.nodes - start.xy) / (model.clock.time_s - start.time_s)  # Lagrangian mean velocity
    st = model.state
    area = model.mesh.areas()
    L = WIND_DOMAIN_M
    return {
        "scene": "wind_square", "solver": solver, "resolution_m": resolution_m, "dt_s": dt_s,
        "dt_over_td": dt_s / (resolution_m / CS), "safety": safety if solver == "explicit" else None,
        "substeps": float(np.mean(rec["substeps"])) if solver == "explicit" else None,
        "n_elements": model.mesh.n_elements, "wall_s": wall, "steps": n_steps,
        "mean_damage": area_weighted(model, st.damage),
        "damaged_fraction": float(area[st.damage > 0.5].sum() / area.sum()),
        "_grid_vel": velocity_on_grid(model.mesh.nodes, vel, (0.02 * L, 0.02 * L, 0.98 * L, 0.98 * L)),
    }


# -- metrics ----------------------------------------------------------------------------
def l2_rel(a, b):
    ok = np.isfinite(a).all(axis=1) & np.isfinite(b).all(axis=1)
    nb = np.linalg.norm(b[ok])
    return float(np.linalg.norm(a[ok] - b[ok]) / nb) if nb > 0 else float("nan")


def curve_err(run, ref):
    s, st = run["_curve"]
    rs, rst = ref["_curve"]
    smax = min(s[-1], rs[-1])
    grid = np.linspace(0, smax, 400)
    a = np.interp(grid, s, st)
    b = np.interp(grid, rs, rst)
    return float(np.sqrt(np.mean((a - b) ** 2)) / rst.max())


def add_errors(runs):
    by_scene = {}
    for r in runs:
        by_scene.setdefault(r["scene"], []).append(r)
    for scene, rs in by_scene.items():
        refs = {}
        for fam in ("implicit", "explicit"):
            cand = [r for r in rs if r["solver"] == fam and r.get("reference")]
            refs[fam] = cand[0] if cand else None
        for r in rs:
            own = refs[r["solver"]]
            other = refs["explicit" if r["solver"] == "implicit" else "implicit"]
            for tag, ref in (("own", own), ("other", other)):
                if ref is None:
                    continue
                r[f"vel_err_{tag}"] = l2_rel(r["_grid_vel"], ref["_grid_vel"])
                r[f"mean_damage_diff_{tag}"] = r["mean_damage"] - ref["mean_damage"]
                r[f"damaged_fraction_diff_{tag}"] = r["damaged_fraction"] - ref["damaged_fraction"]
                if scene == "uniaxial_compression":
                    r[f"stress_err_{tag}"] = curve_err(r, ref)
        # time-step check: a run against the series run of its family on the same mesh
        for r in rs:
            for q in rs:
                if q is not r and q.get("series") and q["solver"] == r["solver"] and \
                        q["resolution_m"] == r["resolution_m"] and r["dt_s"] < q["dt_s"]:
                    r.setdefault("dt_check", {})[str(q["dt_s"])] = l2_rel(r["_grid_vel"], q["_grid_vel"])


def pareto(points):
    """Indices of the Pareto-optimal (cost, error) points (both minimised)."""
    order = np.argsort([p[0] for p in points])
    front, best = [], np.inf
    for i in order:
        if points[i][1] < best:
            front.append(int(i))
            best = points[i][1]
    return front


# -- grid -------------------------------------------------------------------------------
#: the runs of each mode: compression N (elements across the 100 km plate) and
#: wind_square resolutions, coarse to fine; the finest is the reference mesh
MODES = {
    "quick": {"n_across": [10, 20], "max_strain": 3.2e-4, "wind_res": [50e3, 25e3], "wind_days": 1.0},
    "full": {"n_across": [10, 20, 40, 70], "max_strain": 3.2e-4, "wind_res": [50e3, 25e3, 12.5e3, 5e3],
             "wind_days": 1.0},
}
#: reference configuration of each family: (Δt/td or Δt [s], sub-step safety)
REF_COMP = {"implicit": (1.0, None), "explicit": (1.0, 0.35)}
REF_WIND = {"implicit": (1.0, None), "explicit": (60.0, 0.35)}  # implicit: Δt/td; explicit: Δt [s]


def plan(mode):
    """(compression runs, wind runs, max strain, wind days). Every resolution gets the
    reference configuration of both families (the convergence series) and a sweep of
    larger steps; the second-finest resolution also gets a smaller step than the
    reference one (is the reference step converged in time?)."""
    m = MODES[mode]
    comp, wind = [], []
    ns = m["n_across"]
    for n in ns:
        fine, check = n == ns[-1], len(ns) > 1 and n == ns[-2]
        for f in (0.25, 1.0, 4.0, 16.0):
            if f == 0.25 and not check:
                continue
            ser = (f, None) == REF_COMP["implicit"]
            comp.append(dict(n_across=n, solver="implicit", dt_factor=f, safety=None, series=ser,
                             reference=fine and ser))
        for f, sf in ((0.25, 0.35), (1.0, 0.35), (1.0, 0.7), (4.0, 0.7), (16.0, 0.7)):
            if f == 0.25 and not check:
                continue
            ser = (f, sf) == REF_COMP["explicit"]
            comp.append(dict(n_across=n, solver="explicit", dt_factor=f, safety=sf, series=ser,
                             reference=fine and ser))
    rs = m["wind_res"]
    for res in rs:
        fine, check = res == rs[-1], len(rs) > 1 and res == rs[-2]
        td = res / CS
        for f in (0.5, 1.0, 8.0, 64.0):
            if f == 0.5 and not check:
                continue
            ser = (f, None) == REF_WIND["implicit"]
            wind.append(dict(resolution_m=res, solver="implicit", dt_s=f * td, safety=None, series=ser,
                             reference=fine and ser))
        for dt, sf in ((30.0, 0.35), (60.0, 0.35), (300.0, 0.7), (1200.0, 0.7), (1200.0, 0.35), (3600.0, 0.7)):
            if dt == 30.0 and not check:
                continue
            ser = (dt, sf) == REF_WIND["explicit"]
            wind.append(dict(resolution_m=res, solver="explicit", dt_s=dt, safety=sf, series=ser,
                             reference=fine and ser))
    return comp, wind, m["max_strain"], m["wind_days"]


def warm_up():
    """Compile every kernel once, outside the timings (numba caches on disk)."""
    run_compression(4, "implicit", 1.0, None, 2e-5)
    run_compression(4, "explicit", 1.0, 0.7, 2e-5)
    run_wind(100e3, "implicit", 200.0, None, 0.01)
    run_wind(100e3, "explicit", 300.0, 0.7, 0.01)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--quick", action="store_true", help="meshes up to ~2k elements (< 10 min)")
    g.add_argument("--full", action="store_true", help="fine end >= 20 000 elements")
    ap.add_argument("--threads", type=int, default=1,
                    help="numba threads (1: the meshes here are small, one thread is fastest)")
    ap.add_argument("--only", choices=["uniaxial_compression", "wind_square"], help="run one scene only")
    ap.add_argument("--json", type=Path, default=Path(__file__).resolve().parent / Path("out/speed_accuracy.json"))
    ap.add_argument("--png", type=Path, default=Path("docs/figures/speed_accuracy.png"))
    ap.add_argument("--md", type=Path, default=Path("docs/speed_accuracy.md"))
    ap.add_argument("--notes", type=Path, default=Path(__file__).resolve().parent / Path("speed_accuracy_notes.md"),
                    help="hand-written discussion placed into the markdown (if the file exists)")
    ap.add_argument("--from-json", action="store_true",
                    help="only redraw the figure and the markdown from an existing --json file")
    ap.add_argument("--merge", type=Path, nargs="*", default=[],
                    help="with --from-json: more JSON files whose runs are added (e.g. one per scene)")
    a = ap.parse_args(argv)
    if a.from_json:
        data = json.loads(a.json.read_text())
        for extra in a.merge:
            more = json.loads(extra.read_text())
            data["runs"] += more["runs"]
            data["meta"]["total_wall_s"] += more["meta"]["total_wall_s"]
        finish(data["runs"], data["meta"], a)
        return
    mode = "full" if a.full else "quick"
    numba.set_num_threads(a.threads)
    warnings.simplefilter("ignore", StabilityWarning)
    comp, wind, max_strain, days = plan(mode)
    if a.only == "uniaxial_compression":
        wind = []
    elif a.only == "wind_square":
        comp = []
    t_all = time.perf_counter()
    warm_up()
    runs = []
    for c in comp:
        r = run_compression(c["n_across"], c["solver"], c["dt_factor"], c["safety"], max_strain)
        r["reference"], r["series"] = c["reference"], c["series"]
        runs.append(r)
        print(f"compression N={c['n_across']:3d} {c['solver']:8s} dt={r['dt_s']:7.2f} s sub={r['substeps']} "
              f"elements={r['n_elements']} wall={r['wall_s']:7.1f} s peak={r['peak_stress_pa'] / 1e3:6.1f} kPa "
              f"damage={r['mean_damage']:.4f}", flush=True)
    for c in wind:
        r = run_wind(c["resolution_m"], c["solver"], c["dt_s"], c["safety"], days)
        r["reference"], r["series"] = c["reference"], c["series"]
        runs.append(r)
        print(f"wind_square dx={c['resolution_m'] / 1e3:5.1f} km {c['solver']:8s} dt={r['dt_s']:7.1f} s "
              f"sub={r['substeps']} elements={r['n_elements']} wall={r['wall_s']:7.1f} s "
              f"damage={r['mean_damage']:.4f}", flush=True)
    total = time.perf_counter() - t_all
    add_errors(runs)
    clean = [_clean(r) for r in runs]
    meta = {"mode": mode, "quick": mode == "quick", "threads": a.threads, "total_wall_s": total,
            "max_strain": max_strain, "wind_days": days, "velocity_grid": GRID_N,
            "load_average": list(os_load()), "date": time.strftime("%Y-%m-%d")}
    a.json.parent.mkdir(parents=True, exist_ok=True)
    # the curves and window velocities stay in the --json file, so that --merge can
    # compute errors across files; the figure's JSON (docs) gets the scalars only
    a.json.write_text(json.dumps({"meta": meta, "runs": [_keep_arrays(r) for r in runs]}, indent=1))
    finish(clean, meta, a)
    print(f"total {total:.0f} s; wrote {a.json}, {a.png}, {a.md}")


def os_load():
    import os

    return tuple(round(x, 2) for x in os.getloadavg())


def _keep_arrays(r):
    out = {k: v for k, v in r.items() if not k.startswith("_")}
    out["grid_vel"] = np.asarray(r["_grid_vel"]).tolist()
    if "_curve" in r:
        out["curve"] = [np.asarray(x).tolist() for x in r["_curve"]]
    return out


def _clean(r):
    return {k: v for k, v in r.items() if not k.startswith("_") and k not in ("grid_vel", "curve")}


def finish(runs, meta, a):
    """Errors (when the runs carry their arrays), Pareto fronts, figure, figure JSON, markdown."""
    if runs and "grid_vel" in runs[0]:
        for r in runs:
            r["_grid_vel"] = np.asarray(r["grid_vel"], np.float64)
            if "curve" in r:
                r["_curve"] = tuple(np.asarray(x) for x in r["curve"])
        add_errors(runs)
        runs = [_clean(r) for r in runs]
    fronts = {}
    for scene in ("uniaxial_compression", "wind_square"):
        idx = [i for i, r in enumerate(runs) if r["scene"] == scene and not r["reference"]]
        pts = [(runs[i]["wall_s"], max(runs[i].get("vel_err_own", np.nan), 1e-12)) for i in idx]
        fronts[scene] = [idx[j] for j in pareto(pts)] if pts else []
        for r in runs:
            if r["scene"] == scene:
                r["pareto"] = False
        for i in fronts[scene]:
            runs[i]["pareto"] = True
    plot(runs, a.png)
    a.png.with_suffix(".json").write_text(json.dumps({"meta": meta, "runs": runs}, indent=1))
    notes = a.notes.read_text().strip().splitlines() if a.notes and a.notes.exists() else []
    write_markdown(runs, meta, a.md, a.png, notes)


def plot(runs, png):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenes = ("uniaxial_compression", "wind_square")
    fig, axes = plt.subplots(2, 2, figsize=(12, 9.2))
    colors = {"implicit": "tab:blue", "explicit": "tab:orange"}
    for ax, scene in zip(axes[0], scenes):
        rs = [r for r in runs if r["scene"] == scene and not r["reference"]]
        if not rs:
            continue
        sizes = sorted({r["resolution_m"] for r in runs if r["scene"] == scene})
        marks = dict(zip(sizes, "o^sDv"))
        for r in rs:
            e = r.get("vel_err_own", np.nan)
            eo = r.get("vel_err_other", np.nan)
            mk = marks[r["resolution_m"]]
            ax.scatter(r["wall_s"], e, c=colors[r["solver"]], marker=mk, s=45, zorder=3)
            ax.scatter(r["wall_s"], eo, facecolors="none", edgecolors=colors[r["solver"]], marker=mk,
                       s=45, zorder=2)
            lab = f"Δt={r['dt_s']:.0f}s" + (f"\nN={r['substeps']:.0f}" if r["solver"] == "explicit" else "")
            ax.annotate(lab, (r["wall_s"], e), fontsize=5, xytext=(3, 3), textcoords="offset points")
        fr = sorted([r for r in rs if r.get("pareto")], key=lambda r: r["wall_s"])
        ax.plot([r["wall_s"] for r in fr], [r["vel_err_own"] for r in fr], "k--", lw=1, zorder=1,
                label="Pareto front (vs own reference)")
        ax.scatter([], [], c="tab:blue", label="implicit vs implicit reference")
        ax.scatter([], [], c="tab:orange", label="explicit vs explicit reference")
        ax.scatter([], [], facecolors="none", edgecolors="0.3", label="open: vs the other solver's reference")
        for res in sizes:
            ax.scatter([], [], c="0.5", marker=marks[res], label=f"Δx = {res / 1e3:g} km")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("cost: wall time of the time loop (s)")
        ax.set_ylabel("relative L2 velocity error")
        refs = [r for r in runs if r["scene"] == scene and r["reference"]]
        ne = max((r["n_elements"] for r in refs), default=0)
        ax.set_title(f"{scene}: error vs cost (references: {ne} elements)", fontsize=9)
        ax.legend(fontsize=6, ncol=2)
    for ax, scene in zip(axes[1], scenes):
        for fam in ("implicit", "explicit"):
            ser = sorted([r for r in runs if r["scene"] == scene and r["solver"] == fam and r.get("series")
                          and not r["reference"]], key=lambda r: r["n_elements"])
            if not ser:
                continue
            x = [r["n_elements"] for r in ser]
            ax.loglog(x, [r.get("vel_err_own", np.nan) for r in ser], "o-", color=colors[fam],
                      label=f"{fam}: velocity vs own reference")
            ax.loglog(x, [r.get("vel_err_other", np.nan) for r in ser], "o:", color=colors[fam], mfc="none",
                      label=f"{fam}: velocity vs the other reference")
            if scene == "uniaxial_compression":
                ax.loglog(x, [r.get("stress_err_own", np.nan) for r in ser], "s--", color=colors[fam], ms=4,
                          label=f"{fam}: stress curve vs own reference")
        refs = [r for r in runs if r["scene"] == scene and r["reference"]]
        for r in refs:
            ax.axvline(r["n_elements"], color="0.6", lw=0.8, ls="--")
        if refs:
            xs = np.array([min(r["n_elements"] for r in runs if r["scene"] == scene), refs[0]["n_elements"]])
            ax.loglog(xs, 0.3 * (xs / xs[0]) ** -0.5, color="0.5", lw=0.8, label="slope −1/2 (first order in Δx)")
        ax.set_xlabel("elements (dashed: the reference mesh)")
        ax.set_ylabel("relative error")
        ax.set_title(f"{scene}: convergence at the reference step", fontsize=9)
        ax.legend(fontsize=6)
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=100)
    plt.close(fig)


def _f(x, fmt="{:.3g}"):
    return "–" if x is None or (isinstance(x, float) and not np.isfinite(x)) else fmt.format(x)


def _ref_text(scene, refs):
    out = []
    for fam in ("implicit", "explicit"):
        r = refs.get(fam)
        if r is None:
            continue
        sub = f", {r['substeps']:.0f} sub-steps (safety {r['safety']:g})" if fam == "explicit" else ""
        out.append(f"{fam}: Δx = {r['resolution_m'] / 1e3:g} km ({r['n_elements']} elements), "
                   f"Δt = {r['dt_s']:.3g} s (Δt/td = {r['dt_over_td']:.2f}){sub}, {r['wall_s']:.0f} s wall")
    return "; ".join(out)


def write_markdown(runs, meta, md, png, notes=()):
    mode = meta.get("mode", "quick" if meta.get("quick") else "full")
    load = meta.get("load_average")
    lines = ["# Speed–accuracy of the implicit and explicit solvers", "",
             f"Made by `benchmarks/speed_accuracy.py --{mode}` on {meta.get('date', '?')} through the scene builder "
             "and `Simulation` (the path of `lagice run`; the transport velocity of explicit runs is the sub-step "
             f"mean), {meta['threads']} numba thread(s), total {meta['total_wall_s']:.0f} s on the shared 2-vCPU "
             "development machine" + (f" (load average at the end {load[0]:.1f}, {load[1]:.1f}, {load[2]:.1f})"
                                      if load else "") + ". "
             "Error = relative L2 difference of the velocity averaged over a final window (compression: "
             "last 10 % of the run, the mean transport velocity; wind_square: last 3 h, Lagrangian displacement / "
             f"time; interpolated on a {meta['velocity_grid']}² grid) from the reference of the same solver family "
             "(*own*) and of the other family (*other*); compression also gives the RMS difference "
             "of the macroscopic stress–strain curve / reference peak. Cost = wall time of the time "
             "loop (`sim.run()`). ★ = on the Pareto front (cost vs own-reference velocity error). "
             "Regenerate the figure and this page from the JSON with `--from-json`.", "",
             f"![speed-accuracy](figures/{png.name})", "",
             "## References and convergence", "",
             "The reference of each family is its run on the finest mesh at the family's reference step "
             "(implicit: Δt = td = Δx/cs; explicit: compression Δt = td, wind_square Δt = 60 s, both with "
             "sub-steps at 0.35 × the stability limit). The same configuration on every coarser mesh is the "
             "convergence series (lower panels): its error against the reference falls as the mesh is refined. "
             "One run at the second-finest mesh with a smaller step (implicit Δt = td/4 (compression), "
             "td/2 (wind_square); explicit Δt = td/4, 30 s) measures how far the reference step is from "
             "converged in time.", ""]
    for scene in ("uniaxial_compression", "wind_square"):
        rs = [r for r in runs if r["scene"] == scene]
        if not rs:
            continue
        refs = {r["solver"]: r for r in rs if r["reference"]}
        lines.append(f"* **{scene}** — references: {_ref_text(scene, refs)}.")
        for fam in ("implicit", "explicit"):
            ser = sorted([r for r in rs if r["solver"] == fam and r.get("series") and not r["reference"]],
                         key=lambda r: r["n_elements"])
            if ser:
                lines.append(f"  {fam} convergence (elements: velocity error vs own reference"
                             + ("; stress-curve error" if scene == "uniaxial_compression" else "") + "): "
                             + ", ".join(f"{r['n_elements']}: {_f(r.get('vel_err_own'))}"
                                         + (f"; {_f(r.get('stress_err_own'))}" if scene == "uniaxial_compression"
                                            else "") for r in ser) + ".")
            ref = refs.get(fam)
            if ref is not None:
                series_res = sorted({r["resolution_m"] for r in rs})
                if len(series_res) > 1:
                    second = series_res[1]
                    same = [r for r in rs if r["solver"] == fam and r["resolution_m"] == second]
                    s_ref = [r for r in same if r.get("series")]
                    smaller = [r for r in same if s_ref and r["dt_s"] < s_ref[0]["dt_s"]]
                    if s_ref and smaller:
                        d = l2_rel_lists(smaller[0], s_ref[0])
                        if d is not None:
                            lines.append(f"  {fam} time-step check at Δx = {second / 1e3:g} km: Δt = "
                                         f"{smaller[0]['dt_s']:.3g} s and {s_ref[0]['dt_s']:.3g} s differ by "
                                         f"{_f(d)} (velocity).")
    if notes:
        lines += [""] + list(notes)
    lines += ["", "## Summary (computed from this run)", ""]
    for scene in ("uniaxial_compression", "wind_square"):
        rs = [r for r in runs if r["scene"] == scene]
        refs = {r["solver"]: r for r in rs if r["reference"]}
        if len(refs) == 2:
            ri, re_ = refs["implicit"], refs["explicit"]
            txt = (f"* **{scene}**: the references of the two families differ by "
                   f"{_f(re_.get('vel_err_other'))} (relative L2, window-mean velocity); mean damage "
                   f"implicit {ri['mean_damage']:.3f} vs explicit {re_['mean_damage']:.3f}, damaged-area "
                   f"fraction {ri['damaged_fraction']:.3f} vs {re_['damaged_fraction']:.3f}")
            if "peak_stress_pa" in ri:
                txt += (f"; peak macroscopic stress {ri['peak_stress_pa'] / 1e3:.1f} vs "
                        f"{re_['peak_stress_pa'] / 1e3:.1f} kPa, stress-curve difference "
                        f"{_f(re_.get('stress_err_other'))} of the peak")
            lines.append(txt + ".")
        fr = sorted([r for r in rs if r.get("pareto")], key=lambda r: r["wall_s"])
        if fr:
            lines.append("  Pareto front: " + "; ".join(
                f"{r['solver']} Δx={r['resolution_m'] / 1e3:g} km Δt={r['dt_s']:.0f} s "
                f"({r['wall_s']:.2f} s, err {_f(r.get('vel_err_own'))})" for r in fr) + ".")
    lines.append("")
    for scene in ("uniaxial_compression", "wind_square"):
        rs = [r for r in runs if r["scene"] == scene]
        if not rs:
            continue
        extra = " | stress err own | stress err other" if scene == "uniaxial_compression" else ""
        lines += [f"## {scene}", "",
                  "| solver | Δx (km) | Δt (s) | Δt/td | sub-steps | elements | wall (s) | vel err own | "
                  "vel err other | mean damage | damaged frac" + extra + " |",
                  "|---" * (11 + (2 if extra else 0)) + "|"]
        for r in sorted(rs, key=lambda r: (r["solver"], -r["resolution_m"], r["dt_s"], r["safety"] or 0)):
            star = " ★" if r.get("pareto") else (" (ref)" if r["reference"] else "")
            row = (f"| {r['solver']}{star} | {r['resolution_m'] / 1e3:.1f} | {r['dt_s']:.1f} | "
                   f"{r['dt_over_td']:.2f} | {_f(r['substeps'], '{:.0f}')} | {r['n_elements']} | "
                   f"{r['wall_s']:.2f} | {_f(r.get('vel_err_own'))} | {_f(r.get('vel_err_other'))} | "
                   f"{r['mean_damage']:.4f} | {r['damaged_fraction']:.4f}")
            if extra:
                row += f" | {_f(r.get('stress_err_own'))} | {_f(r.get('stress_err_other'))}"
            lines.append(row + " |")
        lines.append("")
    md.parent.mkdir(parents=True, exist_ok=True)
    md.write_text("\n".join(lines) + "\n")


def l2_rel_lists(a, b):
    """Velocity difference of two runs of the same mesh (``dt_check`` from add_errors)."""
    return a.get("dt_check", {}).get(str(b["dt_s"]))


if __name__ == "__main__":
    main()
