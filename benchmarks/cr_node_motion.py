"""What the mesh follows with Crouzeix–Raviart velocities (``solver.velocity_element``;
docs/solvers.md, "Crouzeix–Raviart velocities", "What the mesh follows").

With Crouzeix–Raviart velocities the rheology sees each element's own linear field (its edge
velocities), while the nodes, and so the mesh, the drifters and every Lagrangian window of the
deformation statistics, move with the area-weighted mean of the elements' fields at each vertex.
This script runs ``winter_basin_pack`` through the scene builder and ``Simulation`` from its
shipped spun-up state with each velocity element and, after every outer step, compares per element:

* ``mismatch``: Σ A |ε̇_mesh − ε̇| / Σ A |ε̇|, ε̇ the strain rate the rheology used (the mean over
  the step's sub-steps) and ε̇_mesh the strain rate of the nodes' mean velocity over the step (the
  one that moves the mesh), |ε̇|² = ε̇xx² + ε̇yy² + 2 ε̇xy². For linear velocities, whose nodes
  carry the field itself, it is 0 but for the mesh's motion within the step (0.003);
* ``roughness``: the same sum for ε̇ against its one-element smoothing (the area-weighted mean at
  the nodes, then the mean of the three nodes): how much of the strain field lives at the
  element scale; ``mesh roughness``: the same for ε̇_mesh (for linear velocities the two are one);
* ``shear ratio``: Σ A ε̇_II of the mesh's field over that of the rheology's (ε̇_II the maximum
  shear rate).

It prints the medians over the steps (the steps of a remesh are left out).

``--remesh-triggers`` prints, for each velocity element over the same steps, what fired the
remeshes: the events, the elements each criterion of the trigger caught (angle, edge length,
near inversion; :mod:`lagice.remesh.trigger`) summed over the events, the elements replaced,
and the strain rates the mesh moved by (the area-weighted mean of ε̇_II of the mesh's field).

``--statistics`` (thirty-ninth session; docs/solvers.md, "What the mesh follows") computes the
deformation statistics of the validation (β, both PDF tails, the half-shear area, R², the mean total
rate) twice over the same blocks of ``--block-steps`` outer steps: once from the rheology's own
strain rate (the mean over the block of the strain the stress was made from) and once from the
mesh's (the strain rate of the nodes' mean velocity, which is what every Lagrangian window of the
published statistics measures), both on the interior (centroid at least 100 km from the coast at
the block's start) and with the same estimators (:func:`lagice.diagnostics.report.rate_statistics`).
Blocks during which a remesh fired are left out (it renumbers the elements). It prints the medians
over the blocks, over all of them and over the blocks from ``--storm-from`` days on, and writes
the per-block values to ``--json``. One-hour blocks are not the published 3-day windows, so only
the two fields are compared with each other, not with the observed bands.

    NUMBA_NUM_THREADS=1 python benchmarks/cr_node_motion.py --steps 60
    NUMBA_NUM_THREADS=2 python benchmarks/cr_node_motion.py --steps 432 --remesh-triggers
    NUMBA_NUM_THREADS=2 python benchmarks/cr_node_motion.py --statistics --steps 1440 --variants cr \
        --set rheology.max_pressure_pa=10e3 --set rheology.max_pressure_thickness_exponent=1.5 \
        --set initial.state_file=benchmarks/out/physics/spinup-H1125-P-vcrj1-m10.npz \
        --json benchmarks/out/cr_stats/cr.json
    python benchmarks/cr_node_motion.py --statistics --from-json benchmarks/out/cr_stats/*.json \
        --summary-json docs/figures/cr_rate_statistics.json
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

from lagice.deformation import invariants
from lagice.diagnostics.faults import interior_triangles
from lagice.diagnostics.report import rate_statistics
from lagice.diagnostics.strain import ElementStrainRates, symmetric_gradient
from lagice.fem import shape_gradients, strain_rate
from lagice.scenes.builder import build_simulation
from lagice.scenes.config import load_scene

# Rule, written before the runs (2026-11-29, 21:22 UTC, thirty-ninth session). The best-β set-up
# (neXtSIM's compressive term on Crouzeix-Raviart velocities, kappa = 1) has PDF tails lighter than
# observed (10 km validation month: shear 2.63 against 1.9-2.5) and R^2 below its band (0.66 against
# 0.73-0.93), and docs/physics.md s5 asks what makes its bands deform at rates too alike. Its
# statistics are measured on the mesh's motion, a vertex mean of the elements' fields. Run: 1440
# outer steps (10 days) of winter_basin_pack from its own 10 km spin-up (spinup-H1125-P-vcrj1-m10),
# one-hour blocks, each velocity element in its own process (NUMBA_NUM_THREADS=1). Claim (a): the
# node motion makes the shear tail lighter if, over the Crouzeix-Raviart blocks, the median shear-tail
# exponent of the rheology's field is at least 0.3 below the mesh's, AND the same difference for the
# linear element (the estimator's own spread on two fields that are one) is under 0.1 in size.
# Otherwise the rheology's own bands deform at rates too alike. Claim (b), the same for R^2: the
# rheology's median R^2 at least 0.05 above the mesh's with the linear element's difference under
# 0.02. Predicted: (a) holds (the rheology's field is rougher: 0.85-0.90 against 0.63-0.71), (b) fails
# (the roughness is in the shear and divergence alike). One-hour blocks are not the 3-day windows, so
# neither field is compared with the observed bands.

# Result (21:45 UTC): both claims fail, against the prediction for (a). The mesh's field has the heavier tails
# (rheology - mesh: +0.15 shear, +0.17 |div|), the higher R2 (-0.053) and the higher beta (-0.094 in every one
# of 122 blocks: 0.056 against 0.157) and a third more deformation; the linear element's differences are 0.
# docs/physics.md s4, "What the best-beta set-up's statistics measure".
#
# Rule, written before the runs (2026-11-29, 21:47 UTC). If the mesh's extra beta is slip in the velocity jumps
# across edges, it must shrink as the jump penalty kappa grows. Runs: winter_basin_pack at 20 km from the 20 km
# spin-up of the best-beta set-up (spinup-H20-P-vcrj1-m20, made with kappa = 1; the same start for every kappa,
# so this is a diagnostic of the mechanism, not a screen of kappa), 1440 outer steps, one-hour blocks,
# kappa = 0.1, 0.3, 1, 3 and 10. Claim: the median block difference mesh - rheology in beta falls monotonically
# from kappa = 0.1 to 10 (a tolerance of 0.01 between neighbours) and is at least 3 times smaller at 10 than
# at 0.1; the same for the rate's relative difference. Predicted: it holds; at kappa = 10 the beta gap is
# under 0.03 and the mesh's beta falls with kappa (the rheology's changes less).

# Result (22:02 UTC): the claim fails, and so does the prediction. The beta gap (rheology - mesh, all blocks) is
# -0.173 / -0.156 / -0.138 / -0.135 / -0.109 at kappa 0.1 / 0.3 / 1 / 3 / 10: monotonic, but only 1.6 times
# smaller at 10 (the rate's relative gap +44 % -> +24 %, 1.8 times). In the storm (from day 7) the rheology's shear
# tails are 1.47-1.53 at every kappa and the mesh's 2.72-3.52. So most of the gap is the vertex mean of a
# non-conforming field, whatever kappa; docs/physics.md s4, "What the best-beta set-up's statistics measure".

# Rule, written before the runs (2026-11-29, 22:04 UTC). Could another node motion carry the rheology's statistics?
# Any node motion is a continuous linear field. The one whose strain is nearest the rheology's (least squares,
# area-weighted, the same norm as `mismatch`; prescribed components held) is the best any node motion can do;
# what it misses is the non-conforming part of the Crouzeix-Raviart strain. --statistics now also computes that
# field ("fit", per block, from the block's mean strain). Runs: as the kappa sweep, kappa = 1, 20 km. Claim: a node
# motion fitted to the strains would carry the rheology's statistics if the median paired beta difference fit -
# rheology lies within 0.03 over all blocks AND the storm blocks' (from day 7) median shear tail of the fit lies
# within 0.3 of the rheology's. Otherwise no node motion can, and the gap is the field's non-conforming part.
# Predicted: the fit lies between the two, nearer the mesh's (beta gap >= 0.06), since the rheology's strain is
# rough at the element scale (0.85-0.90) and most of that roughness is non-conforming.

# Result (22:10 UTC): the claim fails, as predicted. The fitted motion's beta is 0.179 against the rheology's 0.073
# and the mean's 0.204 (fit - rheology +0.109 [+0.108, +0.112]); in the storm its shear tail is 3.04 against 1.52
# (mean 3.19). The rheology's and the mean's numbers are the kappa-sweep run's to the last digit (the run is
# deterministic). So no continuous node motion carries the rheology's statistics: the gap is the non-conforming
# part of the Crouzeix-Raviart strain.

#: the statistics ``--statistics`` compares (keys of rate_statistics), with the mean total rate
STAT_KEYS = ("beta_space", "pdf_tail_exponent_shear", "pdf_tail_exponent_divergence",
             "localisation_half_shear_area_fraction", "shear_divergence_r2", "mean_total_s")
#: the coast buffer of the published window statistics [m]
BUFFER_M = 100e3
DAY_S = 86400.0

VARIANTS = (("linear", {}),
            ("crouzeix_raviart, jump_penalty 1", {"solver.velocity_element": "crouzeix_raviart",
                                                  "solver.jump_penalty": 1.0}))


def _norm(e: np.ndarray) -> np.ndarray:
    return np.sqrt(e[:, 0] ** 2 + e[:, 1] ** 2 + 2.0 * e[:, 2] ** 2)


def smoothed(tri: np.ndarray, area: np.ndarray, node_area: np.ndarray, field: np.ndarray) -> np.ndarray:
    """One-element smoothing of an element field (m, k): the area-weighted mean at each node
    (``node_area``: the summed area of each node's elements), then the mean of each element's
    three nodes."""
    n = len(node_area)
    nodal = np.stack([np.bincount(tri.ravel(), weights=np.repeat(area * field[:, j], 3), minlength=n) / node_area
                      for j in range(field.shape[1])], axis=1)
    return nodal[tri].mean(axis=1)


def step_measures(sim) -> dict | None:
    """The measures of the step just made, on a mesh no remesh changed during it (None before
    the stepper has a strain rate, or for a pack at rest)."""
    st, mesh = sim.model.stepper, sim.model.mesh
    eps, tri = st.last_strain_rate, mesh.triangles
    if eps is None:
        return None
    b, c, area = shape_gradients(mesh.nodes, tri)
    eps_mesh = strain_rate(tri, b, c, st.transport_velocity)
    den = float(np.sum(area * _norm(eps)))
    if den == 0.0:
        return None
    node_area = np.bincount(tri.ravel(), weights=np.repeat(area, 3), minlength=mesh.n_nodes)
    return {"mismatch": float(np.sum(area * _norm(eps_mesh - eps))) / den,
            "roughness": float(np.sum(area * _norm(smoothed(tri, area, node_area, eps) - eps))) / den,
            "mesh_roughness": float(np.sum(area * _norm(smoothed(tri, area, node_area, eps_mesh) - eps_mesh))
                                    / np.sum(area * _norm(eps_mesh))),
            "shear_ratio": float(np.sum(area * invariants(eps_mesh)[1]) / np.sum(area * invariants(eps)[1]))}


def strain_fit(xy, tri, eps: np.ndarray, fixed: np.ndarray, held: np.ndarray) -> np.ndarray:
    """The nodal velocity (n, 2) whose linear strain rate is nearest ``eps`` (m, 3: ε̇xx, ε̇yy, ε̇xy)
    in Σ A |ε̇(U) − ε̇|², |ε̇|² = ε̇xx² + ε̇yy² + 2 ε̇xy² (the norm of ``mismatch``), with the
    components flagged in ``fixed`` (n, 2) held at ``held`` (n, 2). The best any node motion can do;
    the rest is the non-conforming part of a Crouzeix–Raviart strain. Normal equations solved with
    scipy's sparse LU."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.linalg import spsolve

    n, m = len(xy), len(tri)
    b, c, area = shape_gradients(xy, tri)
    # rows ε̇xx, ε̇yy, √2 ε̇xy of each element against its six dofs (u0, u1, u2, v0, v1, v2)
    B = np.zeros((m, 3, 6))
    B[:, 0, :3] = b
    B[:, 1, 3:] = c
    B[:, 2, :3] = c / np.sqrt(2.0)
    B[:, 2, 3:] = b / np.sqrt(2.0)
    target = np.column_stack([eps[:, 0], eps[:, 1], np.sqrt(2.0) * eps[:, 2]])
    ke = area[:, None, None] * np.einsum("mki,mkj->mij", B, B)
    fe = area[:, None] * np.einsum("mki,mk->mi", B, target)
    dof = np.concatenate([tri, tri + n], axis=1)            # u of node i is dof i, v is n + i
    rows = np.repeat(dof, 6, axis=1).ravel()
    cols = np.tile(dof, (1, 6)).ravel()
    K = coo_matrix((ke.ravel(), (rows, cols)), shape=(2 * n, 2 * n)).tocsr()
    F = np.bincount(dof.ravel(), weights=fe.ravel(), minlength=2 * n)
    held_flat = np.concatenate([held[:, 0], held[:, 1]])
    is_fixed = np.concatenate([fixed[:, 0], fixed[:, 1]]).astype(bool)
    U = np.where(is_fixed, held_flat, 0.0)
    free = ~is_fixed
    rhs = F[free] - K[free][:, is_fixed] @ U[is_fixed]
    U[free] = spsolve(K[free][:, free].tocsc(), rhs)
    return np.column_stack([U[:n], U[n:]])


def block_statistics(xy, tri, inside, eps_mean: np.ndarray) -> dict:
    """The statistics of the interior elements ``inside`` for a mean strain rate ``eps_mean``
    (m, 3: ε̇xx, ε̇yy, ε̇xy [s⁻¹]) on the mesh ``xy``, ``tri``. The gradient handed to the
    estimators is the symmetric one, which has the same divergence and maximum shear."""
    sub = tri[inside]
    _, _, area = shape_gradients(xy, sub)
    rates = ElementStrainRates(symmetric_gradient(eps_mean[inside]), area, xy[sub].mean(axis=1),
                               np.array([xy[:, 0].min(), xy[:, 1].min(), xy[:, 0].max(), xy[:, 1].max()]))
    st, _ = rate_statistics(rates)
    return {k: float(st[k]) for k in STAT_KEYS}


def run_statistics(name: str, sim, steps: int, block: int, fit: bool = False) -> list[dict]:
    """Per block of ``block`` outer steps without a remesh: the statistics of the rheology's
    field and of the mesh's (see the module's docstring); with ``fit`` also of :func:`strain_fit`'s."""
    blocks, acc, acc_mesh, k, n0 = [], None, None, 0, None
    for _ in range(steps):
        mesh = sim.model.mesh
        if k == 0:
            n0 = sim.model.state.counters.get("remesh_count", 0)
            inside = interior_triangles(mesh.nodes, mesh.triangles, BUFFER_M)
            acc = np.zeros((mesh.n_elements, 3))
            acc_mesh = np.zeros((mesh.n_elements, 3))
            t0 = sim.model.clock.time_s
        sim.run(n_steps=1)
        if sim.model.state.counters.get("remesh_count", 0) != n0:
            k = 0  # a remesh renumbered the elements: the block is dropped
            continue
        st = sim.model.stepper
        eps = st.last_strain_rate
        if eps is None:
            k = 0
            continue
        b, c, _ = shape_gradients(mesh.nodes, mesh.triangles)
        acc += eps
        acc_mesh += strain_rate(mesh.triangles, b, c, st.transport_velocity)
        k += 1
        if k == block:
            k = 0
            if inside.sum() < 100:
                continue
            row = {"variant": name, "start_day": t0 / DAY_S, "end_day": sim.model.clock.time_s / DAY_S,
                   "n_interior": int(inside.sum())}
            row["rheology"] = block_statistics(mesh.nodes, mesh.triangles, inside, acc / block)
            row["mesh"] = block_statistics(mesh.nodes, mesh.triangles, inside, acc_mesh / block)
            if fit:  # b, c: this step's geometry, the one the block's statistics use
                u_fit = strain_fit(mesh.nodes, mesh.triangles, acc / block, st.nodes.fixed, st.transport_velocity)
                row["fit"] = block_statistics(mesh.nodes, mesh.triangles, inside,
                                              strain_rate(mesh.triangles, b, c, u_fit))
            blocks.append(row)
            print(f"  {name} day {row['end_day']:.2f}: tails shear {row['rheology']['pdf_tail_exponent_shear']:.2f}"
                  f" / {row['mesh']['pdf_tail_exponent_shear']:.2f} (rheology / mesh)", flush=True)
    return blocks


def _medians(rows: list[dict], field: str) -> dict:
    return {k: float(np.nanmedian([r[field][k] for r in rows])) for k in STAT_KEYS}


def paired_differences(rows: list[dict], n_boot: int = 2000, a: str = "rheology", b: str = "mesh") -> dict:
    """Per statistic: the median over the blocks (or windows: ``window_split.py``) of field ``a`` −
    field ``b``, a 90 % bootstrap interval of that median (rows resampled, seed 0), and the share
    of rows where it is > 0. A statistic that is undefined (None or NaN) in a row leaves that row
    out; one undefined in every row gets NaN."""
    rng = np.random.default_rng(0)
    out = {}
    for k in STAT_KEYS:
        d = np.array([r[a][k] - r[b][k] for r in rows if r[a][k] is not None and r[b][k] is not None],
                     dtype=float)
        d = d[np.isfinite(d)]
        if d.size == 0:
            out[k] = dict.fromkeys(("median", "low", "high", "share_positive"), float("nan"))
            continue
        boot = np.median(rng.choice(d, (n_boot, d.size)), axis=1)
        out[k] = {"median": float(np.median(d)), "low": float(np.percentile(boot, 5)),
                  "high": float(np.percentile(boot, 95)), "share_positive": float(np.mean(d > 0))}
    return out


def summary(blocks: list[dict], storm_from: float) -> dict:
    """Per variant and phase ("all", "from day D"): the blocks, both fields' medians and the
    paired differences (what :func:`print_statistics` prints)."""
    out = {}
    for name in dict.fromkeys(r["variant"] for r in blocks):
        mine = [r for r in blocks if r["variant"] == name]
        for label, rows in (("all", mine), (f"from day {storm_from:g}",
                                            [r for r in mine if r["start_day"] >= storm_from - 1e-9])):
            if rows:
                res = {"blocks": len(rows), "rheology": _medians(rows, "rheology"), "mesh": _medians(rows, "mesh"),
                       "rheology_minus_mesh": paired_differences(rows)}
                if all("fit" in r for r in rows):
                    res["fit"] = _medians(rows, "fit")
                    res["fit_minus_rheology"] = paired_differences(rows, a="fit", b="rheology")
                out.setdefault(name, {})[label] = res
    return out


def print_statistics(blocks: list[dict], storm_from: float) -> None:
    print("\n| variant | field | blocks | β | shear tail | \\|div\\| tail | half-shear area | R² "
          "| mean total rate (day⁻¹) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name in dict.fromkeys(r["variant"] for r in blocks):
        for label, rows in (("all", [r for r in blocks if r["variant"] == name]),
                            (f"from day {storm_from:g}", [r for r in blocks if r["variant"] == name
                                                         and r["start_day"] >= storm_from - 1e-9])):
            if not rows:
                continue
            has_fit = all("fit" in r for r in rows)
            for field in ("rheology", "mesh") + (("fit",) if has_fit else ()):
                m = _medians(rows, field)
                print(f"| {name} ({label}) | {field} | {len(rows)} | {m['beta_space']:.3f} | "
                      f"{m['pdf_tail_exponent_shear']:.2f} | {m['pdf_tail_exponent_divergence']:.2f} | "
                      f"{100 * m['localisation_half_shear_area_fraction']:.1f} % | {m['shear_divergence_r2']:.2f} | "
                      f"{m['mean_total_s'] * DAY_S:.4f} |")
            for a, b in (("rheology", "mesh"),) + ((("fit", "rheology"),) if has_fit else ()):
                d = paired_differences(rows, a=a, b=b)
                print(f"| {name} ({label}) | {a} − {b}, median [90 %] | {len(rows)} | "
                      + " | ".join(f"{d[k]['median'] * f:+.3f} [{d[k]['low'] * f:+.3f}, {d[k]['high'] * f:+.3f}]"
                                   for k, f in zip(STAT_KEYS, (1, 1, 1, 100, 1, DAY_S))) + " |")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=60, help="outer steps measured")
    ap.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                    help="a scene override for every variant (repeatable)")
    ap.add_argument("--remesh-triggers", action="store_true",
                    help="also what fired the remeshes of each velocity element over the steps")
    ap.add_argument("--statistics", action="store_true",
                    help="the validation's statistics of the rheology's field against the mesh's, per block")
    ap.add_argument("--block-steps", type=int, default=6, help="outer steps per block of --statistics (default 6)")
    ap.add_argument("--storm-from", type=float, default=7.0,
                    help="--statistics also prints the medians over the blocks from this day on (default 7)")
    ap.add_argument("--variants", choices=("both", "linear", "cr"), default="both",
                    help="the velocity elements run (default both)")
    ap.add_argument("--json", type=Path, help="--statistics: write the per-block values here")
    ap.add_argument("--fit", action="store_true",
                    help="--statistics: also the node motion fitted to the rheology's strain (strain_fit)")
    ap.add_argument("--from-json", type=Path, nargs="+", metavar="FILE",
                    help="--statistics: print the tables from files written by --json instead of running")
    ap.add_argument("--summary-json", type=Path,
                    help="with --from-json: write the tables' numbers (medians, paired differences) here")
    args = ap.parse_args(argv)
    if args.block_steps < 1 or args.steps < args.block_steps:
        ap.error(f"--block-steps {args.block_steps}: expected 1 to --steps ({args.steps})")
    if args.from_json:
        docs = [json.loads(f.read_text()) for f in args.from_json]
        blocks = [b for d in docs for b in d["blocks"]]
        print_statistics(blocks, args.storm_from)
        if args.summary_json:
            args.summary_json.write_text(json.dumps({"commands": [d["command"] for d in docs],
                                                     "block_steps": sorted({d["block_steps"] for d in docs}),
                                                     "summary": summary(blocks, args.storm_from)}, indent=1) + "\n")
            print(f"wrote {args.summary_json}")
        return
    extra = dict(s.split("=", 1) for s in args.sets)
    variants = [v for v in VARIANTS if args.variants == "both" or (args.variants == "cr") == (v[0] != "linear")]
    print(f"winter_basin_pack from its shipped spun-up state, {args.steps} outer steps"
          + (f", {' '.join(args.sets)}" if args.sets else ""))
    print("| velocity element | mismatch (mesh against rheology) | roughness | mesh roughness | shear ratio | steps |")
    print("|---|---|---|---|---|---|")
    triggers, blocks = [], []
    for name, ov in variants:
        if "solver.jump_penalty" in ov and "solver.jump_penalty" in extra:  # name the penalty the run has
            name = name.replace(f"jump_penalty {ov['solver.jump_penalty']:g}",
                                f"jump_penalty {extra['solver.jump_penalty']}")
        if "domain.resolution_m" in extra:
            name += f", {float(extra['domain.resolution_m']) / 1e3:g} km"
        cfg = load_scene("winter_basin_pack", [f"{k}={v}" for k, v in {**ov, **extra}.items()]
                         + ["run.progress=false", "output.plot=false", "run.duration=100d", "output.every=100d",
                            "checkpoint.every=100d"])
        rows = []
        with tempfile.TemporaryDirectory() as tmp:
            sim = build_simulation(cfg, Path(tmp) / "run")
            if args.statistics:
                blocks += run_statistics(name, sim, args.steps, args.block_steps, args.fit)
                continue
            for _ in range(args.steps):
                n0 = sim.model.state.counters.get("remesh_count", 0)
                sim.run(n_steps=1)
                r = step_measures(sim) if sim.model.state.counters.get("remesh_count", 0) == n0 else None
                if r is not None:
                    rows.append(r)
            if args.remesh_triggers:
                ev = [e for e in sim.model.component("remeshing").log.events if e.kind != "failed"]
                caught = {k: sum(e.trigger_counts.get(k, 0) for e in ev)
                          for k in ("angle", "edge_length", "near_inversion", "total")}
                triggers.append((name, len(ev), caught, sum(e.n_patch_old for e in ev), rows))
        if args.statistics:
            continue
        med = {k: float(np.median([r[k] for r in rows])) for k in rows[0]}
        print(f"| {name} | {med['mismatch']:.3f} | {med['roughness']:.3f} | {med['mesh_roughness']:.3f} | "
              f"{med['shear_ratio']:.3f} | {len(rows)} |", flush=True)
    if args.statistics:
        print_statistics(blocks, args.storm_from)
        if args.json:
            args.json.write_text(json.dumps({"command": "python benchmarks/cr_node_motion.py "
                                             + " ".join(argv if argv is not None else sys.argv[1:]),
                                             "block_steps": args.block_steps, "blocks": blocks}, indent=1) + "\n")
            print(f"wrote {args.json}")
    if args.remesh_triggers:
        print("\n| velocity element | remeshes | elements caught: angle / edge length / near inversion (total) "
              "| elements replaced |")
        print("|---|---|---|---|")
        for name, n, c, replaced, _ in triggers:
            print(f"| {name} | {n} | {c['angle']} / {c['edge_length']} / {c['near_inversion']} ({c['total']}) "
                  f"| {replaced} |")


if __name__ == "__main__":
    main()
