"""Drifting points (virtual buoys) advected with the ice velocity.

Each outer step a drifter moves by u·Δt, with u interpolated linearly (P1)
in the triangle that contains it. Positions are recorded every step they are
asked for, and carried in checkpoints so trajectories resume bit for bit.
A drifter that leaves the mesh (through an open boundary) stops and is
flagged ``lost``; nothing is dropped silently.
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
    """Virtual buoys; ``positions_m`` (k, 2) initial positions [m]."""

    def __init__(self, positions_m):
        self.positions = np.array(positions_m, dtype=np.float64).reshape(-1, 2)
        self.lost = np.zeros(len(self.positions), dtype=bool)
        self.track = [self.positions.copy()]

    def advance(self, state, dt_s: float) -> None:
        mesh = state.mesh
        elem, w = locate(self.positions, mesh.nodes, mesh.triangles)
        self.lost |= elem < 0
        ok = ~self.lost
        if ok.any():
            vel = np.einsum("kj,kjc->kc", w[ok], state.velocity[mesh.triangles[elem[ok]]])
            self.positions[ok] += vel * dt_s
        self.track.append(self.positions.copy())

    def trajectories(self):
        """List of (n_t, 2) arrays, one per drifter [m]."""
        t = np.array(self.track)
        return [t[:, k] for k in range(t.shape[1])]

    # checkpoint protocol
    def checkpoint_arrays(self):
        return {"positions": self.positions, "lost": self.lost, "track": np.array(self.track)}

    def load_checkpoint(self, arrays, meta):
        self.positions = arrays["positions"].copy()
        self.lost = arrays["lost"].copy()
        self.track = list(arrays["track"])
