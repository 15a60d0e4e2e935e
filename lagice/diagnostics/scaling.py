"""Spatial and temporal scaling of the mean total deformation rate.

Spatial coarse-graining follows Girard 2010 §3.5 ("changement d'échelle", after
Marsan et al. 2004, used for Girard et al. 2011 Fig. 5):

1. element-scale velocity gradients G_e (s-1) and areas A_e (m²);
2. for a box width W, cover the bounding box of the mesh with a regular grid
   of W × W boxes starting at its lower-left corner (or ``origin_xy_m``);
   each element belongs to the box holding its centroid;
3. box gradient = area-weighted mean ``Σ A_e G_e / Σ A_e``. By Green's theorem
   this equals the line integral ``(1/A) ∮ u n ds`` around the union of the
   box's elements (interior edges cancel), i.e. the RGPS recipe at scale W;
4. ε̇tot of the box gradient; the box scale is ``sqrt(Σ A_e)`` (m);
5. a box is counted only if its covered area ``Σ A_e ≥ min_coverage · W²``
   (default 0.75), which drops boxes cut by coasts or the domain edge;
6. per W: ⟨ε̇tot⟩ = unweighted mean over counted boxes, scale L = mean box scale.

The exponent β of ⟨ε̇tot⟩ ∝ L^−β is fitted by ordinary least squares on
(log L, log ⟨ε̇tot⟩) inside a fit range. Note (derived in
``docs/diagnostics.md``): the area-weighted mean gradient is linear, so for a
field whose gradients all have the same sign the mean over all boxes is
conserved across scales (β = 0); β > 0 measures cancellation between
deformation events of different sense/orientation at larger scales.

Temporal scaling (Girard 2010 §2.2 eq. 2.5, ⟨ε̇⟩ ∝ T^−α): element rates over
windows of K steps of a position time series on fixed connectivity.
"""

from dataclasses import dataclass, field

import numpy as np

from lagice.diagnostics._checks import as_triangles, choice, positive
from lagice.diagnostics.strain import (
    GEOMETRIES,
    ElementStrainRates,
    _lagrangian,
    total_deformation_rate,
)
from lagice.errors import ConfigError, check_range


@dataclass(frozen=True)
class PowerLawFit:
    """Least-squares fit of ``y = prefactor · x^(−exponent)`` in log–log space.

    Attributes
    ----------
    exponent : float
        β (or α): minus the log–log slope.
    exponent_stderr : float
        Standard error of the slope (NaN with fewer than 3 points).
    prefactor : float
        ``y`` at ``x = 1`` in the units of ``y``.
    r2 : float
        Coefficient of determination of the log–log fit.
    fit_range : tuple(float, float)
        Smallest and largest ``x`` actually used.
    n_points : int
        Number of points in the fit.
    """

    exponent: float
    exponent_stderr: float
    prefactor: float
    r2: float
    fit_range: tuple
    n_points: int


def fit_power_law(x, y, fit_range=None):
    """Fit ``y ∝ x^(−exponent)`` by least squares on ``(log x, log y)``.

    Parameters
    ----------
    x, y : array_like (k,)
        Positive abscissae (e.g. scale, m) and values (e.g. ⟨ε̇tot⟩, s-1);
        non-positive or non-finite pairs are ignored.
    fit_range : (float, float), optional
        Inclusive ``[x_lo, x_hi]`` restricting the points used (default: all).

    Returns
    -------
    PowerLawFit
        NaN exponent if fewer than 2 usable points.
    """
    x = np.asarray(x, dtype=np.float64).ravel()
    y = np.asarray(y, dtype=np.float64).ravel()
    if x.shape != y.shape:
        raise ConfigError(f"x and y must have the same length; got {x.size} and {y.size}")
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    if fit_range is not None:
        lo, hi = fit_range
        if not (float(lo) <= float(hi)):
            raise ConfigError(f"fit_range = {fit_range!r}; expected (low, high) with low <= high")
        ok &= (x >= lo * (1 - 1e-12)) & (x <= hi * (1 + 1e-12))
    n = int(ok.sum())
    nan = float("nan")
    if n < 2:
        return PowerLawFit(nan, nan, nan, nan, (nan, nan), n)
    lx, ly = np.log(x[ok]), np.log(y[ok])
    mx, my = lx.mean(), ly.mean()
    sxx = np.sum((lx - mx) ** 2)
    if sxx == 0.0:
        return PowerLawFit(nan, nan, nan, nan, (float(x[ok].min()), float(x[ok].max())), n)
    slope = np.sum((lx - mx) * (ly - my)) / sxx
    intercept = my - slope * mx
    resid = ly - (intercept + slope * lx)
    ssr = float(np.sum(resid**2))
    sst = float(np.sum((ly - my) ** 2))
    r2 = 1.0 - ssr / sst if sst > 0 else 1.0
    stderr = float(np.sqrt(ssr / (n - 2) / sxx)) if n > 2 else nan
    return PowerLawFit(float(-slope), stderr, float(np.exp(intercept)), float(r2),
                       (float(x[ok].min()), float(x[ok].max())), n)


