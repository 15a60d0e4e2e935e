"""All diagnostics in one dictionary, JSON output and figures (GitHub issue 7).

JSON keys written by :func:`write_json` (rates in s-1, lengths in m, times in s;
``null`` where a quantity could not be computed) are documented in
:data:`JSON_KEYS` and in ``docs/diagnostics.md``.
"""

import json
import math
from pathlib import Path

import numpy as np

from lagice.diagnostics._checks import as_points, as_triangles, choice, positive
from lagice.diagnostics.scaling import (
    BETA_GRIDS,
    MIN_FIT_BOXES,
    grid_averaged_beta,
    scaling_curve,
    spatial_scaling,
    temporal_scaling,
)
from lagice.diagnostics.statistics import (
    fit_power_law_tail,
    localisation_area_fraction,
    log_binned_pdf,
    shear_divergence_r2,
)
from lagice.diagnostics.strain import GEOMETRIES, _lagrangian
from lagice.errors import ConfigError
from lagice.io.cf import write_text_atomic

SCHEMA_VERSION = 1

JSON_KEYS = {
    "schema_version": "version of this key set (int)",
    "n_nodes": "number of mesh nodes",
    "n_elements": "number of triangles",
    "dt_s": "window length of the Lagrangian rates (s)",
    "geometry": "triangle geometry of the gradients: 'mid' (x0+x1)/2, 'start' or 'end'",
    "mean_divergence_s": "mean element divergence ε̇I = ∂u/∂x + ∂v/∂y (s-1), signed",
    "mean_abs_divergence_s": "mean element |ε̇I| (s-1)",
    "mean_shear_s": "mean element shear ε̇II = sqrt((∂u/∂x−∂v/∂y)² + (∂u/∂y+∂v/∂x)²) (s-1)",
    "mean_total_s": "mean element ε̇tot = sqrt(ε̇I² + ε̇II²) (s-1)",
    "element_scale_m": "mean sqrt(element area) (m)",
    "beta_space": "β of ⟨ε̇tot⟩ ∝ L^−β (coarse-graining, least squares in log–log)",
    "beta_space_stderr": "standard error of β",
    "beta_space_r2": "R² of the log–log fit",
    "beta_space_fit_range_m": "[L_min, L_max] (m) of the scales used in the β fit (scales with >= min_boxes boxes)",
    "beta_space_grid_mean": "mean of β over box grids laid from several corners (the default one first; "
                            "lagice.diagnostics.scaling.grid_averaged_beta): less dependent on where the boxes fall",
    "beta_space_grid_sd": "standard deviation of β over those grids",
    "beta_space_grids": "number of box grids of beta_space_grid_mean",
    "scaling_space": "{box_size_m, scale_m, mean_total_s, n_boxes} per scale (element scale first, box_size_m null)",
    "scaling_space_grids": "the same curve on each grid of beta_space_grid_mean (the default one first), for "
                           "lagice.diagnostics.scaling.pooled_spatial_scaling",
    "min_box_coverage": "minimum covered fraction of a box's W² for it to count",
    "alpha_time": "α of ⟨ε̇tot⟩ ∝ T^−α (null without a position time series)",
    "alpha_time_stderr": "standard error of α",
    "alpha_time_fit_range_s": "[T_min, T_max] (s) used in the α fit",
    "scaling_time": "{window_s, mean_total_s, n_windows} per window length, or null",
    "pdf_tail_exponent_shear": "γ of the shear-rate density tail p(ε̇II) ∝ ε̇II^−γ (maximum likelihood)",
    "pdf_tail_exponent_shear_stderr": "(γ−1)/sqrt(n_tail)",
    "pdf_tail_fit_range_shear_s": "[x_min, x_max] (s-1) of the shear tail fit",
    "pdf_tail_n_shear": "number of elements in the shear tail",
    "pdf_tail_ks_shear": "Kolmogorov–Smirnov distance of the shear tail fit",
    "pdf_tail_exponent_divergence": "γ of the |ε̇I| density tail",
    "pdf_tail_exponent_divergence_stderr": "(γ−1)/sqrt(n_tail)",
    "pdf_tail_fit_range_divergence_s": "[x_min, x_max] (s-1) of the |divergence| tail fit",
    "pdf_tail_n_divergence": "number of elements in the |divergence| tail",
    "pdf_tail_ks_divergence": "Kolmogorov–Smirnov distance of the |divergence| tail fit",
    "pdf_shear": "{bin_centres_s, density_s} log-binned PDF of ε̇II",
    "pdf_divergence": "{bin_centres_s, density_s} log-binned PDF of |ε̇I|",
    "localisation_half_shear_area_fraction": "area fraction of the highest-shear elements holding half of Σ ε̇II·A",
    "shear_divergence_r2": "squared Pearson correlation of |ε̇I| and ε̇II over elements",
    "figures": "PNG files written next to diagnostics.json (names)",
}


