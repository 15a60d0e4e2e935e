"""Goodness of fit and the likelihood-ratio test of power-law tails (Clauset, Shalizi &
Newman 2009), used by ``lagice diagnose`` to warn about poor fits."""
import warnings

import numpy as np
import pytest

from lagice.diagnostics.statistics import compare_lognormal, tail_fit_quality


def test_a_power_law_passes_and_draws_no_warning():
    rng = np.random.default_rng(1)
    x = 1e-6 * (1.0 - rng.random(5000)) ** (-1.0 / 1.5)  # density exponent 2.5 above 1e-6
    q = tail_fit_quality(x)
    assert q.exponent == pytest.approx(2.5, abs=0.1)
    assert q.gof_p > 0.1, "data drawn from a power law are not ruled out"
    assert not (q.loglikelihood_ratio < 0 and q.loglikelihood_ratio_p < 0.1)
    assert q.warnings("shear") == []


def test_a_lognormal_is_flagged():
    rng = np.random.default_rng(2)
    x = np.exp(rng.normal(-14.0, 1.0, 20000))
    q = tail_fit_quality(x)
    assert q.gof_p <= 0.1, "a lognormal sample is ruled out as a power law"
    assert q.loglikelihood_ratio < 0 and q.loglikelihood_ratio_p < 0.1, "the lognormal is preferred"
    msgs = q.warnings("PDF tail of shear")
    assert len(msgs) == 2 and "goodness-of-fit p" in msgs[0] and "lognormal fits the tail better" in msgs[1]


@pytest.mark.parametrize("sigma", [2.0, 3.0])
def test_likelihood_ratio_agrees_with_the_powerlaw_package(sigma):
    powerlaw = pytest.importorskip("powerlaw")
    rng = np.random.default_rng(3)
    x = np.exp(rng.normal(-14.0, sigma, 8000))
    x_min = float(np.quantile(x, 0.7))
    r, p, mu, s = compare_lognormal(x, x_min)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fit = powerlaw.Fit(x, xmin=x_min, verbose=False)
        r_ref, p_ref = fit.distribution_compare("power_law", "lognormal")
    assert r == pytest.approx(r_ref, rel=1e-5) and p == pytest.approx(p_ref, rel=1e-4, abs=1e-12)
    assert mu == pytest.approx(fit.lognormal.mu, rel=1e-4) and s == pytest.approx(fit.lognormal.sigma, rel=1e-4)
