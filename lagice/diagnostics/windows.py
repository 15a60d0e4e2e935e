"""Deformation statistics of a run over back-to-back Lagrangian windows (as RGPS).

A run's snapshots (``RUN/snapshots``) give node positions at the snapshot times.
:func:`window_statistics` cuts the run into back-to-back windows of
``window_days`` from ``start_day`` on (the first days are spin-up), follows the
nodes through each window (across remeshing by their persistent ids,
:func:`lagice.io.snapshots.load_window`), keeps the elements whose centroid is at
least ``coast_buffer_km`` from the mesh boundary at the start of the window
(:func:`lagice.diagnostics.faults.interior_triangles`; Girard et al. 2011 used
150 km from the Arctic coasts), and computes the statistics of
:func:`lagice.diagnostics.summarise` per window (β of the spatial scaling, tail
exponents of the shear and |divergence| PDFs, localisation, shear–|divergence|
R², mean rates) on those elements and on all elements. It reports, per metric,
the median over the windows and the [min, max]: a window in which the ice hardly
moves gives degenerate values, and the median is not pulled by one such window.

``lagice diagnose RUN --window-days 3 --coast-buffer-km 100 --start-day 1`` and
``benchmarks/validate.py`` use this function. See ``docs/diagnostics.md``.
"""
from __future__ import annotations

import math

import numpy as np

from lagice.diagnostics.scaling import pooled_spatial_scaling
from lagice.errors import ConfigError, LagiceError

DAY_S = 86400.0


class WindowError(LagiceError):
    """A window with too few elements followed through it (remeshing replaced them)."""

#: the metrics :func:`window_statistics` summarises over the windows (keys of :func:`summarise`)
WINDOW_METRICS = ("beta_space", "beta_space_grid_mean", "pdf_tail_exponent_divergence", "pdf_tail_exponent_shear",
                  "localisation_half_shear_area_fraction", "shear_divergence_r2", "mean_total_s")

#: per-window keys kept from :func:`summarise` (JSON-serialisable)
WINDOW_KEYS = ("beta_space", "beta_space_stderr", "beta_space_r2", "beta_space_fit_range_m",
               "beta_space_grid_mean", "beta_space_grid_sd", "beta_space_grids",
               "pdf_tail_exponent_shear", "pdf_tail_fit_range_shear_s", "pdf_tail_n_shear", "pdf_tail_ks_shear",
               "pdf_tail_exponent_divergence", "pdf_tail_fit_range_divergence_s", "pdf_tail_n_divergence",
               "pdf_tail_ks_divergence", "localisation_half_shear_area_fraction", "shear_divergence_r2",
               "mean_total_s", "mean_shear_s", "mean_abs_divergence_s", "scaling_space", "scaling_space_grids",
               "pdf_shear", "pdf_divergence", "element_scale_m")
#: the per-window keys kept for the RGPS view (:data:`WINDOW_KEYS` without the PDFs)
RGPS_WINDOW_KEYS = tuple(k for k in WINDOW_KEYS if k not in ("pdf_shear", "pdf_divergence"))


