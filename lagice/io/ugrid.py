"""UGRID-1.0 mesh topology for netCDF outputs (xarray / xugrid readable)."""
from __future__ import annotations

import numpy as np
import xarray as xr


def mesh_dataset(mesh, name: str = "mesh") -> xr.Dataset:
    """An xarray Dataset holding the UGRID 2-D mesh topology of ``mesh``."""
    ds = xr.Dataset()
    ds[name] = xr.DataArray(np.int32(0), attrs={
        "cf_role": "mesh_topology", "topology_dimension": 2,
        "node_coordinates": f"{name}_node_x {name}_node_y",
        "face_node_connectivity": f"{name}_face_nodes",
        "face_dimension": f"{name}_face", "node_dimension": f"{name}_node",
    })
    ds[f"{name}_node_x"] = (f"{name}_node", mesh.nodes[:, 0],
                            {"units": "m", "standard_name": "projection_x_coordinate"})
    ds[f"{name}_node_y"] = (f"{name}_node", mesh.nodes[:, 1],
                            {"units": "m", "standard_name": "projection_y_coordinate"})
    ds[f"{name}_face_nodes"] = ((f"{name}_face", f"{name}_nmax_face"), mesh.triangles.astype(np.int32),
                                {"cf_role": "face_node_connectivity", "start_index": np.int32(0)})
    return ds
