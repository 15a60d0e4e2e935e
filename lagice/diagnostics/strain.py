"""Per-triangle velocity gradients and strain-rate invariants.

Conventions (Girard et al. 2011 eqs. 10 and 15; Girard 2010 eqs. 2.1–2.3 and 3.15–3.16):

    ε̇xx = ∂u/∂x,   ε̇yy = ∂v/∂y,   ε̇xy = (∂u/∂y + ∂v/∂x) / 2
    divergence   ε̇I   = ε̇xx + ε̇yy                                   (s-1)
    max. shear   ε̇II  = sqrt((ε̇xx − ε̇yy)² + (2 ε̇xy)²)
                      = sqrt((∂u/∂x − ∂v/∂y)² + (∂u/∂y + ∂v/∂x)²)   (s-1)
    total        ε̇tot = sqrt(ε̇I² + ε̇II²)                            (s-1)
    vorticity    ζ    = ∂v/∂x − ∂u/∂y                                 (s-1)

ε̇II is twice the maximum shear-strain rate of the tensor ε̇ (the RGPS
"shear", Kwok 1998), i.e. the difference of the principal strain rates.

On a P1 triangle the velocity is linear, so its gradient is constant and equals
the line integral ``(1/A) ∮ u n ds`` around the triangle used for RGPS cells
(Girard 2010 §2.2). Gradients are therefore exact (to round-off) for any affine
velocity field on any mesh.

Lagrangian (RGPS-like) rates use node displacements over a window Δt:
``u = (x1 − x0)/Δt``; the gradient is taken on the triangle geometry at the
window start (``geometry="start"``), end (``"end"``) or, by default, at the
mid-window positions ``(x0 + x1)/2`` (``"mid"``). For a steady linear flow
``ẋ = G x`` the start-geometry estimate is ``(e^{GΔt} − I)/Δt = G + G²Δt/2 + …``
(first order in Δt) while the mid-geometry estimate is
``(2/Δt) tanh(GΔt/2) = G − G³Δt²/12 + …`` (second order), which is why "mid"
is the default. For an affine map ``x1 = x0 + Δt (G x0 + c)`` "start" is exact.
"""

from dataclasses import dataclass

import numpy as np

from lagice.diagnostics._checks import as_points, as_triangles, choice, positive
from lagice.errors import ConfigError

GEOMETRIES = ("start", "mid", "end")


@dataclass(frozen=True)
class ElementStrainRates:
    """Velocity gradient and geometry of each triangle (structure of arrays).

    Attributes
    ----------
    gradient_s : ndarray (m, 2, 2)
        ``[[∂u/∂x, ∂u/∂y], [∂v/∂x, ∂v/∂y]]`` in s-1.
    area_m2 : ndarray (m,)
        Triangle area (m²) in the geometry the gradient was computed on.
    centroid_xy_m : ndarray (m, 2)
        Triangle centroid (m) in that geometry.
    bounds_m : ndarray (4,) or None
        ``(x_min, y_min, x_max, y_max)`` of the nodes in that geometry (m).
    """

    gradient_s: np.ndarray
    area_m2: np.ndarray
    centroid_xy_m: np.ndarray
    bounds_m: np.ndarray = None

    @property
    def divergence_s(self):
        """ε̇I = ∂u/∂x + ∂v/∂y (s-1), signed (positive = opening)."""
        return divergence_rate(self.gradient_s)

    @property
    def shear_s(self):
        """ε̇II = sqrt((∂u/∂x − ∂v/∂y)² + (∂u/∂y + ∂v/∂x)²) (s-1)."""
        return shear_rate(self.gradient_s)

    @property
    def total_s(self):
        """ε̇tot = sqrt(ε̇I² + ε̇II²) (s-1)."""
        return total_deformation_rate(self.gradient_s)

    @property
    def vorticity_s(self):
        """ζ = ∂v/∂x − ∂u/∂y (s-1)."""
        return self.gradient_s[..., 1, 0] - self.gradient_s[..., 0, 1]


