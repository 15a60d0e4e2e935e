"""Mesh imprint: do fractures follow the mesh's edge directions? (issue 12)

gmsh's frontal-Delaunay meshes are locally close to a triangular lattice: most edge
length lies near three directions 60° apart. Damage bands one element wide can run
along those rows instead of the directions the stress selects. This module measures it.

1. :func:`mesh_directions`: the dominant edge directions of a mesh (peaks of the
   length-weighted, 180°-periodic histogram of edge directions) and the fraction of the
   edge length within ±``half_width_deg`` of them (``lattice_fraction``).
2. :func:`fracture_orientations`: the local direction of the fracture set, at a scale
   larger than one element. The fracture set is the elements whose field (damage,
   shear rate, ...) is at least ``threshold`` (default: the ``quantile`` of the field).
   Around each of them, the fractured elements within ``radius_m`` (their centroids)
   give a covariance; its principal axis is the local band direction and
   a = (λ1 − λ2)/(λ1 + λ2) its anisotropy (1 for a line, 0 for a blob). Segments with
   a ≥ ``min_anisotropy`` are kept, weighted by a. Measured this way, a band that
   crosses a lattice at 15° as a staircase has direction ≈ 15°, and a band along a
   mesh row has the row's direction. (The boundary edges of a band are always mesh
   edges, so they cannot be the measure.)
3. :func:`imprint_index`: F = weighted fraction of fracture directions within
   ±``half_width_deg`` of a dominant mesh direction; F0 = the same fraction for
   directions uniform on [0°, 180°) (the windows' total width / 180°, 0.25 for three
   15°-wide windows); **index = (F − F0)/(1 − F0)**: 0 at chance (isotropic fractures),
   1 when every fracture runs along a mesh direction, negative when fractures avoid them.
3b. :func:`local_alignment`: the same question against the edges near each segment
   (for meshes without a domain-wide lattice, e.g. gmsh's Delaunay algorithm):
   **local index** = (F̄ − F0)/(F̄_max − F0), 0 at chance, 1 along the local lattice.
4. :func:`orientation_shift_deg`: the rotation test. For the same physical scene on
   meshes whose lattice is rotated by α, the shift δ that best maps the fracture
   direction histogram of the unrotated mesh onto the rotated one is ≈ 0 when physics
   sets the directions and ≈ α when the mesh does. :func:`ensemble_turn_test` asks the
   same of the mean histograms of many realisations, with a bootstrap interval.

Physically preferred directions can coincide with mesh directions (e.g. Coulomb faults
at 27.5° from a y-axis load lie at 62.5° and 117.5° from x, near a lattice's 60° and
120°), so the index of one run is not enough: the rotation test separates the two.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lagice.diagnostics._checks import as_points, as_triangles, positive, values_1d
from lagice.errors import ConfigError


def _wrap180(a):
    return np.mod(a, 180.0)


def _circ_dist180(a, b):
    """Smallest distance between directions (period 180°) [deg]."""
    d = np.abs(np.mod(np.asarray(a) - np.asarray(b) + 90.0, 180.0) - 90.0)
    return d


def mesh_edges(triangles):
    """Unique undirected edges (k, 2) of a triangulation."""
    tri = np.asarray(triangles, np.int64)
    e = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    return np.unique(e, axis=0)


def edge_orientations(nodes_xy_m, triangles):
    """Directions [deg, 0–180) and lengths [m] of the unique edges."""
    nodes = as_points("nodes_xy_m", nodes_xy_m)
    tri = as_triangles(triangles, nodes.shape[0])
    e = mesh_edges(tri)
    d = nodes[e[:, 1]] - nodes[e[:, 0]]
    return _wrap180(np.degrees(np.arctan2(d[:, 1], d[:, 0]))), np.hypot(d[:, 0], d[:, 1])


def orientation_histogram(angles_deg, weights=None, bin_deg=5.0):
    """Normalised (sum 1) 180°-periodic histogram: (bin centres [deg], fractions)."""
    a = _wrap180(np.asarray(angles_deg, np.float64))
    w = np.ones_like(a) if weights is None else values_1d("weights", weights, a.size)
    nb = round(180.0 / bin_deg)
    h, edges = np.histogram(a, bins=nb, range=(0.0, 180.0), weights=w)
    tot = h.sum()
    return 0.5 * (edges[1:] + edges[:-1]), (h / tot if tot > 0 else h)


@dataclass(frozen=True)
class MeshDirections:
    directions_deg: np.ndarray      # dominant directions, strongest first
    lattice_fraction: float         # edge length within ±half_width of them / total
    half_width_deg: float


def mesh_directions(nodes_xy_m, triangles, n=3, half_width_deg=7.5, min_separation_deg=30.0,
                    smooth_deg=2.0) -> MeshDirections:
    """The ``n`` dominant edge directions (length-weighted, 1° bins smoothed by a
    Gaussian of ``smooth_deg``, peaks ≥ ``min_separation_deg`` apart)."""
    ang, ln = edge_orientations(nodes_xy_m, triangles)
    h, _ = np.histogram(ang, bins=180, range=(0.0, 180.0), weights=ln)
    k = np.arange(-15, 16)
    g = np.exp(-0.5 * (k / smooth_deg) ** 2)
    hs = np.convolve(np.concatenate([h[-15:], h, h[:15]]), g / g.sum(), mode="same")[15:-15]
    centres = np.arange(180) + 0.5
    order = np.argsort(-hs, kind="stable")
    peaks = []
    for i in order:
        left, right = hs[(i - 1) % 180], hs[(i + 1) % 180]
        if hs[i] < left or hs[i] < right:
            continue
        if all(_circ_dist180(centres[i], p) >= min_separation_deg for p in peaks):
            peaks.append(centres[i])
        if len(peaks) == n:
            break
    peaks = np.array(peaks)
    near = np.min(_circ_dist180(ang[:, None], peaks[None, :]), axis=1) <= half_width_deg
    return MeshDirections(peaks, float(ln[near].sum() / ln.sum()), float(half_width_deg))


@dataclass(frozen=True)
class FractureOrientations:
    angles_deg: np.ndarray        # local band direction of each kept fractured element [0, 180)
    weights: np.ndarray           # anisotropy a of each kept segment
    anisotropy: np.ndarray        # a of every fractured element (kept or not)
    n_fractured: int
    threshold: float
    radius_m: float
    positions_xy_m: np.ndarray | None = None  # (k, 2) centroids of the kept segments [m]


def fracture_orientations(centroids_xy_m, field, radius_m, *, threshold=None, quantile=0.9,
                          min_anisotropy=0.5, min_neighbours=4) -> FractureOrientations:
    """Local directions of the fracture set {field ≥ threshold} (module docstring, 2).

    Args:
        centroids_xy_m: (m, 2) element centroids [m].
        field: (m,) damage, shear rate, ... (larger = more fractured).
        radius_m: neighbourhood radius, a few element sizes [m].
        threshold: fracture threshold on ``field``; None: the ``quantile`` of field.
        min_anisotropy: segments with a < this are blobs, not bands (dropped).
        min_neighbours: segments with fewer fractured neighbours are dropped.
    """
    from scipy.spatial import cKDTree

    xy = as_points("centroids_xy_m", centroids_xy_m)
    f = values_1d("field", field, xy.shape[0])
    r = positive("radius_m", radius_m, "m")
    if threshold is None:
        if not 0.0 < quantile < 1.0:
            raise ConfigError(f"quantile = {quantile!r} must be in (0, 1)")
        threshold = float(np.quantile(f, quantile))
    sel = np.flatnonzero((f >= threshold) & (f > 0))
    empty = FractureOrientations(np.zeros(0), np.zeros(0), np.zeros(0), int(sel.size), float(threshold), r,
                                 np.zeros((0, 2)))
    if sel.size < min_neighbours:
        return empty
    p = xy[sel] - xy[sel].mean(axis=0)
    pairs = cKDTree(p).query_pairs(r, output_type="ndarray")
    i = np.concatenate([pairs[:, 0], pairs[:, 1], np.arange(sel.size)])
    j = np.concatenate([pairs[:, 1], pairs[:, 0], np.arange(sel.size)])
    n = sel.size
    cnt = np.bincount(i, minlength=n).astype(float)
    sx = np.bincount(i, weights=p[j, 0], minlength=n)
    sy = np.bincount(i, weights=p[j, 1], minlength=n)
    sxx = np.bincount(i, weights=p[j, 0] ** 2, minlength=n)
    syy = np.bincount(i, weights=p[j, 1] ** 2, minlength=n)
    sxy = np.bincount(i, weights=p[j, 0] * p[j, 1], minlength=n)
    mx, my = sx / cnt, sy / cnt
    cxx, cyy, cxy = sxx / cnt - mx * mx, syy / cnt - my * my, sxy / cnt - mx * my
    tr = cxx + cyy
    with np.errstate(invalid="ignore", divide="ignore"):
        an = np.where(tr > 0, np.sqrt((cxx - cyy) ** 2 + 4 * cxy * cxy) / tr, 0.0)
    ang = _wrap180(np.degrees(0.5 * np.arctan2(2 * cxy, cxx - cyy)))
    keep = (cnt >= min_neighbours) & (an >= min_anisotropy)
    return FractureOrientations(ang[keep], an[keep], an, int(n), float(threshold), r, xy[sel][keep])


def local_alignment(nodes_xy_m, triangles, fo: FractureOrientations, radius_m=None,
                    half_width_deg=7.5) -> dict:
    """Local mesh imprint: do fracture segments run along the edges *near them*?

    The index of :func:`imprint_index` compares fracture directions with the mesh's
    domain-wide dominant directions; a mesh without a domain-wide lattice (gmsh's
    Delaunay algorithm) has none, yet bands can still follow its local edges. For each
    kept segment of ``fo`` (direction θ, weight a), the edges whose midpoints lie within
    ``radius_m`` (default ``fo.radius_m``) give, length-weighted, F = the fraction within
    ±``half_width_deg`` of θ and F_max = the same fraction in the best direction. Over
    the segments (weights a): **local index = (F̄ − F0)/(F̄_max − F0)**, F0 =
    2 half_width/180 (the mean of F over uniformly random θ, for any edge set). 0: bands
    cross the local edges at random; 1: every band runs along its neighbourhood's most
    common edge direction."""
    from scipy.spatial import cKDTree

    nodes = as_points("nodes_xy_m", nodes_xy_m)
    tri = as_triangles(triangles, nodes.shape[0])
    r = positive("radius_m", fo.radius_m if radius_m is None else radius_m, "m")
    f0 = 2.0 * half_width_deg / 180.0
    if fo.angles_deg.size == 0 or fo.positions_xy_m is None:
        return {"local_index": float("nan"), "local_fraction": float("nan"), "local_best_fraction": float("nan"),
                "chance": f0, "n_segments": 0}
    e = mesh_edges(tri)
    mid = 0.5 * (nodes[e[:, 0]] + nodes[e[:, 1]])
    ang, ln = edge_orientations(nodes, tri)
    hw = int(round(half_width_deg))
    kern = np.ones(2 * hw + 1)
    near_lists = cKDTree(mid).query_ball_point(fo.positions_xy_m, r)
    F = np.full(fo.angles_deg.size, np.nan)
    Fmax = np.full(fo.angles_deg.size, np.nan)
    for k, idx in enumerate(near_lists):  # over segments (a diagnostic, not a time step)
        if not idx:
            continue
        a, w = ang[idx], ln[idx]
        tot = w.sum()
        F[k] = w[_circ_dist180(a, fo.angles_deg[k]) <= half_width_deg].sum() / tot
        h, _ = np.histogram(a, bins=180, range=(0.0, 180.0), weights=w)
        Fmax[k] = np.convolve(np.concatenate([h[-hw:], h, h[:hw]]), kern, mode="valid").max() / tot
    ok = np.isfinite(F)
    if not ok.any():  # no edge within radius_m of any segment
        return {"local_index": float("nan"), "local_fraction": float("nan"), "local_best_fraction": float("nan"),
                "chance": f0, "n_segments": 0}
    wt = fo.weights[ok]
    fbar = float(np.average(F[ok], weights=wt))
    fmax = float(np.average(Fmax[ok], weights=wt))
    return {"local_index": (fbar - f0) / (fmax - f0) if fmax > f0 else float("nan"),
            "local_fraction": fbar, "local_best_fraction": fmax, "chance": f0, "n_segments": int(ok.sum())}


def imprint_index(angles_deg, weights, mesh_dirs_deg, half_width_deg=7.5) -> dict:
    """F, chance level F0 and index (F − F0)/(1 − F0) (module docstring, 3)."""
    a = _wrap180(np.asarray(angles_deg, np.float64))
    w = values_1d("weights", weights, a.size) if a.size else np.zeros(0)
    dirs = np.asarray(mesh_dirs_deg, np.float64)
    grid = np.arange(0.0, 180.0, 0.01) + 0.005
    f0 = float(np.mean(np.min(_circ_dist180(grid[:, None], dirs[None, :]), axis=1) <= half_width_deg))
    if a.size == 0 or w.sum() <= 0:
        return {"index": float("nan"), "fraction": float("nan"), "chance": f0, "n_segments": 0}
    near = np.min(_circ_dist180(a[:, None], dirs[None, :]), axis=1) <= half_width_deg
    f = float(w[near].sum() / w.sum())
    return {"index": (f - f0) / (1.0 - f0), "fraction": f, "chance": f0, "n_segments": int(a.size)}


def histogram_correlation(h_ref, h_rot, bin_deg=2.5, smooth_deg=5.0) -> np.ndarray:
    """Circular cross-correlation of two 180°-periodic direction histograms (same bins of
    ``bin_deg``), each smoothed by a Gaussian of ``smooth_deg`` and standardised: element j is
    the correlation when ``h_ref`` is turned by j × ``bin_deg`` (1 for identical shapes, 0 for
    unrelated ones; a flat histogram correlates 0 with anything)."""
    h0 = np.asarray(h_ref, np.float64)
    h1 = np.asarray(h_rot, np.float64)
    if h0.shape != h1.shape or h0.ndim != 1:
        raise ConfigError(f"histogram_correlation: histograms of shapes {h0.shape} and {h1.shape}; expected two "
                          "1-D histograms on the same bins")
    nb = h0.size
    k = np.arange(nb)
    d = np.minimum(k, nb - k) * bin_deg
    g = np.exp(-0.5 * (d / smooth_deg) ** 2)
    fg = np.fft.fft(g / g.sum())

    def standard(h):  # circular convolution with the Gaussian, then zero mean and unit variance
        s = np.real(np.fft.ifft(np.fft.fft(h) * fg))
        return (s - s.mean()) / (s.std() or 1.0)

    s0, s1 = standard(h0), standard(h1)
    return np.array([np.mean(np.roll(s0, j) * s1) for j in range(nb)])


def ensemble_turn_test(hists_ref, hists_rot, rotation_deg, bin_deg=2.5, smooth_deg=5.0, n_boot=2000, seed=0,
                       level=0.90) -> dict:
    """The rotation test on ensembles: ``hists_ref`` are the normalised
    direction histograms (:func:`orientation_histogram`, bins of ``bin_deg``) of runs on one mesh,
    ``hists_rot`` those of *other* realisations on the same mesh turned by ``rotation_deg``.
    Averaging over runs removes most of what one realisation adds. The statistic is
    D = corr(exactly the turn) − corr(no shift) of the ensemble means (:func:`histogram_correlation`):
    D > 0 when the directions turned with the mesh, D < 0 when they stayed with the scene, D ≈ 0 when
    the ensembles cannot tell (no common direction, or equal pulls). Its ``level`` interval comes from
    resampling the runs of each ensemble with replacement (``n_boot`` times, generator ``seed``).
    Also the split-half correlation at no shift of the reference ensemble (its first against its
    second half of runs): how reproducible the ensemble's direction histogram is at all."""
    h0 = np.asarray(hists_ref, np.float64)
    h1 = np.asarray(hists_rot, np.float64)
    if h0.ndim != 2 or h1.ndim != 2 or h0.shape[1] != h1.shape[1] or min(h0.shape[0], h1.shape[0]) < 2:
        raise ConfigError(f"ensemble_turn_test: histogram arrays of shapes {h0.shape} and {h1.shape}; expected "
                          "(runs, bins) with at least 2 runs each and the same bins")
    nb = h0.shape[1]
    j_turn = int(round((float(rotation_deg) % 180.0) / bin_deg)) % nb

    def stat(a, b):
        c = histogram_correlation(a.mean(axis=0), b.mean(axis=0), bin_deg, smooth_deg)
        return c[j_turn] - c[0], c[0], c[j_turn]

    d, c0, ct = stat(h0, h1)
    rng = np.random.default_rng(seed)
    boot = np.array([stat(h0[rng.integers(0, h0.shape[0], h0.shape[0])],
                          h1[rng.integers(0, h1.shape[0], h1.shape[0])])[0] for _ in range(int(n_boot))])
    lo, hi = np.percentile(boot, [50.0 * (1.0 - level), 50.0 * (1.0 + level)])
    half = h0.shape[0] // 2
    split = histogram_correlation(h0[:half].mean(axis=0), h0[half:].mean(axis=0), bin_deg, smooth_deg)[0]
    return {"rotation_deg": float(rotation_deg), "d": float(d), "corr_at_zero": float(c0),
            "corr_at_exact_rotation": float(ct), "d_low": float(lo), "d_high": float(hi), "level": float(level),
            "n_ref": int(h0.shape[0]), "n_rot": int(h1.shape[0]), "split_half_corr_ref": float(split)}


