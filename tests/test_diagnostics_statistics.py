"""PDF tails, localisation and shear–divergence correlation on cases with known answers (Girard et al. 2011)."""

import numpy as np
import pytest

from lagice.diagnostics import (
    fit_power_law_tail,
    localisation_area_fraction,
    log_binned_pdf,
    shear_divergence_r2,
)
from lagice.errors import ConfigError


def pareto_sample(gamma, x_min, n, seed):
    """Inverse-CDF sample of p(x) = (γ−1)/x_min (x/x_min)^−γ, x ≥ x_min: x = x_min (1−U)^(−1/(γ−1))."""
    u = np.random.default_rng(seed).uniform(size=n)
    return x_min * (1.0 - u) ** (-1.0 / (gamma - 1.0))


@pytest.mark.parametrize("gamma", [2.2, 2.5, 3.0])
def test_tail_exponent_of_pure_power_law_within_5_percent(gamma):
    """n = 20000: the ML standard error (γ−1)/sqrt(n) is < 1 % of γ, so 5 % is a > 5-sigma margin."""
    x = pareto_sample(gamma, 1e-6, 20000, seed=11) # s-1
    given = fit_power_law_tail(x, x_min=1e-6)
    assert given.exponent == pytest.approx(gamma, rel=0.05)
    assert given.n_tail == 20000 and given.x_max == x.max()
    assert given.exponent_stderr == pytest.approx((given.exponent - 1) / np.sqrt(20000))
    searched = fit_power_law_tail(x)
    assert searched.exponent == pytest.approx(gamma, rel=0.05)
    assert searched.x_min >= 1e-6 and searched.n_tail >= 50


def test_tail_exponent_above_a_non_power_law_body():
    """Uniform body on [0, x_min) (40 %) + power-law tail γ = 2.5 above x_min (60 %): the KS search finds x_min."""
    rng = np.random.default_rng(7)
    x_min = 2e-6
    body = rng.uniform(0, x_min, 8000)
    tail = pareto_sample(2.5, x_min, 12000, seed=8)
    fit = fit_power_law_tail(np.concatenate([body, tail]))
    assert fit.exponent == pytest.approx(2.5, rel=0.05)
    assert x_min <= fit.x_min <= 2.5 * x_min  # KS picks a threshold at or above the true one (20 seeds: <= 1.9)
    assert fit.ks_distance < 0.02


def test_tail_fit_with_too_few_values_is_nan():
    fit = fit_power_law_tail([1.0, 2.0, 3.0], min_tail=50)
    assert np.isnan(fit.exponent)
    with pytest.raises(ConfigError, match="x_min"):
        fit_power_law_tail([1.0, 2.0], x_min=-1.0)


def test_log_binned_pdf_of_power_law_has_its_slope():
    x = pareto_sample(2.5, 1.0, 200000, seed=3)
    pdf = log_binned_pdf(np.concatenate([x, np.zeros(1000)]), bins_per_decade=5)
    assert pdf.n_total == 201000
    assert pdf.counts.sum() == 200000
    # density integrates to the positive fraction of the sample
    assert np.sum(pdf.density * np.diff(pdf.bin_edges)) == pytest.approx(200000 / 201000)
    good = pdf.counts > 1000
    slope = np.polyfit(np.log(pdf.bin_centres[good]), np.log(pdf.density[good]), 1)[0]
    assert -slope == pytest.approx(2.5, rel=0.05)


def test_localisation_known_answers():
    # ten equal elements, one with shear 9 and nine with shear 1: total 18, the first holds half
    shear = np.array([1, 1, 1, 9, 1, 1, 1, 1, 1, 1], float) * 1e-7
    assert localisation_area_fraction(shear, np.ones(10)) == pytest.approx(0.1)
    # uniform field: half the shear on half the area
    assert localisation_area_fraction(np.full(7, 3e-7), np.full(7, 2.0)) == pytest.approx(0.5)
    # unequal areas: element a (shear 4, area 1) holds 4 of 4+1*4 = 8; half is reached exactly at it
    assert localisation_area_fraction([4.0, 1.0], [1.0, 4.0]) == pytest.approx(0.2)
    # threshold crossed inside an element: shear 2 on area 1 (amount 2) and 1 on area 4 (4): half = 3
    # -> all of the first (area 1) + 1/4 of the second (area 1) = 2/5
    assert localisation_area_fraction([2.0, 1.0], [1.0, 4.0]) == pytest.approx(0.4)
    # a single faulted band holding all the shear on 6 % of the area -> 3 %
    area = np.ones(100)
    band = np.zeros(100)
    band[:6] = 1e-6
    assert localisation_area_fraction(band, area) == pytest.approx(0.03)
    assert np.isnan(localisation_area_fraction(np.zeros(4), np.ones(4)))


def test_localisation_bad_arguments():
    with pytest.raises(ConfigError, match="area_m2"):
        localisation_area_fraction([1.0, 2.0], [1.0])
    with pytest.raises(ConfigError, match="shear_s"):
        localisation_area_fraction([-1.0, 2.0], [1.0, 1.0])
    with pytest.raises(ConfigError, match="fraction_of_shear"):
        localisation_area_fraction([1.0, 2.0], [1.0, 1.0], fraction_of_shear=1.5)


def test_shear_divergence_r2_known_answers():
    # r = 0.8 exactly for x = (1,2,3,4), y = (1,3,2,4)
    assert shear_divergence_r2([1, 2, 3, 4], [1, 3, 2, 4]) == pytest.approx(0.64)
    # |divergence| is used: signs of the divergence do not matter
    assert shear_divergence_r2([1, 2, 3, 4], [-1, 3, -2, 4]) == pytest.approx(0.64)
    # exact linear relation |div| = 0.3 shear + 1e-8
    s = np.linspace(0, 1e-6, 50)
    assert shear_divergence_r2(s, 0.3 * s + 1e-8) == pytest.approx(1.0)
    # weights: a zero weight removes the point
    assert shear_divergence_r2([1, 2, 3, 4, 10], [1, 3, 2, 4, -50], weights=[1, 1, 1, 1, 0]) == pytest.approx(0.64)
    assert np.isnan(shear_divergence_r2([1, 1, 1], [1, 2, 3]))
    with pytest.raises(ConfigError, match="divergence_s"):
        shear_divergence_r2([1, 2], [1, 2, 3])


def test_shear_divergence_r2_of_independent_noise_is_small():
    rng = np.random.default_rng(1)
    assert shear_divergence_r2(rng.exponential(size=20000), rng.normal(size=20000)) < 0.001
