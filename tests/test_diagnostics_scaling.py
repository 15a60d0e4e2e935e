"""Spatial coarse-graining and temporal scaling on fields with analytic answers (Girard 2010 §3.5).

Slip-line fields. The x-velocity jumps by Δu across horizontal lines
y = (k + 1/2) s (k = 0..8) in an 81 km × 81 km domain (s = 9 km); on the mesh
the jump is smeared over the one row of triangles crossing each line.

For a box (union of the elements whose centroids fall inside a W × W cell),
the area-weighted mean gradient equals the line integral (1/A) ∮ u n ds over
the union's boundary (Green), so ∂u/∂y_box = (u_top − u_bottom)/W and
∂u/∂x_box ≈ 0: ε̇tot_box = |net jump| / W, independent of the mesh. With box
widths W = s·3^k the lines sit at the centre of box rows, so every box holds
either no line or a whole number n(W) of lines:

* same-sense slip (jumps all +Δu):
  - W < s: a fraction W/s of the boxes hold one line (ε̇ = Δu/W), the rest 0,
    so the mean over all boxes ⟨ε̇⟩ = Δu/s for every W: β = 0. The
    area-weighted coarse-graining is linear in the gradient, so the mean of a
    sign-coherent field is conserved across scales;
  - the conditional mean over deforming boxes is Δu/W (∝ L^−1) for W ≤ s and
    n Δu / W = Δu/s (plateau) for W ≥ s: this is the "L^−1 then plateau" of
    one-dimensional faults in 2-D; it is also what the second moment shows:
    ⟨ε̇²⟩ = (W/s)(Δu/W)² ∝ L^−1 for W ≤ s.
* alternating slip (+Δu, −Δu, ...): the net jump over an odd number of lines
  is ±Δu, so ⟨ε̇⟩ = Δu/s (plateau, β = 0) for W ≤ s and Δu/W (β = 1) for
  W ≥ s with W/s odd: cancellation between events of opposite sense is what
  makes β > 0.

Tolerances. The only departure from these values is the jagged edge of each
box (centroid assignment): elements crossing a line on the left/right edges of
a box add ∂u/∂x ~ Δu·(node jitter)/W² and change the covered area by
O(h/W). With h = 0.24 km, jitter 0.2 h and W ≥ 1 km the measured means are
within 1.2 % of the analytic ones (1.1 % at W = 1 km, < 0.1 % at W ≥ 9 km),
so exponents fitted over a decade are within log(1.012)/log(9) ≈ 0.006 of the
analytic value; we assert 0.02 (and 2 % on the means).
"""

import numpy as np
import pytest

from lagice.diagnostics import (
    coarse_grain,
    fit_power_law,
    grid_averaged_beta,
    lagrangian_velocity_gradients,
    pooled_spatial_scaling,
    scaling_curve,
    spatial_scaling,
    temporal_scaling,
    velocity_gradients,
)
from lagice.diagnostics.synthetic import jittered_grid_mesh, slip_line_velocity
from lagice.errors import ConfigError

L_M = 81e3
S_M = 9e3
DU = 0.1  # m s-1
W_M = np.array([1, 3, 9, 27, 81]) * 1e3


@pytest.fixture(scope="module")
def mesh():
    return jittered_grid_mesh(340, 340, L_M, L_M, jitter=0.2, seed=1)


def test_same_sense_slip_lines_mean_is_scale_invariant(mesh):
    xy, tri = mesh
    rates = velocity_gradients(xy, tri, slip_line_velocity(xy, S_M, DU))
    sp = spatial_scaling(rates, W_M, include_element_scale=False, min_boxes=1)  # exact field: 1 box suffices
    assert list(sp.coarse.n_boxes) == [6561, 729, 81, 9, 1]
    np.testing.assert_allclose(sp.coarse.scale_m, W_M, rtol=1e-3)
    np.testing.assert_allclose(sp.mean_total_s, DU / S_M, rtol=0.02)
    assert abs(sp.fit.exponent) < 0.02
    assert sp.fit.fit_range == pytest.approx((W_M[0], W_M[-1]), rel=1e-3)


