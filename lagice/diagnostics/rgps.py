"""The model as RGPS would see it: an observation operator for deformation statistics.

RGPS deformation is not the ice's deformation: it is computed from points tracked
between SAR images. The points start on a grid of 10 km squares (Kwok 1998), each cell's
velocity gradient is the line integral of the corner velocities around it, and every
tracked displacement carries an error of about 100 m, which gives error standard
deviations of about 0.5 % day⁻¹ in the divergence, shear and vorticity of a 10 km
cell over 3 days (Lindsay and Stern 2003, "The RADARSAT geophysical processor system:
quality of sea ice trajectory and deformation estimates", J. Atmos. Oceanic Technol. 20;
quoted by Girard 2010, "Modélisation du comportement mécanique de la glace de mer",
§2.2). The error is largest at the cell scale and falls with the box size, so it adds to
both the mean rate at 10 km and to β; comparing a noise-free model with RGPS compares
two different things.

:func:`rgps_cells` applies that operator to one window of model output:

1. a square grid of points with spacing ``cell_m`` (default 10 km) over the elements
   given, at the window start; only cells whose four corners lie in those elements are
   kept;
2. each point moves with the model: its end position is the P1 interpolation of the
   model's node end positions in the element that holds it at the start (a material
   point of the ice, as an RGPS point is);
3. each end position gets an independent Gaussian error of ``tracking_error_m`` per
   component (default 100 m), from a seeded generator;
4. each cell's gradient is the line integral around its four corners (computed as the
   area-weighted mean of its two triangles, which is the same thing by Green's
   theorem), on the mid-window geometry as for the model's elements.

The cells' rates then go through the same statistics as the model's elements
(:func:`lagice.diagnostics.report.rate_statistics`). For a square cell the trapezoid
line integral gives ``std(ε̇I) = sqrt(2) σ / (L Δt)``: 0.0047 day⁻¹ for σ = 100 m,
L = 10 km, Δt = 3 days (tested), the 0.5 % day⁻¹ of Lindsay and Stern (2003). Box
gradients are line integrals around the box, so pure tracking noise falls as
L^−1.5 (β = 1.5, tested).

This is a diagnostic of the comparison, not of the model: it changes nothing in a run.
docs/diagnostics.md §"The model as RGPS would see it".
"""
from __future__ import annotations

import math

import numpy as np

from lagice.diagnostics._checks import as_points, as_triangles, positive
from lagice.diagnostics.strain import ElementStrainRates, _lagrangian
from lagice.errors import ConfigError

#: side of an RGPS Lagrangian cell at the start (m) (Kwok 1998; Girard 2010 §2.2)
RGPS_CELL_M = 10e3
#: RGPS tracking error of a displacement (m), per component (Lindsay and Stern 2003,
#: quoted by Girard 2010 §2.2: 0.5 % day⁻¹ error std in divergence, shear and vorticity)
RGPS_TRACKING_ERROR_M = 100.0


def rgps_cells(nodes_xy0, nodes_xy1, triangles, dt_s, *, cell_m=RGPS_CELL_M, tracking_error_m=RGPS_TRACKING_ERROR_M,
               seed=0, origin_xy_m=None):
    """RGPS-like cells and their velocity gradients from one window of model output.

    Args:
        nodes_xy0, nodes_xy1: (n, 2) model node positions [m] at the window start and end.
        triangles: (m, 3) counter-clockwise elements over which cells are laid (e.g. the
            interior elements followed through the window).
        dt_s: window length [s].
        cell_m: cell side [m] at the start (RGPS: 10 km).
        tracking_error_m: standard deviation [m] of the Gaussian error added to each
            component of each point's end position (RGPS: 100 m); 0 for none.
        seed: seed of the error generator, an int or a sequence of ints (the same seed
            gives the same errors).
        origin_xy_m: a corner of the point grid [m]; default the lower-left corner of
            the elements' bounding box.

    Returns ``(rates, info)``: an :class:`ElementStrainRates` with one entry per cell
    (gradient [s-1], area [m²] and centroid [m] in the mid-window geometry, bounds of
    the cell corners) and ``info`` = ``{"n_cells", "n_cells_folded", "cell_m", "tracking_error_m",
    "seed", "origin_xy_m", "points_xy0", "points_xy1", "cells"}`` (corner indices, (k, 4),
    counter-clockwise; cells folded over the window are dropped and counted, :func:`observe`).
    Raises :class:`~lagice.errors.ConfigError` naming the argument
    for a bad value, or when no cell fits in the elements."""
    from lagice.drifters import locate

    x0 = as_points("nodes_xy0", nodes_xy0)
    x1 = as_points("nodes_xy1", nodes_xy1, x0.shape[0])
    tri = as_triangles(triangles, x0.shape[0])
    dt = positive("dt_s", dt_s, "s")
    cell = positive("cell_m", cell_m, "m")
    if not (math.isfinite(tracking_error_m) and tracking_error_m >= 0.0):
        raise ConfigError(f"tracking_error_m = {tracking_error_m!r}: expected a standard deviation >= 0 m "
                          f"(RGPS: {RGPS_TRACKING_ERROR_M:g} m)")
    used = np.unique(tri)
    lo = x0[used].min(axis=0) if origin_xy_m is None else np.asarray(origin_xy_m, np.float64).reshape(2)
    hi = x0[used].max(axis=0)
    nx, ny = (np.floor((hi - lo) / cell).astype(np.int64) + 1)
    if nx < 2 or ny < 2:
        raise ConfigError(f"cell_m = {cell:g} m: the elements span {hi[0] - lo[0]:.0f} x {hi[1] - lo[1]:.0f} m, "
                          f"less than one cell")
    gx, gy = np.meshgrid(lo[0] + cell * np.arange(nx), lo[1] + cell * np.arange(ny), indexing="ij")
    pts0 = np.column_stack([gx.ravel(), gy.ravel()])
    elem, w = locate(pts0, x0, tri)
    inside = (elem >= 0).reshape(nx, ny)
    # cells (i, j) with all four corners inside, corners counter-clockwise
    ok = inside[:-1, :-1] & inside[1:, :-1] & inside[1:, 1:] & inside[:-1, 1:]
    ii, jj = np.nonzero(ok)
    if ii.size == 0:
        raise ConfigError(f"cell_m = {cell:g} m: no cell has its four corners inside the {tri.shape[0]} elements")
    idx = np.arange(nx * ny).reshape(nx, ny)
    cells = np.column_stack([idx[ii, jj], idx[ii + 1, jj], idx[ii + 1, jj + 1], idx[ii, jj + 1]])
    # points of the kept cells only, renumbered
    keep = np.unique(cells)
    new = np.full(nx * ny, -1, np.int64)
    new[keep] = np.arange(keep.size)
    cells = new[cells]
    e, wk = elem[keep], w[keep]
    p0 = pts0[keep]
    p1 = p0 + np.einsum("kj,kjc->kc", wk, (x1 - x0)[tri[e]])
    truth = {"n_cells": int(cells.shape[0]), "cell_m": cell, "tracking_error_m": 0.0, "seed": None,
             "origin_xy_m": [float(lo[0]), float(lo[1])], "points_xy0": p0, "points_xy1": p1, "cells": cells}
    return observe(truth, dt, tracking_error_m, seed)