def orientation_shift_deg(angles_ref, weights_ref, angles_rot, weights_rot, bin_deg=2.5, smooth_deg=5.0,
                          rotation_deg=None, lattice_period_deg=60.0):
    """Shift δ ∈ (−90°, 90°] that best maps the reference direction histogram onto the
    rotated-mesh one (max circular cross-correlation of smoothed histograms), and the
    correlation at δ and at 0. δ ≈ 0: directions independent of the mesh; δ ≈ the
    lattice rotation: directions follow the mesh. With ``rotation_deg`` also the
    correlation at the lattice rotation (best of rotation + k × ``lattice_period_deg``):
    ``corr_at_rotation`` > ``corr_at_zero`` means the directions follow the mesh. The best of
    the rotation's lattice-period candidates is biased upwards against the single value at 0;
    ``corr_at_exact_rotation`` (the rotation itself, one value) is not, for a mesh that is the
    same mesh turned (gmsh meshes the unrotated domain, :func:`lagice.scenes.builder.build_mesh`)."""
    _, h0 = orientation_histogram(angles_ref, weights_ref, bin_deg)
    _, h1 = orientation_histogram(angles_rot, weights_rot, bin_deg)
    nb = h0.size
    corr = histogram_correlation(h0, h1, bin_deg, smooth_deg)
    j = int(np.argmax(corr))
    shift = j * bin_deg
    if shift > 90.0:
        shift -= 180.0
    out = {"shift_deg": float(shift), "corr_at_shift": float(corr[j]), "corr_at_zero": float(corr[0])}
    if rotation_deg is not None:
        cands = [(rotation_deg + k * lattice_period_deg) % 180.0 for k in range(int(round(180 / lattice_period_deg)))]
        out["corr_at_rotation"] = float(max(corr[int(round(c / bin_deg)) % nb] for c in cands))
        out["corr_at_exact_rotation"] = float(corr[int(round((rotation_deg % 180.0) / bin_deg)) % nb])
    return out