def window_arrays(run_dir, start_s: float, end_s: float, coast_buffer_m: float = 0.0, min_elements: int = 10,
                  keep_datasets: bool = False):
    """Node positions at the snapshots nearest ``start_s`` and ``end_s`` [s] and the
    elements kept for the statistics.

    Returns ``(xy0, xy1, triangles, dt_s, info)``: ``triangles`` are the elements
    present over the whole window (remeshed patches left out) whose mid-window geometry
    is not inverted (see below), ``info`` the window of
    :func:`lagice.io.snapshots.load_window` (without its arrays; ``kept_elements``
    indexes ``triangles`` in the first mesh) plus ``interior``
    (mask of the triangles at least ``coast_buffer_m`` [m] from the boundary of the
    window's first mesh), ``n_elements`` (their number), ``n_elements_all``,
    ``n_elements_folded`` and ``folded_elements`` (their indices in the first mesh), and with
    ``keep_datasets`` the two snapshots (``datasets``, as :func:`~lagice.io.snapshots.load_window`).

    The statistics take each element's gradient on its mid-window geometry
    ``(x0 + x1)/2`` (:mod:`lagice.diagnostics.strain`). The model keeps every element
    counter-clockwise at every step, but an element that turns by about half a turn
    while it is sheared (in a fault or an eddy) can have a mid-window triangle with a
    non-positive area although both ends are fine: its Lagrangian rate is then
    undefined. Such an element is left out of ``triangles`` and counted in
    ``n_elements_folded`` (and ``n_interior_folded`` for those inside the buffer), as RGPS
    leaves out cells it cannot follow; nothing is left out silently.
    A run on a fixed mesh (no node moved) is a Eulerian run: its displacement over
    the window is taken as Δt × the mean of the velocities at both ends. Raises
    :class:`~lagice.errors.ConfigError` naming ``coast_buffer_km`` when fewer than
    ``min_elements`` elements are that far from the boundary."""
    from lagice.diagnostics.faults import interior_triangles
    from lagice.diagnostics.strain import triangle_geometry
    from lagice.io.snapshots import load_window

    if not (math.isfinite(coast_buffer_m) and coast_buffer_m >= 0):
        raise ConfigError(f"coast_buffer_km = {coast_buffer_m / 1e3!r}: expected a distance >= 0 km")
    w = load_window(run_dir, start_s, end_s)
    xy0, xy1, tri, dt = w["xy0"], w["xy1"], w["triangles"], w["dt_s"]
    if w["fixed_mesh"]:
        xy1 = xy0 + 0.5 * (w["velocity0"] + w["velocity1"]) * dt
    inside = interior_triangles(*w["start_mesh"], coast_buffer_m)
    if inside.sum() < min_elements:
        raise ConfigError(f"coast_buffer_km = {coast_buffer_m / 1e3:g}: only {int(inside.sum())} elements lie that "
                          f"far from the boundary (at least {min_elements} needed); use a smaller buffer")
    kept = np.asarray(w["kept_elements"])
    keep = inside[kept]
    unfolded = triangle_geometry(0.5 * (xy0 + xy1), tri)[0] > 0.0  # False for NaN too
    n_folded = int(tri.shape[0] - unfolded.sum())
    n_interior_folded = int(np.sum(keep & ~unfolded))
    folded_elements = kept[~unfolded]
    if n_folded:
        tri, kept, keep = tri[unfolded], kept[unfolded], keep[unfolded]
    if keep.sum() < min_elements:
        folded = f", {n_interior_folded} more inverted in the mid-window geometry" if n_interior_folded else ""
        raise WindowError(f"{run_dir}: window {w['start_s'] / DAY_S:g}-{w['end_s'] / DAY_S:g} days: only "
                          f"{int(keep.sum())} of the {int(inside.sum())} elements >= {coast_buffer_m / 1e3:g} km "
                          f"from the boundary can be followed through the window ({w['remesh_events']} remesh "
                          f"event(s) replaced {w['n_elements_lost']} elements{folded}); choose other windows")
    info = {k: v for k, v in w.items() if k not in ("xy0", "xy1", "triangles", "datasets")}
    if keep_datasets:  # the two snapshots as xarray Datasets (accumulated_strain_rates reads their fields)
        info["datasets"] = w["datasets"]
    info.update(kept_elements=kept, n_elements=int(keep.sum()), n_elements_all=int(tri.shape[0]), interior=keep,
                n_elements_folded=n_folded, n_interior_folded=n_interior_folded, folded_elements=folded_elements)
    return xy0, xy1, tri, dt, info


