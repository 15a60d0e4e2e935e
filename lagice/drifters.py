"""Drifting points (virtual buoys) advected with the ice (component ``drifters``).

Each outer step a drifter moves by u·Δt, with u the model's transport velocity
(the velocity that moves the mesh nodes) interpolated linearly (P1) in the
triangle that contains the drifter at the start of the step. Because the mesh
moves with the same P1 field, a drifter keeps its barycentric coordinates in its
triangle exactly. Positions are recorded every step and carried in checkpoints so
trajectories resume bit for bit. A drifter that leaves the mesh (through an open
boundary) stops and is flagged ``lost``; nothing is dropped silently.
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _barycentric(x, y, nodes, tri, e):
    a, b, c = tri[e, 0], tri[e, 1], tri[e, 2]
    x0, y0 = nodes[a, 0], nodes[a, 1]
    x1, y1 = nodes[b, 0], nodes[b, 1]
    x2, y2 = nodes[c, 0], nodes[c, 1]
    det = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
    l1 = ((x - x0) * (y2 - y0) - (x2 - x0) * (y - y0)) / det
    l2 = ((x1 - x0) * (y - y0) - (x - x0) * (y1 - y0)) / det
    return 1.0 - l1 - l2, l1, l2


@njit(cache=True)
def _locate(points, nodes, tri, hint, elem, w):
    """For each point, the first element (lowest index) whose barycentric coordinates
    are all >= -1e-12, with the arithmetic of the numpy formulation. Shortcuts that
    cannot change the answer: the ``hint`` element (the drifter's element of the last
    step) is taken when the point lies inside it by a margin (1e-9 in barycentric
    coordinates: no other element can then contain it), and elements whose bounding
    box misses the point by more than 1e-9 of the box size are skipped."""
    for k in range(points.shape[0]):
        x, y = points[k, 0], points[k, 1]
        h = hint[k]
        if 0 <= h < tri.shape[0]:
            l0, l1, l2 = _barycentric(x, y, nodes, tri, h)
            if l0 > 1e-9 and l1 > 1e-9 and l2 > 1e-9:
                elem[k] = h
                w[k, 0], w[k, 1], w[k, 2] = l0, l1, l2
                continue
        for e in range(tri.shape[0]):
            a, b, c = tri[e, 0], tri[e, 1], tri[e, 2]
            xmin = min(nodes[a, 0], nodes[b, 0], nodes[c, 0])
            xmax = max(nodes[a, 0], nodes[b, 0], nodes[c, 0])
            ymin = min(nodes[a, 1], nodes[b, 1], nodes[c, 1])
            ymax = max(nodes[a, 1], nodes[b, 1], nodes[c, 1])
            tol = 1e-9 * (xmax - xmin + ymax - ymin)
            if x < xmin - tol or x > xmax + tol or y < ymin - tol or y > ymax + tol:
                continue
            l0, l1, l2 = _barycentric(x, y, nodes, tri, e)
            if l0 >= -1e-12 and l1 >= -1e-12 and l2 >= -1e-12:
                elem[k] = e
                w[k, 0], w[k, 1], w[k, 2] = l0, l1, l2
                break


def locate(points: np.ndarray, nodes: np.ndarray, tri: np.ndarray, hint: np.ndarray | None = None):
    """Element index and barycentric weights of each point (−1 if outside): the
    first (lowest-index) element containing the point. ``hint``: a guess of each
    point's element (e.g. last step's), used only when the point lies well inside it."""
    points = np.ascontiguousarray(points, np.float64).reshape(-1, 2)
    elem = np.full(len(points), -1, np.int64)
    w = np.zeros((len(points), 3))
    hint = np.full(len(points), -1, np.int64) if hint is None else np.ascontiguousarray(hint, np.int64)
    _locate(points, np.ascontiguousarray(nodes, np.float64), np.ascontiguousarray(tri, np.int64), hint, elem, w)
    return elem, w


class Drifters:
    """Virtual buoys (component ``drifters``); ``positions_m`` (k, 2) initial positions [m]."""

    name = "drifters"

    def __init__(self, positions_m):
        self.positions = np.array(positions_m, dtype=np.float64).reshape(-1, 2)
        self.lost = np.zeros(len(self.positions), dtype=bool)
        self.track = [self.positions.copy()]
        self.track_time_s = [0.0]
        self._hint = None  # each drifter's element at the last step (a search shortcut only)

    def move(self, mesh, velocity: np.ndarray, dt_s: float) -> None:
        """Move the drifters by the P1 interpolation of the node ``velocity`` (n, 2)
        [m s-1] over ``dt_s`` [s] in ``mesh`` (the mesh before it moves)."""
        elem, w = locate(self.positions, mesh.nodes, mesh.triangles, self._hint)
        self._hint = elem
        self.lost |= elem < 0
        ok = ~self.lost
        if ok.any():
            vel = np.einsum("kj,kjc->kc", w[ok], velocity[mesh.triangles[elem[ok]]])
            self.positions[ok] += vel * dt_s

    def advance(self, model, dt_s: float) -> dict:
        self.move(model.state.mesh, model.transport_velocity, dt_s)
        self.track.append(self.positions.copy())
        self.track_time_s.append(model.clock.time_s + dt_s)
        return {"lost": int(self.lost.sum())}

    def trajectories(self):
        """List of (n_t, 2) arrays, one per drifter [m]."""
        t = np.array(self.track)
        return [t[:, k] for k in range(t.shape[1])]

    def times_s(self) -> np.ndarray:
        """Times [s] of the recorded positions."""
        return np.array(self.track_time_s)

    # component protocol: checkpoint and restore
    def checkpoint_state(self):
        return ({"positions": self.positions, "lost": self.lost, "track": np.array(self.track),
                 "track_time_s": np.array(self.track_time_s)}, {})

    def restore(self, arrays, meta):
        self.positions = arrays["positions"].copy()
        self.lost = arrays["lost"].copy()
        self.track = list(arrays["track"])
        self.track_time_s = list(arrays["track_time_s"]) if "track_time_s" in arrays else \
            [float("nan")] * len(self.track)
