"""One-point statistics of element strain rates: PDFs, tails, localisation, correlation.

Girard et al. 2011 §"Damage localization" and §"Strain-rate distributions" (Figs. 3–4);
Girard 2010 §2.5 (localisation: share of the area holding half of the shear,
RGPS ≈ 6 % at 10 km; PDF tails p(ε̇) ∝ ε̇^−γ, RGPS γ ≈ 2.2 for shear and 2.5
for |divergence| at 10 km / 3 days; shear–divergence R² = 0.83 for RGPS).
"""

from dataclasses import dataclass

import numpy as np

from lagice.diagnostics._checks import values_1d
from lagice.errors import ConfigError, check_range


@dataclass(frozen=True)
class LogBinnedPdf:
    """Probability density on logarithmic bins.

    Attributes
    ----------
    bin_edges : ndarray (k+1,)
        Geometric bin edges (units of the sample, e.g. s-1).
    bin_centres : ndarray (k,)
        Geometric centres sqrt(e_i e_{i+1}).
    density : ndarray (k,)
        counts / (n_total · width): integrates to the fraction of the sample
        that is positive and inside the bins (units: 1 / sample unit).
    counts : ndarray (k,) int
    n_total : int
        Size of the whole sample, zeros and negatives included.
    """

    bin_edges: np.ndarray
    bin_centres: np.ndarray
    density: np.ndarray
    counts: np.ndarray
    n_total: int


def log_binned_pdf(values, bins_per_decade=10, min_value=None, max_value=None):
    """Log-binned PDF of the positive part of ``values`` (Girard et al. 2011 Fig. 4).

    Parameters
    ----------
    values : array_like
        Sample (e.g. shear rate, s-1). Non-positive values count in ``n_total``
        but fall in no bin.
    bins_per_decade : int
        Number of bins per factor 10 (≥ 1).
    min_value, max_value : float, optional
        Range binned; default the smallest and largest positive values.

    Returns
    -------
    LogBinnedPdf
    """
    x = np.asarray(values, dtype=np.float64).ravel()
    x = x[np.isfinite(x)]
    nb = int(check_range("bins_per_decade", bins_per_decade, 1, None))
    pos = x[x > 0]
    if pos.size == 0:
        empty = np.zeros(0)
        return LogBinnedPdf(empty, empty, empty, np.zeros(0, dtype=np.int64), int(x.size))
    lo = pos.min() if min_value is None else check_range("min_value", min_value, 0, None, low_open=True)
    hi = pos.max() if max_value is None else check_range("max_value", max_value, lo, None)
    if hi <= lo:
        hi = lo * 1.0001
    n = max(1, int(np.ceil(np.log10(hi / lo) * nb)))
    edges = lo * 10.0 ** (np.arange(n + 1) / nb)
    edges[-1] = max(edges[-1], hi)
    counts, _ = np.histogram(pos, bins=edges)
    density = counts / (x.size * np.diff(edges))
    return LogBinnedPdf(edges, np.sqrt(edges[:-1] * edges[1:]), density, counts, int(x.size))


TAIL_MIN_LOG_RANGE = 1e-6  # a tail with x_max / x_min < 1 + this is round-off, not a power law


@dataclass(frozen=True)
class PowerLawTail:
    """Maximum-likelihood power-law tail ``p(x) ∝ x^−exponent`` for ``x ≥ x_min``.

    Attributes
    ----------
    exponent : float
        γ of the density (not of the survival function, whose exponent is γ − 1).
    exponent_stderr : float
        (γ − 1)/sqrt(n_tail) (Clauset et al. 2009, eq. 3.2).
    x_min : float
        Lower bound of the tail (sample units).
    x_max : float
        Largest sample value; ``(x_min, x_max)`` is the fit range.
    n_tail : int
        Number of values ≥ x_min.
    ks_distance : float
        Kolmogorov–Smirnov distance between the tail and the fitted law.
    """

    exponent: float
    exponent_stderr: float
    x_min: float
    x_max: float
    n_tail: int
    ks_distance: float


_KS_MAX_POINTS = 20000  # order statistics at which the KS distance is evaluated (error <= 1/_KS_MAX_POINTS)


