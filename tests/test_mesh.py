"""lagice.mesh: gmsh generation, tags, adjacency, quality, meshio I/O, bad input."""
import numpy as np
import pytest
from shapely.geometry import LineString, Point, Polygon

from lagice.errors import ConfigError, LagiceError, MeshError
from lagice.mesh import angles_deg, edge_lengths, generate_mesh, quality_report, read_mesh, rectangle_domain, write_mesh


def island_domain():
    outer = [(0, 0), (400e3, 0), (450e3, 300e3), (0, 350e3)]
    hole = Point(200e3, 170e3).buffer(50e3, quad_segs=8)
    return Polygon(outer, [list(hole.exterior.coords)[::-1]])


def test_polygon_with_island_ccw_and_area():
    poly = island_domain()
    m = generate_mesh(poly, 20e3, segments={"open": LineString([(0, 0), (400e3, 0)])})
    a = m.areas()
    assert np.all(a > 0), "all triangles counter-clockwise"
    # mesh covers the polygon (straight-sided hole polygon: exact up to round-off)
    assert np.isclose(a.sum(), poly.area, rtol=1e-9)
    assert set(m.tag_names) == {"open", "coast"}
    # every island-boundary node lies on the circle polygon, tagged coast
    coast = m.nodes_with_tag("coast")
    r = np.hypot(m.nodes[coast, 0] - 200e3, m.nodes[coast, 1] - 170e3)
    on_island = r < 60e3
    assert on_island.sum() >= 16
    assert np.all(np.abs(r[on_island] - 50e3) < 1e3)
    # open edge nodes are exactly on y = 0
    assert np.all(m.nodes[m.nodes_with_tag("open"), 1] == 0.0)


def test_boundary_edges_closed_and_left_oriented(plate_mesh):
    m = plate_mesh
    # each boundary node has exactly two boundary edges (closed loop)
    cnt = np.bincount(m.boundary_edges.ravel(), minlength=m.n_nodes)
    assert set(np.unique(cnt[cnt > 0])) == {2}
    # the domain lies to the left: the centroid of the owning triangle is left of the edge
    assert len(m.boundary_edges) == len(m.boundary_tags)
    # sides tagged: the four named segments and corners
    for name, coord, val in (("bottom", 1, 0.0), ("top", 1, 200e3), ("left", 0, 0.0), ("right", 0, 100e3)):
        nodes = m.nodes_with_tag(name)
        assert len(nodes) >= 9
        assert np.allclose(m.nodes[nodes, coord], val)


