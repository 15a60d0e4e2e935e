"""A run's 3-day window statistics from the node motion and from the strain the rheology used,
side by side (docs/physics.md §4, "The published windows split", fortieth session).

The published statistics (``benchmarks/validate.py``, ``physics_experiments.py``) are taken over
back-to-back 3-day Lagrangian windows of the node motion, as RGPS's are of its cells. With linear
velocities the nodes move with the field the rheology uses. With Crouzeix–Raviart velocities each
element has its own linear field and the nodes move with the vertex mean of those fields
(docs/solvers.md, "What the mesh follows"), so the windows measure a smoothed field. The
thirty-ninth session compared the two over one-hour blocks (``cr_node_motion.py --statistics``);
this script does it for the published windows themselves.

A run made with ``output.accumulate_strain = true`` carries in every snapshot the time integral of
the strain rate its rheology used (:meth:`lagice.model.Model.step`; remeshing remaps it as an
area-weighted mean). For each window, :func:`lagice.diagnostics.windows.accumulated_strain_rates`
gives, on the triangles the window follows, the node motion's Lagrangian rates (what the published
statistics use) and the rheology's mean rates (the difference of the accumulated strain between the
window's ends). The same estimators (:func:`lagice.diagnostics.report.rate_statistics`) are applied
to both, on the elements at least 100 km from the coast, and the medians over the windows are set
side by side with the window-by-window differences (rheology minus nodes; 90 % bootstrap interval
of their median and the share of windows where it is positive: ``cr_node_motion.paired_differences``).

    python benchmarks/window_split.py F10-hthick-m10-acc F10-hthick-P-vcrj1-m10-acc
    python benchmarks/window_split.py --from-json docs/figures/window_split.json   # the table again
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

# the one-hour blocks' statistics, coast buffer and paired differences, for the windows
from cr_node_motion import BUFFER_M, paired_differences
from cr_node_motion import STAT_KEYS as KEYS

ROOT = Path(__file__).resolve().parents[1]
RUNS = ROOT / "benchmarks" / "out" / "physics"
DAY_S = 86400.0
#: the published windows: 3 days from day 1 (100 km from the coast: BUFFER_M)
WINDOW_DAYS, START_DAY = 3.0, 1.0
SHORT = {"beta_space": "β", "pdf_tail_exponent_shear": "shear tail", "pdf_tail_exponent_divergence": "|div| tail",
         "localisation_half_shear_area_fraction": "half-shear area", "shear_divergence_r2": "R²",
         "mean_total_s": "⟨ε̇tot⟩ day⁻¹"}


def window_rows(run_dir: Path) -> list[dict]:
    """Per window of the run: the statistics of the interior triangles from the node motion
    (``nodes``) and from the rheology's accumulated strain (``rheology``)."""
    from lagice.diagnostics.report import rate_statistics
    from lagice.diagnostics.strain import ElementStrainRates
    from lagice.diagnostics.windows import WindowError, accumulated_strain_rates, window_starts_days

    rows = []
    for t in window_starts_days(run_dir, WINDOW_DAYS, START_DAY):
        try:
            nodes, rheo, info = accumulated_strain_rates(run_dir, t * DAY_S, (t + WINDOW_DAYS) * DAY_S, BUFFER_M)
        except WindowError as exc:
            print(f"  window {t:g} days skipped: {exc}")
            continue
        inside = info["interior"]
        row = {"start_day": float(t), "n_elements": int(inside.sum()), "remesh_events": int(info["remesh_events"])}
        for name, r in (("nodes", nodes), ("rheology", rheo)):
            sub = ElementStrainRates(r.gradient_s[inside], r.area_m2[inside], r.centroid_xy_m[inside], r.bounds_m)
            st, _ = rate_statistics(sub)
            row[name] = {k: (None if st[k] is None else float(st[k])) for k in KEYS}
        rows.append(row)
    return rows


def _median(rows: list[dict], part: str, key: str) -> float:
    v = np.array([np.nan if r[part][key] is None else r[part][key] for r in rows], float)
    return float(np.nanmedian(v)) if np.isfinite(v).any() else float("nan")


def summary(rows: list[dict]) -> dict:
    return {"windows": len(rows),
            "nodes": {k: _median(rows, "nodes", k) for k in KEYS},
            "rheology": {k: _median(rows, "rheology", k) for k in KEYS},
            "difference": paired_differences(rows, a="rheology", b="nodes")}


def table(results: dict) -> str:
    def fmt(k, v):
        if v != v:
            return "–"
        if k == "mean_total_s":
            return f"{v * DAY_S:.4f}"
        if k == "localisation_half_shear_area_fraction":
            return f"{100 * v:.1f} %"
        return f"{v:.3f}"

    head = "| run | field | windows | " + " | ".join(SHORT[k] for k in KEYS) + " |"
    out = [head, "|" + "---|" * (len(KEYS) + 3)]
    for name, s in results.items():
        for part in ("nodes", "rheology"):
            out.append(f"| {name} | {part} | {s['windows']} | " + " | ".join(fmt(k, s[part][k]) for k in KEYS) + " |")
        cells = []
        for k in KEYS:
            d = s["difference"][k]
            scale = DAY_S if k == "mean_total_s" else (100.0 if k == "localisation_half_shear_area_fraction" else 1.0)
            cells.append("–" if d["median"] != d["median"] else
                         f"{d['median'] * scale:+.3f} [{d['low'] * scale:+.3f}, {d['high'] * scale:+.3f}]")
        out.append(f"| {name} | rheology − nodes | | " + " | ".join(cells) + " |")
    return "\n".join(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="*", help="run names in benchmarks/out/physics (or run folders)")
    ap.add_argument("--json", type=Path, default=ROOT / "docs" / "figures" / "window_split.json",
                    help="the JSON written (per-window rows and summaries; merged with what it holds)")
    ap.add_argument("--from-json", type=Path, default=None, help="print the table from this JSON instead")
    args = ap.parse_args(argv)
    if args.from_json is not None:
        data = json.loads(args.from_json.read_text())
        print(table({k: v["summary"] for k, v in data.items()}))
        return
    if not args.runs:
        ap.error("name at least one run, or --from-json")
    data = json.loads(args.json.read_text()) if args.json.exists() else {}
    for name in args.runs:
        run = Path(name) if Path(name).is_dir() else RUNS / name
        print(f"window_split: {run}", flush=True)
        rows = window_rows(run)
        data[Path(name).name] = {"rows": rows, "summary": summary(rows)}
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(data, indent=1) + "\n")
    print(table({Path(n).name: data[Path(n).name]["summary"] for n in args.runs}))
    print(f"window_split: wrote {args.json}")


if __name__ == "__main__":
    main()