def summarise(nodes_xy0, nodes_xy1, triangles, dt_s, *, geometry="mid", box_sizes_m=None,
              min_coverage=0.75, fit_range_m=None, include_element_scale=True, min_boxes=MIN_FIT_BOXES,
              nodes_xy_series=None, series_dt_s=None, window_steps=None, fit_range_s=None,
              tail_x_min_shear_s=None, tail_x_min_divergence_s=None, min_tail=50,
              pdf_dynamic_range=1e6, pdf_bins_per_decade=10, beta_grids=BETA_GRIDS):
    """Compute all diagnostics of issue 7 from one window of node positions.

    Element-scale rates come from :func:`lagrangian_velocity_gradients`
    (velocity = displacement / dt_s, gradient on the ``geometry``). PDFs,
    localisation and R² use the element-scale rates (Girard et al. 2011 uses the 10 km
    RGPS cell scale); β uses the coarse-graining of Girard 2010 §3.5; α needs a
    position time series.

    Parameters
    ----------
    nodes_xy0, nodes_xy1 : array_like (n, 2)
        Node positions (m) at the start and end of the window.
    triangles : array_like (m, 3) int
        Counter-clockwise connectivity.
    dt_s : float
        Window length (s), > 0.
    geometry : {"mid", "start", "end"}
        Geometry of the gradients (default mid-window).
    box_sizes_m, min_coverage, fit_range_m, include_element_scale, min_boxes
        Passed to :func:`spatial_scaling` (``min_boxes``: boxes a scale needs to
        enter the β fit, default 10).
    beta_grids : int
        Box grids of ``beta_space_grid_mean`` (:func:`grid_averaged_beta`; default 9).
    nodes_xy_series : array_like (k+1, n, 2), optional
        Positions (m) every ``series_dt_s`` for the temporal scaling.
    series_dt_s : float, optional
        Step of ``nodes_xy_series`` (s); required with it.
    window_steps, fit_range_s
        Passed to :func:`temporal_scaling`.
    tail_x_min_shear_s, tail_x_min_divergence_s : float, optional
        Fixed tail thresholds (s-1); default chosen by KS distance.
    min_tail : int
        Minimum tail size for the KS search.
    pdf_dynamic_range : float
        The log-binned PDFs start at ``max(rate) / pdf_dynamic_range`` (default
        1e6), which keeps round-off of Lagrangian differences (≈ 1e-16 · x / (Δt h))
        out of the bins; the density is still normalised by the whole sample.
        The tail fit is not affected.
    pdf_bins_per_decade : int
        Bins per decade of the PDFs.

    Returns
    -------
    dict
        Keys of :data:`JSON_KEYS` (minus ``figures``), floats/lists/None, plus
        ``"_arrays"``: a dict of numpy arrays and result objects for plotting
        (removed by :func:`write_json`).
    """
    x0 = as_points("nodes_xy0", nodes_xy0)
    x1 = as_points("nodes_xy1", nodes_xy1, x0.shape[0])
    tri = as_triangles(triangles, x0.shape[0])
    dt = positive("dt_s", dt_s, "s")
    choice("geometry", geometry, GEOMETRIES)
    rates = _lagrangian(x0, x1, tri, dt, geometry)

    tm = None
    if nodes_xy_series is not None:
        if series_dt_s is None:
            raise ConfigError("series_dt_s is required with nodes_xy_series (time between positions, s)")
        tm = temporal_scaling(nodes_xy_series, tri, series_dt_s, window_steps, geometry,
                              fit_range_s=fit_range_s)

    stats, arrays = rate_statistics(
        rates, box_sizes_m=box_sizes_m, min_coverage=min_coverage, fit_range_m=fit_range_m,
        include_element_scale=include_element_scale, min_boxes=min_boxes,
        tail_x_min_shear_s=tail_x_min_shear_s, tail_x_min_divergence_s=tail_x_min_divergence_s,
        min_tail=min_tail, pdf_dynamic_range=pdf_dynamic_range, pdf_bins_per_decade=pdf_bins_per_decade,
        beta_grids=beta_grids)
    out = {
        "schema_version": SCHEMA_VERSION,
        "n_nodes": int(x0.shape[0]),
        "n_elements": int(tri.shape[0]),
        "dt_s": dt,
        "geometry": geometry,
        **stats,
        "alpha_time": None if tm is None else tm.fit.exponent,
        "alpha_time_stderr": None if tm is None else tm.fit.exponent_stderr,
        "alpha_time_fit_range_s": None if tm is None else list(tm.fit.fit_range),
        "scaling_time": None if tm is None else {
            "window_s": list(tm.window_s), "mean_total_s": list(tm.mean_total_s),
            "n_windows": [int(n) for n in tm.n_windows]},
    }
    out = {k: out[k] for k in JSON_KEYS if k in out}  # the documented key order
    out["_arrays"] = {**arrays, "temporal": tm,
                      "map_xy": 0.5 * (x0 + x1) if geometry == "mid" else (x0 if geometry == "start" else x1),
                      "triangles": tri}
    return out


