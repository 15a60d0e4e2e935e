"""Stability map of the two solvers (issue 3).

For each solver, the largest stable time step as a function of resolution Δx,
Young modulus E0 and damage exponent α, on a small wind-driven closed basin: the
``wind_square`` scene (scene builder + Simulation, the path of ``lagice run``)
on a 200 km square, 20 m/s wind ramped over 1 h and turned over 1 h, Coriolis,
ocean drag, healing on, Lagrangian mesh motion (nodes move with the transport
velocity, the sub-step mean for the explicit stepper).

A run is *stable* when the production run finishes: Simulation's NaN/speed checker
stops a run at the first NaN/Inf in the state or at an ice speed above
``run.max_speed_m_s``, here twice the free-drift speed of the full wind (confined
ice cannot be faster than free ice; an instability grows far past it), and the
mesh-motion component refuses inverted elements.

* explicit: bisection on C = Δt_s sqrt(E0/ρ) / Δx_min (sub-step Δt_s, 10
  sub-steps per outer step) — the elastic-wave (CFL) law — on undamageable
  ice (cohesion 1e9 Pa): with damage on, an unstable run shakes the ice to
  pieces, the softened ice (small E) is then stable and the speed bound alone
  would call the run stable (seen at C = 1.6 with damage; 1.1 is unstable
  without). The smallest C over
  the grid is the limit the model ships (``--write-limits``).
* implicit: Δt = k·td for k = 1, 4, 16, ... (td = Δx/cs): the largest stable k.

Writes ``benchmarks/out/stability.json``, ``docs/figures/stability.png`` and
``docs/figures/stability.json``.

    python benchmarks/stability.py --quick           # small grid, a few minutes
    python benchmarks/stability.py --write-limits    # also update lagice/data/stability_limits.json
"""
from __future__ import annotations

import argparse
import itertools
import json
import math
import time
import warnings
from functools import cache
from pathlib import Path

import numba
import numpy as np
from scene_runs import scene_dx_min, scene_simulation, whole_steps

from lagice.errors import SolverError
from lagice.forces import free_drift_velocity
from lagice.params import RHO_AIR, coriolis_from_latitude
from lagice.stability import LIMITS_PATH, StabilityWarning

DOMAIN = 200e3
WIND = 20.0
LAT = 75.0
RHO_I = 900.0
CS = 500.0  # shear wave speed of the scene [m s-1]: td = Δx/cs


def free_drift_speed():
    tau = RHO_AIR * 1.2e-3 * WIND * WIND
    return abs(free_drift_velocity(complex(tau, 0.0), coriolis_from_latitude(LAT), RHO_I))


def overrides(res, E0, alpha, elastic=False):
    """The wind_square scene of the stability map (everything but the time step)."""
    ov = {"domain.width_m": DOMAIN, "domain.height_m": DOMAIN, "domain.resolution_m": res,
          "forcing.wind.params.speed_m_s": WIND, "forcing.wind.params.ramp_h": 1.0,
          "forcing.wind.params.turn_h": 1.0, "forcing.coriolis.latitude_deg": LAT,
          "rheology.young_modulus_pa": E0, "rheology.alpha": alpha,
          "run.max_speed_m_s": 2.0 * free_drift_speed(), "output.timeseries": None}
    if elastic:
        ov.update({"rheology.cohesion_min_pa": 1e9, "rheology.cohesion_max_pa": 1e9})
    return ov


def run_case(solver, res, E0, alpha, dt, duration_s, substeps=None, elastic=False):
    """(stable, reason, max speed [m s-1]) of one run (see module doc). ``elastic``:
    cohesion 1e9 Pa (no damage), so that damage cannot mask an instability by
    softening the ice it has shaken apart."""
    ov = overrides(res, E0, alpha, elastic)
    n = whole_steps(duration_s, dt)
    ov.update({"solver.name": solver, "solver.dt": dt, "run.duration": n * dt})
    if solver == "explicit":
        ov.update({"solver.substeps": substeps, "solver.allow_unstable": True})
    else:
        ov["solver.linear_solver"] = "cg"
    sim = scene_simulation("wind_square", ov)
    vmax = [0.0]

    def track(sim):
        m = sim.model
        vmax[0] = max(vmax[0], float(np.abs(m.state.velocity).max()), float(np.abs(m.transport_velocity).max()))

    sim.add_callback(track, every="1 steps", name="max_speed")
    try:
        sim.run()
    except SolverError as exc:
        msg = str(exc)
        why = ("speed above 2x free drift" if "above the bound" in msg else "inverted" if "invert" in msg
               else "nan")
        return False, why, vmax[0]
    return True, "stable", vmax[0]