def divergence_rate(gradient_s):
    """Divergence ε̇I = ∂u/∂x + ∂v/∂y (s-1) of gradients of shape (..., 2, 2).

    Girard et al. 2011 eq. 10, Girard 2010 eq. 2.1.
    """
    g = np.asarray(gradient_s, dtype=np.float64)
    return g[..., 0, 0] + g[..., 1, 1]


def shear_rate(gradient_s):
    """Maximum shear rate ε̇II (s-1) of gradients of shape (..., 2, 2).

    ε̇II = sqrt((∂u/∂x − ∂v/∂y)² + (∂u/∂y + ∂v/∂x)²) (Girard 2010 eq. 2.2,
    Girard et al. 2011 eq. 10 with ε̇xy = (∂u/∂y + ∂v/∂x)/2).
    """
    g = np.asarray(gradient_s, dtype=np.float64)
    return np.hypot(g[..., 0, 0] - g[..., 1, 1], g[..., 0, 1] + g[..., 1, 0])


def total_deformation_rate(gradient_s):
    """Total deformation rate ε̇tot = sqrt(ε̇I² + ε̇II²) (s-1) (Girard et al. 2011 §RGPS)."""
    return np.hypot(divergence_rate(gradient_s), shear_rate(gradient_s))


def symmetric_gradient(strain_rate_s):
    """The gradient ``[[ε̇xx, ε̇xy], [ε̇xy, ε̇yy]]`` (m, 2, 2) [s-1] of a strain rate (m, 3)
    (ε̇xx, ε̇yy, ε̇xy, tensor shear component): it has the strain rate's divergence and maximum
    shear (no vorticity), so the estimators of :class:`ElementStrainRates` apply to a strain rate
    the model gives per element (the rheology's, ``output.accumulate_strain``)."""
    e = np.asarray(strain_rate_s, np.float64)
    grad = np.empty((e.shape[0], 2, 2))
    grad[:, 0, 0], grad[:, 1, 1] = e[:, 0], e[:, 1]
    grad[:, 0, 1] = grad[:, 1, 0] = e[:, 2]
    return grad


def triangle_geometry(nodes_xy, triangles):
    """Signed areas (m²) and centroids (m) of triangles; arrays may have leading batch dims.

    Parameters
    ----------
    nodes_xy : ndarray (..., n, 2)
        Node positions (m).
    triangles : ndarray (m, 3) int
        Node indices, counter-clockwise.

    Returns
    -------
    area_m2 : ndarray (..., m)
        Signed area, positive for counter-clockwise triangles.
    centroid_xy_m : ndarray (..., m, 2)
    """
    p = nodes_xy[..., triangles, :]  # (..., m, 3, 2)
    e1 = p[..., 1, :] - p[..., 0, :]
    e2 = p[..., 2, :] - p[..., 0, :]
    area = 0.5 * (e1[..., 0] * e2[..., 1] - e1[..., 1] * e2[..., 0])
    return area, p.mean(axis=-2)


def _p1_gradient(nodes_xy, triangles, nodes_uv):
    """Constant gradient of the P1 interpolant of ``nodes_uv`` on each triangle.

    Broadcasts over leading batch dimensions of ``nodes_xy`` and ``nodes_uv``.
    Returns ``(gradient (..., m, 2, 2), signed area (..., m), centroid (..., m, 2))``.
    """
    p = nodes_xy[..., triangles, :]  # (..., m, 3, 2)
    w = nodes_uv[..., triangles, :]  # (..., m, 3, 2)
    x, y = p[..., 0], p[..., 1]
    # b_i = y_j − y_k, c_i = x_k − x_j for (i, j, k) cyclic: ∇φ_i = (b_i, c_i) / (2A)
    b = np.stack([y[..., 1] - y[..., 2], y[..., 2] - y[..., 0], y[..., 0] - y[..., 1]], axis=-1)
    c = np.stack([x[..., 2] - x[..., 1], x[..., 0] - x[..., 2], x[..., 1] - x[..., 0]], axis=-1)
    two_area = (x[..., 1] - x[..., 0]) * (y[..., 2] - y[..., 0]) - (x[..., 2] - x[..., 0]) * (y[..., 1] - y[..., 0])
    grad = np.empty(two_area.shape + (2, 2))
    with np.errstate(divide="ignore", invalid="ignore"):
        for comp in range(2):  # u then v (loop over 2 components, not elements)
            grad[..., comp, 0] = np.sum(w[..., comp] * b, axis=-1) / two_area
            grad[..., comp, 1] = np.sum(w[..., comp] * c, axis=-1) / two_area
    return grad, 0.5 * two_area, p.mean(axis=-2)


