"""Benchmark helpers that change what a benchmark builds (benchmarks/scene_runs.py)."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))


def test_reused_gmsh_mesh_is_the_mesh_gmsh_gives_and_is_not_shared(monkeypatch):
    from scene_runs import reuse_gmsh_meshes, scene_config

    import lagice.scenes.builder as builder

    monkeypatch.setattr(builder, "generate_mesh", builder.generate_mesh)  # restored after the test
    # without renumbering, build_mesh returns what generate_mesh returned
    cfg = scene_config("wind_square", {"domain.resolution_m": 60e3, "domain.renumber": False})
    fresh, _ = builder.build_mesh(cfg)
    stats = reuse_gmsh_meshes()
    first, _ = builder.build_mesh(cfg)
    first.nodes[:] += 1.0e3  # a run moving its nodes must not move the cached mesh
    second, _ = builder.build_mesh(cfg)
    assert stats == {"gmsh_calls": 1, "reused": 1}
    for name in ("nodes", "triangles", "boundary_edges", "boundary_tags"):
        assert np.array_equal(getattr(second, name), getattr(fresh, name)), name
    other, _ = builder.build_mesh(scene_config("wind_square", {"domain.resolution_m": 80e3}))
    assert stats["gmsh_calls"] == 2 and other.n_elements < fresh.n_elements