def test_same_sense_slip_lines_conditional_mean_L_minus_one_then_plateau(mesh):
    xy, tri = mesh
    rates = velocity_gradients(xy, tri, slip_line_velocity(xy, S_M, DU))
    cg = coarse_grain(rates, W_M)
    threshold = 1e-6 * DU / S_M
    cond = np.array([b[b > threshold].mean() for b in cg.box_total_s])
    frac = np.array([(b > threshold).mean() for b in cg.box_total_s])
    np.testing.assert_allclose(frac, [1 / 9, 1 / 3, 1, 1, 1])
    small = fit_power_law(cg.scale_m, cond, (0.99 * W_M[0], 1.01 * S_M))
    large = fit_power_law(cg.scale_m, cond, (0.99 * S_M, W_M[-1]))
    assert small.n_points == 3 and large.n_points == 3
    assert small.exponent == pytest.approx(1.0, abs=0.02)
    assert abs(large.exponent) < 0.02
    np.testing.assert_allclose(cond[cg.box_size_m <= S_M], DU / W_M[W_M <= S_M], rtol=0.02)
    second = np.array([np.mean(b**2) for b in cg.box_total_s])
    assert fit_power_law(cg.scale_m, second, (0.99 * W_M[0], 1.01 * S_M)).exponent == pytest.approx(1.0, abs=0.03)


def test_alternating_slip_lines_plateau_then_L_minus_one(mesh):
    xy, tri = mesh
    rates = velocity_gradients(xy, tri, slip_line_velocity(xy, S_M, DU, alternating=True))
    sp = spatial_scaling(rates, W_M, include_element_scale=False, fit_range_m=(0.99 * S_M, L_M), min_boxes=1)
    expected = np.where(W_M <= S_M, DU / S_M, DU / W_M)
    np.testing.assert_allclose(sp.mean_total_s, expected, rtol=0.02)
    assert sp.fit.exponent == pytest.approx(1.0, abs=0.02)
    assert sp.fit.n_points == 3
    plateau = fit_power_law(sp.scale_m, sp.mean_total_s, (0.99 * W_M[0], 1.01 * S_M))
    assert plateau.n_points == 3 and abs(plateau.exponent) < 0.02


def test_lagrangian_slip_lines_give_same_scaling(mesh):
    """Same field as displacements over 3 days: the mid-geometry Lagrangian rates give the same β."""
    xy, tri = mesh
    dt = 3 * 86400.0
    uv = slip_line_velocity(xy, S_M, 1e-4, alternating=True)  # 26 m in 3 days, << element size
    rates = lagrangian_velocity_gradients(xy, xy + dt * uv, tri, dt)
    sp = spatial_scaling(rates, W_M, include_element_scale=False, fit_range_m=(0.99 * S_M, L_M), min_boxes=1)
    assert sp.fit.exponent == pytest.approx(1.0, abs=0.02)


def test_scales_with_few_boxes_stay_out_of_the_fit(mesh):
    """Default: a width enters the β fit only with >= 10 counted boxes (MIN_FIT_BOXES).

    Alternating slip lines: with every width the fit sees the plateau (1, 3, 9 km),
    the 9-box 27 km and the 1-box 81 km widths (β = 1 there) and gets a slope in
    between; with the default the 27 and 81 km widths are left out and β is the
    plateau's 0. The curve itself still lists every width."""
    xy, tri = mesh
    rates = velocity_gradients(xy, tri, slip_line_velocity(xy, S_M, DU, alternating=True))
    every = spatial_scaling(rates, W_M, include_element_scale=False, min_boxes=1)
    default = spatial_scaling(rates, W_M, include_element_scale=False)
    assert every.fit.n_points == 5 and every.fit.exponent > 0.3
    assert default.fit.n_points == 3
    assert default.fit.fit_range == pytest.approx((W_M[0], S_M), rel=1e-3)
    assert abs(default.fit.exponent) < 0.02
    np.testing.assert_array_equal(default.mean_total_s, every.mean_total_s)
    assert spatial_scaling(rates, W_M, include_element_scale=False, min_boxes=9).fit.n_points == 4
    for bad in (0, -3, 2.5, True):
        with pytest.raises(ConfigError, match="min_boxes"):
            spatial_scaling(rates, W_M, min_boxes=bad)


