"""Conservative remapping over the supermesh: totals, bounds, accuracy, methods."""
import numpy as np
import pytest

from lagice.mesh import generate_mesh, rectangle_domain
from lagice.remesh import interpolate_nodal, intersect_triangles, remap_field, remap_weights


@pytest.fixture(scope="module")
def two_meshes():
    poly, _ = rectangle_domain(100e3, 100e3)
    return generate_mesh(poly, 9e3), generate_mesh(poly, 6e3)


def _remap(a, b, v, method="clip"):
    i, j, w = intersect_triangles(a.nodes, a.triangles, b.nodes, b.triangles, method=method)
    S = remap_weights(i, j, w, b.n_elements, new_areas=b.areas())
    return remap_field(v, i, j, w, S)


def test_supermesh_areas_match_both_meshes(two_meshes):
    a, b = two_meshes
    i, j, w = intersect_triangles(a.nodes, a.triangles, b.nodes, b.triangles)
    np.testing.assert_allclose(np.bincount(i, w, a.n_elements), a.areas(), rtol=1e-12)
    np.testing.assert_allclose(np.bincount(j, w, b.n_elements), b.areas(), rtol=1e-12)


def test_clip_and_celltree_agree(two_meshes):
    a, b = two_meshes
    i1, j1, w1 = intersect_triangles(a.nodes, a.triangles, b.nodes, b.triangles, method="clip")
    i2, j2, w2 = intersect_triangles(a.nodes, a.triangles, b.nodes, b.triangles, method="celltree")
    M1 = np.zeros((a.n_elements, b.n_elements))
    M2 = np.zeros_like(M1)
    np.add.at(M1, (i1, j1), w1)
    np.add.at(M2, (i2, j2), w2)
    np.testing.assert_allclose(M1, M2, atol=1e-6 * a.areas().mean())


def test_totals_bounds_and_constants(two_meshes, rng):
    a, b = two_meshes
    aa, ab = a.areas(), b.areas()
    h = rng.uniform(0.0, 3.0, a.n_elements)
    A = rng.uniform(0.0, 1.0, a.n_elements)
    A[::7] = 1.0
    A[::11] = 0.0
    d = rng.uniform(0.0, 1.0 - 1e-6, a.n_elements)
    for v in (h, A):
        w = _remap(a, b, v)
        assert abs(np.sum(w * ab) - np.sum(v * aa)) <= 1e-13 * np.sum(v * aa)
    for v in (A, d):
        w = _remap(a, b, v)
        assert w.min() >= 0.0 and w.max() <= 1.0
    assert _remap(a, b, d).max() < 1.0
    assert np.all(_remap(a, b, np.ones(a.n_elements)) == 1.0)  # exactly
    c = _remap(a, b, np.full(a.n_elements, 0.7))
    np.testing.assert_allclose(c, 0.7, rtol=2e-15)
    s = _remap(a, b, np.tile([1.0, -2.0, 3.0], (a.n_elements, 1)))
    np.testing.assert_allclose(s, np.tile([1.0, -2.0, 3.0], (b.n_elements, 1)), rtol=1e-14)


def _f(x, y):
    return np.sin(2 * np.pi * x / 100e3) * np.cos(np.pi * y / 100e3) + 0.5 * x / 100e3


def test_first_order_accuracy():
    """L1 error of remapping a smooth P0 field falls at least linearly with the element size."""
    poly, _ = rectangle_domain(100e3, 100e3)
    sizes = [10e3, 5e3, 2.5e3]
    errs = []
    for s in sizes:
        a = generate_mesh(poly, s)
        b = generate_mesh(poly, 0.83 * s)
        ca, cb = a.centroids(), b.centroids()
        w = _remap(a, b, _f(ca[:, 0], ca[:, 1]))
        errs.append(float(np.sum(np.abs(w - _f(cb[:, 0], cb[:, 1])) * b.areas())))
    rates = np.log(np.array(errs[:-1]) / np.array(errs[1:])) / np.log(2.0)
    assert np.all(rates > 0.9), (errs, rates)


def test_velocity_interpolation_exact_for_linear_fields(two_meshes, rng):
    a, b = two_meshes
    lin = np.column_stack([1.0 + 2e-5 * a.nodes[:, 0] - 3e-5 * a.nodes[:, 1], 0.5 * a.nodes[:, 1] / 1e5])
    pts = rng.uniform(0, 100e3, (200, 2))
    pts = np.concatenate([pts, b.nodes])
    v = interpolate_nodal(a.nodes, a.triangles, lin, pts)
    exact = np.column_stack([1.0 + 2e-5 * pts[:, 0] - 3e-5 * pts[:, 1], 0.5 * pts[:, 1] / 1e5])
    np.testing.assert_allclose(v, exact, atol=1e-12)
