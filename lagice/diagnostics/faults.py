"""Fault orientation of a localised field, and masks away from coasts.

:func:`fault_orientations` finds the directions of straight bands in a
field sampled at element centroids (damage, or a deformation rate): for each
trial direction θ (angle of the band from the x axis, 0–180°) the weights are
projected on the band normal and binned in strips of width ``strip_width_m``;
a straight band of direction θ0 puts all its weight into one strip at θ = θ0
and spreads it over ``length·|sin(θ−θ0)|/strip`` strips otherwise. The score
``S(θ)`` is the largest strip weight over the total weight (two strip grids
offset by half a strip, so a band that straddles a strip edge is not split);
faults are the highest local maxima of ``S``, at least ``min_separation_deg``
apart (a discrete Hough/Radon transform restricted to its maxima). Each
direction is then refined to the weighted principal axis of the samples inside
its strip, because S is flat over the angles for which a band narrower than
the strip still fits in it.

:func:`mohr_coulomb_fault_angle_deg` gives the Coulomb prediction for the angle
between a shear fault and the most compressive principal stress,
``θ = 45° − φ/2`` with ``φ = atan μ`` (Girard 2010 §1.3: μ internal friction
coefficient; Dansereau et al. 2016 uses μ = 0.7, hence θ = 27.5° and conjugate faults
55° apart; observed conjugate leads intersect at 20–50°, Girard 2010 ch. 1).
:func:`damage_mode_fault_angle_deg` gives what a damage model with that envelope
predicts instead: the direction of the damage band that grows fastest.

:func:`distance_to_boundary` and :func:`interior_triangles` build the
"away from the coast" masks of Girard et al. 2011 (statistics from elements more than
150 km from coasts).
"""
from dataclasses import dataclass

import numpy as np

from lagice.diagnostics._checks import as_points, as_triangles, positive, values_1d
from lagice.errors import ConfigError


@dataclass(frozen=True)
class FaultOrientations:
    """Result of :func:`fault_orientations`.

    Attributes
    ----------
    angles_deg : ndarray (k,)
        Directions of the strongest bands, degrees counter-clockwise from the
        x axis in [0, 180), strongest first.
    scores : ndarray (k,)
        Their scores S(θ): fraction of the total weight in the best strip.
    offsets_m : ndarray (k,)
        Position of the band along its normal ``(−sin θ, cos θ)`` (m): the band
        is the line ``−x sin θ + y cos θ = offset`` in the input coordinates.
    trial_angles_deg, trial_scores : ndarray
        S(θ) on the trial directions (for plots).
    strip_width_m : float
    """

    angles_deg: np.ndarray
    scores: np.ndarray
    offsets_m: np.ndarray
    trial_angles_deg: np.ndarray
    trial_scores: np.ndarray
    strip_width_m: float


def _best_strip(s, w, strip):
    """Largest strip weight of projections ``s`` (m) with weights ``w`` and its centre."""
    best, centre = -1.0, 0.0
    for shift in (0.0, 0.5):
        k = np.floor(s / strip + shift).astype(np.int64)
        k0 = k.min()
        sums = np.bincount(k - k0, weights=w)
        j = int(np.argmax(sums))
        if sums[j] > best:
            best, centre = float(sums[j]), (j + k0 + 0.5 - shift) * strip
    return best, centre