def imprint_summary(nodes_xy_m, triangles, field, radius_m=None, **kw) -> dict:
    """Mesh directions, fracture orientations and the index of one field on one mesh,
    as a JSON-able dict. ``radius_m`` default: 3 × the median sqrt(element area)."""
    nodes = as_points("nodes_xy_m", nodes_xy_m)
    tri = as_triangles(triangles, nodes.shape[0])
    p = nodes[tri]
    area = 0.5 * np.abs((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                        - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))
    if radius_m is None:
        radius_m = 3.0 * float(np.median(np.sqrt(area)))
    md = mesh_directions(nodes, tri)
    fo = fracture_orientations(p.mean(axis=1), field, radius_m, **kw)
    idx = imprint_index(fo.angles_deg, fo.weights, md.directions_deg, md.half_width_deg)
    loc = local_alignment(nodes, tri, fo, half_width_deg=md.half_width_deg)
    idx.update({k: loc[k] for k in ("local_index", "local_fraction", "local_best_fraction")})
    centres, hist = orientation_histogram(fo.angles_deg, fo.weights) if fo.angles_deg.size else (None, None)
    return {"mesh_directions_deg": md.directions_deg.tolist(), "mesh_lattice_fraction": md.lattice_fraction,
            "radius_m": radius_m, "threshold": fo.threshold, "n_fractured": fo.n_fractured, **idx,
            "histogram_deg": None if centres is None else centres.tolist(),
            "histogram": None if hist is None else hist.tolist(),
            "_angles": fo.angles_deg, "_weights": fo.weights}