@cache
def dx_min_of(res):
    """Δx_min of the scene's mesh at ``res`` (the mesh does not depend on E0 or α)."""
    return scene_dx_min("wind_square", overrides(res, 1e9, 4.0))


def explicit_limit(res, E0, alpha, duration_s, lo=0.3, hi=1.6, iters=6):
    dxm = dx_min_of(res)
    c = math.sqrt(E0 / RHO_I)
    sub = 10
    ok_hi = run_case("explicit", res, E0, alpha, sub * hi * dxm / c, duration_s, sub, elastic=True)[0]
    if ok_hi:
        return {"C": hi, "bracket": [hi, None], "dx_min_m": dxm}
    for _ in range(iters):
        mid = 0.5 * (lo + hi)
        ok, why, _ = run_case("explicit", res, E0, alpha, sub * mid * dxm / c, duration_s, sub,
                              elastic=True)
        if ok:
            lo = mid
        else:
            hi = mid
    return {"C": lo, "bracket": [lo, hi], "dx_min_m": dxm, "dt_s_max": lo * dxm / c}


def implicit_limit(res, E0, alpha, duration_s, ks):
    td = res / CS
    last_ok, fail = None, None
    for k in ks:
        ok, why, vmax = run_case("implicit", res, E0, alpha, k * td, max(duration_s, 6 * k * td))
        if ok:
            last_ok = k
        else:
            fail = {"k": k, "reason": why}
            break
    return {"dt_over_td_max": last_ok, "first_unstable": fail, "td_s": td}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--write-limits", action="store_true")
    ap.add_argument("--json", type=Path, default=Path(__file__).resolve().parent / Path("out/stability.json"))
    ap.add_argument("--png", type=Path, default=Path("docs/figures/stability.png"))
    ap.add_argument("--from-json", action="store_true", help="only redraw the figure from --json")
    a = ap.parse_args(argv)
    if a.from_json:
        data = json.loads(a.json.read_text())
        plot(data["rows"], data["implicit_k"], a.png)
        print(f"wrote {a.png}")
        return
    numba.set_num_threads(1)  # tiny meshes
    warnings.simplefilter("ignore", StabilityWarning)
    E_def = 2 * 500.0**2 * 1.3 * RHO_I
    if a.quick:
        grid = dict(res=[20e3, 10e3], E0=[E_def / 4, E_def], alpha=[2.0, 4.0])
        cases = list(itertools.product(grid["res"], grid["E0"], grid["alpha"]))
        ks = [1, 8, 64, 512]
        dur_exp, dur_imp = 2 * 3600.0, 3 * 3600.0
    else:
        grid = dict(res=[20e3, 10e3, 5e3], E0=[E_def / 10, E_def / 3, E_def, 3 * E_def], alpha=[2.0, 4.0, 5.0])
        # α only changes λ (Maxwell relaxation, unconditionally stable): the full α
        # axis at 20 and 10 km, α = 4 at 5 km
        cases = [c for c in itertools.product(grid["res"], grid["E0"], grid["alpha"])
                 if c[0] > 5e3 or (c[2] == 4.0 and c[1] != E_def / 3)]
        ks = [1, 4, 16, 64, 256, 1024]
        dur_exp, dur_imp = 3 * 3600.0, 6 * 3600.0
    rows = []
    t0 = time.perf_counter()
    for res, E0, alpha in cases:
        ex = explicit_limit(res, E0, alpha, dur_exp)
        im = implicit_limit(res, E0, alpha, dur_imp, ks)
        row = {"resolution_m": res, "E0_pa": E0, "alpha": alpha, "explicit": ex, "implicit": im}
        rows.append(row)
        print(f"dx = {res / 1e3:4.0f} km  E0 = {E0:9.3g} Pa  alpha = {alpha:3.1f}   explicit C = "
              f"{ex['C']:.3f} (dt_s,max = {ex.get('dt_s_max', float('nan')):.3g} s)   implicit dt/td max = "
              f"{im['dt_over_td_max']} (first unstable: {im['first_unstable']})   "
              f"[{time.perf_counter() - t0:.0f} s]", flush=True)
    Cs = np.array([r["explicit"]["C"] for r in rows])
    summary = {"explicit_C_min": float(Cs.min()), "explicit_C_max": float(Cs.max()),
               "explicit_C_spread": float(Cs.max() / Cs.min()),
               "implicit_dt_over_td_max": [r["implicit"]["dt_over_td_max"] for r in rows],
               "free_drift_speed_m_s": free_drift_speed(), "wall_s": time.perf_counter() - t0}
    a.json.parent.mkdir(parents=True, exist_ok=True)
    data = json.dumps({"grid": grid, "implicit_k": ks, "rows": rows, "summary": summary}, indent=1)
    a.json.write_text(data)
    a.png.parent.mkdir(parents=True, exist_ok=True)
    a.png.with_suffix(".json").write_text(data)  # the data of the figure, next to it
    print(json.dumps(summary, indent=1))
    plot(rows, ks, a.png)
    if a.write_limits:
        imp_all = [r["implicit"]["dt_over_td_max"] for r in rows]
        imp_fail = [r["implicit"]["first_unstable"] for r in rows]
        limits = {
            "explicit": {
                "law": "dt_s_max = C * dx_min / sqrt(E / rho_ice)",
                "C": math.floor(100 * float(Cs.min())) / 100,
                "C_range_measured": [float(Cs.min()), float(Cs.max())],
                "grid": grid, "source": "benchmarks/stability.py (wind_square through Simulation)",
            },
            "implicit": {
                "law": ("dt_max = dt_over_td_max * td, td = dx/cs" if any(imp_fail)
                        else f"none found up to dt = {max(ks)} td"),
                "dt_over_td_max": (min(k for k in imp_all if k is not None) if any(imp_fail) else None),
                "tested_dt_over_td": ks, "source": "benchmarks/stability.py (wind_square through Simulation)",
            },
        }
        LIMITS_PATH.write_text(json.dumps(limits, indent=1) + "\n")
        print(f"wrote {LIMITS_PATH}")


