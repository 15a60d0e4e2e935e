"""β split into its shear and divergence parts, and how coherently the pack converges
(docs/physics.md §4, "Where β is lost, and damaged ice that keeps its pressure").

β is the slope of ⟨ε̇tot⟩(L), the mean over boxes of width L of the total deformation rate of
the box (:func:`lagice.diagnostics.spatial_scaling`). The box's velocity gradient is the
area-weighted mean of its elements' gradients, so a box rate is smaller than the mean of its
elements' rates only where their gradients *cancel*: opposite senses of shear, shear along
different directions, opening next to closing. A part of the deformation that has the same sign
everywhere (a pack that converges everywhere) does not cancel and has β = 0 whatever its
localisation. This script splits each element's velocity gradient into its isotropic part
(ε̇I / 2 · I, the divergence) and the rest (the shear), and fits β to each part alone, with the
estimator of the validation (3-day windows from day 1, the 100 km coast buffer, widths with at
least 10 boxes). It also prints, per window, the *net-divergence ratio*
Σ ε̇I A / Σ |ε̇I| A over the interior's elements (A: area): −1 where every element converges,
0 where opening and closing balance. Girard et al. (2009, "Evaluation of high-resolution sea
ice models on the basis of statistical and scaling properties of Arctic sea ice drift and
deformation", J. Geophys. Res. 114) call large patches of convergence in a winter pack near
100 % concentration incompatible with a fractured plate, whose convergence closes fresh
fractures and builds ridges along narrow faults.

Three checks of where the convergence comes from, per window:

* the share of the mesh's area that the window follows (elements remeshed during the window
  are left out of every window statistic) and the change of that area over the window; in a
  closed basin the mesh keeps its area, so a followed area that shrinks means that the
  remeshed patches opened;
* the share of the interior's area (≥ 100 km from the coast) in patches remeshed during the
  window, and with ``--patches``, β (fitted without the element scale) and the net-divergence
  ratio with each remeshed interior patch added back as one cell: its area-mean velocity
  gradient is the integral of the velocity over its boundary, whose nodes outlive the remesh
  (a patch with a boundary node that does not is left out, and its area is counted);
* ``--wind-curl``: the interior's mean divergence against the interior's mean curl of the
  geostrophic wind (the run's wind rebuilt from its configuration, 6-hourly over the window,
  centred differences 5 km apart). In free drift u = A R(θ) G, div u = −A sin θ curl G.

    python benchmarks/beta_components.py F10-hthick-str50hnullsp F10s-hthick-str50hnullsp
    python benchmarks/beta_components.py F10-hthick-1125-ref --wind-curl

Runs are read from ``benchmarks/out/physics`` (made by ``physics_experiments.py run``); results
are merged into ``docs/figures/beta_components.json`` (one entry per run).
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import xarray as xr

from lagice.diagnostics.faults import interior_triangles
from lagice.diagnostics.scaling import spatial_scaling
from lagice.diagnostics.strain import ElementStrainRates, lagrangian_velocity_gradients, triangle_geometry
from lagice.diagnostics.windows import window_arrays, window_starts_days
from lagice.errors import ConfigError

ROOT = Path(__file__).resolve().parents[1]
RUNS = ROOT / "benchmarks" / "out" / "physics"
OUT = ROOT / "docs" / "figures" / "beta_components.json"
DAY_S = 86400.0
KEYS = ("beta", "beta_shear_part", "beta_divergence_part", "net_divergence_ratio",
        "mean_abs_divergence_to_mean_shear", "element_rate_per_day")


def split_gradient(gradient_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(the gradient less its isotropic part, the isotropic part ε̇I/2 · I) of (m, 2, 2) gradients [s-1]."""
    half_div = 0.5 * (gradient_s[:, 0, 0] + gradient_s[:, 1, 1])
    iso = np.zeros_like(gradient_s)
    iso[:, 0, 0] = half_div
    iso[:, 1, 1] = half_div
    return gradient_s - iso, iso


def window_components(rates: ElementStrainRates) -> dict:
    """β of the whole gradient, of its shear part and of its divergence part, and the
    net-divergence ratio, for the element rates of one window."""
    shear_part, div_part = split_gradient(rates.gradient_s)
    out = {}
    for key, g in (("beta", rates.gradient_s), ("beta_shear_part", shear_part), ("beta_divergence_part", div_part)):
        part = ElementStrainRates(g, rates.area_m2, rates.centroid_xy_m, rates.bounds_m)
        out[key] = float(spatial_scaling(part).fit.exponent)
    div, area = rates.divergence_s, rates.area_m2
    out["net_divergence_ratio"] = float(np.sum(div * area) / np.sum(np.abs(div) * area))
    out["mean_abs_divergence_to_mean_shear"] = float(np.abs(div).mean() / rates.shear_s.mean())
    out["element_rate_per_day"] = float(rates.total_s.mean() * DAY_S)
    return out


