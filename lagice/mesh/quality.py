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


def size_report(nodes: np.ndarray, triangles: np.ndarray, size_field) -> dict:
    """The mesh's edge lengths against the target size ``size_field`` [m] (a number or a
    vectorised ``f(x, y)``, evaluated at the element centroids): ``median_edge_m``,
    ``edge_p05_m`` / ``edge_p95_m``, ``median_edge_to_target`` (median of edge / target) and
    ``mean_area_to_target2`` (mean element area / target²; an equilateral mesh of the target
    size has √3/4 = 0.433), over every edge of every element."""
    from ..remesh.trigger import evaluate_size

    L = edge_lengths(nodes, triangles)
    c = nodes[triangles].mean(axis=1)
    h = evaluate_size(size_field, c[:, 0], c[:, 1])
    area = np.abs(signed_areas(nodes, triangles))
    p05, p50, p95 = np.percentile(L, [5, 50, 95])
    return {"n_elements": int(len(triangles)), "n_nodes": int(len(nodes)), "median_edge_m": float(p50),
            "edge_p05_m": float(p05), "edge_p95_m": float(p95),
            "median_edge_to_target": float(np.median(L / h[:, None])),
            "mean_area_to_target2": float(np.mean(area / h ** 2))}


def size_line(report: dict, target_text: str) -> str:
    """One line for a run's log: the mesh's size against the target (``target_text``, e.g.
    "domain.resolution_m = 10 km"), with why when the median edge is off it by over 10 %."""
    r = report
    line = (f"mesh: {r['n_elements']} elements, {r['n_nodes']} nodes; edges {r['median_edge_m'] / 1e3:.3g} km "
            f"median (5-95 %: {r['edge_p05_m'] / 1e3:.3g}-{r['edge_p95_m'] / 1e3:.3g} km), "
            f"{r['median_edge_to_target']:.2f} x {target_text}")
    if abs(r["median_edge_to_target"] - 1.0) > 0.10:
        line += ("; elements are smaller along a boundary whose vertices are closer than the target, and a moved "
                 "or remeshed mesh drifts from it (docs/remeshing.md, section 7.1); remeshed patches are made at the "
                 "target")
    return line