def test_uniform_strain_has_no_scale_dependence():
    xy, tri = jittered_grid_mesh(60, 40, 60e3, 40e3, jitter=0.3, seed=2)
    g = np.array([[1e-6, 2e-7], [5e-7, -3e-7]])
    rates = velocity_gradients(xy, tri, xy @ g.T)
    sp = spatial_scaling(rates)  # default box sizes, element scale included
    assert sp.scale_m.size >= 4
    np.testing.assert_allclose(sp.mean_total_s, sp.mean_total_s[0], rtol=1e-9)
    assert abs(sp.fit.exponent) < 1e-8


def test_coverage_threshold_drops_partial_boxes():
    """A 10 km x 10 km domain tiled by 4 km boxes: edge boxes cover 50 % or 25 % of W²."""
    xy, tri = jittered_grid_mesh(50, 50, 10e3, 10e3, jitter=0.0)
    rates = velocity_gradients(xy, tri, np.zeros_like(xy))
    assert coarse_grain(rates, [4e3], min_coverage=0.75).n_boxes[0] == 4
    assert coarse_grain(rates, [4e3], min_coverage=0.49).n_boxes[0] == 8
    assert coarse_grain(rates, [4e3], min_coverage=0.2).n_boxes[0] == 9
    with pytest.raises(ConfigError, match="min_coverage"):
        coarse_grain(rates, [4e3], min_coverage=0.0)
    with pytest.raises(ConfigError, match="box_sizes_m"):
        coarse_grain(rates, [-1.0])
    with pytest.raises(ConfigError, match="box_sizes_m"):
        coarse_grain(rates, ["big"])
    with pytest.raises(ConfigError, match="origin_xy_m"):
        coarse_grain(rates, [4e3], origin_xy_m=(0.0,))
    # shifting the grid origin by half a box re-tiles the domain: 2 x 2 full boxes + partial ones
    assert coarse_grain(rates, [4e3], origin_xy_m=(1e3, 1e3)).n_boxes[0] == 4


def test_fit_power_law_recovers_exponent_and_stderr():
    x = np.geomspace(1e4, 1e6, 7)
    y = 3.0 * x**-0.2
    fit = fit_power_law(x, y)
    assert fit.exponent == pytest.approx(0.2, abs=1e-12)
    assert fit.prefactor == pytest.approx(3.0, rel=1e-9)
    assert fit.exponent_stderr == pytest.approx(0.0, abs=1e-12)
    noisy = y * np.exp(np.array([0.01, -0.02, 0.015, 0.0, -0.01, 0.02, -0.015]))
    f2 = fit_power_law(x, noisy, fit_range=(2e4, 1e6))
    assert f2.n_points == 6 and f2.fit_range[0] > 2e4
    # standard error of the OLS slope computed independently
    lx, ly = np.log(x[1:]), np.log(noisy[1:])
    A = np.vstack([lx, np.ones_like(lx)]).T
    coef, res, *_ = np.linalg.lstsq(A, ly, rcond=None)
    se = np.sqrt(res[0] / (lx.size - 2) / np.sum((lx - lx.mean()) ** 2))
    assert f2.exponent == pytest.approx(-coef[0], rel=1e-12)
    assert f2.exponent_stderr == pytest.approx(se, rel=1e-9)


def slip_back_and_forth_series(xy, n_steps, slip_m):
    """Nodes above y = 4.5 km slip +slip_m in x at odd steps and back at even steps."""
    above = xy[:, 1] > 4.5e3
    series = np.repeat(xy[None], n_steps + 1, axis=0)
    series[1::2, above, 0] += slip_m
    return series