def fault_orientations(centroids_xy_m, weights, strip_width_m, n_faults=2, min_separation_deg=10.0,
                       angle_step_deg=0.25):
    """Directions of the strongest straight bands in a field at element centroids.

    Parameters
    ----------
    centroids_xy_m : array_like (m, 2)
        Sample positions (m), e.g. element centroids.
    weights : array_like (m,)
        Non-negative weights, e.g. ``damage · area`` or ``ε̇tot · area``.
    strip_width_m : float
        Width of the strips (m), about twice the element size.
    n_faults : int
        Number of directions returned (fewer if S has fewer local maxima).
    min_separation_deg : float
        Minimum angle between returned directions (degrees).
    angle_step_deg : float
        Step of the trial directions (degrees).

    Returns
    -------
    FaultOrientations
    """
    xy = as_points("centroids_xy_m", centroids_xy_m)
    w = values_1d("weights", weights, xy.shape[0])
    if np.any(w < 0):
        raise ConfigError(f"weights must be >= 0; found {int(np.sum(w < 0))} negative values (min {w.min():.3g})")
    total = float(w.sum())
    if not total > 0:
        raise ConfigError("weights sum to zero: no band to orient")
    strip = positive("strip_width_m", strip_width_m, "m")
    if int(n_faults) != n_faults or n_faults < 1:
        raise ConfigError(f"n_faults = {n_faults!r} must be an integer >= 1")
    sep = float(min_separation_deg)
    if not 0 <= sep < 90:
        raise ConfigError(f"min_separation_deg = {min_separation_deg!r} must be in [0, 90)")
    step = positive("angle_step_deg", angle_step_deg, "deg")
    keep = w > 0
    xy, w = xy[keep], w[keep]
    origin = xy.mean(axis=0)
    xy = xy - origin
    trial = np.arange(0.0, 180.0, step)
    rad = np.deg2rad(trial)
    scores = np.empty(trial.size)
    centres = np.empty(trial.size)
    for i, t in enumerate(rad):  # loop over ~720 directions, each vectorised over elements
        s = -xy[:, 0] * np.sin(t) + xy[:, 1] * np.cos(t)
        scores[i], centres[i] = _best_strip(s, w, strip)
    scores /= total
    # local maxima on the circle of directions (period 180°), strongest first
    left, right = np.roll(scores, 1), np.roll(scores, -1)
    peaks = np.flatnonzero((scores >= left) & (scores >= right))
    peaks = peaks[np.argsort(-scores[peaks], kind="stable")]
    chosen = []
    for p in peaks:
        d = [abs((trial[p] - trial[q] + 90.0) % 180.0 - 90.0) for q in chosen]
        if all(x >= sep for x in d):
            chosen.append(p)
        if len(chosen) == n_faults:
            break
    chosen = np.array(chosen, dtype=np.int64)
    angles, offsets = trial[chosen].copy(), centres[chosen].copy()
    for k in range(chosen.size):
        angles[k], offsets[k] = _refine(xy, w, angles[k], offsets[k], strip)
        t = np.deg2rad(angles[k])
        offsets[k] += -origin[0] * np.sin(t) + origin[1] * np.cos(t)
    return FaultOrientations(angles, scores[chosen], offsets, trial, scores, strip)


def _refine(xy, w, angle_deg, offset, strip, n_iter=3):
    """Direction of the weighted principal axis of the samples within half a
    strip of the line (a plateau of S(θ) is wider than the trial step when the
    band is narrower than the strip); a few fixed-point passes."""
    for _ in range(n_iter):
        t = np.deg2rad(angle_deg)
        s = -xy[:, 0] * np.sin(t) + xy[:, 1] * np.cos(t)
        near = np.abs(s - offset) <= 0.5 * strip
        if near.sum() < 3:
            break
        p, q = xy[near], w[near]
        c = np.average(p, axis=0, weights=q)
        d = p - c
        cov = (d * q[:, None]).T @ d
        vals, vecs = np.linalg.eigh(cov)
        v = vecs[:, 1]
        angle_deg = float(np.degrees(np.arctan2(v[1], v[0])) % 180.0)
        t = np.deg2rad(angle_deg)
        offset = float(-c[0] * np.sin(t) + c[1] * np.cos(t))
    return angle_deg, offset


def angle_to_axis_deg(band_angle_deg, axis_angle_deg=90.0):
    """Acute angle (0–90°) between band directions and an axis (default: the y axis)."""
    a = np.asarray(band_angle_deg, np.float64) - float(axis_angle_deg)
    return np.abs((a + 90.0) % 180.0 - 90.0)


def mohr_coulomb_fault_angle_deg(friction_coefficient):
    """Coulomb angle between a shear fault and the most compressive stress:
    ``45° − φ/2``, ``φ = atan μ`` (degrees; μ = 0.7 gives 27.5°)."""
    mu = positive("friction_coefficient", friction_coefficient)
    return 45.0 - 0.5 * float(np.degrees(np.arctan(mu)))