def plot(rows, ks, png):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    alphas = sorted({r["alpha"] for r in rows})
    marks = dict(zip(alphas, "os^D"))
    for r in rows:
        ex = r["explicit"]
        c = math.sqrt(r["E0_pa"] / RHO_I)
        ax[0].scatter(ex["dx_min_m"] / c, ex["C"] * ex["dx_min_m"] / c, marker=marks[r["alpha"]],
                      c=[np.log10(r["E0_pa"])], vmin=7.5, vmax=9.5, cmap="viridis", s=40)
    xd = [r["explicit"]["dx_min_m"] / math.sqrt(r["E0_pa"] / RHO_I) for r in rows]
    xs = np.array([0.8 * min(xd), 1.25 * max(xd)])
    Cmin = min(r["explicit"]["C"] for r in rows)
    ax[0].plot(xs, Cmin * xs, "k--", lw=1, label=f"Δt_s = {Cmin:.2f} Δx_min/√(E/ρ)")
    ax[0].set_xscale("log")
    ax[0].set_yscale("log")
    from matplotlib.ticker import NullFormatter

    ax[0].xaxis.set_minor_formatter(NullFormatter())
    ax[0].yaxis.set_minor_formatter(NullFormatter())
    ax[0].set_xlabel("Δx_min / √(E0/ρ)  (s)")
    ax[0].set_ylabel("largest stable sub-step Δt_s (s)")
    ax[0].set_title("explicit: elastic-wave limit (colour: log10 E0, marker: α)", fontsize=9)
    ax[0].legend(fontsize=8)
    labels = []
    for i, r in enumerate(rows):
        im = r["implicit"]
        k = im["dt_over_td_max"] or 0.5
        col = "tab:green" if im["first_unstable"] is None else "tab:red"
        ax[1].bar(i, k, color=col)
        labels.append(f"{r['resolution_m'] / 1e3:.0f} km {r['E0_pa'] / 1e6:.0f} MPa α={r['alpha']:.0f}")
    ax[1].set_yscale("log", base=2)
    ax[1].set_xticks(range(len(rows)))
    ax[1].set_xticklabels(labels, fontsize=5, rotation=90)
    ax[1].set_ylabel("largest stable Δt / td")
    ax[1].set_title(f"implicit (green: stable up to the largest tried, {max(ks)} td; red: a larger one failed)",
                    fontsize=9)
    fig.tight_layout()
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=100)
    plt.close(fig)


if __name__ == "__main__":
    main()
