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


def locate(points: np.ndarray, nodes: np.ndarray, tri: np.ndarray):
    """Element index and barycentric weights of each point (−1 if outside)."""
    p0, p1, p2 = nodes[tri[:, 0]], nodes[tri[:, 1]], nodes[tri[:, 2]]
    det = (p1[:, 0] - p0[:, 0]) * (p2[:, 1] - p0[:, 1]) - (p2[:, 0] - p0[:, 0]) * (p1[:, 1] - p0[:, 1])
    elem = np.full(len(points), -1, np.int64)
    w = np.zeros((len(points), 3))
    for k, (x, y) in enumerate(points):
        l1 = ((x - p0[:, 0]) * (p2[:, 1] - p0[:, 1]) - (p2[:, 0] - p0[:, 0]) * (y - p0[:, 1])) / det
        l2 = ((p1[:, 0] - p0[:, 0]) * (y - p0[:, 1]) - (x - p0[:, 0]) * (p1[:, 1] - p0[:, 1])) / det
        l0 = 1.0 - l1 - l2
        inside = np.flatnonzero((l0 >= -1e-12) & (l1 >= -1e-12) & (l2 >= -1e-12))
        if len(inside):
            e = inside[0]
            elem[k] = e
            w[k] = (l0[e], l1[e], l2[e])
    return elem, w


class Drifters:
    """Virtual buoys (component ``drifters``); ``positions_m`` (k, 2) initial positions [m]."""

    name = "drifters"

    def __init__(self, positions_m):
        self.positions = np.array(positions_m, dtype=np.float64).reshape(-1, 2)
        self.lost = np.zeros(len(self.positions), dtype=bool)
        self.track = [self.positions.copy()]
        self.track_time_s = [0.0]

    def move(self, mesh, velocity: np.ndarray, dt_s: float) -> None:
        """Move the drifters by the P1 interpolation of the node ``velocity`` (n, 2)
        [m s-1] over ``dt_s`` [s] in ``mesh`` (the mesh before it moves)."""
        elem, w = locate(self.positions, mesh.nodes, mesh.triangles)
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
