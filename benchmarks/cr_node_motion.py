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

    NUMBA_NUM_THREADS=1 python benchmarks/cr_node_motion.py --steps 60
    NUMBA_NUM_THREADS=2 python benchmarks/cr_node_motion.py --steps 432 --remesh-triggers
"""
from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

from lagice.deformation import invariants
from lagice.fem import shape_gradients, strain_rate
from lagice.scenes.builder import build_simulation
from lagice.scenes.config import load_scene

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


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=60, help="outer steps measured")
    ap.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                    help="a scene override for every variant (repeatable)")
    ap.add_argument("--remesh-triggers", action="store_true",
                    help="also what fired the remeshes of each velocity element over the steps")
    args = ap.parse_args(argv)
    extra = dict(s.split("=", 1) for s in args.sets)
    print(f"winter_basin_pack from its shipped spun-up state, {args.steps} outer steps"
          + (f", {' '.join(args.sets)}" if args.sets else ""))
    print("| velocity element | mismatch (mesh against rheology) | roughness | mesh roughness | shear ratio | steps |")
    print("|---|---|---|---|---|---|")
    triggers = []
    for name, ov in VARIANTS:
        cfg = load_scene("winter_basin_pack", [f"{k}={v}" for k, v in {**ov, **extra}.items()]
                         + ["run.progress=false", "output.plot=false", "run.duration=100d", "output.every=100d",
                            "checkpoint.every=100d"])
        rows = []
        with tempfile.TemporaryDirectory() as tmp:
            sim = build_simulation(cfg, Path(tmp) / "run")
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
        med = {k: float(np.median([r[k] for r in rows])) for k in rows[0]}
        print(f"| {name} | {med['mismatch']:.3f} | {med['roughness']:.3f} | {med['mesh_roughness']:.3f} | "
              f"{med['shear_ratio']:.3f} | {len(rows)} |", flush=True)
    if args.remesh_triggers:
        print("\n| velocity element | remeshes | elements caught: angle / edge length / near inversion (total) "
              "| elements replaced |")
        print("|---|---|---|---|")
        for name, n, c, replaced, _ in triggers:
            print(f"| {name} | {n} | {c['angle']} / {c['edge_length']} / {c['near_inversion']} ({c['total']}) "
                  f"| {replaced} |")


if __name__ == "__main__":
    main()
