"""VTU output for ParaView: one ``snapshot_SSSSSSSS.vtu`` per snapshot with every
snapshot field and diagnostic (the field registry's) and its simulated time [s]
(field data ``TimeValue``), and a ``snapshots.pvd`` collection that lists them
with their times, so ParaView plays the run as a time series (also across
remeshing: each file carries its own mesh)."""
from __future__ import annotations

import os
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from ..deformation import invariants
from ..fields import FIELDS, NODE
from .cf import atomic_write_errors


def vtu_arrays(model) -> tuple[dict, dict]:
    """``(point_data, cell_data)`` of a model snapshot: the state fields written to
    snapshots, the transport velocity and the deformation rates."""
    st = model.state
    point, cell = {}, {}
    for spec in FIELDS.values():
        val = getattr(st, spec.name, None)
        if not spec.snapshot or val is None:
            continue
        arr = np.asarray(val, np.float64 if spec.dtype.startswith("float") else np.int64)
        (point if spec.location == NODE else cell)[spec.name] = arr
    v = model.transport_velocity
    point["velocity"] = np.column_stack([v, np.zeros(len(v))])
    eps = model.strain_rate
    if eps is not None:
        div, shear, tot = invariants(eps)
        cell.update(divergence_rate=div, shear_rate=shear, total_deformation_rate=tot)
    return point, cell


def _add_time(path: Path, time_s: float) -> None:
    """Insert the simulated time [s] as VTK field data ``TimeValue`` (the name ParaView
    reads as the time of a dataset; meshio does not write field data to VTU)."""
    text = path.read_text()
    tag = "<UnstructuredGrid>"
    if tag not in text:  # pragma: no cover - meshio's layout
        raise RuntimeError(f"{path}: no {tag} element to add the time to")
    field = (f'{tag}\n<FieldData>\n<DataArray type="Float64" Name="TimeValue" NumberOfTuples="1" '
             f'format="ascii">{time_s!r}</DataArray>\n</FieldData>')
    path.write_text(text.replace(tag, field, 1))


class VTUWriter:
    """Writes ``.vtu`` files and keeps the ``.pvd`` time collection up to date."""

    def __init__(self, directory, name: str = "snapshots"):
        self.dir = Path(directory)
        self.pvd = self.dir / f"{name}.pvd"

    def write(self, model) -> Path:
        import meshio

        self.dir.mkdir(parents=True, exist_ok=True)
        mesh = model.state.mesh
        step = int(model.clock.iteration)
        path = self.dir / f"snapshot_{step:08d}.vtu"
        point, cell = vtu_arrays(model)
        pts = np.column_stack([mesh.nodes, np.zeros(mesh.n_nodes)])
        m = meshio.Mesh(pts, [("triangle", mesh.triangles)], point_data=point,
                        cell_data={k: [v] for k, v in cell.items()})
        tmp = path.with_suffix(".tmp.vtu")
        with atomic_write_errors(path, tmp):
            m.write(tmp)
            _add_time(tmp, model.clock.time_s)
            os.replace(tmp, path)
        self._collection_add(step, model.clock.time_s, path.name)
        return path

    def _entries(self) -> list:
        if not self.pvd.exists():
            return []
        import re

        pat = re.compile(r'<DataSet timestep="([^"]+)" group="" part="0" file="([^"]+)"/>')
        return [(float(t), f) for t, f in pat.findall(self.pvd.read_text())]

    def _collection_add(self, step: int, time_s: float, fname: str) -> None:
        entries = [(t, f) for t, f in self._entries() if int(f.split("_")[1].split(".")[0]) < step]
        entries.append((time_s, fname))
        lines = ['<?xml version="1.0"?>', '<VTKFile type="Collection" version="0.1">', "  <Collection>"]
        lines += [f'    <DataSet timestep="{t!r}" group="" part="0" file={quoteattr(f)}/>' for t, f in entries]
        lines += ["  </Collection>", "</VTKFile>", ""]
        tmp = self.pvd.with_suffix(".pvd.tmp")
        with atomic_write_errors(self.pvd, tmp):
            tmp.write_text("\n".join(lines))
            os.replace(tmp, self.pvd)
