"""Write ``disk_300km.geojson``: a disk of radius 300 km centred on the origin, a
polygon with one vertex every whole degree (360 vertices, exact to round-off);
``--radius-km 500`` writes ``disk_500km.geojson``, the domain of
``benchmarks/disk_convergence.py`` (β against the element size).

A rotation of the mesh by a whole number of degrees about the centre maps the
boundary onto itself, so the disk is the domain of the mesh-imprint rotation test
(``examples/imprint_cyclone_disk.toml``, docs/physics.md §3).

    python data_stubs/make_disk.py                    # rewrites disk_300km.geojson
    python data_stubs/make_disk.py --radius-km 500    # rewrites disk_500km.geojson
"""
import argparse
import json
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent


def main(radius_m=300e3):
    th = np.radians(np.arange(360.0))
    ring = np.column_stack([radius_m * np.cos(th), radius_m * np.sin(th)]).tolist()
    ring.append(ring[0])
    gj = {"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"radius_m": radius_m},
                                                     "geometry": {"type": "Polygon", "coordinates": [ring]}}]}
    out = HERE / f"disk_{radius_m / 1e3:g}km.geojson"
    out.write_text(json.dumps(gj))
    print(f"wrote {out}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--radius-km", type=float, default=300.0)
    main(ap.parse_args().radius_km * 1e3)