def test_temporal_scaling_alternating_slip_gives_alpha_one():
    """Slip that reverses every step: over K (odd) steps the net slip is ±slip, so ε̇ ∝ 1/(K dt): α = 1 exactly."""
    xy, tri = jittered_grid_mesh(30, 30, 9e3, 9e3, jitter=0.2, seed=4)
    dt = 86400.0
    series = slip_back_and_forth_series(xy, 81, 20.0)
    ts = temporal_scaling(series, tri, dt, window_steps=[1, 3, 9, 27, 81])
    assert list(ts.n_windows) == [81, 27, 9, 3, 1]
    assert ts.fit.exponent == pytest.approx(1.0, abs=1e-9)
    np.testing.assert_allclose(ts.window_s, [dt, 3 * dt, 9 * dt, 27 * dt, 81 * dt])
    overlapping = temporal_scaling(series, tri, dt, window_steps=[1, 3, 9], overlapping=True)
    assert list(overlapping.n_windows) == [81, 79, 73]
    assert overlapping.fit.exponent == pytest.approx(1.0, abs=1e-9)


def test_temporal_scaling_steady_simple_shear_gives_alpha_zero():
    """x(t) = x0 + t γ y0 e_x: every window sees ε̇II = γ whatever its length: α = 0."""
    xy, tri = jittered_grid_mesh(12, 12, 10e3, 10e3, jitter=0.2, seed=6)
    gamma, dt = 1e-6, 3600.0
    t = np.arange(33)[:, None] * dt
    series = np.repeat(xy[None], 33, axis=0)
    series[:, :, 0] += t * gamma * xy[None, :, 1]
    ts = temporal_scaling(series, tri, dt)  # default windows 1, 2, 4, ..., 32
    np.testing.assert_allclose(ts.mean_total_s, gamma, rtol=1e-9)
    assert list(ts.window_steps) == [1, 2, 4, 8, 16, 32]
    assert abs(ts.fit.exponent) < 1e-8


def test_temporal_scaling_bad_arguments():
    xy, tri = jittered_grid_mesh(3, 3, 1e3, 1e3)
    series = np.repeat(xy[None], 5, axis=0)
    with pytest.raises(ConfigError, match="dt_s"):
        temporal_scaling(series, tri, 0.0)
    with pytest.raises(ConfigError, match="window_steps"):
        temporal_scaling(series, tri, 1.0, window_steps=[0, 2])
    with pytest.raises(ConfigError, match="window_steps"):
        temporal_scaling(series, tri, 1.0, window_steps=[5])
    with pytest.raises(ConfigError, match="nodes_xy_series"):
        temporal_scaling(xy, tri, 1.0)


def test_grid_averaged_beta_refits_the_same_field_on_shifted_grids(mesh):
    """The first grid is spatial_scaling's own; grid k is spatial_scaling with the corner moved
    down-left by offsets_m[k], which lie in [0, widest fitted box width); mean and sd are over the grids."""
    xy, tri = mesh
    rates = velocity_gradients(xy, tri, slip_line_velocity(xy, S_M, DU, alternating=True))
    sizes = np.array([2, 4, 8, 16]) * 1e3
    first = spatial_scaling(rates, sizes)
    gb = grid_averaged_beta(rates, n_grids=6, seed=3, box_sizes_m=sizes)
    assert gb.betas[0] == first.fit.exponent
    assert gb.offsets_m.shape == (6, 2) and np.all(gb.offsets_m[0] == 0.0)
    widest = sizes[first.coarse.n_boxes >= 10].max()  # 16 km boxes: 25 of them in the 81 km square
    assert np.all((gb.offsets_m[1:] >= 0.0) & (gb.offsets_m[1:] < widest))
    corner = np.asarray(rates.bounds_m)[:2]
    for k in range(1, 6):
        sp = spatial_scaling(rates, sizes, origin_xy_m=corner - gb.offsets_m[k])
        assert gb.betas[k] == sp.fit.exponent
    assert gb.mean == pytest.approx(gb.betas.mean(), rel=1e-12)
    assert gb.sd == pytest.approx(gb.betas.std(), rel=1e-12)
    # alternating lines 9 km apart: boxes of 2-8 km hold at most one line, whatever the grid, so the
    # grids differ only through the 16 km boxes (one or two lines); the fits must differ a little
    assert gb.sd > 0.0
    again = grid_averaged_beta(rates, n_grids=6, seed=3, box_sizes_m=sizes)
    np.testing.assert_array_equal(again.betas, gb.betas)   # seeded: the same grids