@dataclass(frozen=True)
class CoarseGraining:
    """Box-averaged deformation rates at several box widths (Girard 2010 §3.5).

    Attributes
    ----------
    box_size_m : ndarray (k,)
        Box width W (m).
    scale_m : ndarray (k,)
        Mean over counted boxes of sqrt(covered area) (m): the scale L.
    mean_total_s : ndarray (k,)
        ⟨ε̇tot⟩ over counted boxes (s-1); NaN where no box is counted.
    n_boxes : ndarray (k,) int
        Number of counted boxes.
    box_total_s : list of ndarray
        ε̇tot (s-1) of each counted box, per box width.
    box_scale_m : list of ndarray
        sqrt(covered area) (m) of each counted box, per box width.
    box_gradient_s : list of ndarray (nb, 2, 2)
        Box-averaged velocity gradient (s-1) of each counted box.
    min_coverage : float
        Coverage threshold used.
    """

    box_size_m: np.ndarray
    scale_m: np.ndarray
    mean_total_s: np.ndarray
    n_boxes: np.ndarray
    box_total_s: list = field(repr=False)
    box_scale_m: list = field(repr=False)
    box_gradient_s: list = field(repr=False)
    min_coverage: float = 0.75


def default_box_sizes(rates, factor=2.0, n_min_boxes=4):
    """Geometric sequence of box widths (m) from 2 element sizes to the domain size.

    Starts at ``2 · sqrt(median element area)``, multiplies by ``factor``, and
    stops when fewer than ``n_min_boxes`` boxes would fit in the bounding box
    of the centroids (the largest widths are dominated by finite-size effects,
    Girard et al. 2011 §Scaling).
    """
    h = np.sqrt(np.median(rates.area_m2))
    ext = np.ptp(rates.centroid_xy_m, axis=0)
    domain_area = float(max(ext[0], h) * max(ext[1], h))
    sizes = []
    w = 2.0 * h
    while domain_area / (w * w) >= n_min_boxes:
        sizes.append(w)
        w *= factor
    if not sizes:
        sizes.append(2.0 * h)
    return np.asarray(sizes)