def window_summary(run_dir, start_s: float, window_s: float, coast_buffer_m: float = 0.0,
                   keep_arrays: bool = False, rgps_tracking_error_m: float | None = None,
                   rgps_seed: int = 0) -> dict:
    """Statistics of one Lagrangian window ``[start_s, start_s + window_s]`` [s].

    Returns ``{"start_day", "end_day", "n_elements" (kept), "n_elements_all",
    "remesh_events", "n_elements_lost", "n_elements_folded", "n_interior_folded" (elements left out
    because their mid-window geometry is inverted: :func:`window_arrays`), "interior": {...},
    "all": {...}}`` with the
    :data:`WINDOW_KEYS` of :func:`lagice.diagnostics.summarise` on the elements
    ``coast_buffer_m`` [m] from the boundary (``interior``) and on all elements.
    ``keep_arrays``: ``interior`` also holds ``"_map"`` = (element-map node
    positions, triangles, shear rate [s-1]) for figures (not JSON-serialisable).
    ``rgps_tracking_error_m``: also the statistics of the interior as RGPS would see
    it (:func:`lagice.diagnostics.rgps.rgps_cells`: 10 km cells, this tracking error
    [m], seeded by ``(rgps_seed, start_s)``) under ``rgps``, and of the same cells
    without error under ``rgps_cells``; each with ``n_cells`` and ``n_cells_folded`` (cells the
    window's displacement inverts, dropped: :func:`lagice.diagnostics.rgps.observe`; and without
    the PDFs)."""
    from lagice.diagnostics.report import rate_statistics, summarise
    from lagice.diagnostics.rgps import observe, rgps_cells

    xy0, xy1, tri, dt, info = window_arrays(run_dir, start_s, start_s + window_s, coast_buffer_m)
    out = {"start_day": info["start_s"] / DAY_S, "end_day": info["end_s"] / DAY_S,
           "n_elements": info["n_elements"], "n_elements_all": info["n_elements_all"],
           "remesh_events": info["remesh_events"], "n_elements_lost": info["n_elements_lost"],
           "n_elements_folded": info["n_elements_folded"], "n_interior_folded": info["n_interior_folded"]}
    for name, sub in (("interior", tri[info["interior"]]), ("all", tri)):
        s = summarise(xy0, xy1, sub, dt)
        arr = s.pop("_arrays")
        res = {k: s[k] for k in WINDOW_KEYS}
        if name == "interior" and keep_arrays:
            res["_map"] = (arr["map_xy"], sub, arr["rates"].shear_s)
        out[name] = res
    if rgps_tracking_error_m is not None:
        truth = rgps_cells(xy0, xy1, tri[info["interior"]], dt, tracking_error_m=0.0)
        seen = observe(truth[1], dt, rgps_tracking_error_m, seed=(rgps_seed, int(round(start_s))))
        for name, (rates, ci) in (("rgps", seen), ("rgps_cells", truth)):
            st, _ = rate_statistics(rates)
            out[name] = {**{k: st[k] for k in RGPS_WINDOW_KEYS}, "n_cells": ci["n_cells"],
                         "n_cells_folded": ci["n_cells_folded"],
                         "tracking_error_m": ci["tracking_error_m"], "seed": ci["seed"]}
    return out


def accumulated_strain_rates(run_dir, start_s: float, end_s: float, coast_buffer_m: float = 0.0):
    """The mean strain rate the rheology used over a window, from the snapshots' accumulated
    strain (``output.accumulate_strain``), on the triangles :func:`window_arrays` follows.

    For each followed triangle, the accumulated strain S (ε̇xx, ε̇yy, ε̇xy integrated in time) at
    the window's end is the area-weighted mean of the end snapshot's S over the triangle's end
    position (:func:`lagice.remesh.remap.intersect_triangles`: exact for an element that is still
    an element at the end; for one whose nodes survived a remesh around it, the mean of the
    elements that now cover it), and its S at the start is the start snapshot's. Their
    difference over the window's length is the rheology's mean strain rate [s⁻¹].

    Returns ``(node_rates, rheology_rates, info)``: two
    :class:`~lagice.diagnostics.strain.ElementStrainRates` of the same triangles on their
    mid-window geometry (the node motion's Lagrangian gradient, as :func:`window_summary`
    takes it; and the symmetric gradient ``[[ε̇xx, ε̇xy], [ε̇xy, ε̇yy]]`` of the rheology's rate,
    which has the same divergence and maximum shear), and :func:`window_arrays`'s ``info``.
    A window that begins at the step from which the field counts (a resume that switched the
    option on: the snapshot written then has no field) starts from zero. Raises
    :class:`~lagice.errors.ConfigError` when a snapshot lacks the field otherwise, or the two
    count it from different starts (a resume that switched it on inside the window)."""
    from lagice.diagnostics.strain import (
        ElementStrainRates,
        lagrangian_velocity_gradients,
        symmetric_gradient,
        triangle_geometry,
    )
    from lagice.remesh.remap import intersect_triangles, remap_field, remap_weights

    xy0, xy1, tri, dt, info = window_arrays(run_dir, start_s, end_s, coast_buffer_m, keep_datasets=True)
    ds0, ds1 = info.pop("datasets")
    names = [f"strain_accumulated_{c}" for c in ("xx", "yy", "xy")]
    has = [all(n in ds for n in names) for ds in (ds0, ds1)]
    s1 = ds1.attrs.get("strain_accumulated_since_s")
    # a resume that switched the option on counts from its first step: the snapshot written at
    # that time (before the resume) has no field, and its value there is zero by definition
    counts_from_start = has[1] and s1 is not None and float(s1) == info["start_s"]
    for ok, when in ((has[0] or counts_from_start, info["start_s"]), (has[1], info["end_s"])):
        if not ok:
            raise ConfigError(f"{run_dir}: the snapshot at {when / DAY_S:g} days has no accumulated strain; run the "
                              f"scene with output.accumulate_strain = true")
    s0 = ds0.attrs.get("strain_accumulated_since_s") if has[0] else s1
    if s0 != s1:
        raise ConfigError(f"{run_dir}: the accumulated strain of the window {info['start_s'] / DAY_S:g}-"
                          f"{info['end_s'] / DAY_S:g} days starts at {s0} s in its first snapshot and at {s1} s in "
                          f"its last (switched on by a resume inside the window); choose windows after it")
    kept = info["kept_elements"]
    acc0 = (np.column_stack([ds0[n].values[0] for n in names])[kept] if has[0]
            else np.zeros((len(kept), 3)))
    acc1_mesh = np.column_stack([ds1[n].values[0] for n in names])
    end_nodes = np.column_stack([ds1["mesh_node_x"].values, ds1["mesh_node_y"].values])
    end_tri = ds1["mesh_face_nodes"].values.astype(np.int64)
    i_old, j_new, w = intersect_triangles(end_nodes, end_tri, xy1, tri)
    area_end = triangle_geometry(xy1, tri)[0]
    weights = remap_weights(i_old, j_new, w, tri.shape[0], new_areas=area_end)
    acc1 = remap_field(acc1_mesh, i_old, j_new, w, weights)
    eps = (acc1 - acc0) / dt
    nodes = lagrangian_velocity_gradients(xy0, xy1, tri, dt, geometry="mid")
    rheo = ElementStrainRates(symmetric_gradient(eps), nodes.area_m2, nodes.centroid_xy_m, nodes.bounds_m)
    return nodes, rheo, info


