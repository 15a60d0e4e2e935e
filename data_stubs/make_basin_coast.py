"""Write ``winter_basin_coast.geojson``: a ~1000 km wide synthetic Arctic-like
basin with an irregular coastline and one island, in metres of the model's
projected plane (EPSG:3413 polar stereographic, centred near the pole).

Deterministic: the outline is a circle of radius 500 km perturbed by a few
seeded Fourier modes; the island is a perturbed circle of radius 70 km.

    python data_stubs/make_basin_coast.py        # rewrites the file
"""
import json
from pathlib import Path

import numpy as np
from shapely.geometry import Polygon, mapping

OUT = Path(__file__).with_name("winter_basin_coast.geojson")


def outline(radius_m, n_points, modes, seed, centre=(0.0, 0.0)):
    rng = np.random.default_rng(seed)
    th = np.linspace(0, 2 * np.pi, n_points, endpoint=False)
    r = np.ones_like(th)
    for k, amp in modes:
        r += amp * np.cos(k * th + rng.uniform(0, 2 * np.pi))
    x = centre[0] + radius_m * r * np.cos(th)
    y = centre[1] + radius_m * r * np.sin(th)
    return np.round(np.column_stack([x, y]), 1)


def main():
    outer = outline(500e3, 96, [(2, 0.10), (3, 0.07), (5, 0.05), (9, 0.025), (14, 0.012)], seed=2026)
    island = outline(70e3, 24, [(2, 0.15), (3, 0.08)], seed=7, centre=(-150e3, 120e3))
    poly = Polygon(outer, [island[::-1]])
    assert poly.is_valid, "coastline polygon must be valid"
    feature = {"type": "FeatureCollection", "features": [{
        "type": "Feature",
        "properties": {"name": "winter_basin", "crs": "EPSG:3413", "units": "m",
                       "made_by": "data_stubs/make_basin_coast.py"},
        "geometry": mapping(poly)}]}
    OUT.write_text(json.dumps(feature))
    print(f"wrote {OUT} (area {poly.area / 1e6:.0f} km2, {len(outer)} + {len(island)} vertices)")


if __name__ == "__main__":
    main()
