"""lagice.diagnostics.rgps: the model as RGPS would see it (10 km cells, tracked points
with a 100 m error). Checked against exact results: an affine displacement is recovered
by the cells to round-off; a pure tracking error gives the analytic error standard
deviation of a square cell, sqrt(2) σ / (L Δt), which for RGPS's σ = 100 m, L = 10 km,
Δt = 3 days is the 0.5 % day⁻¹ Lindsay and Stern (2003) quote; and, since a box
gradient is a line integral around the box, pure error falls as L^−1.5 with box size."""
import math

import numpy as np
import pytest

from lagice.diagnostics.report import rate_statistics
from lagice.diagnostics.rgps import RGPS_CELL_M, RGPS_TRACKING_ERROR_M, observe, rgps_cells
from lagice.diagnostics.synthetic import jittered_grid_mesh
from lagice.errors import ConfigError

DAY = 86400.0
DT = 3 * DAY


@pytest.fixture(scope="module")
def mesh():
    """400 km square, 8 km jittered triangles (not aligned with the 10 km cells)."""
    return jittered_grid_mesh(50, 50, 400e3, 400e3, jitter=0.25, seed=3)


def test_affine_displacement_is_recovered_exactly(mesh):
    xy, tri = mesh
    g = np.array([[3e-7, -1e-7], [2.5e-7, -1.5e-7]])  # s-1, a mix of divergence, shear and rotation
    c = np.array([0.05, -0.02])  # m s-1, a drift
    xy1 = xy + DT * (xy @ g.T + c)
    rates, info = rgps_cells(xy, xy1, tri, DT, tracking_error_m=0.0)
    # P1 interpolation of an affine map is exact, so every cell moves as the ice; on the
    # mid-window geometry the gradient of u = A x0/Δt is (A/Δt)(I + A/2)^-1, A = Δt G
    a = DT * g
    expect = (a / DT) @ np.linalg.inv(np.eye(2) + 0.5 * a)
    assert info["n_cells"] == 40 * 40  # 41 x 41 points (the edges included), every cell inside
    assert np.abs(rates.gradient_s - expect).max() < 1e-12 * np.abs(expect).max()
    assert rates.area_m2.sum() == pytest.approx(np.abs(np.linalg.det(np.eye(2) + 0.5 * a)) * (400e3) ** 2,
                                                rel=1e-9)


def test_tracking_error_gives_the_rgps_error_of_a_cell(mesh):
    xy, tri = mesh
    rates, info = rgps_cells(xy, xy, tri, DT, seed=1)
    assert info["tracking_error_m"] == RGPS_TRACKING_ERROR_M and info["cell_m"] == RGPS_CELL_M
    expect = math.sqrt(2.0) * RGPS_TRACKING_ERROR_M / (RGPS_CELL_M * DT)  # s-1
    assert expect * DAY == pytest.approx(0.0047, abs=1e-4)  # Lindsay and Stern (2003): about 0.5 % per day
    div = rates.divergence_s
    # 1600 cells: the sample standard deviation is within about 2 % (1 sigma) of the true one
    assert np.std(div) == pytest.approx(expect, rel=0.07)
    assert abs(np.mean(div)) < 4 * expect / math.sqrt(div.size)
    # the same seed gives the same errors, another seed others
    again, _ = rgps_cells(xy, xy, tri, DT, seed=1)
    other, _ = rgps_cells(xy, xy, tri, DT, seed=2)
    assert np.array_equal(again.gradient_s, rates.gradient_s)
    assert not np.allclose(other.gradient_s, rates.gradient_s)


def test_pure_tracking_error_falls_as_box_size_to_the_minus_1_5(mesh):
    xy, tri = mesh
    rates, info = rgps_cells(xy, xy, tri, DT, seed=4)
    st, _ = rate_statistics(rates, box_sizes_m=[20e3, 40e3, 80e3], origin_xy_m=info["origin_xy_m"])
    # the trapezoid line integral around an n x n box of cells of side L weighs the 4n
    # boundary points (corners half): var(∂u/∂x) = σu² (2n − 1) / (n⁴ L²), every component
    # alike, so ⟨ε̇tot⟩ ∝ sqrt((2n − 1) / n⁴), tending to n^-1.5
    n = np.array([1.0, 2.0, 4.0, 8.0])
    beta_exact = -np.polyfit(np.log(n), 0.5 * np.log((2 * n - 1) / n ** 4), 1)[0]
    assert beta_exact == pytest.approx(1.35, abs=0.01)
    assert st["beta_space"] == pytest.approx(beta_exact, abs=0.05)
    # and it is not localised: half of the shear is on far more than the observed 4-8 % of the area
    assert st["localisation_half_shear_area_fraction"] > 0.25


