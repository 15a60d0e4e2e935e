"""Speed–accuracy chart of the implicit and explicit solvers (issue 3).

Runs ``uniaxial_compression`` and ``wind_square`` over a grid of (solver, Δt,
sub-step size, resolution) and measures, for every run:

* cost: wall time of the time loop [s] (numba compilation excluded by a warm-up run);
* L2 velocity error, ‖u − u_ref‖/‖u_ref‖ of the velocity averaged over a final
  window (compression: last 10 % of the run; wind_square: last 3 h, from the node
  displacements), on a regular 60×60 grid (linear interpolation from the nodes,
  so different resolutions compare). Instantaneous velocities are not used: the
  explicit solver resolves elastic waves that ring in undamaged ice (Maxwell
  λ0 = 1e7 s) and dominate the instantaneous field; the implicit solver damps them;
  against the fine reference of the **same** solver family (smallest Δt, smallest
  sub-step, finest resolution) and against the fine reference of the **other** family;
* mean damage and damaged-area fraction (d > 0.5) at the end;
* compression only: the macroscopic stress–strain curve, error = RMS difference
  from the reference curve divided by the reference peak stress.

Writes ``benchmarks/out/speed_accuracy.json``, ``docs/figures/speed_accuracy.png``
(log–log error vs cost, Pareto front of each scene marked) and
``docs/speed_accuracy.md`` (tables).

    python benchmarks/speed_accuracy.py --quick      # < 10 min on 2 cores
    python benchmarks/speed_accuracy.py              # larger grid
"""
from __future__ import annotations

import argparse
import json
import time
import warnings
from pathlib import Path

import numba
import numpy as np
from scipy.interpolate import LinearNDInterpolator

from lagice.scenes import compression, wind_square
from lagice.stability import StabilityWarning

GRID_N = 60
#: velocities are compared as means over a final window (displacement / time), which
#: filters the elastic waves that the explicit sub-steps resolve and the implicit
#: solver damps: compression, the last 10 % of the run; wind_square, the last 3 h
WINDOW_FRACTION = 0.1
WIND_WINDOW_S = 3 * 3600.0


def _vel(sc):
    v = getattr(sc.solver, "mean_velocity", None)
    return sc.state.velocity if v is None else v


# -- runs ------------------------------------------------------------------------------
def velocity_on_grid(nodes, vel, box):
    x0, y0, x1, y1 = box
    gx, gy = np.meshgrid(np.linspace(x0, x1, GRID_N), np.linspace(y0, y1, GRID_N))
    out = np.empty((GRID_N * GRID_N, 2))
    for k in range(2):
        f = LinearNDInterpolator(nodes, vel[:, k], fill_value=np.nan)
        out[:, k] = f(gx.ravel(), gy.ravel())
    return out


def run_compression(n_across, solver, dt_factor, safety, max_strain):
    width = 0.5 * compression.PLATE_LENGTH_M
    td = width / n_across / 500.0
    kw = {"safety": safety} if solver == "explicit" else {}
    sc = compression.build(n_across=n_across, solver=solver, dt_s=dt_factor * td, seed=0, **kw)
    n_steps = int(np.ceil(max_strain * sc.length_m / sc.push_speed_m_s / sc.dt_s))
    strain, stress = np.zeros(n_steps), np.zeros(n_steps)
    subs = []
    t_win = (1.0 - WINDOW_FRACTION) * n_steps * sc.dt_s
    disp = np.zeros_like(sc.state.velocity)
    t0 = time.perf_counter()
    for k in range(n_steps):
        info = sc.solver.step(sc.state, sc.dt_s)
        subs.append(info.iterations)
        strain[k] = sc.push_speed_m_s * sc.state.time_s / sc.length_m
        stress[k] = -compression.macro_stress(sc)
        if sc.state.time_s > t_win:
            disp += sc.dt_s * _vel(sc)
    wall = time.perf_counter() - t0
    vel = disp / (sc.state.time_s - t_win)
    area = sc.solver.area
    return {
        "scene": "uniaxial_compression", "solver": solver, "resolution_m": sc.dx_m, "n_across": n_across,
        "dt_s": sc.dt_s, "dt_over_td": dt_factor, "safety": safety if solver == "explicit" else None,
        "substeps": float(np.mean(subs)) if solver == "explicit" else None,
        "n_elements": sc.mesh.n_elements, "wall_s": wall,
        "mean_damage": float(np.average(sc.state.damage, weights=area)),
        "damaged_fraction": float(area[sc.state.damage > 0.5].sum() / area.sum()),
        "peak_stress_pa": float(stress.max()), "strain_at_peak": float(strain[np.argmax(stress)]),
        "_grid_vel": velocity_on_grid(sc.mesh.nodes, vel, (0, 0, sc.width_m, sc.length_m)),
        "_curve": (strain, stress),
    }