def coarse_grain(rates, box_sizes_m=None, min_coverage=0.75, origin_xy_m=None):
    """Coarse-grain element velocity gradients over square boxes of increasing width.

    Parameters
    ----------
    rates : ElementStrainRates
        Element gradients (s-1), areas (m²) and centroids (m), e.g. from
        :func:`lagice.diagnostics.lagrangian_velocity_gradients`.
    box_sizes_m : array_like, optional
        Box widths W (m), > 0. Default :func:`default_box_sizes`.
    min_coverage : float
        A box counts only if the area of its elements is at least
        ``min_coverage · W²`` (0 < min_coverage ≤ 1, default 0.75).
    origin_xy_m : (float, float), optional
        Lower-left corner of the box grid (m). Default: lower-left corner of the
        bounding box of the mesh nodes (``rates.bounds_m``), or of the element
        centroids if the bounds are unknown.

    Returns
    -------
    CoarseGraining
        Boxes are the cells ``[x0 + i W, x0 + (i+1) W) × [y0 + j W, y0 + (j+1) W)``.
    """
    if not isinstance(rates, ElementStrainRates):
        raise ConfigError(f"rates must be an ElementStrainRates; got {type(rates).__name__}")
    cov = check_range("min_coverage", min_coverage, 0.0, 1.0, low_open=True)
    if box_sizes_m is None:
        sizes = default_box_sizes(rates)
    else:
        try:
            sizes = np.atleast_1d(np.asarray(box_sizes_m, dtype=np.float64))
        except (TypeError, ValueError):
            sizes = np.zeros(0)
        if sizes.ndim != 1 or sizes.size == 0 or not np.all(np.isfinite(sizes) & (sizes > 0)):
            raise ConfigError(f"box_sizes_m = {box_sizes_m!r}; expected a non-empty list of widths > 0 m")
    cen = rates.centroid_xy_m
    if origin_xy_m is None:
        origin = cen.min(axis=0) if rates.bounds_m is None else np.asarray(rates.bounds_m)[:2]
    else:
        origin = np.asarray(origin_xy_m, dtype=np.float64) if np.size(origin_xy_m) == 2 else None
        if origin is None or not np.all(np.isfinite(origin)):
            raise ConfigError(f"origin_xy_m = {origin_xy_m!r}; expected two finite coordinates (m)")
        origin = origin.reshape(2)
    area = rates.area_m2
    weighted = (rates.gradient_s * area[:, None, None]).reshape(-1, 4)
    rel = cen - origin
    box_total, box_scale, box_grad = [], [], []
    mean_tot = np.full(sizes.size, np.nan)
    scale = np.full(sizes.size, np.nan)
    nbox = np.zeros(sizes.size, dtype=np.int64)
    for k, w in enumerate(sizes):  # loop over scales, not elements
        ij = np.floor(rel / w).astype(np.int64)
        ij -= ij.min(axis=0)  # centroids below the origin get their own boxes
        nx = int(ij[:, 0].max()) + 1
        ids = ij[:, 1] * nx + ij[:, 0]
        _, inv = np.unique(ids, return_inverse=True)
        nb = int(inv.max()) + 1
        a_box = np.bincount(inv, weights=area, minlength=nb)
        g_box = np.stack([np.bincount(inv, weights=weighted[:, c], minlength=nb) for c in range(4)], axis=-1)
        keep = a_box >= cov * w * w
        g = (g_box[keep] / a_box[keep, None]).reshape(-1, 2, 2)
        tot = total_deformation_rate(g)
        sc = np.sqrt(a_box[keep])
        box_total.append(tot)
        box_scale.append(sc)
        box_grad.append(g)
        nbox[k] = tot.size
        if tot.size:
            mean_tot[k] = tot.mean()
            scale[k] = sc.mean()
    return CoarseGraining(sizes, scale, mean_tot, nbox, box_total, box_scale, box_grad, cov)


@dataclass(frozen=True)
class SpatialScaling:
    """Result of :func:`spatial_scaling`: coarse-graining plus the β fit."""

    coarse: CoarseGraining
    element_scale_m: float
    element_mean_total_s: float
    scale_m: np.ndarray
    mean_total_s: np.ndarray
    fit: PowerLawFit
    n_elements: int = 0


MIN_FIT_BOXES = 10
"""Default minimum number of counted boxes for a scale to enter the β fit.

⟨ε̇tot⟩ at a scale is a mean over its boxes, and box rates are heavy-tailed (their
coefficient of variation is about 1 in the model's runs), so a mean over n boxes is
uncertain by about 1/√n: ±100 % for the one box a 300 km width leaves inside a
1000 km basin, ±30 % for 10 boxes. One box at the widest scale carries the whole
fit's lever arm, so it used to decide β (docs/physics.md, "How β was estimated")."""