def window_starts_days(run_dir, window_days: float, start_day: float = 1.0, end_day: float | None = None):
    """Start days of the back-to-back windows of ``window_days`` from ``start_day`` that end
    by ``end_day`` (default: the last snapshot)."""
    from lagice.io.snapshots import read_index

    if not (math.isfinite(window_days) and window_days > 0):
        raise ConfigError(f"window_days = {window_days!r}: expected a window length > 0 days")
    if not (math.isfinite(start_day) and start_day >= 0):
        raise ConfigError(f"start_day = {start_day!r}: expected a day >= 0 (the spin-up to skip)")
    idx = read_index(run_dir)
    last = idx[-1]["time_s"] / DAY_S
    end = last if end_day is None else float(end_day)
    starts = np.arange(start_day, end - window_days + 1e-9, window_days)
    if starts.size == 0:
        raise ConfigError(f"window_days = {window_days:g} from start_day = {start_day:g}: no whole window fits "
                          f"before day {end:g} (the run's snapshots span days {idx[0]['time_s'] / DAY_S:g}–{last:g})")
    return starts


def window_statistics(run_dir, window_days: float = 3.0, coast_buffer_km: float = 100.0, start_day: float = 1.0,
                      end_day: float | None = None, metrics=WINDOW_METRICS, keep_arrays: bool = False,
                      rgps_tracking_error_m: float | None = None, rgps_seed: int = 0) -> dict:
    """Deformation statistics over back-to-back Lagrangian windows of a run.

    Args:
        run_dir: a run folder (with ``snapshots/``) or a snapshot folder.
        window_days: window length [days] (RGPS: 3).
        coast_buffer_km: statistics on the elements whose centroid is at least this
            far from the mesh boundary [km] (``all`` keeps every element).
        start_day: first window start [days] (the days before are spin-up).
        end_day: last window end [days] (default: the last snapshot).
        metrics: the per-window keys summarised over the windows.
        keep_arrays: keep the element maps of each window (see :func:`window_summary`).
        rgps_tracking_error_m, rgps_seed: also the statistics as RGPS would see them
            (see :func:`window_summary`), summarised as ``median_rgps`` (with the
            tracking error) and ``median_rgps_cells`` (the same cells without it), and
            ``pooled_rgps``, ``pooled_rgps_cells`` (:func:`pooled_window_scaling` on those cells).

    Returns ``{"window_days", "coast_buffer_km", "start_day", "windows": [per-window
    dicts of :func:`window_summary`], "skipped": [{"start_day", "end_day", "reason"}],
    "n_elements_folded", "n_interior_folded" (summed over the windows: elements left out because
    their mid-window geometry is inverted, :func:`window_arrays`),
    "median", "min", "max": {metric: value over the windows, interior elements},
    "median_all_elements": {metric: median, all elements}, "pooled": β of the interior's curve
    pooled over every box of every window (:func:`pooled_window_scaling`)}``. A window in which
    remeshing replaced (nearly) all the elements cannot be followed: it is listed
    in ``skipped`` with the reason, not in ``windows``. A metric that is NaN in some
    windows is summarised over the others (``None`` if NaN in all)."""
    starts = window_starts_days(run_dir, window_days, start_day, end_day)
    windows, skipped = [], []
    for t in starts:
        try:
            windows.append(window_summary(run_dir, t * DAY_S, window_days * DAY_S, coast_buffer_km * 1e3,
                                          keep_arrays, rgps_tracking_error_m, rgps_seed))
        except WindowError as exc:
            skipped.append({"start_day": float(t), "end_day": float(t + window_days), "reason": str(exc)})
    if not windows:
        raise WindowError(f"{run_dir}: no window could be followed: " + "; ".join(s["reason"] for s in skipped))

    def over(fn, part):
        out = {}
        for k in metrics:
            v = np.array([np.nan if w[part][k] is None else w[part][k] for w in windows], np.float64)
            v = v[np.isfinite(v)]
            out[k] = float(fn(v)) if v.size else None
        return out

    out = {"window_days": float(window_days), "coast_buffer_km": float(coast_buffer_km),
           "start_day": float(start_day), "windows": windows, "skipped": skipped,
           "n_elements_folded": int(sum(w["n_elements_folded"] for w in windows)),
           "n_interior_folded": int(sum(w["n_interior_folded"] for w in windows)),
           "median": over(np.median, "interior"), "min": over(np.min, "interior"),
           "max": over(np.max, "interior"), "median_all_elements": over(np.median, "all"),
           "pooled": pooled_window_scaling(windows)}
    if rgps_tracking_error_m is not None:
        out["rgps_tracking_error_m"] = float(rgps_tracking_error_m)
        out["median_rgps"] = over(np.median, "rgps")
        out["median_rgps_cells"] = over(np.median, "rgps_cells")
        out["pooled_rgps"] = pooled_window_scaling(windows, "rgps")
        out["pooled_rgps_cells"] = pooled_window_scaling(windows, "rgps_cells")
    return out