def run_wind(resolution_m, solver, dt_s, safety, days):
    kw = {"safety": safety} if solver == "explicit" else {}
    sc = wind_square.build(resolution_m=resolution_m, solver=solver, dt_s=dt_s, days=days, seed=0, **kw)
    n_steps = int(np.ceil(sc.t_end_s / sc.dt_s - 1e-9))
    subs = []
    t_win = sc.t_end_s - WIND_WINDOW_S
    x_start = None
    t0 = time.perf_counter()
    for _ in range(n_steps):
        if x_start is None and sc.state.time_s >= t_win - 1e-6:
            x_start, t_start = sc.mesh.nodes.copy(), sc.state.time_s
        info = sc.solver.step(sc.state, sc.dt_s)
        subs.append(info.iterations)
        wind_square.lagrangian_step(sc.mesh, sc.state, sc.solver, sc.dt_s)
    wall = time.perf_counter() - t0
    vel = (sc.mesh.nodes - x_start) / (sc.state.time_s - t_start)  # Lagrangian mean velocity
    area = sc.solver.area
    L = wind_square.DOMAIN_M
    return {
        "scene": "wind_square", "solver": solver, "resolution_m": resolution_m, "dt_s": sc.dt_s,
        "dt_over_td": sc.dt_s / (resolution_m / 500.0), "safety": safety if solver == "explicit" else None,
        "substeps": float(np.mean(subs)) if solver == "explicit" else None,
        "n_elements": sc.mesh.n_elements, "wall_s": wall,
        "mean_damage": float(np.average(sc.state.damage, weights=area)),
        "damaged_fraction": float(area[sc.state.damage > 0.5].sum() / area.sum()),
        "_grid_vel": velocity_on_grid(sc.mesh.nodes, vel, (0.02 * L, 0.02 * L, 0.98 * L, 0.98 * L)),
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
def plan(quick):
    comp, wind = [], []
    if quick:
        n_list, max_strain = [10, 20], 3.2e-4
        res_list, days = [50e3, 25e3], 1.0
    else:
        n_list, max_strain = [10, 20], 3.2e-4
        res_list, days = [25e3, 12.5e3], 2.0
    nref = max(n_list)
    for n in n_list:
        for f in ((0.25, 1.0, 4.0, 16.0) if n == nref else (1.0, 4.0, 16.0)):
            comp.append(dict(n_across=n, solver="implicit", dt_factor=f, safety=None,
                             reference=(n == nref and f == 0.25)))
        for f, sf in ((0.25, 0.35), (1.0, 0.7), (1.0, 0.35), (4.0, 0.7), (16.0, 0.7)):
            if n != nref and f == 0.25:
                continue
            comp.append(dict(n_across=n, solver="explicit", dt_factor=f, safety=sf,
                             reference=(n == nref and f == 0.25)))
    rref = min(res_list)
    for res in res_list:
        td = res / 500.0
        for f in ((0.5, 1.0, 8.0, 64.0) if res == rref else (1.0, 8.0, 64.0)):
            wind.append(dict(resolution_m=res, solver="implicit", dt_s=f * td, safety=None,
                             reference=(res == rref and f == 0.5)))
        for dt, sf in ((60.0, 0.35), (300.0, 0.7), (1200.0, 0.7), (1200.0, 0.35), (3600.0, 0.7)):
            if res != rref and dt == 60.0:
                continue
            wind.append(dict(resolution_m=res, solver="explicit", dt_s=dt, safety=sf,
                             reference=(res == rref and dt == 60.0)))
    return comp, wind, max_strain, days


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--threads", type=int, default=1,
                    help="numba threads (1: the meshes here are small, one thread is fastest)")
    ap.add_argument("--json", type=Path, default=Path("benchmarks/out/speed_accuracy.json"))
    ap.add_argument("--png", type=Path, default=Path("docs/figures/speed_accuracy.png"))
    ap.add_argument("--md", type=Path, default=Path("docs/speed_accuracy.md"))
    ap.add_argument("--from-json", action="store_true",
                    help="only redraw the figure and the markdown from an existing --json file")
    a = ap.parse_args(argv)
    if a.from_json:
        data = json.loads(a.json.read_text())
        plot(data["runs"], a.png)
        write_markdown(data["runs"], data["meta"], a.md, a.png)
        print(f"wrote {a.png}, {a.md}")
        return
    numba.set_num_threads(a.threads)
    warnings.simplefilter("ignore", StabilityWarning)
    comp, wind, max_strain, days = plan(a.quick)
    t_all = time.perf_counter()
    # warm-up: compile every kernel once, outside the timings
    run_compression(4, "implicit", 1.0, None, 2e-5)
    run_compression(4, "explicit", 1.0, 0.7, 2e-5)
    runs = []
    for c in comp:
        r = run_compression(c["n_across"], c["solver"], c["dt_factor"], c["safety"], max_strain)
        r["reference"] = c["reference"]
        runs.append(r)
        print(f"compression N={c['n_across']:3d} {c['solver']:8s} dt={r['dt_s']:7.1f} s sub={r['substeps']} "
              f"wall={r['wall_s']:6.1f} s peak={r['peak_stress_pa'] / 1e3:6.1f} kPa "
              f"damage={r['mean_damage']:.4f}", flush=True)
    for c in wind:
        r = run_wind(c["resolution_m"], c["solver"], c["dt_s"], c["safety"], days)
        r["reference"] = c["reference"]
        runs.append(r)
        print(f"wind_square dx={c['resolution_m'] / 1e3:5.1f} km {c['solver']:8s} dt={r['dt_s']:7.1f} s "
              f"sub={r['substeps']} wall={r['wall_s']:6.1f} s damage={r['mean_damage']:.4f}", flush=True)
    add_errors(runs)
    total = time.perf_counter() - t_all
    clean = [{k: v for k, v in r.items() if not k.startswith("_")} for r in runs]
    fronts = {}
    for scene in ("uniaxial_compression", "wind_square"):
        idx = [i for i, r in enumerate(clean) if r["scene"] == scene and not r["reference"]]
        pts = [(clean[i]["wall_s"], max(clean[i].get("vel_err_own", np.nan), 1e-12)) for i in idx]
        fronts[scene] = [idx[j] for j in pareto(pts)]
        for i in fronts[scene]:
            clean[i]["pareto"] = True
    meta = {"quick": a.quick, "threads": a.threads, "total_wall_s": total, "max_strain": max_strain,
            "wind_days": days, "velocity_grid": GRID_N}
    a.json.parent.mkdir(parents=True, exist_ok=True)
    a.json.write_text(json.dumps({"meta": meta, "runs": clean}, indent=1))
    plot(clean, a.png)
    write_markdown(clean, meta, a.md, a.png)
    print(f"total {total:.0f} s; wrote {a.json}, {a.png}, {a.md}")