def test_node_element_adjacency(plate_mesh):
    m = plate_mesh
    ptr, el, loc = m.node_elements
    assert ptr[-1] == 3 * m.n_elements
    # node i is vertex loc[k] of element el[k]
    for i in (0, 5, m.n_nodes // 2, m.n_nodes - 1):
        for k in range(ptr[i], ptr[i + 1]):
            assert m.triangles[el[k], loc[k]] == i
    # every (element, vertex) appears exactly once
    assert len(set(zip(el.tolist(), loc.tolist()))) == 3 * m.n_elements


def test_size_function_is_followed():
    poly, _ = rectangle_domain(400e3, 100e3)
    m = generate_mesh(poly, lambda x, y: 5e3 + 20e3 * (x / 400e3))
    L = edge_lengths(m.nodes, m.triangles).mean(axis=1)
    cx = m.centroids()[:, 0]
    left, right = L[cx < 60e3].mean(), L[cx > 340e3].mean()
    assert 4e3 < left < 9e3
    assert 18e3 < right < 28e3


def test_quality_metrics_consistent(plate_mesh):
    m = plate_mesh
    ang = angles_deg(m.nodes, m.triangles)
    assert np.allclose(ang.sum(axis=1), 180.0)
    q = quality_report(m.nodes, m.triangles)
    assert q["n_inverted"] == 0 and q["min_angle_deg"] > 20
    # equilateral check on a hand-made triangle
    nodes = np.array([[0, 0], [1, 0], [0.5, np.sqrt(3) / 2]])
    assert np.allclose(angles_deg(nodes, np.array([[0, 1, 2]])), 60.0)
    assert np.allclose(edge_lengths(nodes, np.array([[0, 1, 2]])), 1.0)


@pytest.mark.parametrize("suffix", [".vtu", ".msh"])
def test_meshio_roundtrip(tmp_path, plate_mesh, suffix):
    p = write_mesh(tmp_path / f"m{suffix}", plate_mesh)
    m2 = read_mesh(p)
    assert np.array_equal(m2.triangles, plate_mesh.triangles)
    assert np.allclose(m2.nodes, plate_mesh.nodes)
    assert np.array_equal(m2.boundary_edges, plate_mesh.boundary_edges)
    assert np.array_equal(m2.boundary_tags, plate_mesh.boundary_tags)
    if suffix == ".msh":  # gmsh physical names carry the tag names
        assert m2.tag_names == plate_mesh.tag_names


def test_bad_polygon_and_size():
    bowtie = Polygon([(0, 0), (1e5, 1e5), (1e5, 0), (0, 1e5)])
    with pytest.raises(MeshError, match="invalid.*Self-intersection"):
        generate_mesh(bowtie, 1e4)
    poly, _ = rectangle_domain(1e5, 1e5)
    for bad in (0.0, -5.0, float("nan")):
        with pytest.raises(ConfigError, match="element size"):
            generate_mesh(poly, bad)
    with pytest.raises(ConfigError, match="element size function returned"):
        generate_mesh(poly, lambda x, y: -1.0 + 0 * x)
    with pytest.raises(ConfigError, match="rectangle size"):
        rectangle_domain(-1.0, 1.0)


def test_unknown_tag_error(plate_mesh):
    with pytest.raises(ConfigError, match="unknown boundary tag 'north'"):
        plate_mesh.nodes_with_tag("north")
    assert issubclass(ConfigError, LagiceError) and issubclass(MeshError, LagiceError)


def test_segment_off_the_boundary_is_refused_before_meshing(monkeypatch):
    """A segment whose points are 0.4 m off the coast (rounded coordinates)
    used to tag no edge at all, silently; it is refused before gmsh runs, and
    a segment on the boundary's own vertices tags exactly its edges."""
    import lagice.mesh.generate as gen

    ring = [(0.0, 0.0), (1000.3, 0.0), (1000.3, 800.7), (0.0, 800.7)]
    poly = Polygon(ring)
    called = []
    real_session = gen.gmsh_session
    monkeypatch.setattr(gen, "gmsh_session", lambda: called.append(1) or real_session())
    with pytest.raises(ConfigError, match="segment 'open' leaves the domain boundary.*0.3"):
        generate_mesh(poly, 200.0, segments={"open": LineString([(1000.0, 0.0), (1000.0, 800.0)])})
    assert not called
    mesh = generate_mesh(poly, 200.0, segments={"open": LineString([(1000.3, 0.0), (1000.3, 800.7)])})
    assert called
    e = mesh.edges_with_tag("open")
    assert len(e) >= 4 and np.allclose(mesh.nodes[e.ravel(), 0], 1000.3)


def test_size_report_against_the_target():
    """A fresh gmsh mesh of a square at h has its median edge near h, and so do the 10 km
    basin (97 coast vertices 27-43 km apart) and the 8 km disk (coast vertices about 5 km
    apart): the size is not taken from the pieces gmsh cuts the coast into (before
    2026-11-29 it was: median edges 8.0 km and 5.2 km). An off mesh's log line says why."""
    from lagice.mesh import size_line, size_report
    from lagice.scenes.builder import build_mesh
    from lagice.scenes.config import load_scene

    poly, _ = rectangle_domain(200e3, 120e3)
    mesh = generate_mesh(poly, 8e3, algorithm=6)
    r = size_report(mesh.nodes, mesh.triangles, 8e3)
    assert r["n_elements"] == mesh.n_elements and 0.9 < r["median_edge_to_target"] < 1.05
    assert r["edge_p05_m"] < r["median_edge_m"] < r["edge_p95_m"]
    assert 0.38 < r["mean_area_to_target2"] < 0.44  # equilateral: 0.433
    line = size_line(r, "domain.resolution_m = 8 km")
    assert "x domain.resolution_m = 8 km" in line and "elements are smaller" not in line
    # a size field: the ratio is taken element by element
    half = size_report(mesh.nodes, mesh.triangles, lambda x, y: 0.0 * x + 16e3)
    assert half["median_edge_to_target"] == pytest.approx(r["median_edge_to_target"] / 2)
    assert "elements are smaller along a boundary" in size_line(half, "domain.resolution_m = 16 km")
    for scene, target_m in (("winter_basin_pack", 10e3), ("imprint_cyclone_disk", 8e3)):
        m = build_mesh(load_scene(scene))[0]
        b = size_report(m.nodes, m.triangles, target_m)
        assert 0.9 < b["median_edge_to_target"] < 1.05, (scene, b["median_edge_to_target"])
        assert "elements are smaller" not in size_line(b, "domain.resolution_m")
