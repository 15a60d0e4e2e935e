"""Mesh read/write through meshio.

Gmsh ``.msh`` files keep the boundary tag names (as physical groups); other
formats (``.vtu``, ``.xdmf``) keep the integer ``boundary_tag`` of each
boundary edge and element/node fields for ParaView; their tag names come back
as ``tag_<id>`` unless the format stores meshio field data.
"""
from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np

from ..errors import MeshError
from .core import COAST, Mesh, boundary_edges_of

_DOMAIN_PHYSICAL = 10000


def write_mesh(path, mesh: Mesh, cell_data: dict | None = None, point_data: dict | None = None) -> Path:
    """Write a mesh (and optional element/node fields) with meshio."""
    path = Path(path)
    pts = np.column_stack([mesh.nodes, np.zeros(mesh.n_nodes)])
    cells = [("triangle", mesh.triangles), ("line", mesh.boundary_edges)]
    tags = mesh.boundary_tags.astype(np.int32)
    if path.suffix == ".msh":
        phys = [np.full(mesh.n_elements, _DOMAIN_PHYSICAL, np.int32), tags + 1]
        cd = {"gmsh:physical": phys, "gmsh:geometrical": [np.ones(mesh.n_elements, np.int32), tags + 1]}
        fd = {name: np.array([i + 1, 1]) for i, name in enumerate(mesh.tag_names)}
        fd["domain"] = np.array([_DOMAIN_PHYSICAL, 2])
        meshio.Mesh(pts, cells, cell_data=cd, field_data=fd).write(path, file_format="gmsh22", binary=False)
        return path
    cd = {"boundary_tag": [np.full(mesh.n_elements, -1, np.int32), tags]}
    for k, v in (cell_data or {}).items():
        cd[k] = [np.asarray(v, dtype=np.float64), np.full(len(mesh.boundary_edges), np.nan)]
    fd = {name: np.array([i, 1]) for i, name in enumerate(mesh.tag_names)}
    meshio.Mesh(pts, cells, cell_data=cd, point_data=dict(point_data or {}), field_data=fd).write(path)
    return path


def read_mesh(path) -> Mesh:
    """Read a mesh written by :func:`write_mesh` (or any triangle mesh meshio reads;
    without boundary information all boundary edges are tagged ``coast``)."""
    path = Path(path)
    if not path.exists():
        raise MeshError(f"mesh file {path} does not exist")
    try:
        m = meshio.read(path)
    except Exception as exc:  # noqa: BLE001
        raise MeshError(f"cannot read mesh file {path}: {exc}") from exc
    tri, lines, tags = None, None, None
    for i, block in enumerate(m.cells):
        if block.type == "triangle":
            tri = np.asarray(block.data, np.int64)
        elif block.type == "line":
            lines = np.asarray(block.data, np.int64)
            if "gmsh:physical" in m.cell_data:
                tags = np.asarray(m.cell_data["gmsh:physical"][i], np.int64) - 1
            elif "boundary_tag" in m.cell_data:
                tags = np.asarray(m.cell_data["boundary_tag"][i], np.int64)
    if tri is None:
        raise MeshError(f"mesh file {path} has no triangles")
    if lines is None or tags is None:
        lines = boundary_edges_of(tri)
        return Mesh(np.asarray(m.points)[:, :2], tri, lines, np.zeros(len(lines), np.int32), (COAST,))
    offset = 1 if "gmsh:physical" in m.cell_data else 0
    named = [int(v[0]) - offset for v in m.field_data.values() if len(v) < 2 or int(v[1]) == 1]
    n_tags = max([int(tags.max()) + 1 if len(tags) else 0] + [i + 1 for i in named])
    names = [f"tag_{i}" for i in range(n_tags)]
    for name, val in m.field_data.items():
        idx = int(val[0]) - offset
        if 0 <= idx < n_tags and (len(val) < 2 or int(val[1]) == 1):
            names[idx] = name
    return Mesh(np.asarray(m.points)[:, :2], tri, lines, tags.astype(np.int32), tuple(names))