def damage_mode_fault_angle_deg(friction_coefficient, poisson_ratio=None, dilatancy_angle_deg=None):
    """Fault angle to the compression axis predicted by the most unstable damage band of a
    homogeneously damaged plate in uniaxial compression (degrees; docs/physics.md §4,
    "The damage band that grows fastest").

    A straight band of extra damage keeps the traction of the plate around it (σnn, σnt) and
    its strain along the band (εtt); a damage event in the band (a drop of its stiffness, or
    the stress correction, read as an inelastic strain εi) changes only the stress along the
    band, by −E′ εi,tt. The envelope q σ1 − σ2 in the band then grows in proportion to

        G(θ) ∝ (cos²θ − cos²θR) (cos²θC − cos²θ),

    θ the band's angle to the compression axis, θC = 45° − φ/2 (Coulomb: the envelope does
    not feel the stress along a band of that direction) and θR = 45° − ψ/2 (Roscoe: εi has
    no component along the band), tan φ = μ, sin ψ = (εi,1 + εi,2)/(εi,1 − εi,2) the
    dilatancy of the inelastic strain. G is largest half way between the two roots in
    cos²θ:

        cos 2θ* = (sin φ + sin ψ) / 2.

    Give ``poisson_ratio`` ν for the correction towards the origin (Dansereau et al. 2016,
    neXtSIM, lagice's explicit steppers): εi ∝ K⁻¹σ, so sin ψ = −(1 − ν)/(1 + ν) (it
    compacts); or ``dilatancy_angle_deg`` ψ for another path (ψ = φ, the associated return,
    gives the Coulomb angle). The approach, a linear stability analysis of the uniformly
    damaged state, is that of Dansereau, Démery, Berthier, Weiss and Ponson (2019,
    "Collective damage growth controls fault orientation in quasibrittle compressive
    failure", PRL 122); this closed form for lagice's envelope and plane stress is ours.
    """
    mu = float(friction_coefficient)
    if not np.isfinite(mu) or mu < 0.0:
        raise ConfigError(f"friction_coefficient = {friction_coefficient!r}: expected a finite value >= 0")
    if (poisson_ratio is None) == (dilatancy_angle_deg is None):
        raise ConfigError("damage_mode_fault_angle_deg: give exactly one of poisson_ratio (origin correction) "
                          "and dilatancy_angle_deg")
    if poisson_ratio is not None:
        nu = float(poisson_ratio)
        if not 0.0 <= nu < 1.0:
            raise ConfigError(f"poisson_ratio = {poisson_ratio!r}: expected 0 <= ν < 1 (plane stress)")
        sin_psi = -(1.0 - nu) / (1.0 + nu)
    else:
        psi = float(dilatancy_angle_deg)
        if not -90.0 <= psi <= 90.0:
            raise ConfigError(f"dilatancy_angle_deg = {dilatancy_angle_deg!r}: expected -90 to 90")
        sin_psi = float(np.sin(np.radians(psi)))
    sin_phi = float(np.sin(np.arctan(mu)))
    return 0.5 * float(np.degrees(np.arccos(0.5 * (sin_phi + sin_psi))))


def damage_mode_growth(theta_deg, friction_coefficient, sin_psi):
    """G(θ) of :func:`damage_mode_fault_angle_deg`, up to a positive factor: the change of
    the envelope q σ1 − σ2 inside a band at θ (degrees from the compression axis) per unit
    inelastic strain of the band, under σ = (0, −1) (x lateral, y the compression axis).
    Computed from the band's stress change, not from the closed form: δσtt = −εi,tt with
    εi = ((1 + sin ψ)/2, −(1 − sin ψ)/2) in the principal axes, and the envelope's
    derivative q sin²θ − cos²θ along the band."""
    t = np.radians(np.asarray(theta_deg, np.float64))
    mu = float(friction_coefficient)
    q = (np.sqrt(mu * mu + 1.0) + mu) ** 2
    e1, e2 = 0.5 * (1.0 + sin_psi), -0.5 * (1.0 - sin_psi)
    eps_tt = e1 * np.sin(t) ** 2 + e2 * np.cos(t) ** 2   # band direction t = (sin θ, cos θ)
    return -eps_tt * (q * np.sin(t) ** 2 - np.cos(t) ** 2)


def boundary_edges(triangles):
    """Edges (k, 2) used by exactly one triangle: the mesh boundary (coasts, open edges)."""
    tri = np.asarray(triangles, np.int64)
    e = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    key = np.sort(e, axis=1)
    _, inv, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    return e[counts[inv.ravel()] == 1]


def distance_to_boundary(nodes_xy_m, triangles, points_xy_m):
    """Distance (m) from points to the boundary of the mesh (all boundary edges)."""
    import shapely

    nodes = as_points("nodes_xy_m", nodes_xy_m)
    tri = as_triangles(triangles, nodes.shape[0])
    pts = as_points("points_xy_m", points_xy_m)
    edges = boundary_edges(tri)
    lines = shapely.multilinestrings(nodes[edges])
    return shapely.distance(shapely.points(pts), lines)


def interior_triangles(nodes_xy_m, triangles, buffer_m):
    """Boolean mask of triangles whose centroid lies at least ``buffer_m`` (m)
    from the mesh boundary (Girard et al. 2011: 150 km from coastlines and straits)."""
    nodes = as_points("nodes_xy_m", nodes_xy_m)
    tri = as_triangles(triangles, nodes.shape[0])
    b = float(buffer_m)
    if not (np.isfinite(b) and b >= 0):
        raise ConfigError(f"buffer_m = {buffer_m!r} m must be finite and >= 0")
    if b == 0:
        return np.ones(tri.shape[0], dtype=bool)
    centroids = nodes[tri].mean(axis=1)
    return distance_to_boundary(nodes, tri, centroids) >= b
