"""Write ``disk_300km.geojson``: a disk of radius 300 km centred on the origin, a
polygon with one vertex every whole degree (360 vertices, exact to round-off).

A rotation of the mesh by a whole number of degrees about the centre maps the
boundary onto itself, so the disk is the domain of the mesh-imprint rotation test
(``examples/imprint_cyclone_disk.toml``, docs/physics.md §3).

    python data_stubs/make_disk.py        # rewrites the file
"""
import json
from pathlib import Path

import numpy as np

OUT = Path(__file__).with_name("disk_300km.geojson")


def main(radius_m=300e3):
    th = np.radians(np.arange(360.0))
    ring = np.column_stack([radius_m * np.cos(th), radius_m * np.sin(th)]).tolist()
    ring.append(ring[0])
    gj = {"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"radius_m": radius_m},
                                                     "geometry": {"type": "Polygon", "coordinates": [ring]}}]}
    OUT.write_text(json.dumps(gj))
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
