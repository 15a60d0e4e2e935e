"""Deformation diagnostics that tell physics from noise (docs/design.md §8, GitHub issue 7).

Works on plain arrays (node positions in m, CCW triangles, window in s) so it
applies equally to model output and to RGPS-like Lagrangian data:

- :func:`velocity_gradients`, :func:`lagrangian_velocity_gradients`:
  per-triangle gradients and invariants (divergence, shear, total; s-1);
- :func:`coarse_grain`, :func:`spatial_scaling`: ⟨ε̇tot⟩(L) ∝ L^−β (Girard 2010 §3.5);
  :func:`grid_averaged_beta`: β averaged over box grids laid from several corners;
  :func:`pooled_spatial_scaling`: β of the curve over every box of several windows or grids
  (the observations' estimator);
- :func:`temporal_scaling`: ⟨ε̇tot⟩(T) ∝ T^−α;
- :func:`log_binned_pdf`, :func:`fit_power_law_tail`: PDFs and ML tail exponents;
- :func:`localisation_area_fraction`, :func:`shear_divergence_r2`;
- :func:`summarise`, :func:`write_json`, :func:`write_figures`, :func:`diagnose_arrays`;
- :func:`window_statistics`: the statistics of a run over back-to-back Lagrangian
  windows (median and [min, max] over the windows, coast buffer), as used by
  ``lagice diagnose --window-days`` and ``benchmarks/validate.py``.

See ``docs/diagnostics.md``.
"""

from lagice.diagnostics.report import (
    JSON_KEYS,
    diagnose_arrays,
    summarise,
    write_figures,
    write_json,
)
from lagice.diagnostics.scaling import (
    CoarseGraining,
    GridAveragedBeta,
    PooledScaling,
    PowerLawFit,
    SpatialScaling,
    TemporalScaling,
    coarse_grain,
    default_box_sizes,
    fit_power_law,
    grid_averaged_beta,
    pooled_spatial_scaling,
    scaling_curve,
    spatial_scaling,
    temporal_scaling,
)
from lagice.diagnostics.statistics import (
    LogBinnedPdf,
    PowerLawTail,
    fit_power_law_tail,
    localisation_area_fraction,
    log_binned_pdf,
    shear_divergence_r2,
)
from lagice.diagnostics.strain import (
    ElementStrainRates,
    divergence_rate,
    lagrangian_velocity_gradients,
    shear_rate,
    total_deformation_rate,
    triangle_geometry,
    velocity_gradients,
)
from lagice.diagnostics.windows import (
    WINDOW_METRICS,
    window_arrays,
    window_statistics,
    window_summary,
)

__all__ = [
    "ElementStrainRates", "divergence_rate", "lagrangian_velocity_gradients", "shear_rate",
    "total_deformation_rate", "triangle_geometry", "velocity_gradients",
    "CoarseGraining", "PowerLawFit", "SpatialScaling", "TemporalScaling", "coarse_grain",
    "default_box_sizes", "fit_power_law", "grid_averaged_beta", "GridAveragedBeta", "spatial_scaling",
    "temporal_scaling", "pooled_spatial_scaling", "PooledScaling", "scaling_curve",
    "LogBinnedPdf", "PowerLawTail", "fit_power_law_tail", "localisation_area_fraction",
    "log_binned_pdf", "shear_divergence_r2",
    "JSON_KEYS", "diagnose_arrays", "summarise", "write_figures", "write_json",
    "WINDOW_METRICS", "window_arrays", "window_statistics", "window_summary",
]
