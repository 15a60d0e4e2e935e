"""``[scene] extends``: a scene file built on another one (winter_basin_strait)."""
import numpy as np
import pytest
from shapely.geometry import LineString

from lagice.errors import ConfigError
from lagice.mesh import generate_mesh
from lagice.scenes.builder import build_domain
from lagice.scenes.config import load_scene


def test_strait_scene_is_the_basin_plus_an_open_segment():
    base = load_scene("winter_basin")
    strait = load_scene("winter_basin_strait")
    assert strait["scene"]["name"] == "winter_basin_strait" and base["scene"]["name"] == "winter_basin"
    assert list(strait["domain"]["segments"]) == ["open"] and base["domain"]["segments"] == {}
    for table in base:
        if table in ("scene", "domain"):
            continue
        assert strait[table] == base[table], table
    for key in base["domain"]:
        if key != "segments":
            assert strait["domain"][key] == base["domain"][key], key
    # overrides still apply on top of the merged scene
    short = load_scene("winter_basin_strait", ["run.duration=2d", "domain.resolution_m=40e3"])
    assert short["run"]["duration"] == "2d" and short["domain"]["segments"] == strait["domain"]["segments"]


def test_strait_mesh_has_the_open_gate_on_the_coast():
    cfg = load_scene("winter_basin_strait", ["domain.resolution_m=40e3"])
    poly, segs, ext, size = build_domain(cfg["domain"])
    mesh = generate_mesh(poly, size, segments=segs, exterior_tag=ext)
    e = mesh.edges_with_tag("open")
    gate = LineString(cfg["domain"]["segments"]["open"])
    d = mesh.nodes[e[:, 1]] - mesh.nodes[e[:, 0]]
    # the gate edges follow the coast polyline: their lengths add up to the gate length
    assert np.hypot(d[:, 0], d[:, 1]).sum() == pytest.approx(gate.length, rel=1e-9)
    assert len(mesh.edges_with_tag("coast")) > 10 * len(e) > 0


def test_extends_merges_tables_and_reports_bad_bases(tmp_path):
    (tmp_path / "base.toml").write_text('[scene]\nname = "base"\n[run]\nduration = "3d"\nseed = 5\n'
                                        '[domain]\nkind = "rectangle"\nwidth_m = 1e5\nheight_m = 1e5\n'
                                        'resolution_m = 2e4\n[solver]\nname = "implicit"\ndt = "1h"\n')
    (tmp_path / "child.toml").write_text('[scene]\nextends = "base.toml"\n[run]\nseed = 7\n')
    cfg = load_scene(tmp_path / "child.toml")
    assert cfg["run"]["seed"] == 7 and cfg["run"]["duration"] == "3d"  # sibling key kept
    assert cfg["scene"]["name"] == "child"  # the base's name is not inherited
    (tmp_path / "a.toml").write_text('[scene]\nextends = "b.toml"\n')
    (tmp_path / "b.toml").write_text('[scene]\nextends = "a.toml"\n')
    with pytest.raises(ConfigError, match="cycle"):
        load_scene(tmp_path / "a.toml")
    (tmp_path / "orphan.toml").write_text('[scene]\nextends = "missing.toml"\n')
    with pytest.raises(ConfigError, match="missing.toml.*does not exist"):
        load_scene(tmp_path / "orphan.toml")
