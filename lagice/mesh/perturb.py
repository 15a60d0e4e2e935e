"""Mesh post-processing for the mesh-imprint experiments (issue 12).

(Rotating the node lattice of an invariant domain, the rotation test of
``docs/physics.md`` §3, is ``[domain] rotate_deg``: :func:`lagice.mesh.rotate_mesh`.)

* :func:`jitter_mesh` (``[domain] jitter``): move interior nodes by a random vector of length up to
  ``amplitude`` × their mean incident edge length (seeded), undoing the moves of the
  nodes of any triangle that would invert or get an angle below ``min_angle_deg``.
  It breaks the lattice-like regularity of gmsh's frontal meshes.
"""
from __future__ import annotations

import numpy as np

from ..errors import ConfigError, check_range
from .core import Mesh, signed_areas
from .quality import angles_deg


def _copy_with_nodes(mesh: Mesh, nodes: np.ndarray) -> Mesh:
    return Mesh(nodes, mesh.triangles.copy(), mesh.boundary_edges.copy(), mesh.boundary_tags.copy(),
                tuple(mesh.tag_names))


def check_jitter(amplitude, key="domain.jitter") -> float:
    """The jitter amplitude, checked (ConfigError naming key, value and range [0, 0.45])."""
    return check_range(key, amplitude, 0.0, 0.45)


def jitter_mesh(mesh: Mesh, amplitude: float, seed: int, min_angle_deg: float = 15.0,
                key="domain.jitter") -> Mesh:
    """Interior nodes moved by up to ``amplitude`` × their mean incident edge length
    (uniform in a disk); moves that would make a triangle inverted or sharper than
    ``min_angle_deg`` are undone (their count is in ``mesh.jitter_undone``)."""
    check_jitter(amplitude, key)
    if amplitude == 0.0:
        return mesh
    tri = mesh.triangles
    n = mesh.n_nodes
    e = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    ln = np.hypot(*(mesh.nodes[e[:, 1]] - mesh.nodes[e[:, 0]]).T)
    lsum = np.bincount(e[:, 0], weights=ln, minlength=n) + np.bincount(e[:, 1], weights=ln, minlength=n)
    lcnt = np.bincount(e[:, 0], minlength=n) + np.bincount(e[:, 1], minlength=n)
    lmean = lsum / np.maximum(lcnt, 1)
    interior = np.ones(n, bool)
    interior[np.unique(mesh.boundary_edges)] = False
    rng = np.random.default_rng(seed)
    r = amplitude * lmean * np.sqrt(rng.uniform(0.0, 1.0, n))
    t = rng.uniform(0.0, 2 * np.pi, n)
    d = np.column_stack([r * np.cos(t), r * np.sin(t)]) * interior[:, None]
    undone = np.zeros(n, bool)
    a0 = angles_deg(mesh.nodes, tri).min(axis=1)
    for _ in range(20):
        nodes = mesh.nodes + d
        sharp = angles_deg(nodes, tri).min(axis=1) < np.minimum(min_angle_deg, 0.999 * a0)
        bad = (signed_areas(nodes, tri) <= 0) | sharp
        if not bad.any():
            break
        nb = np.unique(tri[bad])
        d[nb] = 0.0
        undone[nb] = True
    else:
        raise ConfigError(f"{key} = {amplitude!r}: could not make a valid jittered mesh")
    out = _copy_with_nodes(mesh, mesh.nodes + d)
    out.jitter_undone = int((undone & interior).sum())
    return out