def mean_geostrophic_curl(wind, surface_factor: float, t0_s: float, t1_s: float, xy_m, area_m2,
                          every_s: float = 6 * 3600.0, h_m: float = 5e3) -> float:
    """Area-weighted mean over points ``xy_m`` and over [t0, t1] (every ``every_s``) of the
    curl of the geostrophic wind [s-1]: the 10-m wind's curl by centred differences ``h_m``
    apart, divided by the climatology's surface factor (its turning does not change the curl)."""
    x, y = xy_m[:, 0], xy_m[:, 1]
    out = []
    for t in np.arange(t0_s, t1_s + 1e-6, every_s):
        u_n, _ = wind(t, x, y + h_m)
        u_s, _ = wind(t, x, y - h_m)
        _, v_e = wind(t, x + h_m, y)
        _, v_w = wind(t, x - h_m, y)
        curl = (np.asarray(v_e) - np.asarray(v_w) - np.asarray(u_n) + np.asarray(u_s)) / (2.0 * h_m)
        out.append(np.sum(curl * area_m2) / np.sum(area_m2))
    return float(np.mean(out)) / surface_factor


def patch_cells(xy0, xy1, triangles, dt_s: float):
    """One cell per connected patch of ``triangles`` (those remeshed during the window): its
    area-mean velocity gradient [s-1] = (1/A) ∮ u ⊗ n dl over the patch boundary (mid-window
    geometry, u = (xy1 − xy0)/Δt at the boundary nodes, exact for the P1 field of the lost
    triangles), area A [m²] and centroid [m]. Returns (gradients (k, 2, 2), areas, centroids,
    start area of the patches used, start area of those left out because a boundary node is gone)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    m = len(triangles)
    if m == 0:
        return np.zeros((0, 2, 2)), np.zeros(0), np.zeros((0, 2)), 0.0, 0.0
    edges = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    owner = np.tile(np.arange(m), 3)
    _, inv, counts = np.unique(np.sort(edges, axis=1), axis=0, return_inverse=True, return_counts=True)
    inv = inv.ravel()
    shared = np.flatnonzero(counts[inv] == 2)
    shared = shared[np.argsort(inv[shared], kind="stable")]  # each shared edge twice, side by side
    a, b = owner[shared[0::2]], owner[shared[1::2]]
    _, label = connected_components(coo_matrix((np.ones(len(a)), (a, b)), shape=(m, m)), directed=False)
    p0, p1, p2 = (xy0[triangles[:, i]] for i in range(3))
    signed = 0.5 * ((p1[:, 0] - p0[:, 0]) * (p2[:, 1] - p0[:, 1]) - (p1[:, 1] - p0[:, 1]) * (p2[:, 0] - p0[:, 0]))
    mid, vel = 0.5 * (xy0 + xy1), (xy1 - xy0) / dt_s
    grads, areas, cents = [], [], []
    used = dropped = 0.0
    boundary = counts[inv] == 1
    for c in np.unique(label):
        sel = boundary & (label[owner] == c)
        ed = edges[sel].copy()
        flip = signed[owner[sel]] < 0
        ed[flip] = ed[flip][:, ::-1]  # counter-clockwise
        start_area = np.abs(signed[label == c]).sum()
        if not np.all(np.isfinite(xy1[ed])):
            dropped += start_area
            continue
        pa, pb = mid[ed[:, 0]], mid[ed[:, 1]]
        cross = pa[:, 0] * pb[:, 1] - pb[:, 0] * pa[:, 1]
        area = 0.5 * cross.sum()
        normal = np.column_stack([pb[:, 1] - pa[:, 1], pa[:, 0] - pb[:, 0]])
        u_edge = 0.5 * (vel[ed[:, 0]] + vel[ed[:, 1]])
        grads.append((u_edge[:, :, None] * normal[:, None, :]).sum(axis=0) / area)
        areas.append(area)
        cents.append(np.array([((pa[:, 0] + pb[:, 0]) * cross).sum(), ((pa[:, 1] + pb[:, 1]) * cross).sum()])
                     / (6.0 * area))
        used += start_area
    if not grads:
        return np.zeros((0, 2, 2)), np.zeros(0), np.zeros((0, 2)), used, dropped
    return np.array(grads), np.array(areas), np.array(cents), used, dropped


def with_patches(info: dict, dt_s: float, inside) -> dict:
    """β (no element scale) and the net-divergence ratio of the interior's followed elements,
    and of the same with the remeshed interior patches added back as cells (:func:`patch_cells`).
    ``info``: a window of :func:`window_arrays` (its start mesh and the end position of each
    start node); ``inside``: the start mesh's interior mask."""
    xy0, tri = info["start_mesh"][:2]
    xy1, dt = info["start_nodes_at_end"], dt_s
    kept = np.zeros(len(tri), bool)
    kept[info["kept_elements"]] = True
    folded = np.zeros(len(tri), bool)  # followed but left out (inverted mid-window): not a remeshed patch
    folded[info["folded_elements"]] = True
    rates = lagrangian_velocity_gradients(xy0, np.where(np.isfinite(xy1), xy1, xy0), tri[kept & inside], dt)
    g, a, c, used, dropped = patch_cells(xy0, xy1, tri[~kept & ~folded & inside], dt)
    out = {}
    for key, r in (("followed", rates), ("with_patches", ElementStrainRates(
            np.concatenate([rates.gradient_s, g]), np.concatenate([rates.area_m2, a]),
            np.concatenate([rates.centroid_xy_m, c]), rates.bounds_m))):
        div = r.gradient_s[:, 0, 0] + r.gradient_s[:, 1, 1]
        beta = spatial_scaling(r, include_element_scale=False, origin_xy_m=rates.bounds_m[:2]).fit.exponent
        out[key] = {"beta_without_element_scale": float(beta),
                    "net_divergence_ratio": float(np.sum(div * r.area_m2) / np.sum(np.abs(div) * r.area_m2))}
    out.update(patches=int(len(a)), patch_start_area_km2=used / 1e6, patch_area_left_out_km2=dropped / 1e6)
    return out