def _tail_fit(log_tail, log_min, log_sum=None):
    """γ̂ and KS distance of an ascending tail given by its logs, all ≥ ``log_min``.

    ``log_sum`` (Σ log_tail) may be passed precomputed. The KS distance is
    evaluated at up to ``_KS_MAX_POINTS`` evenly spaced order statistics.
    Returns ``(inf, 1.0)`` if the tail spans no range (x_max/x_min < 1 + 1e-6).
    """
    n = log_tail.size
    s = (np.sum(log_tail) if log_sum is None else log_sum) - n * log_min
    if s <= 0 or log_tail[-1] - log_min <= np.log1p(TAIL_MIN_LOG_RANGE):
        return np.inf, 1.0
    gamma = 1.0 + n / s
    k = np.arange(n) if n <= _KS_MAX_POINTS else np.unique(np.linspace(0, n - 1, _KS_MAX_POINTS).astype(np.int64))
    cdf = -np.expm1((1.0 - gamma) * (log_tail[k] - log_min))
    ks = max(np.max((k + 1) / n - cdf), np.max(cdf - k / n))
    return gamma, float(ks)


def fit_power_law_tail(values, x_min=None, min_tail=50, max_candidates=200):
    """Continuous power-law tail by maximum likelihood (Hill / Clauset et al. 2009).

    ``γ̂ = 1 + n / Σ ln(x_i / x_min)`` over the ``n`` values ``x_i ≥ x_min``. If
    ``x_min`` is not given it is the candidate minimising the KS distance
    between the empirical and fitted tail CDFs (Clauset et al. 2009 §3.3);
    candidates are up to ``max_candidates`` sample values (quantile-spaced)
    leaving at least ``min_tail`` values in the tail.

    Parameters
    ----------
    values : array_like
        Sample (e.g. shear or |divergence| rates, s-1); only positive finite
        values are used.
    x_min : float, optional
        Fixed lower bound of the tail (> 0, sample units).
    min_tail : int
        Minimum number of tail values (≥ 2) when x_min is searched.
    max_candidates : int
        Maximum number of x_min candidates tried.

    Returns
    -------
    PowerLawTail
        NaN exponent if fewer than ``min_tail`` usable values (or < 2 above a
        given x_min), or if the tail spans no range (x_max/x_min < 1 + 1e-6).
    """
    x = np.asarray(values, dtype=np.float64).ravel()
    x = np.sort(x[np.isfinite(x) & (x > 0)])
    m_tail = int(check_range("min_tail", min_tail, 2, None))
    n_cand = int(check_range("max_candidates", max_candidates, 1, None))
    nan = float("nan")
    if x_min is not None:
        xm = check_range("x_min", x_min, 0.0, None, low_open=True)
        tail = x[x >= xm]
        if tail.size < 2:
            return PowerLawTail(nan, nan, xm, nan, int(tail.size), nan)
        gamma, ks = _tail_fit(np.log(tail), np.log(xm))
        if not np.isfinite(gamma):
            return PowerLawTail(nan, nan, xm, float(tail[-1]), int(tail.size), nan)
        return PowerLawTail(float(gamma), float((gamma - 1) / np.sqrt(tail.size)), xm,
                            float(tail[-1]), int(tail.size), ks)
    if x.size < m_tail:
        return PowerLawTail(nan, nan, nan, nan, int(x.size), nan)
    last = x.size - m_tail  # index of the largest admissible x_min
    uniq_idx = np.flatnonzero(np.diff(np.concatenate([[-np.inf], x[: last + 1]])) > 0)
    if uniq_idx.size > n_cand:
        uniq_idx = uniq_idx[np.unique(np.linspace(0, uniq_idx.size - 1, n_cand).round().astype(np.int64))]
    log_x = np.log(x)
    suffix = np.cumsum(log_x[::-1])[::-1]
    best = None
    for i in uniq_idx:  # loop over candidate thresholds (≤ max_candidates)
        gamma, ks = _tail_fit(log_x[i:], log_x[i], suffix[i])
        if np.isfinite(gamma) and (best is None or ks < best[1]):
            best = (gamma, ks, i)
    if best is None:
        return PowerLawTail(nan, nan, nan, nan, 0, nan)
    gamma, ks, i = best
    n = x.size - i
    return PowerLawTail(float(gamma), float((gamma - 1) / np.sqrt(n)), float(x[i]), float(x[-1]), int(n), ks)