def observe(cells_info: dict, dt_s, tracking_error_m=RGPS_TRACKING_ERROR_M, seed=0):
    """The cells of an error-free :func:`rgps_cells` result (``tracking_error_m = 0``) seen
    with another tracking error: ``(rates, info)`` as :func:`rgps_cells` with that error and
    seed returns them, without laying and locating the grid again (steps 3 and 4 of the
    module doc). A cell either of whose two triangles is inverted in the mid-window geometry
    (the points' displacement folds it; a fixed mesh whose nodes are carried by a sheared
    velocity can do that) has no strain rate: it is dropped, and counted in ``info``'s
    ``n_cells_folded`` (``n_cells``: the cells kept); all folded is an error."""
    if cells_info["tracking_error_m"] != 0.0:
        raise ConfigError(f"observe: the cells already carry a {cells_info['tracking_error_m']:g} m tracking error; "
                          f"pass the result of rgps_cells(..., tracking_error_m=0)")
    if not (math.isfinite(tracking_error_m) and tracking_error_m >= 0.0):
        raise ConfigError(f"tracking_error_m = {tracking_error_m!r}: expected a standard deviation >= 0 m "
                          f"(RGPS: {RGPS_TRACKING_ERROR_M:g} m)")
    dt = positive("dt_s", dt_s, "s")
    p0, p1, cells = cells_info["points_xy0"], cells_info["points_xy1"], cells_info["cells"]
    if tracking_error_m > 0.0:
        p1 = p1 + np.random.default_rng(seed).normal(0.0, tracking_error_m, p1.shape)
    folded = _folded_cells(p0, p1, cells)
    n_folded = int(folded.sum())
    if n_folded:  # a cell whose mid-window geometry is inverted has no strain rate: dropped, counted
        if n_folded == cells.shape[0]:
            raise ConfigError(f"every one of the {n_folded} cells is inverted in its mid-window geometry (the "
                              f"points' displacement over the window folds them)")
        cells = cells[~folded]
    halves = np.concatenate([cells[:, [0, 1, 2]], cells[:, [0, 2, 3]]])
    r = _lagrangian(p0, p1, halves, dt, "mid")
    k = cells.shape[0]
    a = r.area_m2.reshape(2, k)
    area = a.sum(axis=0)
    grad = (r.gradient_s.reshape(2, k, 2, 2) * a[..., None, None]).sum(axis=0) / area[:, None, None]
    cen = (r.centroid_xy_m.reshape(2, k, 2) * a[..., None]).sum(axis=0) / area[:, None]
    rates = ElementStrainRates(grad, area, cen, r.bounds_m)
    info = {**cells_info, "tracking_error_m": float(tracking_error_m),
            "seed": seed if np.isscalar(seed) else [int(v) for v in seed], "points_xy1": p1,
            "cells": cells, "n_cells": int(cells.shape[0]),
            "n_cells_folded": int(cells_info.get("n_cells_folded", 0)) + n_folded}
    return rates, info


def _folded_cells(p0, p1, cells):
    """(k,) bool: cells either of whose two triangles (0, 1, 2) and (0, 2, 3) has a non-positive
    area in the mid-window geometry (0.5 (p0 + p1)), where :func:`observe` takes its gradient."""
    mid = 0.5 * (p0 + p1)
    out = np.zeros(cells.shape[0], bool)
    for a, b, c in ((0, 1, 2), (0, 2, 3)):  # the two halves (not a loop over cells)
        pa, pb, pc = mid[cells[:, a]], mid[cells[:, b]], mid[cells[:, c]]
        cross = (pb[:, 0] - pa[:, 0]) * (pc[:, 1] - pa[:, 1]) - (pb[:, 1] - pa[:, 1]) * (pc[:, 0] - pa[:, 0])
        out |= ~(cross > 0.0)
    return out