def rate_statistics(rates, *, box_sizes_m=None, min_coverage=0.75, fit_range_m=None, include_element_scale=True,
                    min_boxes=MIN_FIT_BOXES, origin_xy_m=None, tail_x_min_shear_s=None,
                    tail_x_min_divergence_s=None, min_tail=50, pdf_dynamic_range=1e6, pdf_bins_per_decade=10,
                    beta_grids=BETA_GRIDS):
    """The statistics of :func:`summarise` that depend only on the element rates.

    ``rates`` is an :class:`~lagice.diagnostics.strain.ElementStrainRates` of any
    cells (model triangles, or RGPS-like cells from :mod:`lagice.diagnostics.rgps`);
    the keyword arguments are those of :func:`summarise` (``origin_xy_m``: lower-left
    corner of the box grid, see :func:`coarse_grain`). Returns ``(stats, arrays)``:
    the JSON keys from ``mean_divergence_s`` to ``shear_divergence_r2`` (no temporal
    scaling), and the result objects for figures (``rates``, ``spatial``, ``pdf``,
    ``tail``; ``beta_grids``: the box grids of ``beta_space_grid_mean``, :func:`grid_averaged_beta`)."""
    div, shear, tot = rates.divergence_s, rates.shear_s, rates.total_s
    sp = spatial_scaling(rates, box_sizes_m, min_coverage, fit_range_m, include_element_scale,
                         origin_xy_m=origin_xy_m, min_boxes=min_boxes)
    gb = grid_averaged_beta(rates, beta_grids, 0, sp.coarse.box_size_m, min_coverage, fit_range_m,
                            include_element_scale, min_boxes, origin_xy_m=origin_xy_m, first=sp)
    tail_s = fit_power_law_tail(shear, tail_x_min_shear_s, min_tail)
    tail_d = fit_power_law_tail(np.abs(div), tail_x_min_divergence_s, min_tail)
    dyn = positive("pdf_dynamic_range", pdf_dynamic_range)
    pdf_s = log_binned_pdf(shear, pdf_bins_per_decade, _pdf_floor(shear, dyn))
    pdf_d = log_binned_pdf(np.abs(div), pdf_bins_per_decade, _pdf_floor(np.abs(div), dyn))
    stats = {
        "mean_divergence_s": float(np.mean(div)),
        "mean_abs_divergence_s": float(np.mean(np.abs(div))),
        "mean_shear_s": float(np.mean(shear)),
        "mean_total_s": float(np.mean(tot)),
        "element_scale_m": sp.element_scale_m,
        "beta_space": sp.fit.exponent,
        "beta_space_stderr": sp.fit.exponent_stderr,
        "beta_space_r2": sp.fit.r2,
        "beta_space_fit_range_m": list(sp.fit.fit_range),
        "beta_space_grid_mean": gb.mean,
        "beta_space_grid_sd": gb.sd,
        "beta_space_grids": int(gb.betas.size),
        "scaling_space": scaling_curve(sp),
        "scaling_space_grids": list(gb.curves),
        "min_box_coverage": sp.coarse.min_coverage,
        "pdf_tail_exponent_shear": tail_s.exponent,
        "pdf_tail_exponent_shear_stderr": tail_s.exponent_stderr,
        "pdf_tail_fit_range_shear_s": [tail_s.x_min, tail_s.x_max],
        "pdf_tail_n_shear": tail_s.n_tail,
        "pdf_tail_ks_shear": tail_s.ks_distance,
        "pdf_tail_exponent_divergence": tail_d.exponent,
        "pdf_tail_exponent_divergence_stderr": tail_d.exponent_stderr,
        "pdf_tail_fit_range_divergence_s": [tail_d.x_min, tail_d.x_max],
        "pdf_tail_n_divergence": tail_d.n_tail,
        "pdf_tail_ks_divergence": tail_d.ks_distance,
        "pdf_shear": {"bin_centres_s": list(pdf_s.bin_centres), "density_s": list(pdf_s.density)},
        "pdf_divergence": {"bin_centres_s": list(pdf_d.bin_centres), "density_s": list(pdf_d.density)},
        "localisation_half_shear_area_fraction": localisation_area_fraction(shear, rates.area_m2, 0.5),
        "shear_divergence_r2": shear_divergence_r2(shear, div),
    }
    arrays = {"rates": rates, "spatial": sp, "pdf": {"shear": pdf_s, "|divergence|": pdf_d},
              "tail": {"shear": tail_s, "|divergence|": tail_d}}
    return stats, arrays