def localisation_area_fraction(shear_s, area_m2, fraction_of_shear=0.5):
    """Fraction of the area holding a given share of the total shear (Girard et al. 2011, Girard 2010 §2.5).

    Elements are sorted by shear rate (descending); the shear "amount"
    ``ε̇II · A`` is accumulated, and the returned value is the area fraction at
    which the cumulative amount reaches ``fraction_of_shear`` of the total.
    The element in which the threshold is crossed contributes the part of its
    area needed (linear interpolation), so a uniform field gives exactly
    ``fraction_of_shear``.

    Parameters
    ----------
    shear_s : array_like (m,)
        Element shear rates ε̇II (s-1), ≥ 0.
    area_m2 : array_like (m,)
        Element areas (m²), > 0.
    fraction_of_shear : float
        Share of the total shear (0 < f ≤ 1), default 0.5.

    Returns
    -------
    float
        Area fraction in (0, 1]; NaN if the total shear is zero.
    """
    shear = values_1d("shear_s", shear_s)
    area = values_1d("area_m2", area_m2, shear.size)
    f = check_range("fraction_of_shear", fraction_of_shear, 0.0, 1.0, low_open=True)
    if shear.size == 0:
        raise ConfigError("shear_s is empty; expected at least one element")
    if np.any(shear < 0):
        raise ConfigError(f"shear_s has negative values (min {shear.min():.3g} s-1); expected shear rates >= 0")
    if np.any(area <= 0):
        raise ConfigError(f"area_m2 has non-positive values (min {area.min():.3g} m2); expected > 0")
    order = np.argsort(-shear, kind="stable")
    amount = shear[order] * area[order]
    total = amount.sum()
    if total <= 0:
        return float("nan")
    cum = np.cumsum(amount)
    target = f * total
    k = int(np.searchsorted(cum, target * (1 - 1e-12)))
    k = min(k, shear.size - 1)
    before = cum[k - 1] if k > 0 else 0.0
    area_before = np.sum(area[order][:k])
    part = (target - before) / amount[k] if amount[k] > 0 else 0.0
    return float((area_before + np.clip(part, 0.0, 1.0) * area[order][k]) / area.sum())


def shear_divergence_r2(shear_s, divergence_s, weights=None):
    """R² between |divergence| and shear per element (Girard et al. 2011: RGPS 0.83, EB 0.77, VP 0.58).

    Squared Pearson correlation coefficient between ε̇II and |ε̇I| (absolute
    value: opening and closing both accompany slip on rough faults, Girard et al. 2011),
    equal to the R² of the least-squares line |ε̇I| = a ε̇II + b.

    Parameters
    ----------
    shear_s, divergence_s : array_like (m,)
        Element shear and (signed) divergence rates (s-1).
    weights : array_like (m,), optional
        Non-negative weights (e.g. areas, m²); default equal weights.

    Returns
    -------
    float
        R² in [0, 1]; NaN if either field is constant (standard deviation
        ≤ 1e-9 of its largest magnitude, i.e. round-off).
    """
    x = values_1d("shear_s", shear_s)
    y = np.abs(values_1d("divergence_s", divergence_s, x.size))
    w = np.ones_like(x) if weights is None else values_1d("weights", weights, x.size)
    if np.any(w < 0) or w.sum() <= 0:
        raise ConfigError("weights must be >= 0 with a positive sum")
    w = w / w.sum()
    dx = x - np.sum(w * x)
    dy = y - np.sum(w * y)
    sxx, syy, sxy = np.sum(w * dx * dx), np.sum(w * dy * dy), np.sum(w * dx * dy)
    # a field constant up to round-off (e.g. uniform strain) has no defined correlation
    tiny = 1e-9
    if sxx <= (tiny * np.max(np.abs(x))) ** 2 or syy <= (tiny * np.max(np.abs(y))) ** 2:
        return float("nan")
    return float(sxy * sxy / (sxx * syy))


