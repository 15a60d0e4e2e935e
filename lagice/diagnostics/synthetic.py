"""Synthetic triangular meshes and deformation fields for tests and demonstrations."""

import numpy as np

from lagice.diagnostics._checks import positive
from lagice.errors import check_range


def jittered_grid_mesh(nx, ny, length_x_m, length_y_m, jitter=0.2, seed=0):
    """Structured grid split into counter-clockwise triangles, interior nodes jittered.

    Parameters
    ----------
    nx, ny : int
        Number of cells along x and y (≥ 1).
    length_x_m, length_y_m : float
        Domain size (m); the domain is ``[0, length_x_m] × [0, length_y_m]``.
    jitter : float
        Interior nodes move by a uniform random offset in
        ``[−jitter, jitter]`` cell sizes per axis (0 ≤ jitter < 0.5 keeps
        every triangle counter-clockwise). Boundary nodes stay on the edges.
    seed : int
        Seed of ``numpy.random.default_rng``.

    Returns
    -------
    nodes_xy : ndarray (n, 2) float64 (m)
    triangles : ndarray (m, 3) int64
        Two triangles per cell, diagonal direction alternating like a chessboard.
    """
    nx = int(check_range("nx", nx, 1, None))
    ny = int(check_range("ny", ny, 1, None))
    lx = positive("length_x_m", length_x_m, "m")
    ly = positive("length_y_m", length_y_m, "m")
    jit = check_range("jitter", jitter, 0.0, 0.5, high_open=True)
    hx, hy = lx / nx, ly / ny
    ii, jj = np.meshgrid(np.arange(nx + 1), np.arange(ny + 1), indexing="xy")
    xy = np.stack([ii.ravel() * hx, jj.ravel() * hy], axis=-1)
    interior = ((ii > 0) & (ii < nx) & (jj > 0) & (jj < ny)).ravel()
    rng = np.random.default_rng(seed)
    xy[interior] += rng.uniform(-jit, jit, size=(int(interior.sum()), 2)) * np.array([hx, hy])
    ci, cj = np.meshgrid(np.arange(nx), np.arange(ny), indexing="xy")
    ci, cj = ci.ravel(), cj.ravel()
    n00 = cj * (nx + 1) + ci
    n10, n01, n11 = n00 + 1, n00 + nx + 1, n00 + nx + 2
    even = (ci + cj) % 2 == 0
    t1 = np.where(even[:, None], np.stack([n00, n10, n11], 1), np.stack([n00, n10, n01], 1))
    t2 = np.where(even[:, None], np.stack([n00, n11, n01], 1), np.stack([n10, n11, n01], 1))
    tri = np.concatenate([t1, t2]).astype(np.int64)
    return xy, tri


def slip_line_velocity(nodes_xy, spacing_m, jump_m_s, first_line_m=None, alternating=False):
    """x-velocity (m s-1) jumping by ``jump_m_s`` across horizontal lines ``y = y0 + k·spacing_m``.

    Nodes below the first line have ``u = 0``; each line crossed upwards adds
    ``+jump_m_s`` (or alternately ``+jump_m_s`` and ``−jump_m_s`` when
    ``alternating``). ``v = 0``. Default ``y0 = spacing_m / 2``.

    Returns
    -------
    ndarray (n, 2)
        Node velocities (m s-1).
    """
    s = positive("spacing_m", spacing_m, "m")
    y0 = 0.5 * s if first_line_m is None else float(first_line_m)
    n_crossed = np.floor((np.asarray(nodes_xy)[:, 1] - y0) / s).astype(np.int64) + 1
    n_crossed = np.maximum(n_crossed, 0)
    if alternating:
        u = jump_m_s * (n_crossed % 2)
    else:
        u = jump_m_s * n_crossed
    return np.stack([u, np.zeros_like(u)], axis=-1).astype(np.float64)
