"""Mesh quality metrics: angles, areas, edge lengths."""
from __future__ import annotations

import numpy as np

from .core import signed_areas


def edge_lengths(nodes: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(m, 3) edge lengths [m]; column k is the edge opposite vertex k."""
    p = nodes[triangles]
    e0 = p[:, 2] - p[:, 1]
    e1 = p[:, 0] - p[:, 2]
    e2 = p[:, 1] - p[:, 0]
    return np.stack([np.hypot(e[:, 0], e[:, 1]) for e in (e0, e1, e2)], axis=1)


def angles_deg(nodes: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(m, 3) interior angles [degrees] at each vertex (law of cosines)."""
    L = edge_lengths(nodes, triangles)
    a, b, c = L[:, 0], L[:, 1], L[:, 2]
    with np.errstate(invalid="ignore", divide="ignore"):
        A = np.arccos(np.clip((b * b + c * c - a * a) / (2 * b * c), -1.0, 1.0))
        B = np.arccos(np.clip((a * a + c * c - b * b) / (2 * a * c), -1.0, 1.0))
    C = np.pi - A - B
    return np.degrees(np.stack([A, B, C], axis=1))


def quality_report(nodes: np.ndarray, triangles: np.ndarray) -> dict:
    """Summary statistics of the mesh quality (angles in degrees, areas m², lengths m)."""
    ang = angles_deg(nodes, triangles)
    area = signed_areas(nodes, triangles)
    L = edge_lengths(nodes, triangles)
    return {
        "n_elements": int(len(triangles)),
        "min_angle_deg": float(ang.min()),
        "max_angle_deg": float(ang.max()),
        "min_area_m2": float(area.min()),
        "max_area_m2": float(area.max()),
        "min_edge_m": float(L.min()),
        "max_edge_m": float(L.max()),
        "mean_edge_m": float(L.mean()),
        "n_inverted": int(np.sum(area <= 0)),
    }
