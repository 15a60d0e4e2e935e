"""How long are the shear bands? (docs/physics.md §4, "The concentration in bands one element wide, and
the widths both meshes resolve", forty-sixth session, rule BL.)

Over the widths both meshes resolve, the 10 km months' rate falls less with the box width than the
20 km months' at the same cohesion: their deformation cancels less between 24 and 92 km. One reading is
that a finer mesh lets bands propagate further (an element at a band's tip averages the tip's stress
concentration over a smaller size), so the shear gathers into fewer, longer bands. This script
measures the bands' lengths.

For each 3-day Lagrangian window of a run (the published windows: from day 1, every 3 days, the
elements at least 100 km from the coast, :func:`lagice.diagnostics.windows.window_arrays`), it takes
the elements that hold half of the window's shear (Σ ε̇II·A, as the half-shear area;
:func:`band_persistence.band_set`) and groups them into bands: two elements of the set belong to the
same band when they share a node. A band's length is √12 times the standard deviation of its
elements' centroids along its main axis (area-weighted: a straight, uniform band of length ℓ gives
ℓ), and at least its elements' mean size √(2A). Per window it reports the number of bands, the
shear-weighted median band length (half of the set's shear lies in bands at least that long), the
set's area fraction, and the bands' total length per 10⁴ km² of interior. A run's row is the median
over its windows.

``--split`` also coarse-grains two parts of each window's deformation alone (rule BB): the band
set's (the other elements' gradients set to zero) and the background's (the reverse), with the
validation's boxes and estimator (:func:`lagice.diagnostics.spatial_scaling`). Per run and part it
pools ⟨ε̇tot⟩(L) over the windows (the geometric mean per width, as ``beta_estimator.py``) and fits
β over the widths of 20 km and more, which a 20 km and a 10 km mesh both resolve.

    python benchmarks/band_geometry.py RUN [RUN ...] [--split] [--json PATH]   # runs in benchmarks/out/physics
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
from band_persistence import band_set
from beta_estimator import pool_curves
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from lagice.diagnostics.scaling import MIN_FIT_BOXES, fit_power_law, spatial_scaling
from lagice.diagnostics.strain import ElementStrainRates, lagrangian_velocity_gradients, shear_rate
from lagice.diagnostics.windows import window_arrays, window_starts_days

ROOT = Path(__file__).resolve().parents[1]
RUNS = ROOT / "benchmarks" / "out" / "physics"
DAY_S = 86400.0
#: the published windows: 3 days from day 1, interior 100 km from the coast
WINDOW_DAYS, START_DAY, BUFFER_M = 3.0, 1.0, 100e3
ROW_KEYS = ("n_bands", "weighted_median_length_km", "set_area_fraction", "length_per_1e4_km2")
#: the narrowest box width [m] of the split's fit: widths a 20 km mesh resolves
SPLIT_MIN_WIDTH_M = 20e3
PARTS = ("whole", "bands", "background")


def bands(triangles: np.ndarray, in_set: np.ndarray) -> tuple[int, np.ndarray]:
    """Group the elements of ``in_set`` (mask over ``triangles``) into bands: elements sharing a
    node are in one band. Returns (number of bands, band label per element of the set, in the
    order of ``np.flatnonzero(in_set)``)."""
    idx = np.flatnonzero(in_set)
    if idx.size == 0:
        return 0, np.zeros(0, np.int64)
    tri = triangles[idx]
    nodes, local = np.unique(tri.ravel(), return_inverse=True)
    n_el = idx.size
    # the element-node incidence as a bipartite graph: elements 0..n_el-1, nodes after them
    rows = np.repeat(np.arange(n_el), 3)
    cols = n_el + local
    g = coo_matrix((np.ones(rows.size), (rows, cols)), shape=(n_el + nodes.size,) * 2)
    n, labels = connected_components(g, directed=False)
    el_labels = labels[:n_el]
    _, el_labels = np.unique(el_labels, return_inverse=True)  # 0..k-1 over the bands
    return int(el_labels.max()) + 1, el_labels


def band_lengths(centroids: np.ndarray, area: np.ndarray, labels: np.ndarray, n_bands: int) -> np.ndarray:
    """Length [m] of each band: √12 × the area-weighted standard deviation of its centroids along its
    main axis, and at least its elements' mean size √(2A)."""
    out = np.empty(n_bands)
    for k in range(n_bands):  # bands, not elements: a few hundred per window at most
        m = labels == k
        w = area[m] / area[m].sum()
        c = centroids[m]
        d = c - w @ c
        cov = (d * w[:, None]).T @ d
        out[k] = max(np.sqrt(12.0 * np.linalg.eigvalsh(cov)[-1]), float(np.mean(np.sqrt(2.0 * area[m]))))
    return out


def weighted_median(values: np.ndarray, weights: np.ndarray) -> float:
    """The value at which the weights of the values at or above it first reach half the total."""
    order = np.argsort(-values, kind="stable")
    cum = np.cumsum(weights[order])
    return float(values[order][int(np.searchsorted(cum, 0.5 * cum[-1]))])