def test_bad_arguments_are_named(mesh):
    xy, tri = mesh
    with pytest.raises(ConfigError, match="tracking_error_m = -1"):
        rgps_cells(xy, xy, tri, DT, tracking_error_m=-1.0)
    with pytest.raises(ConfigError, match="cell_m = 1e"):
        rgps_cells(xy, xy, tri, DT, cell_m=1e6)
    with pytest.raises(ConfigError, match="dt_s"):
        rgps_cells(xy, xy, tri, 0.0)


def test_observe_is_rgps_cells_without_relaying_the_grid(mesh):
    """The error-free cells seen with an error give what rgps_cells with that error and seed gives."""
    xy, tri = mesh
    g = np.array([[2e-7, 1e-7], [-1e-7, 0.5e-7]])
    xy1 = xy + DT * (xy @ g.T)
    direct, dinfo = rgps_cells(xy, xy1, tri, DT, tracking_error_m=RGPS_TRACKING_ERROR_M, seed=(5, 7))
    _, truth = rgps_cells(xy, xy1, tri, DT, tracking_error_m=0.0)
    seen, sinfo = observe(truth, DT, RGPS_TRACKING_ERROR_M, seed=(5, 7))
    assert np.array_equal(seen.gradient_s, direct.gradient_s)
    assert sinfo["seed"] == dinfo["seed"] == [5, 7] and sinfo["tracking_error_m"] == RGPS_TRACKING_ERROR_M
    assert truth["tracking_error_m"] == 0.0  # the error-free record is left as it was
    with pytest.raises(ConfigError, match="already carry a 100 m tracking error"):
        observe(sinfo, DT, 50.0)


def test_cells_folded_over_the_window_are_dropped_and_counted(mesh):
    """A band of convergence that closes by more than a cell's height folds the cells across it
    in the mid-window geometry (a fixed mesh whose nodes are carried by a sheared velocity does
    that): those cells are dropped and counted (``n_cells_folded``), never used with a negative
    area; the cells away from the band, which only translate, keep a zero gradient; and a
    displacement that folds every cell is an error."""
    xy, tri = mesh
    y0, amp, width = 205e3, 15e3, 1e3  # the band at y = 205 km, half its closing 15 km, 1 km wide
    xy1 = xy.copy()
    xy1[:, 1] -= amp * np.tanh((xy[:, 1] - y0) / width)
    rates, info = rgps_cells(xy, xy1, tri, DT, tracking_error_m=0.0)
    assert 0 < info["n_cells_folded"] < 40 * 40
    assert info["n_cells"] + info["n_cells_folded"] == 40 * 40
    assert len(rates.area_m2) == info["n_cells"] == len(info["cells"])
    assert (rates.area_m2 > 0).all() and np.isfinite(rates.gradient_s).all()
    corners_y = info["points_xy0"][info["cells"], 1]
    away = (np.abs(corners_y - y0) > 25e3).all(axis=1)  # all four corners beyond the band's 8 km elements
    assert away.sum() > 1000
    assert np.abs(rates.gradient_s[away]).max() < 1e-12 * amp / DT
    # seen with a tracking error: the folded cells stay out, the count carried
    seen, info2 = observe(info, DT, RGPS_TRACKING_ERROR_M, seed=1)
    assert info2["n_cells_folded"] >= info["n_cells_folded"] and len(seen.area_m2) == info2["n_cells"]
    mirrored = xy.copy()
    mirrored[:, 0] = 3.0 * 200e3 - 2.0 * xy[:, 0]  # the mid-window geometry is the plate mirrored: all inverted
    with pytest.raises(ConfigError, match="every one of the 1600 cells is inverted"):
        rgps_cells(xy, mirrored, tri, DT, tracking_error_m=0.0)