def plot(runs, png):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenes = ("uniaxial_compression", "wind_square")
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    colors = {"implicit": "tab:blue", "explicit": "tab:orange"}
    for ax, scene in zip(axes, scenes):
        rs = [r for r in runs if r["scene"] == scene and not r["reference"]]
        for r in rs:
            e = r.get("vel_err_own", np.nan)
            eo = r.get("vel_err_other", np.nan)
            mk = "o" if r["resolution_m"] == min(x["resolution_m"] for x in rs) else "s"
            ax.scatter(r["wall_s"], e, c=colors[r["solver"]], marker=mk, s=45, zorder=3)
            ax.scatter(r["wall_s"], eo, facecolors="none", edgecolors=colors[r["solver"]], marker=mk,
                       s=45, zorder=2)
            lab = f"Δt={r['dt_s']:.0f}s" + (f"\nN={r['substeps']:.0f}" if r["solver"] == "explicit" else "")
            ax.annotate(lab, (r["wall_s"], e), fontsize=6, xytext=(3, 3), textcoords="offset points")
        fr = sorted([r for r in rs if r.get("pareto")], key=lambda r: r["wall_s"])
        ax.plot([r["wall_s"] for r in fr], [r["vel_err_own"] for r in fr], "k--", lw=1, zorder=1,
                label="Pareto front (vs own reference)")
        ax.scatter([], [], c="tab:blue", label="implicit vs implicit reference")
        ax.scatter([], [], c="tab:orange", label="explicit vs explicit reference")
        ax.scatter([], [], facecolors="none", edgecolors="0.3", label="open: vs the other solver's reference")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("cost: wall time (s)")
        ax.set_ylabel("relative L2 velocity error")
        ax.set_title(scene + " (circle: finest resolution, square: coarser)", fontsize=9)
        ax.legend(fontsize=7)
    fig.tight_layout()
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=100)
    plt.close(fig)


def _f(x, fmt="{:.3g}"):
    return "–" if x is None or (isinstance(x, float) and not np.isfinite(x)) else fmt.format(x)


def write_markdown(runs, meta, md, png):
    lines = ["# Speed–accuracy of the implicit and explicit solvers", "",
             "Made by `benchmarks/speed_accuracy.py`" + (" --quick" if meta["quick"] else "")
             + f" ({meta['threads']} numba thread(s); total {meta['total_wall_s']:.0f} s). "
             "Error = relative L2 difference of the velocity averaged over a final window (compression: "
             "last 10 % of the run; wind_square: last 3 h, Lagrangian displacement / time; interpolated on a "
             f"{meta['velocity_grid']}² grid) from the fine reference of the same solver family "
             "(*own*) and of the other family (*other*); compression also gives the RMS difference "
             "of the macroscopic stress–strain curve / reference peak. Cost = wall time of the time "
             "loop. ★ = on the Pareto front (cost vs own-reference velocity error).", "",
             f"![speed-accuracy](figures/{png.name})", ""]
    lines += ["## Summary (computed from this run)", ""]
    for scene in ("uniaxial_compression", "wind_square"):
        rs = [r for r in runs if r["scene"] == scene]
        refs = {r["solver"]: r for r in rs if r["reference"]}
        if len(refs) == 2:
            ri, re_ = refs["implicit"], refs["explicit"]
            txt = (f"* **{scene}**: the fine references of the two families differ by "
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


if __name__ == "__main__":
    main()