def _pdf_floor(values, dynamic_range):
    """Lower bound of the PDF bins: max(smallest positive value, largest / dynamic_range)."""
    pos = values[values > 0]
    if pos.size == 0:
        return None
    return float(max(pos.min(), pos.max() / dynamic_range))


def _jsonable(value):
    """Convert numpy scalars/arrays to JSON types; NaN and inf become None."""
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [_jsonable(v) for v in value]
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return v if math.isfinite(v) else None
    return value


def write_json(summary, path):
    """Write a :func:`summarise` dictionary to ``path`` as JSON (keys: :data:`JSON_KEYS`).

    Private entries (leading underscore) are dropped; NaN becomes ``null``.
    Returns the path.
    """
    clean = {k: v for k, v in summary.items() if not k.startswith("_")}
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(path, json.dumps(_jsonable(clean), indent=2, ensure_ascii=False) + "\n")
    return path


def write_figures(summary, out_dir):
    """Write the PNG figures of a :func:`summarise` dictionary into ``out_dir``.

    Files: ``scaling_space.png`` (⟨ε̇tot⟩(L) with β fit), ``scaling_time.png``
    (if a time series was given), ``pdfs.png`` (shear and |divergence| with
    tail fits), ``map_total_deformation.png`` (log10 ε̇tot on the triangles).
    Returns the list of file names written.
    """
    from lagice.diagnostics import plots

    arr = summary.get("_arrays")
    if arr is None:
        raise ConfigError("summary has no '_arrays' entry; pass the dict returned by summarise()")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    sp = arr["spatial"]
    names = [plots.plot_scaling(sp.scale_m, sp.mean_total_s, sp.fit, out / "scaling_space.png",
                                "scale L (m)", "spatial scaling ⟨ε̇tot⟩ ∝ L$^{-β}$").name]
    tm = arr["temporal"]
    if tm is not None:
        names.append(plots.plot_scaling(tm.window_s, tm.mean_total_s, tm.fit, out / "scaling_time.png",
                                        "window T (s)", "temporal scaling ⟨ε̇tot⟩ ∝ T$^{-α}$").name)
    names.append(plots.plot_pdfs(arr["pdf"], arr["tail"], out / "pdfs.png").name)
    names.append(plots.plot_map(arr["map_xy"], arr["triangles"], arr["rates"].total_s,
                                out / "map_total_deformation.png").name)
    return names


def diagnose_arrays(nodes_xy0, nodes_xy1, triangles, dt_s, out_dir, **kwargs):
    """Compute all diagnostics, write ``diagnostics.json`` and PNG figures in ``out_dir``.

    Parameters
    ----------
    nodes_xy0, nodes_xy1 : array_like (n, 2)
        Node positions (m) at the start and end of the window.
    triangles : array_like (m, 3) int
        Counter-clockwise connectivity.
    dt_s : float
        Window length (s), > 0.
    out_dir : str or Path
        Output folder (created).
    **kwargs
        Passed to :func:`summarise`.

    Returns
    -------
    dict
        The JSON content (keys :data:`JSON_KEYS`, NaN as None).
    """
    summary = summarise(nodes_xy0, nodes_xy1, triangles, dt_s, **kwargs)
    summary["figures"] = write_figures(summary, out_dir)
    write_json(summary, Path(out_dir) / "diagnostics.json")
    return _jsonable({k: v for k, v in summary.items() if not k.startswith("_")})