def spatial_scaling(rates, box_sizes_m=None, min_coverage=0.75, fit_range_m=None,
                    include_element_scale=True, origin_xy_m=None, min_boxes=MIN_FIT_BOXES):
    """⟨ε̇tot⟩(L) by coarse-graining and the exponent β of ⟨ε̇tot⟩ ∝ L^−β (Girard 2010 §3.5).

    Parameters
    ----------
    rates : ElementStrainRates
        Element-scale gradients (s-1).
    box_sizes_m, min_coverage, origin_xy_m
        See :func:`coarse_grain`.
    fit_range_m : (float, float), optional
        Inclusive range of scales L (m) used in the fit; default all points.
    include_element_scale : bool
        Prepend the element scale (L = mean sqrt(A_e), ⟨ε̇tot⟩ = mean over
        elements), "the smallest scale" of Girard 2010 §3.5.
    min_boxes : int
        A box width enters the fit only if at least this many boxes are counted
        at it (default :data:`MIN_FIT_BOXES` = 10; 1 keeps every width with a
        box). Widths with fewer boxes stay in ``scale_m``/``mean_total_s``.

    Returns
    -------
    SpatialScaling
        ``fit.exponent`` is β, ``fit.fit_range`` the scales (m) used.
    """
    if isinstance(min_boxes, bool) or not isinstance(min_boxes, (int, np.integer)) or min_boxes < 1:
        raise ConfigError(f"min_boxes = {min_boxes!r}; expected an integer >= 1 (boxes per scale in the β fit)")
    cg = coarse_grain(rates, box_sizes_m, min_coverage, origin_xy_m)
    el_scale = float(np.mean(np.sqrt(rates.area_m2)))
    el_mean = float(np.mean(rates.total_s))
    ok = np.isfinite(cg.mean_total_s)
    scale, mean = cg.scale_m[ok], cg.mean_total_s[ok]
    used = cg.n_boxes[ok] >= min_boxes
    if include_element_scale:
        scale = np.concatenate([[el_scale], scale])
        mean = np.concatenate([[el_mean], mean])
        used = np.concatenate([[rates.total_s.size >= min_boxes], used])
    fit = fit_power_law(scale[used], mean[used], fit_range_m)
    return SpatialScaling(cg, el_scale, el_mean, scale, mean, fit, int(rates.total_s.size))


#: box grids :func:`grid_averaged_beta` lays by default: the default corner and 8 seeded offsets of it
BETA_GRIDS = 9


@dataclass(frozen=True)
class GridAveragedBeta:
    """Result of :func:`grid_averaged_beta`: β fitted on several box grids.

    Attributes
    ----------
    mean, sd : float
        Mean and standard deviation (ddof 0) of β over the grids whose fit is finite.
    betas : np.ndarray
        β per grid, the default corner's first (NaN where a grid's fit failed).
    offsets_m : np.ndarray
        (n_grids, 2) shift of each grid's corner from the default corner (m); the first is (0, 0).
    curves : tuple of dict
        Each grid's ⟨ε̇tot⟩(L) in the JSON form of :func:`scaling_curve` (the default corner's
        first), for :func:`pooled_spatial_scaling`.
    """

    mean: float
    sd: float
    betas: np.ndarray
    offsets_m: np.ndarray
    curves: tuple = field(default=(), repr=False)


def grid_averaged_beta(rates, n_grids=BETA_GRIDS, seed=0, box_sizes_m=None, min_coverage=0.75,
                       fit_range_m=None, include_element_scale=True, min_boxes=MIN_FIT_BOXES, origin_xy_m=None,
                       first=None):
    """β of :func:`spatial_scaling` averaged over box grids laid from different corners.

    Where the boxes fall decides which bands share a box and which boxes a coast cuts,
    so one grid's β carries an error of its own: in the winter basin, one month's
    window-median β moves by 0.02–0.05 from grid to grid (docs/physics.md §4, "How far β
    moves with the box grid"). Observed β (Marsan et al. 2004) averages over the boxes of
    a whole basin and winter; a model basin holds far fewer, so this estimator averages
    over grids instead. The first grid starts at :func:`coarse_grain`'s default corner; the
    others at that corner shifted down and left by seeded offsets uniform in [0, L_max) in
    x and y, where L_max is the widest box width the first grid's fit uses (its widest
    box width if the fit used none). Box widths, coverage and the fit's rules are those of
    :func:`spatial_scaling` on every grid.

    Parameters
    ----------
    rates : ElementStrainRates
    n_grids : int
        Number of grids, the default one included (>= 1; default :data:`BETA_GRIDS`).
    seed : int
        Seed of the offsets (``numpy.random.default_rng``).
    origin_xy_m : (float, float), optional
        The first grid's corner (default: :func:`coarse_grain`'s).
    first : SpatialScaling, optional
        The default grid's :func:`spatial_scaling` with the same arguments, if already
        computed (it is not computed again).

    Returns
    -------
    GridAveragedBeta
    """
    if isinstance(n_grids, bool) or not isinstance(n_grids, (int, np.integer)) or n_grids < 1:
        raise ConfigError(f"n_grids = {n_grids!r}; expected an integer >= 1 (box grids for β)")
    if box_sizes_m is None:
        box_sizes_m = default_box_sizes(rates)
    if first is None:
        first = spatial_scaling(rates, box_sizes_m, min_coverage, fit_range_m, include_element_scale,
                                origin_xy_m=origin_xy_m, min_boxes=min_boxes)
    if origin_xy_m is not None:
        corner = np.asarray(origin_xy_m, dtype=np.float64).reshape(2)
    else:
        corner = (rates.centroid_xy_m.min(axis=0) if rates.bounds_m is None
                  else np.asarray(rates.bounds_m, dtype=np.float64)[:2])
    widest = first.fit.fit_range[1] if first.fit.n_points >= 2 else np.nan
    if not np.isfinite(widest) or widest <= first.element_scale_m:
        widest = float(np.max(box_sizes_m))
    else:  # the fit's widest point is a box scale (the mean box's √area); take its box width
        widths = np.asarray(first.coarse.box_size_m, dtype=np.float64)
        scales = np.asarray(first.coarse.scale_m, dtype=np.float64)
        ok = np.isfinite(scales) & (scales <= widest * (1 + 1e-12))
        widest = float(widths[ok].max()) if ok.any() else float(np.max(box_sizes_m))
    rng = np.random.default_rng(seed)
    offsets = np.vstack([[0.0, 0.0], rng.uniform(0.0, widest, size=(int(n_grids) - 1, 2))])
    betas = [first.fit.exponent]
    curves = [scaling_curve(first)]
    for off in offsets[1:]:
        sp = spatial_scaling(rates, box_sizes_m, min_coverage, fit_range_m, include_element_scale,
                             origin_xy_m=corner - off, min_boxes=min_boxes)
        betas.append(sp.fit.exponent)
        curves.append(scaling_curve(sp))
    betas = np.asarray(betas, dtype=np.float64)
    ok = np.isfinite(betas)
    return GridAveragedBeta(float(betas[ok].mean()) if ok.any() else float("nan"),
                            float(betas[ok].std()) if ok.any() else float("nan"), betas, offsets, tuple(curves))


