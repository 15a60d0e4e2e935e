"""The issue-12 flagship scene (examples/winter_basin_pack.toml): the spin-up state it
starts from, and a short coarse run of its physics that breaks a pristine pack in the
interior."""
import json

import numpy as np
import pytest

from lagice.diagnostics import lagrangian_velocity_gradients
from lagice.diagnostics.faults import interior_triangles
from lagice.spinup import WINTER_BASIN, field_from_spinup, save_spinup

from helpers import scene_sim

DAY = 86400.0


def test_spinup_state_round_trip(tmp_path):
    """save_spinup keeps the last snapshot's element fields; the scene hook returns, at
    each element centroid of that snapshot, that element's own value."""
    import xarray as xr

    sim = scene_sim("winter_basin_pack", tmp_path / "run", {"domain.resolution_m": 80e3, "run.duration": "1h",
                                                            "solver.dt": "1h", "output.every": "1h",
                                                            "drifters.count": 0})
    sim.run()
    npz = save_spinup(tmp_path / "run", tmp_path / "s.npz")
    idx = json.loads((tmp_path / "run" / "snapshots" / "index.json").read_text())
    with xr.open_dataset(tmp_path / "run" / "snapshots" / idx[-1]["file"], decode_times=False) as ds:
        nodes = np.column_stack([ds["mesh_node_x"].values, ds["mesh_node_y"].values])
        c = nodes[ds["mesh_face_nodes"].values.astype(int)].mean(axis=1)
        h = ds["thickness"].values[0]
        d = ds["damage"].values[0]
    np.testing.assert_allclose(field_from_spinup(npz, "thickness", c[:, 0], c[:, 1]), h, rtol=1e-6)
    np.testing.assert_allclose(field_from_spinup(npz, "damage", c[:, 0], c[:, 1]), d, rtol=1e-6, atol=1e-7)


def test_shipped_spinup_is_heterogeneous_and_damaged():
    """data_stubs/winter_basin_spinup.npz (14 days of the pack physics from pristine
    ice): a partly damaged, heterogeneous pack, not a uniform one; the flagship scene
    starts from it (nearest spin-up centroid of each element)."""
    z = np.load(WINTER_BASIN)
    d = z["damage"]
    assert 0.2 < d.mean() < 0.98 and d.std() > 0.05 and (d < 0.5).any() and (d > 0.9).any()
    assert float(z["time_s"]) == pytest.approx(14 * DAY)
    from lagice.scenes.builder import build_model
    from lagice.scenes.config import load_scene

    st = build_model(load_scene("winter_basin_pack", {"domain.resolution_m": 60e3, "run.duration": "1h",
                                                      "solver.dt": "1h"})).state
    c = st.mesh.centroids()
    np.testing.assert_allclose(st.damage, field_from_spinup(WINTER_BASIN, "damage", c[:, 0], c[:, 1]))
    assert st.damage.std() > 0.05


def test_shipped_spinup_is_a_pack_of_thick_and_thin_ice():
    """Since 2026-11-25 the spin-up starts from thickness waves of 120-370 km (the
    variability of winter Arctic ice, Laxon et al. 2013): its state keeps a thickness
    standard deviation near 0.5 m, a 5th percentile below 1 m and a 95th above 2.3 m (the
    pack shipped before: 0.22 m, 1.47 m, 1.97 m), with the
    thick and thin ice in regions hundreds of km wide (the field is smooth on the 10 km
    elements, not noise), and the scene's initial thickness takes it."""
    from lagice.scenes.builder import build_model
    from lagice.scenes.config import load_scene

    z = np.load(WINTER_BASIN)
    h, x, y = z["thickness"], z["centroid_x_m"], z["centroid_y_m"]
    assert 0.4 < h.std() < 0.7 and np.quantile(h, 0.05) < 1.0 and np.quantile(h, 0.95) > 2.3
    # smooth at the element scale: neighbours within 20 km differ far less than random pairs
    from scipy.spatial import cKDTree

    pairs = cKDTree(np.column_stack([x, y])).query_pairs(20e3, output_type="ndarray")
    near = np.abs(h[pairs[:, 0]] - h[pairs[:, 1]]).mean()
    rng = np.random.default_rng(0)
    far = np.abs(h[rng.integers(0, h.size, 20000)] - h[rng.integers(0, h.size, 20000)]).mean()
    assert near < 0.35 * far
    st = build_model(load_scene("winter_basin_pack", {"domain.resolution_m": 60e3, "run.duration": "1h",
                                                      "solver.dt": "1h"})).state
    c = st.mesh.centroids()
    np.testing.assert_allclose(st.thickness, field_from_spinup(WINTER_BASIN, "thickness", c[:, 0], c[:, 1]),
                               rtol=1e-6)
    assert st.thickness.std() > 0.4