def pooled_window_scaling(windows, part: str = "interior") -> dict:
    """β of ⟨ε̇tot⟩(L) over every box of every window, as observed β is computed (Marsan et al.
    2004; Girard et al. 2011; :func:`lagice.diagnostics.scaling.pooled_spatial_scaling`): the
    windows that deform most weigh most, where the median of the windows' own β weighs a locked
    window as much as a storm.

    ``windows``: per-window dicts of :func:`window_summary` (or records with their ``part``'s
    ``scaling_space`` and ``scaling_space_grids``), of one run or of several runs of one mesh.
    Returns ``{"n_windows", "beta_space" (the default box grid), "beta_space_fit_range_m",
    "curve": {"scale_m", "mean_total_s", "n_boxes"}, "beta_space_grids" (every box of
    every grid of every window; None where a window lacks its grids' curves), "n_grid_curves"}``."""
    windows = list(windows)
    if not windows:
        raise ConfigError("pooled_window_scaling: no window")
    one = pooled_spatial_scaling([w[part]["scaling_space"] for w in windows])
    grids = [w[part].get("scaling_space_grids") for w in windows]
    every = None if any(not g for g in grids) else pooled_spatial_scaling([c for g in grids for c in g])
    return {"n_windows": len(windows), "beta_space": one.fit.exponent,
            "beta_space_fit_range_m": list(one.fit.fit_range),
            "curve": {"scale_m": [float(x) for x in one.scale_m],
                      "mean_total_s": [float(x) for x in one.mean_total_s],
                      "n_boxes": [int(n) for n in one.n_boxes]},
            "beta_space_grids": None if every is None else every.fit.exponent,
            "n_grid_curves": 0 if every is None else every.n_curves}
