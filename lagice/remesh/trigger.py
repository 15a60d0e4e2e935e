"""Remesh trigger (docs/design.md §5): which elements are too distorted.

An element is *bad* when any of these holds:

* one of its angles is below ``min_angle_deg`` (neXtSIM: 10°);
* it is near inversion: its area is below ``near_inversion`` × the area of
  an equilateral triangle of the target size at its centroid (this includes
  inverted elements), or the Lagrangian inversion guard flagged it;
* one of its interior edges is longer than ``length_factor`` × the target
  size or shorter than target / ``length_factor``.

When the trigger fires, the patch is seeded with the bad elements **and**
every element with an angle below ``min_angle_deg + seed_margin_deg``
(default 5°): elements about to become bad are fixed in the same event.

Elements with two or more edges on the domain boundary ("ears" at corners)
are exempt from the angle and length tests: their shape is fixed by boundary
nodes that remeshing keeps, so remeshing cannot improve them.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numba import njit

from ..errors import ConfigError, check_range
from ..mesh import Mesh

EQUILATERAL = np.sqrt(3.0) / 4.0


def evaluate_size(size_field, x, y) -> np.ndarray:
    """Target element size [m] at points (x, y): ``size_field`` is a positive
    number or a vectorised callable ``f(x, y) -> m``."""
    x = np.asarray(x, np.float64)
    if callable(size_field):
        s = np.broadcast_to(np.asarray(size_field(x, np.asarray(y, np.float64)), np.float64), x.shape)
    else:
        s = np.full(x.shape, float(size_field))
    if not np.all(np.isfinite(s) & (s > 0)):
        raise ConfigError("size_field returned a non-positive or non-finite element size [m]")
    return s


@dataclass(frozen=True)
class TriggerParams:
    """Thresholds of the remesh trigger (module docstring)."""

    min_angle_deg: float = 10.0
    near_inversion: float = 0.05
    length_factor: float = 3.0
    seed_margin_deg: float = 2.0

    def __post_init__(self):
        check_range("min_angle_deg", self.min_angle_deg, 0.0, 60.0, high_open=True, unit="deg")
        check_range("seed_margin_deg", self.seed_margin_deg, 0.0, 60.0 - self.min_angle_deg,
                    high_open=True, unit="deg")
        check_range("near_inversion", self.near_inversion, 0.0, 1.0, high_open=True)
        check_range("length_factor", self.length_factor, 1.0, None, low_open=True)


@dataclass
class TriggerResult:
    """Bad-element mask, how many elements each criterion caught, and the
    ``seeds`` of a remesh patch: the bad elements plus those with an angle
    below ``min_angle_deg + seed_margin_deg`` (about to become bad; remeshing
    them in the same event makes events fewer and larger)."""

    bad: np.ndarray
    counts: dict = field(default_factory=dict)
    min_angle_deg: float = 180.0
    seeds: np.ndarray | None = None

    @property
    def any(self) -> bool:
        return bool(self.bad.any())

    @property
    def elements(self) -> np.ndarray:
        return np.flatnonzero(self.bad)


def boundary_edge_counts(mesh: Mesh) -> np.ndarray:
    """(m, 3) bool: edge k (opposite vertex k) of each element lies on the domain
    boundary (:attr:`lagice.mesh.Mesh.edge_on_boundary`, cached on the mesh)."""
    return mesh.edge_on_boundary


@njit(cache=True)
def _trigger_kernel(nodes, tri, on_bnd, target, cos_thr, cos_seed, inv_coef, lf):
    """Per element: bit 1 angle, bit 2 near inversion, bit 4 edge length,
    bit 8 angle below the seed threshold; and the largest cosine of an angle
    over non-ear elements."""
    m = tri.shape[0]
    flags = np.zeros(m, np.int8)
    cmax_all = -1.0
    for e in range(m):
        x0, y0 = nodes[tri[e, 0], 0], nodes[tri[e, 0], 1]
        x1, y1 = nodes[tri[e, 1], 0], nodes[tri[e, 1], 1]
        x2, y2 = nodes[tri[e, 2], 0], nodes[tri[e, 2], 1]
        area = 0.5 * ((x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0))
        t = target[e]
        if area <= inv_coef * t * t:
            flags[e] |= 2
        nb = 0
        for k in range(3):
            if on_bnd[e, k]:
                nb += 1
        if nb >= 2:
            continue  # ear: fixed by boundary nodes
        # edge k opposite vertex k (scalars: arrays allocated per element cost ~70 % of the kernel)
        ex0, ey0 = x2 - x1, y2 - y1
        ex1, ey1 = x0 - x2, y0 - y2
        ex2, ey2 = x1 - x0, y1 - y0
        L0 = np.sqrt(ex0 * ex0 + ey0 * ey0)
        L1 = np.sqrt(ex1 * ex1 + ey1 * ey1)
        L2 = np.sqrt(ex2 * ex2 + ey2 * ey2)
        if ((not on_bnd[e, 0] and (L0 > lf * t or L0 < t / lf))
                or (not on_bnd[e, 1] and (L1 > lf * t or L1 < t / lf))
                or (not on_bnd[e, 2] and (L2 > lf * t or L2 < t / lf))):
            flags[e] |= 4
        # angle at vertex k between edges (k+1) and (k+2), pointing away from k
        cmax = -1.0
        den = L1 * L2
        c = 1.0 if den == 0.0 else -(ex1 * ex2 + ey1 * ey2) / den
        if c > cmax:
            cmax = c
        den = L2 * L0
        c = 1.0 if den == 0.0 else -(ex2 * ex0 + ey2 * ey0) / den
        if c > cmax:
            cmax = c
        den = L0 * L1
        c = 1.0 if den == 0.0 else -(ex0 * ex1 + ey0 * ey1) / den
        if c > cmax:
            cmax = c
        if cmax > cos_thr or area <= 0.0:
            flags[e] |= 1
        if cmax > cos_seed:
            flags[e] |= 8
        if area <= 0.0:
            cmax = 1.0
        if cmax > cmax_all:
            cmax_all = cmax
    return flags, cmax_all


def check_trigger(mesh: Mesh, size_field, params: TriggerParams | None = None,
                  flagged=None) -> TriggerResult:
    """Evaluate the trigger on ``mesh`` with target size ``size_field`` [m]
    (number or ``f(x, y)``); ``flagged``: extra element indices or mask (e.g.
    from the Lagrangian inversion guard)."""
    p = params or TriggerParams()
    nodes, tri = mesh.nodes, mesh.triangles
    if callable(size_field):
        cen = nodes[tri].mean(axis=1)
        target = evaluate_size(size_field, cen[:, 0], cen[:, 1])
    else:
        target = evaluate_size(size_field, np.zeros(len(tri)), np.zeros(len(tri)))
    on_bnd = mesh.edge_on_boundary
    flags, cmax = _trigger_kernel(nodes, tri, on_bnd, target, np.cos(np.radians(p.min_angle_deg)),
                                  np.cos(np.radians(p.min_angle_deg + p.seed_margin_deg)),
                                  p.near_inversion * EQUILATERAL, p.length_factor)
    by_angle = (flags & 1) != 0
    by_inv = (flags & 2) != 0
    by_len = (flags & 4) != 0
    if flagged is not None:
        f = np.asarray(flagged)
        fm = np.zeros(len(tri), bool)
        if f.dtype == bool:
            fm[:] = f
        else:
            fm[f.astype(np.int64)] = True
        by_inv |= fm
    bad = by_angle | by_inv | by_len
    seeds = bad | ((flags & 8) != 0)
    return TriggerResult(bad, {"angle": int(by_angle.sum()), "near_inversion": int(by_inv.sum()),
                               "edge_length": int(by_len.sum()), "total": int(bad.sum()),
                               "seeds": int(seeds.sum())},
                         float(np.degrees(np.arccos(min(1.0, max(-1.0, cmax))))), seeds)
