"""lagice.diagnostics.window_statistics: deformation statistics over back-to-back
Lagrangian windows of a run, checked on an analytic shear field (known rates,
known coast-buffer element count) and on a real run through the CLI
(``lagice diagnose --window-days`` reports the same numbers as the function, and
its last window the same as the single-window ``lagice diagnose``)."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import shapely

from lagice.diagnostics import summarise, window_arrays, window_statistics
from lagice.errors import ConfigError
from lagice.lagrangian import MeshMotion
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.model import Model
from lagice.simulation import Simulation
from lagice.solvers import PrescribedStepper
from lagice.state import IceState

DAY = 86400.0
L = 400e3
GAMMA = 2e-7  # s-1: simple shear u = GAMMA (y - L/2), v = 0 (about 1.7 % per day)


def shear(t, x, y):
    return GAMMA * (np.asarray(y) - 0.5 * L), np.zeros(np.shape(x))


def prescribed_run(out, velocity, resolution_m, dt, stop, every):
    """A free L × L square whose nodes move with ``velocity(t, x, y)`` (nothing fixed), run
    through Model/Simulation with snapshots every ``every`` in ``out/snapshots``; returns ``out``."""
    poly, _ = rectangle_domain(L, L)
    mesh = generate_mesh(poly, resolution_m, exterior_tag="free")
    st = IceState.uniform(mesh, thickness_m=1.0, concentration=1.0, cohesion_pa=1e9)
    model = Model(st, solver=PrescribedStepper(mesh=mesh, velocity=velocity), mover=MeshMotion())
    sim = Simulation(model, dt=dt, stop=stop, progress=False)
    sim.output(every=every, path=out / "snapshots", crs=None)
    sim.run()
    return out


@pytest.fixture(scope="module")
def shear_run(tmp_path_factory):
    """7 days of simple shear of a free 400 km square, 6-h steps, daily snapshots."""
    return prescribed_run(tmp_path_factory.mktemp("shear_run"), shear, 25e3, "6h", "7d", "1d")


def test_windows_of_an_analytic_shear(shear_run):
    buffer_km = 60.0
    res = window_statistics(shear_run, window_days=3.0, coast_buffer_km=buffer_km, start_day=1.0)
    w = res["windows"]
    assert [(x["start_day"], x["end_day"]) for x in w] == [(1.0, 4.0), (4.0, 7.0)]  # back to back, day 7 is the end
    assert res["skipped"] == []
    for x in w:
        for part in ("interior", "all"):
            s = x[part]
            # a linear velocity field with nilpotent gradient moves the nodes by exactly T·G·x:
            # the Lagrangian rates are the field's, element by element
            assert s["mean_shear_s"] == pytest.approx(GAMMA, rel=1e-9)
            assert s["mean_total_s"] == pytest.approx(GAMMA, rel=1e-9)
            assert s["mean_abs_divergence_s"] < 1e-9 * GAMMA
            # a uniform rate is the same at every scale: β = 0; half of the shear is on half the area
            assert abs(s["beta_space"]) < 1e-9
            assert s["localisation_half_shear_area_fraction"] == pytest.approx(0.5, rel=1e-9)
        # the coast buffer: elements whose centroid is >= 60 km inside the sheared square at
        # the window start (corners moved by u·t: a parallelogram), computed from the geometry
        t0 = x["start_day"] * DAY
        corners = np.array([[0, 0], [L, 0], [L, L], [0, L]], float)
        corners[:, 0] += GAMMA * (corners[:, 1] - 0.5 * L) * t0
        boundary = shapely.Polygon(corners).exterior
        xy0, _, tri, _, info = window_arrays(shear_run, t0, t0 + 3 * DAY)
        c = xy0[tri].mean(axis=1)
        dist = shapely.distance(shapely.points(c), boundary)
        assert x["n_elements"] == int(np.sum(dist >= buffer_km * 1e3)) < x["n_elements_all"] == tri.shape[0]
    # summaries over the windows: the median of two windows is their mean, [min, max] brackets it
    for k, med in res["median"].items():
        vals = [x["interior"][k] for x in w]
        if any(v is None or not np.isfinite(v) for v in vals):
            continue
        assert med == pytest.approx(np.mean(vals), rel=1e-12, abs=1e-15)
        assert res["min"][k] == min(vals) and res["max"][k] == max(vals)
    assert res["median"]["mean_total_s"] == pytest.approx(GAMMA, rel=1e-9)
    # the curve over every box of both windows (the observations' estimator): a uniform rate is
    # GAMMA in every box of every grid, so β = 0 pooled too, and the counts add up
    pooled = res["pooled"]
    assert pooled["n_windows"] == 2 and pooled["n_grid_curves"] == 2 * w[0]["interior"]["beta_space_grids"]
    assert abs(pooled["beta_space"]) < 1e-9 and abs(pooled["beta_space_grids"]) < 1e-9
    np.testing.assert_allclose(pooled["curve"]["mean_total_s"], GAMMA, rtol=1e-9)
    assert pooled["curve"]["n_boxes"][0] == sum(x["n_elements"] for x in w)
    # a uniform shear rate has no spread: its R² against |divergence| and its PDF tail are
    # undefined in every window (NaN), and the summary says so (None), not a number
    assert all(np.isnan(x["interior"]["shear_divergence_r2"]) for x in w)
    assert res["median"]["shear_divergence_r2"] is None and res["median"]["pdf_tail_exponent_shear"] is None


def test_windows_refuse_bad_input_naming_the_value(shear_run):
    with pytest.raises(ConfigError, match="window_days = 0"):
        window_statistics(shear_run, window_days=0.0)
    with pytest.raises(ConfigError, match="no whole window fits"):
        window_statistics(shear_run, window_days=3.0, start_day=5.0)
    with pytest.raises(ConfigError, match="coast_buffer_km = 300: only 0 elements"):
        window_statistics(shear_run, window_days=3.0, coast_buffer_km=300.0)
    with pytest.raises(ConfigError, match="start_day = -1"):
        window_statistics(shear_run, window_days=3.0, start_day=-1.0)


def _cli(*args):
    r = subprocess.run([sys.executable, "-m", "lagice.cli", *args], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    return r


@pytest.mark.slow
def test_cli_diagnose_windows_on_a_real_run(tmp_path):
    """shear_channel at 20 km for 4 days (prescribed shear, mesh motion, remeshing):
    ``lagice diagnose --window-days`` writes what window_statistics computes, and its
    last window is the single window of ``lagice diagnose --window-steps 2``."""
    run = tmp_path / "run"
    _cli("run", "shear_channel", "--out", str(run), "--set", "domain.resolution_m=20e3",
         "--set", "domain.params.vertex_spacing_m=20e3", "--set", "run.duration=4d", "--set", "output.every=12h",
         "--set", "output.plot=false", "--set", "run.progress=false")
    r = _cli("diagnose", str(run), "--window-days", "1", "--start-day", "1", "--coast-buffer-km", "15",
             "--out", str(tmp_path / "win"))
    assert "3 back-to-back windows of 1 days" in r.stdout
    assert r.stdout.count("(over 9 box grids ") == 3   # each window's β over nine grids, beside the default one
    got = json.loads((tmp_path / "win" / "window_statistics.json").read_text())
    ref = window_statistics(run, window_days=1.0, coast_buffer_km=15.0, start_day=1.0)
    assert [(w["start_day"], w["end_day"]) for w in got["windows"]] == [(1.0, 2.0), (2.0, 3.0), (3.0, 4.0)]
    for k in ref["median"]:
        assert got["median"][k] == pytest.approx(ref["median"][k], rel=1e-12)
        vals = [w["interior"][k] for w in ref["windows"]]
        assert got["median"][k] == pytest.approx(float(np.median(vals)), rel=1e-12)
        assert got["min"][k] <= got["median"][k] <= got["max"][k]
    # the prescribed field shears the channel: every window deforms, the interior less than the walls
    for w in got["windows"]:
        assert 10 <= w["n_elements"] < w["n_elements_all"]
        assert w["interior"]["mean_shear_s"] > 0
    one = _cli("diagnose", str(run), "--window-steps", "2", "--coast-buffer-km", "15", "--out", str(tmp_path / "one"))
    assert "elements are >= 15 km from the boundary" in one.stdout
    single = json.loads((tmp_path / "one" / "diagnostics.json").read_text())
    last = got["windows"][-1]
    assert single["n_elements"] == last["n_elements"]
    for k in ("beta_space", "beta_space_grid_mean", "beta_space_grid_sd", "mean_shear_s", "pdf_tail_exponent_shear",
              "localisation_half_shear_area_fraction"):
        assert single[k] == pytest.approx(last["interior"][k], rel=1e-12)
    # and the same numbers straight from the arrays
    xy0, xy1, tri, dt, info = window_arrays(run, 3 * DAY, 4 * DAY, 15e3)
    s = summarise(xy0, xy1, tri[info["interior"]], dt)
    assert s["beta_space"] == pytest.approx(last["interior"]["beta_space"], rel=1e-12)
    # the RGPS view: with --window-days it adds the cells' medians; without, it is refused by name
    rg = _cli("diagnose", str(run), "--window-days", "1", "--start-day", "1", "--coast-buffer-km", "15",
              "--rgps-error-m", "100", "--out", str(tmp_path / "rgps"))
    assert "as RGPS would see it (10 km cells, 100 m tracking error" in rg.stdout
    got_rgps = json.loads((tmp_path / "rgps" / "window_statistics.json").read_text())
    assert got_rgps["median"] == got["median"] and got_rgps["rgps_tracking_error_m"] == 100.0
    assert got_rgps["median_rgps"]["mean_total_s"] > got_rgps["median_rgps_cells"]["mean_total_s"] > 0
    bad = subprocess.run([sys.executable, "-m", "lagice.cli", "diagnose", str(run), "--rgps-error-m", "100"],
                         capture_output=True, text=True, timeout=600)
    assert bad.returncode != 0 and "--rgps-error-m = 100 needs --window-days" in bad.stderr


def test_window_statistics_as_rgps_would_see_them(shear_run):
    """A uniform simple shear seen through the operator: without error the cells give the
    field's rate exactly; with the 100 m error the mean rate rises by the error's part."""
    res = window_statistics(shear_run, window_days=3.0, coast_buffer_km=60.0, start_day=1.0,
                            rgps_tracking_error_m=100.0, rgps_seed=0)
    for w in res["windows"]:
        assert w["rgps_cells"]["mean_shear_s"] == pytest.approx(GAMMA, rel=1e-9)
        assert w["rgps_cells"]["tracking_error_m"] == 0.0
        assert w["rgps"]["n_cells"] == w["rgps_cells"]["n_cells"] > 100
        assert w["rgps"]["mean_total_s"] > w["rgps_cells"]["mean_total_s"]
    assert res["median_rgps_cells"]["mean_total_s"] == pytest.approx(GAMMA, rel=1e-9)
    assert res["rgps_tracking_error_m"] == 100.0
    # the pooled curve on the cells: a uniform rate has β = 0 without error; the error adds rate at the
    # cell scale that cancels in larger boxes, so β > 0 with it
    assert abs(res["pooled_rgps_cells"]["beta_space_grids"]) < 1e-9
    assert res["pooled_rgps"]["beta_space_grids"] > 0.0
    # the model part is unchanged by asking for the operator
    plain = window_statistics(shear_run, window_days=3.0, coast_buffer_km=60.0, start_day=1.0)
    assert plain["median"] == res["median"]


# -- an eddy that folds elements in the mid-window geometry ----------------------------------
R_EDDY = 200e3  # m: the eddy's radius
PHI_EDDY = 4.0  # rad: how far its centre turns in the 3-day window


def eddy_turn(r):
    """Angle [rad] a point at radius r [m] turns in the window, and s = r dφ/dr."""
    x = np.clip(r * r / R_EDDY**2, 0.0, 1.0)
    return PHI_EDDY * (1.0 - x) ** 2, -4.0 * PHI_EDDY * x * (1.0 - x)


def eddy(t, x, y):
    dx, dy = np.asarray(x) - 0.5 * L, np.asarray(y) - 0.5 * L
    w = eddy_turn(np.hypot(dx, dy))[0] / (3 * DAY)
    return -w * dy, w * dx


@pytest.fixture(scope="module")
def eddy_run(tmp_path_factory):
    """3 days of a steady eddy (differential rotation, no divergence) on a free 400 km square:
    the ring that turns by a little more than half a turn while it is sheared has every element
    fine at both ends, but inverted in the mid-window geometry (x0 + x1)/2."""
    return prescribed_run(tmp_path_factory.mktemp("eddy_run"), eddy, 10e3, "1h", "3d", "3d")


def test_windows_leave_out_and_count_elements_folded_mid_window(eddy_run, shear_run):
    from lagice.diagnostics.faults import interior_triangles
    from lagice.diagnostics.strain import triangle_geometry
    from lagice.io.snapshots import load_window

    w = load_window(eddy_run, 0.0, 3 * DAY)
    xy0, xy1, tri = w["xy0"], w["xy1"], w["triangles"]
    assert (triangle_geometry(xy0, tri)[0] > 0).all() and (triangle_geometry(xy1, tri)[0] > 0).all()
    folded = triangle_geometry(0.5 * (xy0 + xy1), tri)[0] <= 0
    # the folds are where the continuum map A = R(φ) [[1, 0], [s, 1]] (local radial/tangential
    # frame) has det(I + A) = 2 + 2 cos φ − s sin φ < 0: turned past half a turn while sheared
    r = np.hypot(*(xy0[tri].mean(axis=1) - 0.5 * L).T)
    phi, s = eddy_turn(r)
    det_mid = 2.0 + 2.0 * np.cos(phi) - s * np.sin(phi)
    assert not np.any(folded & (det_mid > 0.2)) and not np.any(~folded & (det_mid < -0.2))
    assert 50 < folded.sum() < 0.2 * tri.shape[0]

    res = window_statistics(eddy_run, window_days=3.0, coast_buffer_km=60.0, start_day=0.0)
    (win,) = res["windows"]
    assert win["n_elements_folded"] == res["n_elements_folded"] == int(folded.sum())
    _, _, kept, _, info = window_arrays(eddy_run, 0.0, 3 * DAY, coast_buffer_m=60e3)
    inside = info["interior"]
    assert win["n_elements_all"] == kept.shape[0] == tri.shape[0] - folded.sum()
    assert 0 < win["n_interior_folded"] == res["n_interior_folded"] <= win["n_elements_folded"]
    n_inside = int(interior_triangles(*w["start_mesh"], 60e3).sum())  # no remesh: every element followed
    assert win["n_elements"] == int(inside.sum()) == n_inside - win["n_interior_folded"]
    # the statistics are those of the unfolded elements
    s_all = summarise(xy0, xy1, tri[~folded], 3 * DAY)
    for k in ("mean_shear_s", "mean_total_s", "beta_space", "shear_divergence_r2"):
        assert win["all"][k] == pytest.approx(s_all[k], rel=1e-12)
    # the whole window as one set would raise (the diagnostics refuse an inverted cell) ...
    with pytest.raises(ConfigError, match="non-positive area"):
        summarise(xy0, xy1, tri, 3 * DAY)
    # the command line says so, in the window's line, and writes the counts
    r = _cli("diagnose", str(eddy_run), "--window-days", "3", "--start-day", "0", "--coast-buffer-km", "60",
             "--out", str(eddy_run / "win"))
    assert (f"{win['n_elements_folded']} inverted in the mid-window geometry left out "
            f"({win['n_interior_folded']} inside the buffer)") in r.stdout
    got = json.loads((eddy_run / "win" / "window_statistics.json").read_text())
    assert got["n_interior_folded"] == win["n_interior_folded"] and got["median"] == res["median"]
    # ... and a run without folds counts none and keeps every element
    calm = window_statistics(shear_run, window_days=3.0, coast_buffer_km=60.0, start_day=1.0)
    assert calm["n_elements_folded"] == 0 and all(x["n_elements_folded"] == 0 for x in calm["windows"])


def test_beta_components_count_folded_elements_apart_from_remeshed_ones(eddy_run):
    """benchmarks/beta_components.py reads windows through window_arrays: the eddy's folded ring is
    left out and counted as folded, not as remeshed area (it was 11 % of the interior before)."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    from beta_components import run_components

    res = run_components(eddy_run, window_days=3.0, start_day=0.0, coast_buffer_m=60e3, patches=True)
    (row,) = res["windows"]
    ref = window_statistics(eddy_run, window_days=3.0, coast_buffer_km=60.0, start_day=0.0)
    assert row["folded_elements"] == ref["n_elements_folded"] > 0
    assert row["remeshed_elements"] == 0 and row["interior_area_remeshed_fraction"] == 0.0