@dataclass(frozen=True)
class TailFitQuality:
    """How well a power-law tail fits (Clauset, Shalizi & Newman 2009, "Power-law
    distributions in empirical data", SIAM Review 51, §4 and §5).

    Attributes
    ----------
    exponent, x_min, n_tail, ks_distance :
        The fit judged (γ of the density, threshold, tail size, KS distance D).
    gof_p : float
        Goodness-of-fit p-value: the fraction of synthetic samples drawn from the
        fitted model (power law above x_min, the data below it) whose own fit has a
        KS distance ≥ D (§4.1, semi-parametric bootstrap, x_min searched again in
        each). p ≤ 0.1 rules the power law out.
    n_bootstrap : int
        Synthetic samples used (resolution of ``gof_p``: 1/n_bootstrap).
    lognormal_mu, lognormal_sigma : float
        Maximum-likelihood lognormal truncated at x_min (parameters of ln x).
    loglikelihood_ratio : float
        R = Σ ln p_powerlaw(x_i) − ln p_lognormal(x_i) over the tail (§5, Vuong's
        test): R > 0 favours the power law, R < 0 the lognormal.
    loglikelihood_ratio_p : float
        Two-sided significance of the sign of R: erfc(|R| / (σ √(2n))), σ the
        standard deviation of the pointwise differences. p ≥ 0.1: the data cannot
        tell the two apart.
    """

    exponent: float
    x_min: float
    n_tail: int
    ks_distance: float
    gof_p: float
    n_bootstrap: int
    lognormal_mu: float
    lognormal_sigma: float
    loglikelihood_ratio: float
    loglikelihood_ratio_p: float

    def warnings(self, name: str = "tail", gof_threshold: float = 0.1, lr_threshold: float = 0.1) -> list[str]:
        """Plain-language warnings when the power law is ruled out (``gof_p`` ≤
        ``gof_threshold``) or a lognormal fits significantly better (R < 0 with
        p < ``lr_threshold``); empty when the fit holds up."""
        out = []
        if not np.isfinite(self.exponent):
            return [f"{name}: no power-law tail could be fitted (too few positive values)"]
        if np.isfinite(self.gof_p) and self.gof_p <= gof_threshold:
            out.append(f"{name}: the power-law tail (exponent {self.exponent:.2f}, x_min {self.x_min:.3g}) fits "
                       f"poorly: goodness-of-fit p = {self.gof_p:.2f} <= {gof_threshold:g} ({self.n_bootstrap} "
                       f"synthetic samples; KS distance {self.ks_distance:.3f})")
        if (np.isfinite(self.loglikelihood_ratio) and self.loglikelihood_ratio < 0
                and self.loglikelihood_ratio_p < lr_threshold):
            out.append(f"{name}: a lognormal fits the tail better than the power law (log-likelihood ratio "
                       f"R = {self.loglikelihood_ratio:.1f}, p = {self.loglikelihood_ratio_p:.2g}); the exponent "
                       f"{self.exponent:.2f} describes a curved tail")
        return out


def _lognormal_tail_fit(log_tail, log_min):
    """ML (μ, σ) of a lognormal truncated at x_min, and the pointwise log densities."""
    from scipy.optimize import minimize
    from scipy.special import log_ndtr

    n = log_tail.size

    def logpdf(mu, sigma):
        z = (log_tail - mu) / sigma
        return (-log_tail - np.log(sigma) - 0.5 * np.log(2 * np.pi) - 0.5 * z * z
                - log_ndtr(-(log_min - mu) / sigma))

    def nll(p):
        mu, log_sigma = p
        return -np.sum(logpdf(mu, np.exp(log_sigma))) / n

    m0, s0 = float(np.mean(log_tail)), float(max(np.std(log_tail), 1e-3))
    best = None
    for mu0 in (m0, log_min, m0 - 2 * s0):  # the truncated likelihood can have a flat ridge: several starts
        r = minimize(nll, (mu0, np.log(s0)), method="Nelder-Mead",
                     options={"xatol": 1e-8, "fatol": 1e-12, "maxiter": 4000})
        if best is None or r.fun < best.fun:
            best = r
    mu, sigma = float(best.x[0]), float(np.exp(best.x[1]))
    return mu, sigma, logpdf(mu, sigma)


