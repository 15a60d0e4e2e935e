"""Mesh transformations that keep the triangles: rotation about a point, and a
renumbering of nodes and elements along a space-filling curve for memory
locality (the gathers of the solver kernels then hit nearby memory)."""
from __future__ import annotations

import math

import numpy as np

from .core import Mesh


def rotate_mesh(mesh: Mesh, angle_deg: float, center) -> Mesh:
    """A copy of ``mesh`` rotated by ``angle_deg`` (counter-clockwise) about
    ``center`` [m]; quarter turns are exact (no round-off)."""
    center = np.asarray(center, np.float64)
    if angle_deg == 0:
        return mesh
    if angle_deg % 90 == 0:
        k = int(round(angle_deg / 90)) % 4
        ca, sa = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][k]
    else:
        a = math.radians(angle_deg)
        ca, sa = math.cos(a), math.sin(a)
    d = mesh.nodes - center
    nodes = np.ascontiguousarray(np.c_[ca * d[:, 0] - sa * d[:, 1], sa * d[:, 0] + ca * d[:, 1]] + center)
    return Mesh(nodes, mesh.triangles.copy(), mesh.boundary_edges.copy(), mesh.boundary_tags.copy(),
                mesh.tag_names)


def morton_order(xy: np.ndarray, bits: int = 16) -> np.ndarray:
    """Permutation sorting points (n, 2) along a Z-order (Morton) curve."""
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    q = ((xy - lo) / np.maximum(hi - lo, 1e-30) * (2**bits - 1)).astype(np.uint64)
    code = np.zeros(len(xy), np.uint64)
    for k in range(bits):
        code |= ((q[:, 0] >> np.uint64(k)) & np.uint64(1)) << np.uint64(2 * k)
        code |= ((q[:, 1] >> np.uint64(k)) & np.uint64(1)) << np.uint64(2 * k + 1)
    return np.argsort(code, kind="stable")


def renumber_for_locality(mesh: Mesh) -> tuple[Mesh, np.ndarray, np.ndarray]:
    """The same mesh with nodes and elements renumbered along a Morton curve.

    Returns ``(mesh, node_perm, element_perm)``: new node k is old node
    ``node_perm[k]``, new element k is old element ``element_perm[k]``."""
    pn = morton_order(mesh.nodes)
    inv = np.empty_like(pn)
    inv[pn] = np.arange(len(pn))
    tri = inv[mesh.triangles]
    pe = morton_order(mesh.nodes[mesh.triangles].mean(axis=1))
    return (Mesh(mesh.nodes[pn], tri[pe], inv[mesh.boundary_edges], mesh.boundary_tags, mesh.tag_names),
            pn, pe)