def test_grid_averaged_beta_keeps_a_sign_coherent_field_scale_free_on_every_grid(mesh):
    """Same-sense slip lines: the mean over the counted boxes is Δu/s at every width on any grid
    (the coarse-graining is linear), so β = 0 on each of the grids, not only on the default one."""
    xy, tri = mesh
    rates = velocity_gradients(xy, tri, slip_line_velocity(xy, S_M, DU))
    gb = grid_averaged_beta(rates, n_grids=9, box_sizes_m=np.array([1, 2, 4, 8]) * 1e3,
                            include_element_scale=False)   # the boxes alone, as the analytic case
    assert np.all(np.isfinite(gb.betas))
    assert np.abs(gb.betas).max() < 0.02
    assert abs(gb.mean) < 0.02


def test_grid_averaged_beta_bad_grid_count(mesh):
    xy, tri = mesh
    rates = velocity_gradients(xy, tri, slip_line_velocity(xy, S_M, DU))
    for bad in (0, 2.5, True):
        with pytest.raises(ConfigError, match="n_grids"):
            grid_averaged_beta(rates, n_grids=bad)
    one = grid_averaged_beta(rates, n_grids=1)
    assert one.sd == 0.0 and one.betas.size == 1


def test_pooled_curve_is_the_mean_over_every_box_of_every_window(mesh):
    """Pooling two windows' curves gives, at each width, the mean over the union of their boxes (and
    at the element scale over the union of their elements), as observed β averages every box of every
    3-day interval (Marsan et al. 2004); one curve pooled alone is itself."""
    xy, tri = mesh
    a = velocity_gradients(xy, tri, slip_line_velocity(xy, S_M, DU))
    lower = tri[xy[tri].mean(axis=1)[:, 1] < 0.5 * L_M]   # a second window: the lower half of the square
    b = velocity_gradients(xy, lower, slip_line_velocity(xy, S_M, 3 * DU, alternating=True))
    spa, spb = spatial_scaling(a, W_M), spatial_scaling(b, W_M)
    pooled = pooled_spatial_scaling([scaling_curve(spa), scaling_curve(spb)])
    assert pooled.n_curves == 2
    assert pooled.mean_total_s[0] == pytest.approx(np.concatenate([a.total_s, b.total_s]).mean(), rel=1e-12)
    assert pooled.n_boxes[0] == a.total_s.size + b.total_s.size
    k = 0
    for ta, tb, sa, sb in zip(spa.coarse.box_total_s, spb.coarse.box_total_s, spa.coarse.box_scale_m,
                              spb.coarse.box_scale_m):
        if ta.size == 0 or tb.size == 0:
            break
        k += 1
        assert pooled.mean_total_s[k] == pytest.approx(np.concatenate([ta, tb]).mean(), rel=1e-12)
        assert pooled.scale_m[k] == pytest.approx(np.concatenate([sa, sb]).mean(), rel=1e-12)
        assert pooled.n_boxes[k] == ta.size + tb.size
        assert pooled.fewest_boxes[k] == min(ta.size, tb.size)
    assert k >= 3
    alone = pooled_spatial_scaling([scaling_curve(spa)])
    np.testing.assert_allclose(alone.mean_total_s, spa.mean_total_s, rtol=1e-12)
    assert alone.fit.exponent == pytest.approx(spa.fit.exponent, abs=1e-12)


