"""Which branch of the failure envelope the flagship's damage meets (issue 12, a diagnostic).

Three changes that leave broken ice with more pressure stiffened the flagship's pack
(docs/physics.md §4), and the question left open was where the pack fails: in tension,
or in shear under compression, where the envelope's friction makes pressed ice strong.
Maxwell-EB's envelope (Dansereau et al. 2016, lagice's tension-positive form) has two
branches: the tensile cut-off s1 = σT and the Coulomb line q s1 − s2 = σc. Scaled
towards the origin from outside, a stress meets the cut-off exactly when its minor
principal stress is tensile, s2 ≥ 0 (σT/s1 ≤ σc/(q s1 − s2) ⟺ s2 ≥ 0), and the Coulomb
line otherwise. This script splits the Coulomb events by the sign of the mean stress
m = (s1 + s2)/2:

* ``cutoff``: s2 ≥ 0 (both principal stresses tensile; opening in tension),
* ``coulomb_tension``: m ≥ 0 > s2 (shear with a tensile mean stress),
* ``coulomb_compression``: m < 0 (shear under pressure).

It runs the scene through the scene builder and ``Simulation`` (the same run as
``physics_experiments.py run F10-hthick-1125`` / ``F10s-hthick-1125``: the shipped
spin-up, which equals ``spinup-H1125.npz`` bit for bit) with a callback after every
step. An element "damages" in a step when its damage rose over the step (the solver's
damage events minus healing, net), and it is classed by its stress at the end of the
step: the correction scales the stress towards the origin, and the relaxation that
follows scales it again, which keeps the signs of s1, s2 and m, so the class of the
last event of the step is read from the end-of-step stress unless the elastic
increments of later sub-steps changed a sign (an approximation, stated with the
result). Steps with a remesh (new elements) are skipped and counted. Area-weighted sums
over the interior (≥ 100 km from the coast, the validation's buffer) go into 3-day
windows.

Stated before the month's runs (2026-11-27, 22:18 UTC; a one-day test run had given 0.18 /
0.33 / 0.49 of the damage gain): over the month, most of the interior's damage gain comes
under a compressive mean stress (more than half in both basins), and the cut-off carries less
than a fifth.

Two mechanism diagnostics (closed basin, from the shipped spin-up; not candidates). The drift runs
8-26 deg to the left of the geostrophic wind (Thorndike and Colony: about 5 deg to the right), and
the climatology's surface wind is turned 25 deg towards low pressure, so under a cyclone the ice
is driven inwards and the pack is pressed. ``turn25``: neXtSIM's 25 deg ocean turning angle
(``forcing.drag.turning_angle_deg=25``); ``isobar0``: the surface wind along the isobars
(``forcing.wind.cross_isobar_angle_deg=0``; this changes the calibrated wind, so it only
tests the mechanism). Stated before their runs (2026-11-27, 22:54 UTC): if the inflow presses the
pack, isobar0's share of damage gain under pressure falls below 0.6 (shipped: 0.77) and its
storm windows press less than 0.7 of the interior (shipped: 0.79-0.91); turn25, which turned the
drift by about 10 deg only, moves the share by less than 0.1.

Is the weather wider than the basin? (2026-11-27/28, twenty-first session; mechanism
diagnostics, not candidates): with ``--experiment NAME`` the script runs an experiment of
``physics_experiments.py`` (its basin, resolution and overrides, in its own folder, so that
``physics_experiments.py`` finds it finished) and stores that script's record as well, with the
window statistics. The experiments and the rule stated before their runs (23:40 UTC) are in
``physics_experiments.py`` ("storms as wide as the basin?"): ``F10x2-hthick`` (the basin twice as
wide), ``F10-hthick-halfwx`` / ``F10s-hthick-halfwx`` (the climatology's lengths halved) and the
control month ``F10-hthick-1125-w2027``. Result: rejected; the share under pressure is 0.80 in the
wide basin and 0.72-0.73 under the half-scale weather (docs/physics.md §4).

    python benchmarks/envelope_branches.py closed strait --jobs 2   # both basins, 28 days
    python benchmarks/envelope_branches.py --experiment F10-hthick-halfwx F10s-hthick-halfwx --jobs 2
    python benchmarks/envelope_branches.py closed --set forcing.drag.turning_angle_deg=25 --label turn25
    python benchmarks/envelope_branches.py --table                   # the stored result
    python benchmarks/envelope_branches.py --budget closed F10-hthick-halfwx-w2028   # damage budgets
    python benchmarks/envelope_branches.py --budget-figure closed F10-hthick-1125-w2028 F10-hthick-halfwx-w2028

``--budget RECORD ...`` (2026-11-28): per window, the interior's damage gain of the stored record
against the net change of its Σ d·A between the run's snapshots at the window's ends; the
difference is what healing took away (docs/physics.md §4, "The damage budget").
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "out" / "physics"
PUBLISHED = ROOT / "docs" / "figures" / "envelope_branches.json"
SCENES = {"closed": "winter_basin_pack", "strait": "winter_basin_pack_strait"}
CLASSES = ("cutoff", "coulomb_tension", "coulomb_compression")
DAY = 86400.0
BUFFER_M = 100e3
WINDOW_DAYS = 3
#: the windows start at day 1, as the validation's (docs/validation.md), so that each window's shares
#: sit beside that window's beta and rate in the published records
WINDOW_START_DAY = 1.0


def classify(stress: np.ndarray) -> np.ndarray:
    """(m,) class index into :data:`CLASSES` of (m, 3) stresses [Pa]: 0 where the minor
    principal stress s2 ≥ 0, 1 where the mean m ≥ 0 > s2, 2 where m < 0."""
    from lagice.rheology.maxwell_eb import principal_stresses

    s1, s2 = principal_stresses(stress)
    return np.where(s2 >= 0.0, 0, np.where(s1 + s2 >= 0.0, 1, 2))


def window_sums(steps: list, n_windows: int, start_day: float = WINDOW_START_DAY, width: float = WINDOW_DAYS) -> list:
    """Per-step records (``day``: the end of the step, area per class [m2], damage-area gain per
    class [m2], the interior's compressed area fraction) summed into windows of ``width`` days
    from ``start_day``; a step belongs to the window that holds its end."""
    out = []
    for w in range(n_windows):
        lo, hi = start_day + w * width, start_day + (w + 1) * width
        rows = [s for s in steps if lo < s["day"] <= hi]
        area = np.sum([s["area_m2"] for s in rows], axis=0) if rows else np.zeros(3)
        gain = np.sum([s["gain_m2"] for s in rows], axis=0) if rows else np.zeros(3)
        comp = float(np.mean([s["compressed_fraction"] for s in rows])) if rows else float("nan")
        out.append({"days": [lo, hi], "steps": len(rows),
                    "event_area_fraction": dict(zip(CLASSES, (area / max(area.sum(), 1e-300)).round(4).tolist())),
                    "damage_gain_fraction": dict(zip(CLASSES, (gain / max(gain.sum(), 1e-300)).round(4).tolist())),
                    "damage_gain_m2": float(gain.sum()), "mean_compressed_area_fraction": round(comp, 4)})
    return out


def run(basin: str, days: float = 28.0, sets: tuple = (), label: str | None = None,
        out_dir: Path | None = None) -> dict:
    """One month of the scene of ``basin`` with the per-step callback; returns the record.
    ``sets``: ``KEY=VALUE`` overrides (diagnostics: another configuration), recorded under
    ``label`` (default: the basin's name); the run's folder is ``out_dir`` (default
    ``branches-LABEL``)."""
    from lagice.diagnostics.faults import interior_triangles
    from lagice.scenes.builder import build_simulation, finish
    from lagice.scenes.config import load_scene, split_overrides

    name = label or basin
    out_dir = out_dir or OUT / f"branches-{name}"
    ov = {"run.duration": f"{days:g}d", "output.every": "1d", "output.plot": False, "run.progress": False,
          "checkpoint.every": "7d", **dict(split_overrides(list(sets)))}
    sim = build_simulation(load_scene(SCENES[basin], ov), out_dir)
    model = sim.model
    # the interior mask of a mesh's first step (kept until the next remesh; nodes drift meanwhile)
    memo = {"triangles": None, "interior": None}
    prev = {"damage": model.state.damage.copy(), "triangles": model.state.mesh.triangles}
    steps, skipped = [], [0]

    def after_step(s):
        st = s.model.state
        mesh = st.mesh
        if mesh.triangles is not prev["triangles"] or st.damage.shape != prev["damage"].shape:
            skipped[0] += 1  # remeshed in this step: new elements, no per-element change to read
        else:
            if memo["triangles"] is not mesh.triangles:
                memo["triangles"] = mesh.triangles
                memo["interior"] = interior_triangles(mesh.nodes, mesh.triangles, BUFFER_M)
            inner = memo["interior"]
            area = np.abs(mesh.areas())
            gain = st.damage - prev["damage"]
            hit = inner & (gain > 0.0)
            cls = classify(st.stress)
            m = 0.5 * (st.stress[:, 0] + st.stress[:, 1])
            steps.append({"day": s.model.clock.time_s / DAY,
                          "area_m2": [float(area[hit & (cls == k)].sum()) for k in range(3)],
                          "gain_m2": [float((gain * area)[hit & (cls == k)].sum()) for k in range(3)],
                          "compressed_fraction": float(area[inner & (m < 0.0)].sum() / area[inner].sum())})
        prev["damage"] = st.damage.copy()
        prev["triangles"] = mesh.triangles

    sim.add_callback(after_step, "1 steps", name="envelope_branches")
    t0 = time.perf_counter()
    finish(sim)  # as `lagice run` does: the run, then summary.json (which physics_experiments.py reads)
    n_win = int((days - WINDOW_START_DAY) // WINDOW_DAYS)
    (OUT / f"branches-{name}-steps.json").write_text(json.dumps(steps))
    return {"label": name, "basin": basin, "scene": SCENES[basin], "overrides": list(sets), "days": days,
            "buffer_m": BUFFER_M,
            "steps_read": len(steps), "steps_skipped_remesh": skipped[0], "wall_s": round(time.perf_counter() - t0, 1),
            "classes": list(CLASSES), "windows": window_sums(steps, n_win),
            "month": window_sums(steps, 1, start_day=0.0, width=days)[0]}


def run_experiment(name: str) -> dict:
    """Experiment ``name`` of ``physics_experiments.py`` run here, in its own folder and with its
    overrides (the same settings as its ``lagice run`` command), then analysed and stored by
    that script; the envelope record gets the window statistics' medians and the drift."""
    import physics_experiments as pe

    scene, overrides, res, days, _what = pe.EXPERIMENTS[name]
    sets = (f"domain.resolution_m={res:g}", *overrides)
    rec = run(scene, days, sets, label=name, out_dir=pe.OUT / name)
    stats = pe.run_experiment(name, run=False)
    rec["statistics"] = {"median": stats["median"], "inside": stats["inside"], "drift": stats["drift"],
                         "remesh_count": stats["remesh_count"]}
    return rec


def damage_budget(rec: dict, run_dir: Path) -> list:
    """Per window of a record: the interior's damage gain (the per-step record: the steps whose
    damage rose, net of their own healing), its net change between the snapshots at the window's
    ends (Σ d·A over the elements >= 100 km from the boundary, each on its own mesh) and the
    difference, ``healed_m2`` = gain − net: what healing took away, plus the steps with a remesh
    (skipped by the record) and the remapping's change of the interior's Σ d·A."""
    from beta_vs_damage import start_damage

    days = sorted({d for w in rec["windows"] for d in w["days"]})  # each snapshot read once
    at = {d: start_damage(run_dir, d, BUFFER_M) for d in days}
    rows = []
    for w in rec["windows"]:
        d0, d1 = w["days"]
        a, b = at[d0], at[d1]
        net = b["damage_area_m2"] - a["damage_area_m2"]
        rows.append({"days": [d0, d1], "gain_m2": w["damage_gain_m2"], "net_m2": net,
                     "healed_m2": w["damage_gain_m2"] - net, "interior_area_m2": a["area_m2"],
                     "mean_damage_start": a["mean_damage"], "mean_damage_end": b["mean_damage"]})
    return rows


def budget_table(name: str, rows: list, rates: list | None = None) -> str:
    """The damage budget of :func:`damage_budget` as a table [10⁹ m²], with the window's rate."""
    lines = [f"| {name}: days | rate day⁻¹ | gain | net change | healed (gain − net) | mean damage, start → end |",
             "|---|---|---|---|---|---|"]
    for i, r in enumerate(rows):
        rate = f"{rates[i]:.4f}" if rates else "–"
        lines.append(f"| {r['days'][0]:g}–{r['days'][1]:g} | {rate} | {r['gain_m2'] / 1e9:.1f} | "
                     f"{r['net_m2'] / 1e9:+.1f} | {r['healed_m2'] / 1e9:.1f} | "
                     f"{r['mean_damage_start']:.3f} → {r['mean_damage_end']:.3f} |")
    g, n = sum(r["gain_m2"] for r in rows), sum(r["net_m2"] for r in rows)
    lines.append(f"| month | | {g / 1e9:.0f} | {n / 1e9:+.0f} | {(g - n) / 1e9:.0f} | |")
    return "\n".join(lines)


def _summary(rec: dict) -> str:
    """β and the rate of a record that has statistics, else a dash."""
    st = rec.get("statistics")
    if not st:
        return "–"
    med = st["median"]
    return f"β {med['beta_space']:.3f}, {med['mean_total_deformation_rate_per_day']:.4f} d⁻¹"


def table(records: dict) -> str:
    lines = ["| run | days | damage gain: cut-off / Coulomb, tensile mean / Coulomb, compressive mean "
             "| event area, same order | interior area under compression (mean) | month's medians |",
             "|---|---|---|---|---|---|"]
    for basin, rec in records.items():
        for w in [rec["month"], *rec["windows"]]:
            g, a = w["damage_gain_fraction"], w["event_area_fraction"]
            days = f"{w['days'][0]:g}–{w['days'][1]:g}"
            lines.append(f"| {basin} | {days} | {g['cutoff']:.2f} / {g['coulomb_tension']:.2f} / "
                         f"{g['coulomb_compression']:.2f} | {a['cutoff']:.2f} / {a['coulomb_tension']:.2f} / "
                         f"{a['coulomb_compression']:.2f} | {w['mean_compressed_area_fraction']:.2f} | "
                         f"{_summary(rec) if w is rec['month'] else ''} |")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("basins", nargs="*", help=f"any of {sorted(SCENES)}")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--days", type=float, default=28.0)
    ap.add_argument("--table", action="store_true")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="an override for a diagnostic configuration (needs --label and one basin)")
    ap.add_argument("--label", help="the record's name for a run with --set")
    ap.add_argument("--experiment", nargs="+", default=[], metavar="NAME",
                    help="experiments of physics_experiments.py, run in their own folders and stored by both scripts")
    ap.add_argument("--budget", nargs="+", default=[], metavar="RECORD",
                    help="stored records: the interior's damage gain against its net change per window "
                         "(from the run's snapshots), stored in the record as damage_budget")
    ap.add_argument("--budget-figure", nargs="+", default=[], metavar="RECORD",
                    help=f"records with a stored damage_budget: one panel each in {BUDGET_FIGURE.name}")
    a = ap.parse_args(argv)
    if a.budget:
        return budget(a.budget)
    if a.budget_figure:
        print(f"branches: wrote {budget_figure(a.budget_figure)}")
        return 0
    if a.experiment and (a.basins or a.set or a.label):
        ap.error("--experiment takes no basin, --set or --label (the experiment defines them)")
    if a.experiment:
        import physics_experiments as pe

        pe.check_names(a.experiment)
    bad = [b for b in a.basins if b not in SCENES]
    if bad:
        ap.error(f"unknown basin(s) {bad}: expected any of {sorted(SCENES)}")
    if (a.set or a.label) and not (a.set and a.label and len(a.basins) == 1):
        ap.error("--set needs --label and exactly one basin (and --label needs --set)")
    if a.label in SCENES:
        ap.error(f"--label {a.label!r} is a basin's own record; choose another name")
    records = json.loads(PUBLISHED.read_text()) if PUBLISHED.exists() else {}
    if a.basins or a.experiment:
        with ProcessPoolExecutor(max_workers=a.jobs) as ex:
            n = len(a.basins)
            jobs = (ex.map(run_experiment, a.experiment) if a.experiment else
                    ex.map(run, a.basins, [a.days] * n, [tuple(a.set)] * n, [a.label] * n))
            for rec in jobs:
                print(f"branches: {rec['label']} done in {rec['wall_s']} s ({rec['steps_read']} steps read, "
                      f"{rec['steps_skipped_remesh']} with a remesh skipped)", flush=True)
                # read again before writing: another invocation may have stored its record meanwhile
                stored = json.loads(PUBLISHED.read_text()) if PUBLISHED.exists() else {}
                records = {**stored, rec["label"]: rec}
                PUBLISHED.write_text(json.dumps(records, indent=1) + "\n")
    if records:
        print(table(records))
    elif not a.basins:
        sys.exit("no stored result: run the basins first")


#: the run folders of the basins' own records (the run of ``physics_experiments.py`` with the same
#: settings: the shipped spin-up, the validation month)
BASIN_RUNS = {"closed": "F10-hthick-1125", "strait": "F10s-hthick-1125"}


#: the figure of ``--budget-figure``
BUDGET_FIGURE = ROOT / "docs" / "figures" / "damage_budget.png"
#: panel titles of known records (others are titled by their name)
BUDGET_TITLES = {"closed": "closed, validation month, spun-up pack",
                 "strait": "strait, validation month, spun-up pack",
                 "F10-hthick-1125-w2028": "closed, calm month, seed 2028",
                 "F10-hthick-halfwx-w2028": "closed, half-scale weather, seed 2028 (locked)",
                 "F10-hthick-1125-intact": "closed, validation month, intact start"}


def budget_figure(names: list, path: Path = BUDGET_FIGURE) -> Path:
    """One panel per stored record with a ``damage_budget``: per window, the damage gain (up) and
    what healing took away (down) [10⁹ m²], and the interior's mean damage at the windows' ends."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    records = json.loads(PUBLISHED.read_text())
    missing = [n for n in names if "damage_budget" not in records.get(n, {})]
    if missing:
        sys.exit(f"branches: no damage_budget stored for {missing}; run --budget first")
    fig, axes = plt.subplots(1, len(names), figsize=(4.2 * len(names), 3.6), sharey=True, squeeze=False)
    for ax, name in zip(axes[0], names):
        rows = records[name]["damage_budget"]
        mid = [0.5 * (r["days"][0] + r["days"][1]) for r in rows]
        ax.bar(mid, [r["gain_m2"] / 1e9 for r in rows], width=2.6, color="tab:red", label="damage gain")
        ax.bar(mid, [-r["healed_m2"] / 1e9 for r in rows], width=2.6, color="tab:blue", label="healed (gain − net)")
        ax.axhline(0.0, color="k", lw=0.6)
        ax.set_title(BUDGET_TITLES.get(name, name), fontsize=9)
        ax.set_xlabel("day")
        twin = ax.twinx()
        days = [rows[0]["days"][0]] + [r["days"][1] for r in rows]
        twin.plot(days, [rows[0]["mean_damage_start"]] + [r["mean_damage_end"] for r in rows], "k.-",
                  label="interior mean damage")
        twin.set_ylim(0.0, 1.0)
        if ax is axes[0][-1]:
            twin.set_ylabel("interior mean damage")
        else:
            twin.set_yticklabels([])
    axes[0][0].set_ylabel("damage-area per 3-day window (10⁹ m²)")
    handles = axes[0][0].get_legend_handles_labels()[0] + twin.get_legend_handles_labels()[0]
    fig.legend(handles, [h.get_label() for h in handles], loc="lower center", ncol=3, fontsize=8)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def budget(names: list) -> int:
    """``--budget``: :func:`damage_budget` of stored records, printed and stored in each record."""
    records = json.loads(PUBLISHED.read_text())
    physics = json.loads((ROOT / "docs" / "figures" / "physics_experiments.json").read_text())
    for name in names:
        if name not in records:
            sys.exit(f"branches: no stored record {name!r}; known: {sorted(records)}")
        run_name = BASIN_RUNS.get(name, name)
        # the experiment's own folder, else the folder this script's basin runs write
        run_dir = next((d for d in (OUT / run_name, OUT / f"branches-{name}") if (d / "snapshots").exists()), None)
        if run_dir is None:
            sys.exit(f"branches: {name}: no snapshots in {OUT / run_name} or {OUT / f'branches-{name}'}")
        rows = damage_budget(records[name], run_dir)
        rates = ([w["mean_total_s"] * DAY for w in physics[run_name]["per_window"]]
                 if run_name in physics else None)
        print(budget_table(name, rows, rates))
        stored = json.loads(PUBLISHED.read_text())
        stored[name]["damage_budget"] = rows
        PUBLISHED.write_text(json.dumps(stored, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    main()