@pytest.mark.slow
def test_short_coarse_run_breaks_the_pack_in_the_interior(tmp_path):
    """The flagship physics (winter_basin_spinup: winter_basin_pack from pristine ice) at
    40 km for 8 days (at 60 km the scene's Delaunay mesh leaves ~280 elements, five
    across, in the interior; at 40 km ~1400): in the interior (≥ 100 km from the coast) the mean damage rises
    from 0 above 0.3, and the mean total deformation rate over days 5–8 exceeds
    0.005 day⁻¹ (RGPS winter: 0.01–0.05) and is at least a third of the whole basin's
    (the interior breaks, not only the coastal shear zones)."""
    from lagice.io.snapshots import load_window

    sim = scene_sim("winter_basin_spinup", tmp_path / "run", {"domain.resolution_m": 40e3, "run.duration": "8d",
                                                              "output.every": "1d", "checkpoint.every": "100d"})
    assert sim.model.state.damage.max() == 0.0
    sim.run()
    st = sim.model.state
    keep = interior_triangles(st.mesh.nodes, st.mesh.triangles, 100e3)
    assert keep.sum() > 50
    assert st.damage[keep].mean() > 0.3
    w = load_window(tmp_path / "run", 5 * DAY, 8 * DAY)
    r = lagrangian_velocity_gradients(w["xy0"], w["xy1"], w["triangles"], w["dt_s"])
    inner = interior_triangles(*w["start_mesh"], 100e3)[w["kept_elements"]]
    rate_in = r.total_s[inner].mean() * DAY
    assert rate_in > 0.005
    assert rate_in > r.total_s.mean() * DAY / 3.0


def _state_npz(path, damage=0.42, thickness=2.0, concentration=0.9, drop=None):
    """A spin-up state file on a 10 km grid over the basin, uniform fields."""
    g = np.arange(-700e3, 700e3, 10e3)
    x, y = (a.ravel().astype(np.float32) for a in np.meshgrid(g, g))
    f = {"damage": np.full(x.size, damage, np.float32), "thickness": np.full(x.size, thickness, np.float32),
         "concentration": np.full(x.size, concentration, np.float32)}
    if drop:
        f.pop(drop)
    np.savez(path, centroid_x_m=x, centroid_y_m=y, time_s=np.float64(0.0), **f)
    return path


def test_state_file_sets_the_initial_state(tmp_path):
    """``--set initial.state_file=PATH`` starts the flagship from another spin-up state:
    every element takes that file's fields, not the shipped state's."""
    from lagice.scenes.builder import build_model
    from lagice.scenes.config import load_scene

    npz = _state_npz(tmp_path / "other.npz")
    st = build_model(load_scene("winter_basin_pack", {"domain.resolution_m": 60e3, "run.duration": "1h",
                                                      "solver.dt": "1h", "initial.state_file": str(npz)})).state
    np.testing.assert_allclose(st.damage, 0.42, rtol=1e-6)
    np.testing.assert_allclose(st.thickness, 2.0, rtol=1e-6)
    np.testing.assert_allclose(st.concentration, 0.9, rtol=1e-6)
    shipped = np.load(WINTER_BASIN)["damage"]
    assert shipped.std() > 0.05  # so the shipped state would not have given a uniform 0.42