def test_pooled_beta_follows_the_window_that_deforms_most(mesh):
    """Same-sense lines (β = 0 at every width) and alternating lines (β = 1 for W >= s), pooled over
    the widths W >= s: the pooled mean is (Δu_a/s + Δu_b/W)/2, so its slope is that of the analytic
    mean, near 1 when the alternating window deforms 100 times more and near 0 when it deforms 100
    times less. The median of the two windows' own β is 0.5 either way."""
    xy, tri = mesh
    fit = (0.99 * S_M, 1.01 * L_M)

    def curve(du, alternating):
        r = velocity_gradients(xy, tri, slip_line_velocity(xy, S_M, du, alternating=alternating))
        return scaling_curve(spatial_scaling(r, W_M, include_element_scale=False, min_boxes=1))

    for du_a, du_b in ((DU, DU), (DU, 100 * DU), (100 * DU, DU)):
        pooled = pooled_spatial_scaling([curve(du_a, False), curve(du_b, True)], min_boxes=1, fit_range_m=fit)
        big = W_M >= S_M
        analytic = 0.5 * (du_a / S_M + du_b / W_M[big])
        np.testing.assert_allclose(pooled.mean_total_s[big], analytic, rtol=0.02)
        expected = fit_power_law(W_M[big], analytic).exponent
        assert pooled.fit.exponent == pytest.approx(expected, abs=0.02)
        if du_b > du_a:
            assert pooled.fit.exponent > 0.9
        elif du_a > du_b:
            assert pooled.fit.exponent < 0.1


def test_pooled_spatial_scaling_refuses_curves_that_do_not_match(mesh):
    xy, tri = mesh
    r = velocity_gradients(xy, tri, slip_line_velocity(xy, S_M, DU))
    c = scaling_curve(spatial_scaling(r, W_M))
    other_mesh = scaling_curve(spatial_scaling(r, 2 * W_M))
    with pytest.raises(ConfigError, match="box widths of the curves differ"):
        pooled_spatial_scaling([c, other_mesh])
    no_element = scaling_curve(spatial_scaling(r, W_M, include_element_scale=False))
    with pytest.raises(ConfigError, match="1 of 2 curves start with the element scale"):
        pooled_spatial_scaling([c, no_element])
    with pytest.raises(ConfigError, match="no curve"):
        pooled_spatial_scaling([])
    with pytest.raises(ConfigError, match="not a scaling curve"):
        pooled_spatial_scaling([{"scale_m": [1.0]}])
    with pytest.raises(ConfigError, match="lengths"):
        pooled_spatial_scaling([{**c, "n_boxes": c["n_boxes"][:-1]}])
    for bad in (0, 2.5, True):
        with pytest.raises(ConfigError, match="min_boxes"):
            pooled_spatial_scaling([c], min_boxes=bad)


def test_pooling_pools_gives_pooling_every_curve():
    """pooled_spatial_scaling of curves that are themselves pools (their PooledScaling as a curve, with
    ``fewest_boxes``) gives the curve and β of pooling all their curves at once, including which widths a
    thinly counted curve leaves out of the fit; without ``fewest_boxes`` the pooled counts would keep them."""
    rng = np.random.default_rng(2)
    widths = [10e3, 20e3, 40e3, 80e3]

    def curve():
        return {"box_size_m": widths, "scale_m": widths, "mean_total_s": list(rng.lognormal(-14, 1.0, 4)),
                "n_boxes": [int(rng.integers(9, 60)) for _ in widths]}

    groups = [[curve() for _ in range(5)] for _ in range(3)]
    groups[1][2]["n_boxes"][3] = 4   # one curve counts 4 boxes at 80 km: that width leaves the fit
    whole = pooled_spatial_scaling([c for g in groups for c in g])
    pools = []
    for g in groups:
        p = pooled_spatial_scaling(g)
        pools.append({"box_size_m": widths, "scale_m": p.scale_m, "mean_total_s": p.mean_total_s,
                      "n_boxes": p.n_boxes, "fewest_boxes": p.fewest_boxes})
    again = pooled_spatial_scaling(pools)
    assert np.allclose(again.mean_total_s, whole.mean_total_s, rtol=1e-13)
    assert np.array_equal(again.fewest_boxes, whole.fewest_boxes) and whole.fewest_boxes[3] == 4
    assert again.fit.exponent == pytest.approx(whole.fit.exponent, rel=1e-12)
    assert whole.fit.n_points == 3
    plain = pooled_spatial_scaling([{k: v for k, v in p.items() if k != "fewest_boxes"} for p in pools])
    assert plain.fit.n_points == 4