def _require_positive_area(area, name):
    bad = ~(area > 0.0)
    if np.any(bad):
        idx = np.unravel_index(int(np.flatnonzero(bad.ravel())[0]), area.shape)
        raise ConfigError(
            f"{int(bad.sum())} triangle(s) have non-positive area in {name} (first: element "
            f"{idx[-1]}, area {float(area[idx]):.6g} m2); triangles must be counter-clockwise and not inverted"
        )


def velocity_gradients(nodes_xy, triangles, nodes_uv):
    """Per-triangle velocity gradients from instantaneous node velocities.

    Parameters
    ----------
    nodes_xy : array_like (n, 2)
        Node positions (m).
    triangles : array_like (m, 3) int
        Counter-clockwise node indices.
    nodes_uv : array_like (n, 2)
        Node velocities (m s-1).

    Returns
    -------
    ElementStrainRates
        Gradients (s-1), areas (m²) and centroids (m) on ``nodes_xy``.
    """
    xy = as_points("nodes_xy", nodes_xy)
    tri = as_triangles(triangles, xy.shape[0])
    uv = as_points("nodes_uv", nodes_uv, xy.shape[0])
    grad, area, cen = _p1_gradient(xy, tri, uv)
    _require_positive_area(area, "nodes_xy")
    return ElementStrainRates(grad, area, cen, _bounds(xy))


def lagrangian_velocity_gradients(nodes_xy0, nodes_xy1, triangles, dt_s, geometry="mid"):
    """Per-triangle velocity gradients from node displacements over a window (RGPS-like).

    The node velocity is ``(nodes_xy1 − nodes_xy0) / dt_s`` and its P1 gradient
    is evaluated on the triangle geometry at the window start, end or middle
    (Girard 2010 §2.2 and §3.5: gradients of the displacement rate over an
    interval; see the module docstring for the accuracy of each choice).

    Parameters
    ----------
    nodes_xy0, nodes_xy1 : array_like (n, 2)
        Node positions (m) at the start and end of the window.
    triangles : array_like (m, 3) int
        Counter-clockwise node indices (fixed connectivity over the window).
    dt_s : float
        Window length (s), > 0.
    geometry : {"mid", "start", "end"}
        Positions on which the gradient is computed; default "mid" = (x0 + x1)/2.

    Returns
    -------
    ElementStrainRates
        Gradients (s-1), areas (m²) and centroids (m) in the chosen geometry.

    Raises
    ------
    ConfigError
        Mismatched shapes, ``dt_s <= 0``, unknown geometry, or a triangle with
        non-positive area in the chosen geometry.
    """
    x0 = as_points("nodes_xy0", nodes_xy0)
    x1 = as_points("nodes_xy1", nodes_xy1, x0.shape[0])
    tri = as_triangles(triangles, x0.shape[0])
    dt = positive("dt_s", dt_s, "s")
    choice("geometry", geometry, GEOMETRIES)
    return _lagrangian(x0, x1, tri, dt, geometry)


def _lagrangian(x0, x1, tri, dt, geometry):
    """Unchecked core of :func:`lagrangian_velocity_gradients`; batch dims allowed."""
    xy = {"start": x0, "end": x1}.get(geometry)
    if xy is None:
        xy = 0.5 * (x0 + x1)
    grad, area, cen = _p1_gradient(xy, tri, (x1 - x0) / dt)
    _require_positive_area(area, f"the {geometry!r} geometry")
    return ElementStrainRates(grad, area, cen, _bounds(xy))


def _bounds(xy):
    """``(x_min, y_min, x_max, y_max)`` over the node axis (-2) of ``xy``."""
    return np.concatenate([xy.min(axis=-2), xy.max(axis=-2)], axis=-1)