def scaling_curve(sp) -> dict:
    """A :class:`SpatialScaling`'s ⟨ε̇tot⟩(L) as JSON: ``{"box_size_m", "scale_m", "mean_total_s",
    "n_boxes"}`` over the box widths that hold a counted box, the element scale first (``box_size_m``
    None, ``n_boxes`` the number of elements) where the scaling includes it. The form of the
    ``scaling_space`` key of :func:`lagice.diagnostics.summarise`."""
    ok = np.isfinite(sp.coarse.mean_total_s)
    sizes = [float(w) for w in sp.coarse.box_size_m[ok]]
    counts = [int(n) for n in sp.coarse.n_boxes[ok]]
    if sp.scale_m.size == len(sizes) + 1:   # the element scale comes first
        sizes = [None] + sizes
        counts = [int(sp.n_elements)] + counts
    return {"box_size_m": sizes, "scale_m": [float(x) for x in sp.scale_m],
            "mean_total_s": [float(x) for x in sp.mean_total_s], "n_boxes": counts}


@dataclass(frozen=True)
class PooledScaling:
    """Result of :func:`pooled_spatial_scaling`: one ⟨ε̇tot⟩(L) over every box of several curves.

    Attributes
    ----------
    scale_m : ndarray (k,)
        Scale L per width (m): the box-count-weighted mean of the curves' scales; the element
        scale first where the curves have it.
    mean_total_s : ndarray (k,)
        ⟨ε̇tot⟩ (s-1) over every counted box of every curve at the width.
    n_boxes : ndarray (k,) int
        Counted boxes (elements, for the element scale) over all curves.
    fewest_boxes : ndarray (k,) int
        The fewest boxes any one curve counts at the width (a width enters the fit only if this
        is at least ``min_boxes``).
    n_curves : int
    fit : PowerLawFit
        β of the pooled curve (``fit.exponent``).
    """

    scale_m: np.ndarray
    mean_total_s: np.ndarray
    n_boxes: np.ndarray
    fewest_boxes: np.ndarray
    n_curves: int
    fit: PowerLawFit