@pytest.mark.parametrize("scene,sets,fragment", [
    ("winter_basin_pack", {"initial.state_file": "nowhere/missing.npz"},
     "initial.state_file = 'nowhere/missing.npz': spin-up state"),
    ("winter_basin_pack", {"initial.state_file": "BAD_DAMAGE"}, "field 'damage' has 1"),
    ("winter_basin_pack", {"initial.state_file": "NO_THICKNESS"}, "lacks ['thickness']"),
    ("winter_basin_pack", {"initial.state_file": ""}, "initial.thickness_m = 'from_state' needs initial.state_file"),
    ("winter_basin_spinup", {"initial.state_file": "GOOD"}, "is set but no initial field uses it"),
    ("winter_basin_spinup", {"initial.snow_m": "from_state"}, "initial.snow_m = 'from_state': only"),
])
def test_bad_state_file_fails_before_meshing(monkeypatch, tmp_path, scene, sets, fragment):
    """A missing or invalid spin-up state, or a state file and ``from_state`` fields that
    do not go together, fail before any meshing with the key, file and field named."""
    from lagice.errors import ConfigError
    from lagice.scenes import builder, config

    files = {"BAD_DAMAGE": lambda p: _state_npz(p, damage=1.5),
             "NO_THICKNESS": lambda p: _state_npz(p, drop="thickness"), "GOOD": _state_npz}
    sets = {k: (str(files[v](tmp_path / f"{v}.npz")) if v in files else v) for k, v in sets.items()}

    def boom(*a, **k):
        raise AssertionError("meshing must not start")

    monkeypatch.setattr(builder, "generate_mesh", boom)
    with pytest.raises(ConfigError) as exc:
        builder.build_model(config.load_scene(scene, sets))
    assert fragment in str(exc.value)


def test_new_ice_undamaged_through_the_scene(tmp_path):
    """``thermo.new_ice_undamaged = true`` in the flagship scene (60 km, one day, through the
    scene builder and Simulation): the leads of the spun-up pack refreeze with undamaged ice, so
    the pack ends less damaged than the same run without it. The steps' reports add up to the
    component's running total (the dynamics differ between the runs, so the difference of the
    damaged areas is only asserted in sign), and ice volume is conserved in both runs."""
    sets = {"domain.resolution_m": 60e3, "run.duration": "1d", "output.every": "1d", "checkpoint.every": "100d",
            "output.plot": False}
    runs, reported = {}, []

    def collect(sim):
        reported.append(sim.model.last_report["thermodynamics"]["damage_diluted_by_new_ice_m2"])

    for flag in (False, True):
        sim = scene_sim("winter_basin_pack", tmp_path / f"run-{flag}", {**sets, "thermo.new_ice_undamaged": flag})
        assert sim.model.component("thermodynamics").new_ice_undamaged is flag
        if flag:
            sim.add_callback(collect, "1 steps", needs_host_state=False)
        sim.run()
        runs[flag] = sim.model
    on, off = runs[True], runs[False]
    area_on = np.abs(on.state.mesh.areas())
    area_off = np.abs(off.state.mesh.areas())
    diluted = on.component("thermodynamics").damage_diluted_m2
    assert diluted > 0 and len(reported) == 144
    assert sum(reported) == pytest.approx(diluted, rel=1e-12)
    assert np.sum(on.state.damage * area_on) < np.sum(off.state.damage * area_off)
    for m in (on, off):
        assert abs(m.ledger.budget(m.state.ice_volume_m3)["relative_residual"]) < 1e-12


@pytest.mark.parametrize("sets,fragment", [
    ({"solver.name": "evp", "rheology.law": "viscous_plastic", "healing.law": "none"},
     "thermo.new_ice_undamaged = true: rheology.law = 'viscous_plastic' has no damage"),
])
def test_new_ice_undamaged_refused_where_it_would_do_nothing(monkeypatch, sets, fragment):
    """The viscous-plastic rheology has no damage: the setting is refused before meshing, with
    the key named. (With thermodynamics off it is named in the unused-keys warning instead:
    tests/test_workflow.py::test_unused_keys_of_each_component_and_kind.)"""
    from lagice.errors import ConfigError
    from lagice.scenes import builder, config

    def boom(*a, **k):
        raise AssertionError("meshing must not start")

    monkeypatch.setattr(builder, "generate_mesh", boom)
    with pytest.raises(ConfigError) as exc:
        builder.build_model(config.load_scene("winter_basin_pack", {"thermo.new_ice_undamaged": True, **sets}))
    assert fragment in str(exc.value)