def compare_lognormal(values, x_min):
    """Vuong's likelihood-ratio test of the power-law tail against a lognormal
    truncated at ``x_min`` (Clauset et al. 2009 §5): ``(R, p, mu, sigma)``, R > 0
    favouring the power law; NaN when the tail has fewer than 2 values."""
    from scipy.special import erfc

    x = np.asarray(values, dtype=np.float64).ravel()
    x = np.sort(x[np.isfinite(x) & (x >= x_min) & (x > 0)])
    nan = float("nan")
    if x.size < 2:
        return nan, nan, nan, nan
    lx, lm = np.log(x), np.log(x_min)
    gamma = 1.0 + x.size / (np.sum(lx) - x.size * lm)
    lp_pl = np.log(gamma - 1.0) - lm - gamma * (lx - lm)
    mu, sigma, lp_ln = _lognormal_tail_fit(lx, lm)
    d = lp_pl - lp_ln
    r = float(np.sum(d))
    s = float(np.std(d))
    p = float(erfc(abs(r) / (s * np.sqrt(2.0 * x.size)))) if s > 0 else nan
    return r, p, mu, sigma


def tail_fit_quality(values, x_min=None, min_tail=50, n_bootstrap=50, seed=0,
                     bootstrap_candidates=30) -> TailFitQuality:
    """Goodness of fit and likelihood-ratio test of the power-law tail of ``values``
    (Clauset et al. 2009 §4.1 and §5; the tests of the ``powerlaw`` package).

    The tail is fitted as :func:`fit_power_law_tail` does (``x_min`` searched by KS
    distance unless given). The goodness-of-fit p-value uses ``n_bootstrap``
    synthetic samples of the same size (deterministic from ``seed``): each value is,
    with probability n_tail/n, drawn from the fitted power law, else resampled from
    the data below x_min; each sample is fitted the same way, its x_min searched
    among ``bootstrap_candidates`` quantile-spaced values (the data's own fit uses
    200). Cost: ``n_bootstrap`` tail fits, at most about 3 s for 2·10⁴ values and 50 samples.
    The likelihood-ratio test agrees with ``powerlaw.Fit(values, xmin=x_min)
    .distribution_compare("power_law", "lognormal")`` (tests/test_diagnostics_statistics.py).
    """
    x = np.asarray(values, dtype=np.float64).ravel()
    x = x[np.isfinite(x) & (x > 0)]
    nb = int(check_range("n_bootstrap", n_bootstrap, 0, None))
    fit = fit_power_law_tail(x, x_min, min_tail)
    nan = float("nan")
    if not np.isfinite(fit.exponent):
        return TailFitQuality(fit.exponent, fit.x_min, fit.n_tail, fit.ks_distance, nan, 0, nan, nan, nan, nan)
    r, p_lr, mu, sigma = compare_lognormal(x, fit.x_min)
    gof = nan
    if nb > 0:
        rng = np.random.default_rng(seed)
        below = x[x < fit.x_min]
        frac_tail = fit.n_tail / x.size
        exceed = 0
        for _ in range(nb):  # over bootstrap samples (n_bootstrap), each one vectorised
            k = rng.binomial(x.size, frac_tail) if below.size else x.size
            u = rng.random(k)
            synth = np.concatenate([fit.x_min * (1.0 - u) ** (-1.0 / (fit.exponent - 1.0)),
                                    rng.choice(below, x.size - k) if below.size else np.zeros(0)])
            f = fit_power_law_tail(synth, fit.x_min if x_min is not None else None, min_tail, bootstrap_candidates)
            if np.isfinite(f.ks_distance) and f.ks_distance >= fit.ks_distance:
                exceed += 1
        gof = exceed / nb
    return TailFitQuality(fit.exponent, fit.x_min, fit.n_tail, fit.ks_distance, gof, nb, mu, sigma, r, p_lr)