def pooled_spatial_scaling(curves, min_boxes=MIN_FIT_BOXES, fit_range_m=None, width_tolerance=0.25):
    """β of ⟨ε̇tot⟩(L) averaged over every box of several curves: the observations' estimator.

    Observed β is not a median of single windows' slopes. Marsan et al. (2004) average ε̇tot
    over every box of width L in the whole basin and every 3-day interval of the period,
    then fit one slope; Girard et al. (2011) merge the periods of a month into one curve. So
    the windows (and box grids) that deform most weigh most. Given curves of single windows
    or grids (:func:`scaling_curve`, the ``scaling_space`` of
    :func:`lagice.diagnostics.summarise`), the pooled ⟨ε̇tot⟩ at a width is
    ``Σ n_c ⟨ε̇tot⟩_c / Σ n_c``, the mean over all their counted boxes, and its scale the
    box-weighted mean of theirs. The element scale is pooled the same way, over elements.

    Parameters
    ----------
    curves : sequence of dict
        ``{"box_size_m", "scale_m", "mean_total_s", "n_boxes"}`` each. Box widths are matched
        in order (the k-th box width of every curve) over the widths every curve holds; they
        must agree within ``width_tolerance`` (relative), so curves of different meshes are
        refused. Either every curve starts with the element scale (``box_size_m`` None) or none.
        A curve that is itself a pool of curves may carry ``fewest_boxes`` (the fewest boxes any
        of its curves counts, :attr:`PooledScaling.fewest_boxes`), so that pooling pools gives
        what pooling all their curves gives.
    min_boxes : int
        A width enters the fit only if every curve counts at least this many boxes at it (the
        rule of each window's own fit, default :data:`MIN_FIT_BOXES`).
    fit_range_m : (float, float), optional
        Inclusive range of scales L (m) of the fit.

    Returns
    -------
    PooledScaling

    Raises
    ------
    ConfigError
        No curve, a curve with mismatched lists, widths that do not agree, or element scales
        in some curves only.
    """
    if isinstance(min_boxes, bool) or not isinstance(min_boxes, (int, np.integer)) or min_boxes < 1:
        raise ConfigError(f"min_boxes = {min_boxes!r}; expected an integer >= 1 (boxes per scale in the β fit)")
    tol = check_range("width_tolerance", width_tolerance, 0.0, None)
    curves = list(curves)
    if not curves:
        raise ConfigError("pooled_spatial_scaling: no curve to pool")
    rows = []
    for i, c in enumerate(curves):
        try:
            w = list(c["box_size_m"])
            sc, m, n = (np.asarray(c[k], dtype=np.float64) for k in ("scale_m", "mean_total_s", "n_boxes"))
        except (KeyError, TypeError) as exc:
            raise ConfigError(f"pooled_spatial_scaling: curve {i} is not a scaling curve "
                              "({box_size_m, scale_m, mean_total_s, n_boxes})") from exc
        if not (len(w) == sc.size == m.size == n.size):
            raise ConfigError(f"pooled_spatial_scaling: curve {i} has lists of lengths {len(w)}, {sc.size}, "
                              f"{m.size}, {n.size}; expected one entry per scale in each")
        few = np.asarray(c.get("fewest_boxes", n), dtype=np.float64)
        if few.size != n.size:
            raise ConfigError(f"pooled_spatial_scaling: curve {i} has {few.size} fewest_boxes for {n.size} scales")
        rows.append((w, sc, m, n, few))
    has_el = [bool(r[0]) and r[0][0] is None for r in rows]
    if any(has_el) != all(has_el):
        raise ConfigError(f"pooled_spatial_scaling: {sum(has_el)} of {len(rows)} curves start with the element "
                          "scale; pool curves made alike (include_element_scale)")
    el = int(has_el[0])
    k_common = min(len(r[0]) - el for r in rows)
    widths = np.array([[float(r[0][el + k]) for k in range(k_common)] for r in rows]).reshape(len(rows), k_common)
    if k_common and np.any(widths.max(axis=0) > (1.0 + tol) * widths.min(axis=0)):
        k = int(np.argmax(widths.max(axis=0) / widths.min(axis=0)))
        raise ConfigError(f"pooled_spatial_scaling: the box widths of the curves differ: width {k} spans "
                          f"{widths[:, k].min():.4g}-{widths[:, k].max():.4g} m (more than {100 * tol:g} %); "
                          "curves of different meshes or box sequences cannot be pooled")
    n_rows = el + k_common
    sc = np.array([r[1][:n_rows] for r in rows]).reshape(len(rows), n_rows)
    m = np.array([r[2][:n_rows] for r in rows]).reshape(len(rows), n_rows)
    n = np.array([r[3][:n_rows] for r in rows]).reshape(len(rows), n_rows)
    few = np.array([r[4][:n_rows] for r in rows]).reshape(len(rows), n_rows)
    n_tot = n.sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(n_tot > 0, (n * np.where(n > 0, m, 0.0)).sum(axis=0) / n_tot, np.nan)
        scale = np.where(n_tot > 0, (n * np.where(n > 0, sc, 0.0)).sum(axis=0) / n_tot, np.nan)
    fewest = few.min(axis=0)
    used = fewest >= min_boxes
    fit = fit_power_law(scale[used], mean[used], fit_range_m)
    return PooledScaling(scale, mean, n_tot.astype(np.int64), fewest.astype(np.int64), len(rows), fit)


