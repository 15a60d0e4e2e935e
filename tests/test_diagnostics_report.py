"""summarise / diagnose_arrays: JSON keys, values read back, PNG figures (issue 7)."""

import json

import numpy as np
import pytest

from lagice.diagnostics import JSON_KEYS, diagnose_arrays, summarise, write_json
from lagice.diagnostics.synthetic import jittered_grid_mesh, slip_line_velocity
from lagice.errors import ConfigError

DT_S = 3 * 86400.0
REQUIRED = [
    "beta_space", "beta_space_fit_range_m", "alpha_time", "pdf_tail_exponent_shear",
    "pdf_tail_exponent_divergence", "localisation_half_shear_area_fraction", "shear_divergence_r2",
]


def test_uniform_strain_summary_values_and_nulls(tmp_path):
    """Uniform strain: β = 0, localisation 0.5, R² and tails undefined (constant fields) -> null."""
    xy0, tri = jittered_grid_mesh(40, 40, 40e3, 40e3, jitter=0.25, seed=9)
    g = np.array([[2e-7, 1e-7], [0.0, -1e-7]])
    xy1 = xy0 + DT_S * (xy0 @ g.T)
    out = diagnose_arrays(xy0, xy1, tri, DT_S, tmp_path, geometry="start")
    on_disk = json.loads((tmp_path / "diagnostics.json").read_text())
    assert on_disk == out
    assert set(out) == set(JSON_KEYS)
    assert out["beta_space"] == pytest.approx(0.0, abs=1e-8)
    assert out["localisation_half_shear_area_fraction"] == pytest.approx(0.5)
    assert out["shear_divergence_r2"] is None
    assert out["pdf_tail_exponent_shear"] is None
    assert out["alpha_time"] is None and out["scaling_time"] is None
    shear = np.hypot(g[0, 0] - g[1, 1], g[0, 1] + g[1, 0])
    assert out["mean_shear_s"] == pytest.approx(shear, rel=1e-9)
    assert out["mean_total_s"] == pytest.approx(np.hypot(shear, g[0, 0] + g[1, 1]), rel=1e-9)
    lo, hi = out["beta_space_fit_range_m"]
    assert lo == pytest.approx(out["element_scale_m"]) and hi > 4 * lo
    for name in out["figures"]:
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert set(out["figures"]) == {"scaling_space.png", "pdfs.png", "map_total_deformation.png"}


def test_slip_lines_with_time_series(tmp_path):
    """Alternating slip lines, reversing every step: α = 1, β > 0 at large scales, localised shear."""
    xy0, tri = jittered_grid_mesh(81, 81, 81e3, 81e3, jitter=0.2, seed=2)
    uv = slip_line_velocity(xy0, 9e3, 1e-4, alternating=True)
    xy1 = xy0 + DT_S * uv
    series = np.repeat(xy0[None], 10, axis=0)
    series[1::2] = xy1
    out = diagnose_arrays(xy0, xy1, tri, DT_S, tmp_path, box_sizes_m=[3e3, 9e3, 27e3, 81e3],
                          fit_range_m=(8e3, 82e3), include_element_scale=False, min_boxes=1,
                          nodes_xy_series=series, series_dt_s=DT_S, window_steps=[1, 3, 9], min_tail=20)
    for key in REQUIRED:
        assert key in out
    assert out["alpha_time"] == pytest.approx(1.0, abs=1e-9)
    assert out["beta_space"] == pytest.approx(1.0, abs=0.05)
    assert out["scaling_space"]["n_boxes"] == [729, 81, 9, 1]
    # shear lives in the one row of cells (h = 1 km) crossing each of the 9 lines: 9/81 of the area
    assert 0 < out["localisation_half_shear_area_fraction"] < 9 / 81
    assert 0.0 <= out["shear_divergence_r2"] <= 1.0
    assert out["pdf_tail_exponent_shear"] is not None
    assert "scaling_time.png" in out["figures"]
    for name in out["figures"]:
        assert (tmp_path / name).stat().st_size > 1000


def test_summarise_bad_arguments(tmp_path):
    xy, tri = jittered_grid_mesh(4, 4, 4e3, 4e3)
    with pytest.raises(ConfigError, match="dt_s"):
        summarise(xy, xy, tri, 0)
    with pytest.raises(ConfigError, match="nodes_xy1"):
        summarise(xy, xy[:3], tri, 1.0)
    with pytest.raises(ConfigError, match="series_dt_s"):
        summarise(xy, xy, tri, 1.0, nodes_xy_series=np.stack([xy, xy]))
    with pytest.raises(ConfigError, match="geometry"):
        diagnose_arrays(xy, xy, tri, 1.0, tmp_path, geometry="centre")


def test_write_json_turns_nan_into_null(tmp_path):
    path = write_json({"beta_space": float("nan"), "x": np.float64(2.0), "n": np.int64(3),
                       "r": [np.nan, 1.0], "_arrays": object()}, tmp_path / "d.json")
    assert json.loads(path.read_text()) == {"beta_space": None, "x": 2.0, "n": 3, "r": [None, 1.0]}