def part_curves(g: ElementStrainRates, in_set: np.ndarray) -> dict:
    """⟨ε̇tot⟩(L) [s-1] by box width L [m] (widths with at least :data:`MIN_FIT_BOXES` boxes) of the
    whole gradient, of the band set's alone and of the background's alone."""
    out = {}
    for part, keep in (("whole", None), ("bands", in_set), ("background", ~in_set)):
        grad = g.gradient_s if keep is None else np.where(keep[:, None, None], g.gradient_s, 0.0)
        sc = spatial_scaling(ElementStrainRates(grad, g.area_m2, g.centroid_xy_m, g.bounds_m),
                             include_element_scale=False)
        ok = np.isfinite(sc.coarse.mean_total_s) & (sc.coarse.n_boxes >= MIN_FIT_BOXES)
        out[part] = {"width_m": sc.coarse.scale_m[ok].tolist(), "rate_s": sc.coarse.mean_total_s[ok].tolist()}
    return out


def pooled_beta(curves: list[dict], min_width_m: float = SPLIT_MIN_WIDTH_M) -> float:
    """β of the windows' curves pooled (the geometric mean of ⟨ε̇tot⟩ per width, widths counted
    from the widest every window has), fitted over the widths of at least ``min_width_m``."""
    w, r = pool_curves([c["width_m"] for c in curves], [c["rate_s"] for c in curves])
    k = w >= min_width_m
    return float(fit_power_law(w[k], r[k]).exponent)


def window_bands(xy0, xy1, triangles, dt_s, split: bool = False) -> dict:
    """The band measures of one window's elements (node positions at both ends, connectivity);
    with ``split`` also :func:`part_curves` (under ``"curves"``)."""
    # every node, as the validation's summarise takes them: the boxes are laid from the corner of the
    # whole mesh's mid-window bounds, so the split's "whole" is the published coarse-graining
    t = triangles
    g = lagrangian_velocity_gradients(xy0, xy1, t, dt_s)
    shear = shear_rate(g.gradient_s)
    in_set = band_set(shear, g.area_m2)
    n, labels = bands(t, in_set)
    a, c = g.area_m2[in_set], g.centroid_xy_m[in_set]
    lengths = band_lengths(c, a, labels, n)
    weight = np.bincount(labels, weights=shear[in_set] * a, minlength=n)
    out = {"n_bands": n, "weighted_median_length_km": weighted_median(lengths, weight) / 1e3,
           "set_area_fraction": float(a.sum() / g.area_m2.sum()),
           "length_per_1e4_km2": float(lengths.sum() / 1e3 / (g.area_m2.sum() / 1e10))}
    if split:
        out["curves"] = part_curves(g, in_set)
    return out


def run_bands(run_dir: Path, split: bool = False) -> dict:
    """Per-window band measures of a run and their medians over the windows; with ``split`` also
    each part's pooled β over the widths of :data:`SPLIT_MIN_WIDTH_M` and more (``"split_beta"``)."""
    rows = []
    for s0 in window_starts_days(run_dir, WINDOW_DAYS, START_DAY):
        xy0, xy1, tri, dt, info = window_arrays(run_dir, s0 * DAY_S, (s0 + WINDOW_DAYS) * DAY_S, BUFFER_M)
        rows.append({"start_day": float(s0), **window_bands(xy0, xy1, tri[info["interior"]], dt, split)})
    res = {"windows": rows, "median": {k: float(np.median([r[k] for r in rows])) for k in ROW_KEYS}}
    if split:
        res["split_beta"] = {p: pooled_beta([r["curves"][p] for r in rows]) for p in PARTS}
    return res


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", help="run names in benchmarks/out/physics")
    ap.add_argument("--split", action="store_true", help="also β of the band set's and the background's "
                    "deformation alone, over the widths of 20 km and more (rule BB)")
    ap.add_argument("--json", type=Path, default=None, help="write the per-window values here")
    args = ap.parse_args(argv)
    missing = [r for r in args.runs if not (RUNS / r / "snapshots").is_dir()]
    if missing:
        raise SystemExit(f"band_geometry: no snapshots for {missing} in {RUNS}")
    out = {}
    split = " β ≥ 20 km: whole / bands / background |" if args.split else ""
    print("| run | bands per window | shear-weighted median band length (km) | half-shear set's area | "
          f"band length per 10⁴ km² (km) |{split}")
    print("|---|---|---|---|---|" + ("---|" if args.split else ""))
    for r in args.runs:
        res = run_bands(RUNS / r, args.split)
        out[r] = res
        m = res["median"]
        betas = " / ".join(f"{res['split_beta'][p]:.3f}" for p in PARTS) if args.split else ""
        cells = f" {betas} |" if args.split else ""
        print(f"| {r} | {m['n_bands']:.0f} | {m['weighted_median_length_km']:.0f} | "
              f"{100 * m['set_area_fraction']:.1f} % | {m['length_per_1e4_km2']:.0f} |{cells}", flush=True)
    if args.json:
        args.json.write_text(json.dumps(out, indent=1))
        print(f"band_geometry: wrote {args.json}")


if __name__ == "__main__":
    sys.exit(main())
