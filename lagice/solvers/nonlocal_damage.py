"""Damage regularised over a physical length: a nonlocal load ratio (issue 12 item 4).

In the local Maxwell-EB scheme of Dansereau et al. (2016) an element damages when *its
own* stress lies outside the Mohr-Coulomb envelope, so a crack is one element wide and
its path can follow the mesh. The nonlocal form here follows the integral-type damage
models of Pijaudier-Cabot and Bažant (1987, "Nonlocal damage theory", J. Eng. Mech. 113)
and the survey of Bažant and Jirásek (2002, "Nonlocal integral formulations of
plasticity and damage: survey of progress", J. Eng. Mech. 128): the quantity that drives
damage is averaged over a neighbourhood of fixed physical radius R before it is compared
with the threshold.

The driving quantity is the element's **load ratio**

    L_e = max(0, s1 / σT, (q s1 − s2) / σc),

s1 ≥ s2 the principal stresses (tension positive), σc = 2C/(√(μ²+1) − μ), σT = σc/q
(Dansereau et al. 2016 eqs. 3-6): L = 1 on the envelope, > 1 outside, and the local
critical factor is d_crit = min(1, 1/L) (their eq. 8 along the path to the origin). The
nonlocal ratio is

    L̄_e = Σ_j w_ej L_j,   w_ej = A_j φ(r_ej) / Σ_k A_k φ(r_ek),   φ(r) = (1 − r²/R²)² (r < R),

over the element centroids (the bell-shaped weight of Bažant and Jirásek 2002; the
element itself has φ = 1, so where no other centroid lies within R the scheme is the
local one). The element then damages with d̄_crit = min(1, 1/L̄_e) and its own stress is
scaled by the same factor f = 1 − min(1, Δt/td)(1 − d̄_crit) as in the local scheme.

What this changes: an element whose own stress is beyond the envelope but whose
neighbourhood is not keeps a super-critical stress (it damages only as fast as its share
of the neighbourhood's overload), and a neighbourhood that is overloaded as a whole
damages as a whole, so a crack is at least about R wide whatever the element size. A
uniformly loaded region behaves exactly as in the local scheme (the weights sum to 1).

The neighbourhood is taken in the current configuration at every outer step (the mesh
moves with the ice). Candidate pairs within R (1 + margin) are found with a k-d tree
and kept until some centroid has moved by more than half the margin, then recomputed;
each row is sorted by element index and pairs beyond R have weight exactly 0, so the
weights (and the run) do not depend on when the candidates were last found: a run
resumed from a checkpoint reproduces the uninterrupted one bit for bit.
"""
from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..errors import ConfigError

#: candidate pairs are found within R (1 + CANDIDATE_MARGIN); recomputed once a centroid has
#: moved by more than R CANDIDATE_MARGIN / 2 (then no pair can have come within R unseen)
CANDIDATE_MARGIN = 0.25


@njit(cache=True, parallel=True)
def _weights(ptr, idx, cx, cy, area, radius2, w, count):
    """Weights on the candidate rows (0 beyond R), normalised; count[e]: the nonzero ones."""
    for e in prange(len(ptr) - 1):
        s = 0.0
        n = 0
        for k in range(ptr[e], ptr[e + 1]):
            j = idx[k]
            dx = cx[j] - cx[e]
            dy = cy[j] - cy[e]
            r2 = dx * dx + dy * dy
            if r2 < radius2:
                t = 1.0 - r2 / radius2
                v = area[j] * t * t
                n += 1
            else:
                v = 0.0
            w[k] = v
            s += v
        for k in range(ptr[e], ptr[e + 1]):
            w[k] /= s
        count[e] = n


@njit(cache=True, parallel=True)
def _compact(ptr, idx, w, ptr_out, idx_out, w_out):
    """The nonzero entries of each row, in the same (column) order."""
    for e in prange(len(ptr) - 1):
        o = ptr_out[e]
        for k in range(ptr[e], ptr[e + 1]):
            if w[k] > 0.0:
                idx_out[o] = idx[k]
                w_out[o] = w[k]
                o += 1