def region_mask(xy_m: np.ndarray, triangles: np.ndarray, region) -> np.ndarray:
    """Triangles whose centroid lies inside ``region`` (a shapely geometry in the mesh's metres)."""
    import shapely

    c = xy_m[triangles].mean(axis=1)
    return shapely.contains_xy(region, c[:, 0], c[:, 1])


def load_region(path: Path, buffer_m: float):
    """The part of the polygon of GeoJSON file ``path`` at least ``buffer_m`` from its boundary
    (its coast and its islands' coasts): the interior another basin would analyse."""
    from shapely.geometry import shape

    g = json.loads(Path(path).read_text())
    geom = shape(g["features"][0]["geometry"] if "features" in g else g)
    if geom.is_empty or not geom.is_valid:
        raise ConfigError(f"{path}: --region needs one valid polygon")
    region = geom.buffer(-buffer_m)
    if region.is_empty:
        raise ConfigError(f"{path}: nothing of the polygon lies {buffer_m / 1e3:g} km from its boundary")
    return region


def run_components(run_dir: Path, window_days: float = 3.0, start_day: float = 1.0,
                   coast_buffer_m: float = 100e3, wind_curl: bool = False, patches: bool = False,
                   region=None) -> dict:
    """Per-window components and their medians over the windows of one finished run, with the
    followed area and (``wind_curl``) the interior's mean divergence against the geostrophic curl.
    ``region`` (shapely, :func:`load_region`): only the interior's elements whose centroid lies in
    it at the window's start (to compare two basins on the same area)."""
    wind = None
    if wind_curl:
        from lagice.diagnostics.drift import run_wind

        with xr.open_dataset(run_dir / "drifters.nc") as ds:
            cfg = json.loads(ds.attrs["lagice_config"])
        wind, (kind, s, _th) = run_wind(cfg)
        if kind != "geostrophic":
            raise ConfigError(f"{run_dir}: --wind-curl needs the climatology's wind (the run's wind is {kind})")
    rows = []
    for s0 in window_starts_days(run_dir, window_days, start_day):
        t0, t1 = s0 * DAY_S, (s0 + window_days) * DAY_S
        xy0, xy1, tri, dt, info = window_arrays(run_dir, t0, t1, coast_buffer_m)
        sel = tri[info["interior"]]
        if region is not None:
            sel = sel[region_mask(xy0, sel, region)]
        rates = lagrangian_velocity_gradients(xy0, xy1, sel, dt)
        row = {"start_day": float(s0), **window_components(rates)}
        row["analysed_area_km2"] = float(rates.area_m2.sum() / 1e6)
        start_xy, start_tri = info["start_mesh"][:2]
        start_area = np.abs(triangle_geometry(start_xy, start_tri)[0])
        a0 = np.abs(triangle_geometry(xy0, tri)[0]).sum()
        a1 = np.abs(triangle_geometry(xy1, tri)[0]).sum()
        inside0 = interior_triangles(start_xy, start_tri, coast_buffer_m)
        lost0 = np.ones(len(start_tri), bool)
        lost0[info["kept_elements"]] = False
        lost0[info["folded_elements"]] = False  # followed, but left out as folded: not remeshed
        row.update(followed_area_fraction=float(a0 / start_area.sum()), followed_area_change=float(a1 / a0 - 1.0),
                   remeshed_elements=int(info["n_elements_lost"]), folded_elements=int(info["n_elements_folded"]),
                   interior_area_remeshed_fraction=float(start_area[inside0 & lost0].sum()
                                                         / start_area[inside0].sum()))
        if patches and info["n_elements_lost"]:
            row["remeshed_patches"] = with_patches(info, dt, inside0)
        if wind is not None:
            area = rates.area_m2
            row["interior_mean_divergence_per_day"] = float(np.sum(rates.divergence_s * area) / area.sum() * DAY_S)
            row["interior_mean_geostrophic_curl_per_day"] = DAY_S * mean_geostrophic_curl(
                wind, s, t0, t1, rates.centroid_xy_m, area)
        rows.append(row)
    res = {"windows": rows, "median": {k: float(np.median([r[k] for r in rows])) for k in KEYS}}
    if wind is not None:
        d = [r["interior_mean_divergence_per_day"] for r in rows]
        c = [r["interior_mean_geostrophic_curl_per_day"] for r in rows]
        res["correlation_divergence_geostrophic_curl"] = float(np.corrcoef(d, c)[0, 1])
    return res


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", help="run names in benchmarks/out/physics")
    ap.add_argument("--patches", action="store_true",
                    help="also β and the net-divergence ratio with the remeshed interior patches added back")
    ap.add_argument("--wind-curl", action="store_true",
                    help="also the interior's mean divergence against the geostrophic wind's curl (slower)")
    ap.add_argument("--region", type=Path, default=None, metavar="GEOJSON",
                    help="only elements >= 100 km from this polygon's boundary too (records as RUN@region:NAME)")
    args = ap.parse_args(argv)
    region = None if args.region is None else load_region(args.region, 100e3)
    missing = [r for r in args.runs if not (RUNS / r).is_dir()]
    if missing:
        raise ConfigError(f"no run folder for {missing} in {RUNS}: make them with physics_experiments.py run")
    table = json.loads(OUT.read_text()) if OUT.exists() else {}
    print(f"{'run':38s} {'beta':>6s} {'shear':>6s} {'div':>6s} {'net div':>8s} {'|div|/sh':>8s} {'rate/d':>8s}")
    for name in args.runs:
        res = run_components(RUNS / name, wind_curl=args.wind_curl, patches=args.patches, region=region)
        if region is not None:
            res["region"] = str(args.region.name)
            name = f"{name}@region:{args.region.stem}"
        table[name] = res
        m = res["median"]
        print(f"{name:38s} {m['beta']:6.3f} {m['beta_shear_part']:6.3f} {m['beta_divergence_part']:6.3f} "
              f"{m['net_divergence_ratio']:8.2f} {m['mean_abs_divergence_to_mean_shear']:8.2f} "
              f"{m['element_rate_per_day']:8.4f}")
        for w in res["windows"]:
            line = (f"    day {w['start_day']:4.0f}: net-div ratio {w['net_divergence_ratio']:+.2f}, followed "
                    f"{w['followed_area_fraction']:.3f} of the area, its change {w['followed_area_change']:+.4f}, "
                    f"{w['remeshed_elements']} elements remeshed "
                    f"({100 * w['interior_area_remeshed_fraction']:.1f} % of the interior's area)")
            if "remeshed_patches" in w:
                p = w["remeshed_patches"]
                line += (f"; with {p['patches']} patches added back ({p['patch_start_area_km2']:.0f} km², "
                         f"{p['patch_area_left_out_km2']:.0f} km² left out) beta w/o element scale "
                         f"{p['followed']['beta_without_element_scale']:.3f} -> "
                         f"{p['with_patches']['beta_without_element_scale']:.3f}, net-div ratio "
                         f"{p['followed']['net_divergence_ratio']:+.2f} -> "
                         f"{p['with_patches']['net_divergence_ratio']:+.2f}")
            if args.wind_curl:
                line += (f"; interior div {w['interior_mean_divergence_per_day']:+.5f}/d, "
                         f"curl G {w['interior_mean_geostrophic_curl_per_day']:+.3f}/d")
            print(line)
        if args.wind_curl:
            print(f"    correlation of the interior's divergence with curl G: "
                  f"{res['correlation_divergence_geostrophic_curl']:+.2f}")
    OUT.write_text(json.dumps(table, indent=1, sort_keys=True) + "\n")
    print(f"medians over the 3-day windows; written to {OUT.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