_WINDOW_BATCH_ELEMENTS = 1_000_000


@dataclass(frozen=True)
class TemporalScaling:
    """⟨ε̇tot⟩(T) over windows of increasing length and the α fit."""

    window_s: np.ndarray
    window_steps: np.ndarray
    mean_total_s: np.ndarray
    n_windows: np.ndarray
    fit: PowerLawFit


def temporal_scaling(nodes_xy_series, triangles, dt_s, window_steps=None, geometry="mid",
                     overlapping=False, fit_range_s=None):
    """⟨ε̇tot⟩(T) ∝ T^−α from a time series of node positions (Girard 2010 eq. 2.5).

    For each window of ``K`` steps (T = K·dt_s) the Lagrangian element rates
    are computed from the positions at the window ends (see
    :func:`lagice.diagnostics.lagrangian_velocity_gradients`), and ⟨ε̇tot⟩ is
    the unweighted mean over all elements and windows.

    Parameters
    ----------
    nodes_xy_series : array_like (k+1, n, 2)
        Node positions (m) at times ``i · dt_s``, fixed connectivity.
    triangles : array_like (m, 3) int
        Counter-clockwise node indices.
    dt_s : float
        Time between successive positions (s), > 0.
    window_steps : array_like of int, optional
        Window lengths in steps (≥ 1, ≤ k). Default: powers of 2 up to k.
    geometry : {"mid", "start", "end"}
        Geometry on which gradients are taken.
    overlapping : bool
        Windows start every step (True) or are back to back (False, default).
    fit_range_s : (float, float), optional
        Inclusive range of T (s) used in the fit.

    Returns
    -------
    TemporalScaling
        ``fit.exponent`` is α.
    """
    pos = np.asarray(nodes_xy_series, dtype=np.float64)
    if pos.ndim != 3 or pos.shape[2] != 2 or pos.shape[0] < 2:
        raise ConfigError(f"nodes_xy_series must have shape (n_times >= 2, n_nodes, 2); got shape {pos.shape}")
    if not np.all(np.isfinite(pos)):
        raise ConfigError("nodes_xy_series contains non-finite positions")
    tri = as_triangles(triangles, pos.shape[1])
    dt = positive("dt_s", dt_s, "s")
    choice("geometry", geometry, GEOMETRIES)
    n_steps = pos.shape[0] - 1
    if window_steps is None:
        steps = 2 ** np.arange(int(np.floor(np.log2(n_steps))) + 1)
    else:
        steps = np.atleast_1d(np.asarray(window_steps))
        if steps.ndim != 1 or steps.size == 0 or not np.issubdtype(steps.dtype, np.integer) \
                or steps.min() < 1 or steps.max() > n_steps:
            raise ConfigError(f"window_steps = {window_steps!r}; expected integers in [1, {n_steps}]")
    steps = steps.astype(np.int64)
    means = np.full(steps.size, np.nan)
    nwin = np.zeros(steps.size, dtype=np.int64)
    for k, K in enumerate(steps):  # loop over window lengths, elements are vectorised
        starts = np.arange(0, n_steps - K + 1, 1 if overlapping else K)
        total_sum = 0.0
        per_chunk = max(1, _WINDOW_BATCH_ELEMENTS // tri.shape[0])  # bounds memory (~250 B/element/window)
        for chunk in np.array_split(starts, -(-starts.size // per_chunk)):
            r = _lagrangian(pos[chunk], pos[chunk + K], tri, K * dt, geometry)
            total_sum += float(np.sum(r.total_s))
        nwin[k] = starts.size
        means[k] = total_sum / (starts.size * tri.shape[0])
    window_s = steps * dt
    fit = fit_power_law(window_s, means, fit_range_s)
    return TemporalScaling(window_s, steps, means, nwin, fit)