class NonlocalWeights:
    """The averaging weights (CSR rows ``ptr``, ``idx``, ``w``) over element centroids for
    the radius ``radius_m`` [m] (module doc). :meth:`update` recomputes them for the current
    geometry; rows are sorted by element index and include the element itself."""

    def __init__(self, radius_m: float):
        if not radius_m > 0.0:
            raise ConfigError(f"rheology.damage_nonlocal_radius_m = {radius_m!r} must be > 0 m")
        self.radius_m = float(radius_m)
        self._tri = None
        self._ref = None
        self.ptr = self.idx = self.w = None
        self._cptr = self._cidx = self._cw = None
        #: how many times the candidate pairs were searched (a k-d tree query)
        self.n_searches = 0

    def _search(self, cx, cy) -> None:
        from scipy.spatial import cKDTree

        n = len(cx)
        pts = np.column_stack([cx, cy])
        pairs = cKDTree(pts).query_pairs(self.radius_m * (1.0 + CANDIDATE_MARGIN), output_type="ndarray")
        rows = np.concatenate([np.arange(n), pairs[:, 0], pairs[:, 1]])
        cols = np.concatenate([np.arange(n), pairs[:, 1], pairs[:, 0]])
        order = np.lexsort((cols, rows))
        rows, cols = rows[order], cols[order]
        self._cptr = np.zeros(n + 1, np.int64)
        np.cumsum(np.bincount(rows, minlength=n), out=self._cptr[1:])
        self._cidx = cols.astype(np.int32)
        self._cw = np.empty(len(cols), np.float64)
        self._ref = pts.copy()
        self.n_searches += 1

    def update(self, triangles: np.ndarray, nodes: np.ndarray, area: np.ndarray):
        """Weights for this geometry: returns ``(ptr, idx, w)``."""
        tri = np.asarray(triangles)
        xy = np.asarray(nodes, np.float64)
        cx = np.ascontiguousarray(xy[tri, 0].mean(axis=1))
        cy = np.ascontiguousarray(xy[tri, 1].mean(axis=1))
        if (self._tri is not tri or self._ref is None or len(self._ref) != len(cx)
                or float(np.max(np.hypot(cx - self._ref[:, 0], cy - self._ref[:, 1]), initial=0.0))
                > 0.5 * CANDIDATE_MARGIN * self.radius_m):
            self._search(cx, cy)
            self._tri = tri
        count = np.empty(len(cx), np.int64)
        _weights(self._cptr, self._cidx, cx, cy, np.ascontiguousarray(area, np.float64), self.radius_m ** 2, self._cw,
                 count)
        # the kernels read the nonzero entries only (a third of the candidates lie beyond R):
        # the same terms in the same order, so the same sums bit for bit
        self.ptr = np.zeros(len(cx) + 1, np.int64)
        np.cumsum(count, out=self.ptr[1:])
        self.idx = np.empty(self.ptr[-1], np.int32)
        self.w = np.empty(self.ptr[-1], np.float64)
        _compact(self._cptr, self._cidx, self._cw, self.ptr, self.idx, self.w)
        return self.ptr, self.idx, self.w

    def mean_neighbours(self) -> float:
        """Mean number of elements with a nonzero weight per row (the element included)."""
        if self.w is None:
            return 0.0
        return len(self.w) / (len(self.ptr) - 1)


def nonlocal_average(ptr, idx, w, field) -> np.ndarray:
    """Σ_j w_ej field_j per row (a helper for diagnostics and tests)."""
    field = np.asarray(field, np.float64)
    rows = np.repeat(np.arange(len(ptr) - 1), np.diff(ptr))
    return np.bincount(rows, weights=w * field[idx], minlength=len(ptr) - 1)