def test_ensemble_member_statistics_are_those_of_lagice_diagnose(eddy_run, shear_run):
    """An ensemble member's statistics (``lagice.ensemble.member.member_diagnostics``: windows
    ending at the last snapshot) go through the windows of ``lagice diagnose --window-days``:
    the same numbers for the same windows. On the eddy, whose ring folds in the mid-window
    geometry, they leave the folded elements out and count them (the ensemble's own path
    used to fail there with a diagnostics error and NaN statistics)."""
    from lagice.ensemble.member import DIAG_KEYS, member_diagnostics

    def medians(res):
        return {k: float(np.median([np.nan if w["interior"][k] is None else w["interior"][k]
                                    for w in res["windows"]])) for k in DIAG_KEYS}

    d = member_diagnostics(eddy_run, {"window_s": 3 * DAY, "windows": 1, "coast_buffer_km": 60.0})
    res = window_statistics(eddy_run, window_days=3.0, coast_buffer_km=60.0, start_day=0.0)
    assert d["diag_status"] == "ok"
    assert d["diag_n_folded"] == res["n_interior_folded"] > 0
    assert d["diag_n_elements"] == res["windows"][0]["n_elements"]
    for k, v in medians(res).items():
        assert d[k] == pytest.approx(v, rel=1e-12, abs=0.0), k
    # two 3-day windows ending at day 7 are days 1-4 and 4-7: window_statistics from day 1
    d2 = member_diagnostics(shear_run, {"window_s": 3 * DAY, "windows": 2, "coast_buffer_km": 60.0})
    res2 = window_statistics(shear_run, window_days=3.0, coast_buffer_km=60.0, start_day=1.0)
    assert d2["diag_n_windows"] == 2 and d2["diag_n_folded"] == 0
    m2 = medians(res2)
    nan_keys = [k for k in DIAG_KEYS if not np.isfinite(m2[k])]  # a uniform shear has no PDF tail, no R²
    assert nan_keys and d2["diag_status"] == f"partial: not computable: {', '.join(nan_keys)}"
    for k, v in m2.items():
        assert d2[k] == pytest.approx(v, rel=1e-12, abs=0.0, nan_ok=True), k
    # a buffer that leaves too few elements is a status, not an exception
    d3 = member_diagnostics(shear_run, {"window_s": 3 * DAY, "windows": 1, "coast_buffer_km": 500.0})
    assert d3["diag_status"].startswith("too_few_elements:") and "coast_buffer_km = 500" in d3["diag_status"]
