"""Conservative remapping of element fields over a supermesh (docs/design.md §5).

Old and new triangles are intersected (candidate pairs from a numba
uniform bucket grid, intersection areas from a numba Sutherland–Hodgman
triangle clipper, :func:`intersect_triangles`; ``numba_celltree``'s
``intersect_faces`` is the alternative ``method="celltree"``, slower here,
see docs/remeshing.md). With
``w_ij`` the area of old element ``i`` ∩ new element ``j`` and
``S_j = Σ_i w_ij`` (= area of ``j`` to round-off), every element field is
transferred as a **convex combination**

    f_j = (Σ_i w_ij f_i) / S_j

which, per quantity, means:

* ice volume ``h·a``, ice area ``A·a`` and snow volume ``hs·a`` are
  extensive: ``h_j a_j = Σ_i h_i w_ij`` (to round-off, because ``a_j = S_j``),
  so totals are preserved to round-off (≈1e-15 relative) where old and new
  meshes cover the same region (always true here: the patch boundary is kept);
* damage, stress and cohesion are weighted by area (the same weights), so a
  constant field stays constant to round-off, and ``0 ≤ A, d ≤ 1`` hold
  without clipping (a convex combination of values in [0, 1] is in [0, 1]).

Nodal velocity is interpolated linearly (barycentric in the old mesh),
:func:`interpolate_nodal`.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..errors import MeshError


@njit(cache=True, inline="always")
def _cross(ax, ay, bx, by):
    return ax * by - ay * bx


@njit(cache=True)
def _clip_area(px, py, qx, qy):
    """Area of triangle p (CCW) ∩ triangle q (CCW), Sutherland–Hodgman.
    Coordinates are relative to a common origin close to both triangles."""
    bx = np.empty(12)
    by = np.empty(12)
    cx = np.empty(12)
    cy = np.empty(12)
    n = 3
    for k in range(3):
        bx[k] = px[k]
        by[k] = py[k]
    for e in range(3):
        ex0, ey0 = qx[e], qy[e]
        ex1, ey1 = qx[(e + 1) % 3], qy[(e + 1) % 3]
        dx, dy = ex1 - ex0, ey1 - ey0
        m = 0
        if n == 0:
            break
        sx, sy = bx[n - 1], by[n - 1]
        ds = _cross(dx, dy, sx - ex0, sy - ey0)
        for k in range(n):
            tx, ty = bx[k], by[k]
            dt = _cross(dx, dy, tx - ex0, ty - ey0)
            if dt >= 0.0:
                if ds < 0.0:
                    r = ds / (ds - dt)
                    cx[m] = sx + r * (tx - sx)
                    cy[m] = sy + r * (ty - sy)
                    m += 1
                cx[m] = tx
                cy[m] = ty
                m += 1
            elif ds >= 0.0:
                r = ds / (ds - dt)
                cx[m] = sx + r * (tx - sx)
                cy[m] = sy + r * (ty - sy)
                m += 1
            sx, sy, ds = tx, ty, dt
        n = m
        for k in range(n):
            bx[k] = cx[k]
            by[k] = cy[k]
    if n < 3:
        return 0.0
    a = 0.0
    for k in range(n):
        k1 = (k + 1) % n
        a += bx[k] * by[k1] - bx[k1] * by[k]
    return 0.5 * a


def _bboxes(nodes, tri):
    p = nodes[tri]
    return np.column_stack([p[:, :, 0].min(1), p[:, :, 0].max(1), p[:, :, 1].min(1), p[:, :, 1].max(1)])


@njit(cache=True, inline="always")
def _cell_range(bb, k, x0, y0, cell, nx, ny):
    """Grid cells (i0, i1, j0, j1), inclusive and clamped, overlapped by bounding box bb[k]."""
    return (min(max(int((bb[k, 0] - x0) / cell), 0), nx - 1), min(max(int((bb[k, 1] - x0) / cell), 0), nx - 1),
            min(max(int((bb[k, 2] - y0) / cell), 0), ny - 1), min(max(int((bb[k, 3] - y0) / cell), 0), ny - 1))


@njit(cache=True)
def _build_grid(bb, x0, y0, cell, nx, ny):
    """CSR bucket grid: triangle k (bbox bb[k]) is listed in every cell its box overlaps."""
    m = bb.shape[0]
    count = np.zeros(nx * ny + 1, np.int64)
    for k in range(m):
        i0, i1, j0, j1 = _cell_range(bb, k, x0, y0, cell, nx, ny)
        for j in range(j0, j1 + 1):
            for i in range(i0, i1 + 1):
                count[j * nx + i + 1] += 1
    ptr = np.cumsum(count)
    fill = ptr[:-1].copy()
    items = np.empty(ptr[-1], np.int64)
    for k in range(m):
        i0, i1, j0, j1 = _cell_range(bb, k, x0, y0, cell, nx, ny)
        for j in range(j0, j1 + 1):
            for i in range(i0, i1 + 1):
                items[fill[j * nx + i]] = k
                fill[j * nx + i] += 1
    return ptr, items


@njit(cache=True)
def _grid_intersect(nodes_a, tri_a, bba, nodes_b, tri_b, bbb, ptr, items, x0, y0, cell, nx, ny):
    """All pairs (i in a, j in b) with positive intersection area; serial and
    deterministic (pairs in order of j, then of i's first appearance in the grid)."""
    ma = tri_a.shape[0]
    cap = 8 * tri_b.shape[0] + 16
    oi = np.empty(cap, np.int64)
    oj = np.empty(cap, np.int64)
    oa = np.empty(cap)
    stamp = np.full(ma, -1, np.int64)
    px = np.empty(3)
    py = np.empty(3)
    qx = np.empty(3)
    qy = np.empty(3)
    n = 0
    for j in range(tri_b.shape[0]):
        i0, i1, j0, j1 = _cell_range(bbb, j, x0, y0, cell, nx, ny)
        tb = tri_b[j]
        ox, oy = nodes_b[tb[0], 0], nodes_b[tb[0], 1]
        for v in range(3):
            qx[v] = nodes_b[tb[v], 0] - ox
            qy[v] = nodes_b[tb[v], 1] - oy
        for cj in range(j0, j1 + 1):
            for ci in range(i0, i1 + 1):
                c = cj * nx + ci
                for q in range(ptr[c], ptr[c + 1]):
                    i = items[q]
                    if stamp[i] == j:
                        continue
                    stamp[i] = j
                    if (bba[i, 0] > bbb[j, 1] or bba[i, 1] < bbb[j, 0]
                            or bba[i, 2] > bbb[j, 3] or bba[i, 3] < bbb[j, 2]):
                        continue
                    ta = tri_a[i]
                    for v in range(3):
                        px[v] = nodes_a[ta[v], 0] - ox
                        py[v] = nodes_a[ta[v], 1] - oy
                    ar = _clip_area(px, py, qx, qy)
                    if ar > 0.0:
                        if n == cap:
                            cap *= 2
                            ni = np.empty(cap, np.int64)
                            nj = np.empty(cap, np.int64)
                            na = np.empty(cap)
                            ni[:n] = oi[:n]
                            nj[:n] = oj[:n]
                            na[:n] = oa[:n]
                            oi, oj, oa = ni, nj, na
                        oi[n] = i
                        oj[n] = j
                        oa[n] = ar
                        n += 1
    return oi[:n], oj[:n], oa[:n]


@njit(cache=True)
def _grid_locate(nodes, tri, points, ptr, items, x0, y0, cell, nx, ny):
    """Element of ``tri`` containing each point (the candidate with the largest
    smallest barycentric coordinate, so round-off outside still finds the best
    element) and the barycentric coordinates; -1 where no candidate exists."""
    p = points.shape[0]
    face = np.full(p, -1, np.int64)
    lam = np.zeros((p, 3))
    for k in range(p):
        x, y = points[k, 0], points[k, 1]
        ci = min(max(int((x - x0) / cell), 0), nx - 1)
        cj = min(max(int((y - y0) / cell), 0), ny - 1)
        c = cj * nx + ci
        best = -np.inf
        for q in range(ptr[c], ptr[c + 1]):
            e = items[q]
            a, b, d = tri[e, 0], tri[e, 1], tri[e, 2]
            det = ((nodes[b, 0] - nodes[a, 0]) * (nodes[d, 1] - nodes[a, 1])
                   - (nodes[d, 0] - nodes[a, 0]) * (nodes[b, 1] - nodes[a, 1]))
            l1 = ((x - nodes[a, 0]) * (nodes[d, 1] - nodes[a, 1])
                  - (nodes[d, 0] - nodes[a, 0]) * (y - nodes[a, 1])) / det
            l2 = ((nodes[b, 0] - nodes[a, 0]) * (y - nodes[a, 1])
                  - (x - nodes[a, 0]) * (nodes[b, 1] - nodes[a, 1])) / det
            l0 = 1.0 - l1 - l2
            mn = min(l0, min(l1, l2))
            if mn > best:
                best = mn
                face[k] = e
                lam[k, 0] = l0
                lam[k, 1] = l1
                lam[k, 2] = l2
    return face, lam


class _Grid:
    """Uniform bucket grid over the bounding boxes of a triangulation."""

    def __init__(self, nodes, tri):
        self.bb = np.ascontiguousarray(_bboxes(nodes, tri))
        x0, x1 = self.bb[:, 0].min(), self.bb[:, 1].max()
        y0, y1 = self.bb[:, 2].min(), self.bb[:, 3].max()
        ext = max(x1 - x0, y1 - y0, 1e-300)
        mean_box = max(float(np.mean(np.maximum(self.bb[:, 1] - self.bb[:, 0],
                                                self.bb[:, 3] - self.bb[:, 2]))), ext * 1e-6)
        cell = max(mean_box, ext / 2048.0)
        self.x0, self.y0, self.cell = float(x0), float(y0), float(cell)
        self.nx = int((x1 - x0) / cell) + 1
        self.ny = int((y1 - y0) / cell) + 1
        self.ptr, self.items = _build_grid(self.bb, self.x0, self.y0, self.cell, self.nx, self.ny)


#: above this many new elements, ``method="auto"`` uses numba_celltree (parallel)
AUTO_CELLTREE_MIN = 100_000


def intersect_triangles(nodes_old, tri_old, nodes_new, tri_new, method: str = "auto"):
    """Supermesh of two triangulations: ``(i_old, j_new, area)`` for every
    pair with positive intersection area [m²], sorted by (j_new, i_old).

    ``method="clip"``: a numba uniform bucket grid for candidate pairs + numba
    Sutherland–Hodgman clipping, serial (fastest for patches and up to ~10⁵
    elements, docs/remeshing.md); ``method="celltree"``:
    ``numba_celltree.CellTree2d.intersect_faces`` (parallel; faster for global
    remeshes of ~2·10⁵ elements on 2 cores); ``"auto"`` picks ``"clip"`` below
    :data:`AUTO_CELLTREE_MIN` new elements. Both are deterministic.
    """
    if method == "auto":
        method = "clip" if len(tri_new) < AUTO_CELLTREE_MIN else "celltree"
    nodes_old = np.ascontiguousarray(nodes_old, np.float64)
    nodes_new = np.ascontiguousarray(nodes_new, np.float64)
    tri_old = np.ascontiguousarray(tri_old, np.int64)
    tri_new = np.ascontiguousarray(tri_new, np.int64)
    if len(tri_old) == 0 or len(tri_new) == 0:
        z = np.zeros(0, np.int64)
        return z, z, np.zeros(0)
    if method == "celltree":
        from numba_celltree import CellTree2d

        tree = CellTree2d(nodes_old, tri_old, -1)
        j, i, area = tree.intersect_faces(nodes_new, tri_new, -1)
        i = np.asarray(i, np.int64)
        j = np.asarray(j, np.int64)
        area = np.asarray(area, np.float64)
    elif method == "clip":
        g = _Grid(nodes_old, tri_old)
        bbn = np.ascontiguousarray(_bboxes(nodes_new, tri_new))
        i, j, area = _grid_intersect(nodes_old, tri_old, g.bb, nodes_new, tri_new, bbn, g.ptr, g.items,
                                     g.x0, g.y0, g.cell, g.nx, g.ny)
    else:
        raise ValueError(f"method = {method!r}; expected 'clip' or 'celltree'")
    keep = area > 0.0
    i, j, area = i[keep], j[keep], area[keep]
    order = np.lexsort((i, j))
    return i[order], j[order], area[order]


def remap_weights(i_old, j_new, area, n_new: int, new_areas=None, rtol: float = 1e-8) -> np.ndarray:
    """Denominators ``S_j = Σ_i w_ij`` of :func:`remap_field`; checks that every
    new element is covered (``S_j`` = its area within ``rtol``) when
    ``new_areas`` is given."""
    S = np.bincount(j_new, weights=area, minlength=n_new)
    if np.any(S <= 0):
        raise MeshError(f"{int(np.sum(S <= 0))} new elements do not overlap any old element")
    if new_areas is not None:
        err = np.abs(S - new_areas) / new_areas
        if err.max() > rtol:
            raise MeshError(f"supermesh covers new element {int(err.argmax())} only to relative "
                            f"{err.max():.3g} of its area; old and new meshes cover different regions")
    return S


def remap_field(values_old, i_old, j_new, area, S) -> np.ndarray:
    """Convex combination ``f_j = (Σ_i w_ij f_i) / S_j`` of an element field
    ((m_old,) or (m_old, k)); ``area`` = w_ij, ``S`` from :func:`remap_weights`.

    Numerator and ``S`` are summed in the same order (``np.bincount``), and
    rounding is monotone, so ``0 ≤ f_i ≤ 1`` for all ``i`` gives
    ``0 ≤ f_j ≤ 1`` exactly (a field equal to 1 stays exactly 1)."""
    v = np.asarray(values_old, np.float64)
    n_new = len(S)
    if v.ndim == 1:
        return np.bincount(j_new, weights=area * v[i_old], minlength=n_new) / S
    out = np.empty((n_new, v.shape[1]))
    for c in range(v.shape[1]):
        out[:, c] = np.bincount(j_new, weights=area * v[i_old, c], minlength=n_new) / S
    return out


def interpolate_nodal(nodes_old, tri_old, values_old, points) -> np.ndarray:
    """Linear (barycentric) interpolation of nodal values ((n_old,) or (n_old, k))
    of the old mesh at ``points`` (p, 2). A point outside the old mesh by
    round-off takes the nearest candidate element, with barycentric
    coordinates clamped to [0, 1]."""
    nodes_old = np.ascontiguousarray(nodes_old, np.float64)
    tri_old = np.ascontiguousarray(tri_old, np.int64)
    points = np.ascontiguousarray(points, np.float64)
    vals = np.asarray(values_old, np.float64)
    if len(points) == 0:
        return np.zeros((0,) + vals.shape[1:])
    g = _Grid(nodes_old, tri_old)
    face, lam = _grid_locate(nodes_old, tri_old, points, g.ptr, g.items, g.x0, g.y0, g.cell, g.nx, g.ny)
    miss = face < 0
    if miss.any():
        cen = nodes_old[tri_old].mean(axis=1)
        for q in np.flatnonzero(miss):
            face[q] = int(np.argmin(np.sum((cen - points[q]) ** 2, axis=1)))
            lam[q] = 1.0 / 3.0
    out_ = lam.min(axis=1) < 0
    if out_.any():
        lam[out_] = np.clip(lam[out_], 0.0, 1.0)
        lam[out_] /= lam[out_].sum(axis=1, keepdims=True)
    v = vals[tri_old[face]]  # (p, 3, ...)
    if vals.ndim == 1:
        return np.sum(lam * v, axis=1)
    return np.einsum("pk,pkc->pc", lam, v)


def locate_points(nodes, tri, points) -> np.ndarray:
    """Index of the triangle containing each point (the best candidate for points
    on edges or outside by round-off; -1 where no triangle is near)."""
    nodes = np.ascontiguousarray(nodes, np.float64)
    tri = np.ascontiguousarray(tri, np.int64)
    points = np.ascontiguousarray(points, np.float64)
    g = _Grid(nodes, tri)
    face, _ = _grid_locate(nodes, tri, points, g.ptr, g.items, g.x0, g.y0, g.cell, g.nx, g.ny)
    return face
