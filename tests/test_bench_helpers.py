"""Benchmark helpers that change what a benchmark builds (benchmarks/scene_runs.py)."""
from __future__ import annotations

import dataclasses
import json
import re
import sys
from pathlib import Path

import numpy as np
import pytest

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


def test_screen_verdict_counts_bands_and_applies_the_stated_tolerances():
    """The screen rule of the physics experiments, made mechanical: more bands inside than
    the reference, and neither β nor the rate further from its band than the tolerances
    (the rate's distance is a factor). The eighth session's second stage: 4 bands against
    3, but β 0.0550 against 0.0552, 0.0002 further, fails with no tolerance and passes
    with one of 0.01."""
    from physics_experiments import TARGETS, band_distance, screen_verdict

    ref = {"beta_space": 0.0552, "pdf_tail_exponent_shear": 2.24, "pdf_tail_exponent_divergence": 2.16,
           "localisation_half_shear_area_fraction": 0.051, "shear_divergence_r2": 0.731,
           "mean_total_deformation_rate_per_day": 0.00215}
    cand = {**ref, "beta_space": 0.0550, "pdf_tail_exponent_divergence": 2.51,
            "mean_total_deformation_rate_per_day": 0.00261}
    assert set(ref) == set(TARGETS)
    v = screen_verdict(cand, ref)
    assert v["bands_inside"] == {"candidate": 4, "reference": 3}
    assert v["beta_further_by"] == pytest.approx(0.0002) and not v["beta_ok"] and not v["passes"]
    assert v["rate_ok"] and v["rate_further_by_factor"] == pytest.approx(0.00215 / 0.00261)
    assert screen_verdict(cand, ref, beta_tolerance=0.01)["passes"]
    # the rate's distance is a factor: 0.005 is ×2 below the band's 0.01, as 0.1 is ×2 above 0.05
    assert band_distance("mean_total_deformation_rate_per_day", 0.005) == pytest.approx(
        band_distance("mean_total_deformation_rate_per_day", 0.1))
    slower = {**cand, "beta_space": 0.06, "mean_total_deformation_rate_per_day": 0.0015}
    v = screen_verdict(slower, ref)
    assert v["beta_ok"] and not v["rate_ok"] and not v["passes"]
    assert screen_verdict(slower, ref, rate_tolerance_factor=1.5)["passes"]
    assert not screen_verdict(ref, ref, beta_tolerance=1.0, rate_tolerance_factor=10.0)["passes"]  # no band gained


def test_paired_band_moves_tells_a_shift_from_the_months_spread():
    """Rule NS's test (forty-ninth session): the move of an eight-month median away from its
    band, with a 90 % interval from resampling months in pairs. The same runs move by
    nothing; a β lowered by 0.03 in every month is worse with an interval clear of 0; one
    month moved alone leaves the interval across 0; a metric that stays inside its band does
    not move; a rate moved closer to its band is a negative move; unequal lists are refused."""
    from physics_experiments import TARGETS, paired_band_moves

    rng = np.random.default_rng(3)
    base = {"beta_space": 0.03 + 0.04 * rng.random(8), "pdf_tail_exponent_shear": 2.0 + 0.4 * rng.random(8),
            "pdf_tail_exponent_divergence": 1.8 + 1.2 * rng.random(8),
            "localisation_half_shear_area_fraction": 0.03 + 0.05 * rng.random(8),
            "shear_divergence_r2": 0.65 + 0.15 * rng.random(8),
            "mean_total_deformation_rate_per_day": 10 ** (-3.5 + 1.5 * rng.random(8))}
    assert set(base) == set(TARGETS)

    def records(tag, change):
        return {f"{tag}{i}": {"median": {k: float(change(k, i, v[i])) for k, v in base.items()}} for i in range(8)}

    ref = records("r", lambda k, i, v: v)
    names_r = list(ref)
    same = paired_band_moves(names_r, names_r, ref)
    assert all(m["move"] == 0.0 and m["lo"] == 0.0 and m["hi"] == 0.0 and not m["worse"] for m in same.values())
    lower = records("c", lambda k, i, v: v - 0.03 if k == "beta_space" else v)
    allr = {**ref, **lower}
    m = paired_band_moves(list(lower), names_r, allr)
    assert m["beta_space"]["move"] == pytest.approx(0.03) and m["beta_space"]["lo"] > 0 and m["beta_space"]["worse"]
    one = records("o", lambda k, i, v: v - 0.03 if (k == "beta_space" and i == 0) else v)
    m = paired_band_moves(list(one), names_r, {**ref, **one})
    assert m["beta_space"]["lo"] <= 0.0 <= m["beta_space"]["hi"] and not m["beta_space"]["worse"]
    # R² shifted inside its band (0.73-0.93) in every month: no move; the rate x2 towards its band: closer
    inside = records("i", lambda k, i, v: (0.80 if k == "shear_divergence_r2" else
                                           2 * v if k == "mean_total_deformation_rate_per_day" else v))
    inside_ref = records("j", lambda k, i, v: 0.85 if k == "shear_divergence_r2" else v)
    m = paired_band_moves(list(inside), list(inside_ref), {**inside, **inside_ref})
    assert m["shear_divergence_r2"]["move"] == 0.0 and not m["shear_divergence_r2"]["worse"]
    rate = m["mean_total_deformation_rate_per_day"]
    assert rate["move"] < 0 and rate["hi"] < 0
    with pytest.raises(ValueError, match="7 candidate runs against 8"):
        paired_band_moves(names_r[:7], names_r, ref)


def test_screen_verdict_applies_the_twelfth_sessions_rule():
    """The two-stage rule of 2026-11-27 (at least as many bands, the rate ×2 or more, β no
    more than 0.005 further, the wind factor in 0.006-0.010) on the eight-month medians the
    twelfth session recorded: the halved strength with hnull passes in the closed basin (3
    bands against 3) and fails in the strait (2 against 3), as docs/physics.md reports; a
    wind factor outside its band or a rate short of ×2 fails on its own."""
    from physics_experiments import screen_verdict

    rule = {"beta_tolerance": 0.005, "band_gain": 0, "rate_gain": 2.0, "wind_factor_band": (0.006, 0.010)}
    keys = ("beta_space", "pdf_tail_exponent_shear", "pdf_tail_exponent_divergence",
            "localisation_half_shear_area_fraction", "shear_divergence_r2", "mean_total_deformation_rate_per_day")
    closed = dict(zip(keys, (0.0513, 2.383, 2.396, 0.0577, 0.7208, 0.008373)), wind_factor=0.00749)
    closed_ref = dict(zip(keys, (0.0467, 2.319, 2.113, 0.0485, 0.7583, 0.001800)))
    strait = dict(zip(keys, (0.0596, 2.636, 2.454, 0.0620, 0.7056, 0.008180)), wind_factor=0.00788)
    strait_ref = dict(zip(keys, (0.0552, 2.240, 2.160, 0.0509, 0.7305, 0.002151)))
    v = screen_verdict(closed, closed_ref, **rule)
    assert v["bands_inside"] == {"candidate": 3, "reference": 3} and v["passes"]
    assert v["rate_ratio"] == pytest.approx(4.65, abs=0.01) and v["beta_further_by"] < 0
    v = screen_verdict(strait, strait_ref, **rule)
    assert v["bands_inside"] == {"candidate": 2, "reference": 3} and not v["bands_ok"] and not v["passes"]
    assert v["rate_gain_ok"] and v["wind_factor_ok"] and v["beta_ok"]
    assert not screen_verdict({**closed, "wind_factor": 0.0055}, closed_ref, **rule)["passes"]
    slow = {**closed, "mean_total_deformation_rate_per_day": 1.9 * closed_ref["mean_total_deformation_rate_per_day"]}
    v = screen_verdict(slow, closed_ref, **rule)
    assert not v["rate_gain_ok"] and not v["passes"]
    # the rule of 2026-11-26 (one band more) fails the closed basin's 3 against 3
    assert not screen_verdict(closed, closed_ref, beta_tolerance=0.005)["passes"]


def test_validation_headline_reports_the_wind_factor_against_its_band():
    """benchmarks/validate.py's headline row of the wind factor: ✓ inside Thorndike and Colony's
    band, ✗ outside, – for a run without a drift response (no drifters, or not the climatology)."""
    import validate

    lo, hi = validate.WIND_FACTOR_BAND
    median = {k: 0.5 * (a + b) for k, (a, b, _s, _n) in validate.TARGETS.items()}

    def run(factor):
        return {"median": median, "remesh_events": 3, "drift_km": {"mean": 10.0, "max": 20.0},
                "resolution_m": 10e3, "drift_response": None if factor is None else {"wind_factor": factor}}

    res = {"basin": {"closed": {"maxwell_eb": run(0.5 * (lo + hi)), "evp": run(0.3 * lo)},
                     "strait": {"maxwell_eb": run(None), "evp": run(1.5 * hi)}}}
    row = next(line for line in validate.headline(res) if line.startswith("| wind factor"))
    cells = [c.strip() for c in re.split(r"(?<!\\)\|", row.strip("|"))][2:]  # "\\|A\\|" is escaped
    assert cells == [f"{0.5 * (lo + hi):.4f} ✓", f"{0.3 * lo:.4f} ✗", "–", f"{1.5 * hi:.4f} ✗"]


def test_validation_headline_adds_the_grid_mean_beta_row_only_when_every_run_has_it():
    """The β over nine box grids is a row of its own under β, judged against β's band and not
    counted; records made before it (no ``beta_space_grid_mean``) keep the old table."""
    import validate

    lo, hi = validate.TARGETS["beta_space"][:2]
    base = {k: 0.5 * (a + b) for k, (a, b, _s, _n) in validate.TARGETS.items()}

    def run(grid_beta):
        median = dict(base) if grid_beta is None else {**base, validate.GRID_BETA: grid_beta}
        return {"median": median, "remesh_events": 3, "drift_km": {"mean": 10.0, "max": 20.0},
                "resolution_m": 10e3, "drift_response": None}

    res = {"basin": {"closed": {"maxwell_eb": run(0.5 * (lo + hi))}, "strait": {"maxwell_eb": run(0.3 * lo)}}}
    lines = validate.headline(res)
    i = next(n for n, line in enumerate(lines) if line.startswith("| β, ⟨ε̇tot⟩"))
    assert lines[i + 1].startswith(f"| {validate.GRID_BETA_LABEL} |")
    cells = [c.strip() for c in lines[i + 1].strip("|").split("|")][2:]
    assert cells == [f"{0.5 * (lo + hi):.2f} ✓", f"{0.3 * lo:.2f} ✗"]
    res["basin"]["strait"]["maxwell_eb"] = run(None)
    assert not any(line.startswith(f"| {validate.GRID_BETA_LABEL}") for line in validate.headline(res))


def test_a_run_never_imports_the_analysis_code_that_validate_leaves_out_of_its_provenance(tmp_path):
    """validate.ANALYSIS_CODE (lagice/diagnostics) is left out of the model code whose changes
    flag a reused run: that holds only while a run's time stepping never imports it. A real
    ``lagice run`` (the compression plate, a few steps, with its plot) checks it, and the
    provenance check must still see a change to the model proper."""
    import subprocess
    import sys

    import validate

    code = ("import sys; from lagice.cli import main; rc = main(['run', 'uniaxial_compression', '--out', sys.argv[1], "
            "'--set', 'domain.resolution_m=12500', '--set', 'run.duration=2000s']); "
            "print('LOADED', sorted(m for m in sys.modules if m.startswith('lagice.diagnostics'))); sys.exit(rc)")
    r = subprocess.run([sys.executable, "-c", code, str(tmp_path / "run")], capture_output=True, text=True,
                       timeout=600)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "run" / "snapshots").is_dir()
    assert "LOADED []" in r.stdout, r.stdout[-500:]
    assert validate.ANALYSIS_CODE == ("lagice/diagnostics",)
    # the exclusion is only of the analysis folder: a model file modified in a dirty tree still counts
    head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=validate.ROOT, capture_output=True,
                          text=True).stdout.strip()
    assert "lagice/diagnostics/scaling.py" not in validate.model_code_changes(head + "-dirty",
                                                                              ["lagice/diagnostics/scaling.py"])
    assert "lagice/model.py" in validate.model_code_changes(head + "-dirty", ["lagice/model.py"])


def test_drift_response_store_keeps_the_published_records_in_a_fresh_checkout(tmp_path, monkeypatch):
    """A fresh checkout has no benchmarks/out/physics/drift_response.json: the first new run
    must be added to the published records, not replace them (it did until the tenth
    session), and the published copy stays without the daily speed pairs."""
    import json

    import drift_response as dr

    published = tmp_path / "published.json"
    key = "observed_thorndike_colony_1982_winter"
    published.write_text(json.dumps({key: {"factor": [0.006, 0.01]}, "OLD": {"name": "OLD", "fit": {"factor": 0.003}}}))
    monkeypatch.setattr(dr, "STORE", tmp_path / "out" / "store.json")
    monkeypatch.setattr(dr, "PUBLISHED", published)
    (tmp_path / "out").mkdir()
    dr.store({"name": "NEW", "fit": {"factor": 0.007}, "daily_speeds_g_u_m_s": [[1.0, 0.01]]})
    full = json.loads(dr.STORE.read_text())
    slim = json.loads(published.read_text())
    assert set(full) == set(slim) == {key, "NEW", "OLD"}
    assert full["OLD"]["fit"]["factor"] == 0.003 and full["NEW"]["daily_speeds_g_u_m_s"] == [[1.0, 0.01]]
    assert "daily_speeds_g_u_m_s" not in slim["NEW"]
    assert full[key] == json.loads(json.dumps(dr.OBSERVED))  # the observed band is always the module's


def _store_many(prefix: str, n: int) -> None:
    import drift_response as dr

    for i in range(n):
        dr.store({"name": f"{prefix}{i}", "fit": {"factor": 0.007}})


def test_drift_response_store_keeps_every_record_when_analyses_finish_together(tmp_path, monkeypatch):
    """Two queues of runs analysed side by side write the store at the same time: every record
    must survive (without the lock one process's read-modify-write dropped the other's record,
    forty-first session). Four processes, 25 records each."""
    import json
    import multiprocessing as mp

    import drift_response as dr

    published = tmp_path / "published.json"
    published.write_text(json.dumps({"OLD": {"name": "OLD", "fit": {"factor": 0.003}}}))
    monkeypatch.setattr(dr, "STORE", tmp_path / "out" / "store.json")
    monkeypatch.setattr(dr, "PUBLISHED", published)
    ctx = mp.get_context("fork")  # the children inherit the patched paths
    procs = [ctx.Process(target=_store_many, args=(f"P{k}-", 25)) for k in range(4)]
    for p in procs:
        p.start()
    for p in procs:
        p.join(60)
        assert p.exitcode == 0
    full = json.loads(dr.STORE.read_text())
    slim = json.loads(published.read_text())
    expected = {"OLD", dr.OBSERVED_KEY} | {f"P{k}-{i}" for k in range(4) for i in range(25)}
    assert set(full) == set(slim) == expected


def test_physics_run_queues_deal_the_runs_round_robin_and_check_names_first(monkeypatch):
    """``physics_experiments.py run ... --jobs N``: the closed/strait pairs of a set-up, listed
    in pairs, land one basin per queue in their order; an unknown name, or a run whose scene
    overrides do not resolve, stops the command before any run starts."""
    import physics_experiments as pe

    monkeypatch.setattr(pe, "SCENE_DIRS", {})   # today's scene files (those of an earlier commit come from git)
    names = ["F10-hthick-hnullsp", "F10s-hthick-hnullsp", "F10-hthick-hnullsp-w2027", "F10s-hthick-hnullsp-w2027",
             "F10-hthick-hnullsp-w2028"]
    assert pe.queues(names, 2) == [names[0::2], names[1::2]]
    assert pe.queues(names[:1], 3) == [names[:1]]  # no empty queue
    assert pe.queues(names, 1) == [names]
    with pytest.raises(SystemExit, match="--jobs 0"):
        pe.queues(names, 0)
    started = []
    monkeypatch.setattr(pe.subprocess, "Popen", lambda *a, **k: started.append(a))
    with pytest.raises(SystemExit, match="unknown experiment 'F10-nope'"):
        pe.run_queues(names + ["F10-nope"], 2)
    assert started == []
    # a defined run whose overrides do not resolve stops the queue before it starts too
    scene, overrides, *rest = pe.EXPERIMENTS["F10-hthick-hnullsp"]
    bad = {"F10-bad-key": (scene, [*overrides, "rheology.no_such_key=1"], *rest),
           "F10-twice": (scene, [*overrides, "run.seed=1", "run.seed=2"], *rest)}
    monkeypatch.setattr(pe, "EXPERIMENTS", {**pe.EXPERIMENTS, **bad})
    for name in bad:
        with pytest.raises(SystemExit, match=rf"experiment '{name}' \(scene \S*winter_basin_pack\.toml\) does not "
                                             "resolve"):
            pe.run_queues(names + [name], 2)
    assert started == []
    # the command line takes the names before or after --jobs (argparse read none after it, 2026-11-29)
    monkeypatch.setattr(pe, "prepare_inputs", lambda: None)  # no inputs written into the checkout
    for argv in (["run", "--jobs", "2", *names[:2], "F10-nope"], ["run", *names[:2], "F10-nope", "--jobs", "2"]):
        with pytest.raises(SystemExit, match="unknown experiment 'F10-nope'"):
            pe.main(argv)
    assert started == []


def test_physics_queue_goes_on_after_a_failed_run_and_then_fails(monkeypatch):
    """A run (or its analysis) that fails in a queue does not stop the runs after it: each is
    attempted in order, and the command fails at the end naming the failed ones."""
    import physics_experiments as pe

    from lagice.errors import ConfigError

    names = ["F10-hthick-hnullsp", "F10s-hthick-hnullsp", "F10-hthick-hnullsp-w2027"]
    tried = []

    def fake(name, force=False, run=True):
        tried.append(name)
        if name == names[0]:
            raise ConfigError("4 triangle(s) have non-positive area")
        if name == names[1]:
            raise SystemExit(f"physics: {name} failed; log x")
        return {}

    monkeypatch.setattr(pe, "run_experiment", fake)
    with pytest.raises(SystemExit, match=r"2 of 3 failed: F10-hthick-hnullsp, F10s-hthick-hnullsp"):
        pe.run_each(names)
    assert tried == names
    tried.clear()
    pe.run_each(names[2:])  # none failed: no exit
    assert tried == names[2:]


def test_every_physics_experiment_resolves_to_a_valid_scene(tmp_path, monkeypatch):
    """Each run and spin-up of benchmarks/physics_experiments.py is a bundled scene with
    ``--set`` overrides; a key given twice with two values or a key the scene does not know
    would stop that run only when its turn came (hours into a queue). All of them resolve
    here (the checks that need a run's input files, such as its spin-up state, are left to
    the run), and a screened set's overrides reach the resolved scene."""
    import physics_experiments as pe

    from lagice.scenes.config import load_scene

    # the definitions made before 2026-11-30's scene change read that commit's scene files (written from git)
    folder = tmp_path / "scenes"
    try:
        pe.write_scenes(pe.SCENES_BEFORE_NS_COMMIT, folder)
    except SystemExit as exc:   # a clone without that commit (shallow): said, not silently passed
        pytest.skip(f"git history without commit {pe.SCENES_BEFORE_NS_COMMIT}: {exc}")
    monkeypatch.setattr(pe, "SCENE_DIRS", {k: folder for k in pe.SCENE_DIRS})
    shipped = {sc: load_scene(name) for sc, name in pe.SCENES.items()}
    for name, (scene, overrides, _res, _days, _what) in pe.EXPERIMENTS.items():
        cfg = load_scene(str(pe.scene_file(name)), overrides)
        assert cfg["scene"]["name"] == shipped[scene]["scene"]["name"], name
    for name, (overrides, _target, _res) in pe.SPINUPS.items():
        if overrides is not None:
            load_scene(str(pe.scene_file(f"spinup:{name}")), overrides)
    # a definition made before the change keeps the values of then; the runs of the change read today's scene
    before = load_scene(str(pe.scene_file("F10-hthick-m10")), pe.EXPERIMENTS["F10-hthick-m10"][1])
    after = load_scene(str(pe.scene_file("F10-hthick-src-m10")), pe.EXPERIMENTS["F10-hthick-src-m10"][1])
    assert before["forcing"]["drag"].get("turning_angle_deg", 0.0) == 0.0
    assert after["forcing"]["drag"]["turning_angle_deg"] == 25.0
    assert pe.scene_file("F10-hthick-src-m10") == pe.EXAMPLES / "winter_basin_pack.toml"
    # the screened set's own overrides reach the scene
    cfg = load_scene(pe.SCENES["closed"], pe.EXPERIMENTS["F10-hthick-str50hnullsp"][1])
    assert cfg["rheology"]["strength_lab_pa"] == 1.4e6 and cfg["thermo"]["params"]["new_ice_thickness_m"] == 0.25
    assert cfg != shipped["closed"]


def test_a_physics_run_is_not_made_again_under_its_name_with_other_settings(tmp_path, monkeypatch):
    """physics_experiments.check_settings: a run recorded as made from a commit's scene file with some
    overrides may be made again by a definition that resolves to the same settings (with the scene
    files of that commit, from git), and is refused, naming the key, once the definition (or the scene)
    gives another value; a run made from a work tree whose scene files were modified cannot be checked
    and is let through (with a note)."""
    import json
    import subprocess

    import physics_experiments as pe

    head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=pe.ROOT, capture_output=True, text=True,
                          check=True).stdout.strip()
    if subprocess.run(["git", "diff", "--quiet", "HEAD", "--", "examples"], cwd=pe.ROOT).returncode != 0:
        pytest.skip("examples/ differs from HEAD in this work tree: the test compares HEAD's scene files")
    monkeypatch.setattr(pe, "OUT", tmp_path)
    name = "T10-check"
    (tmp_path / name).mkdir()
    made = pe.command("closed", ["rheology.friction=0.9"], 10e3, 28, tmp_path / name)
    line = " ".join(made[2:]).replace("lagice.cli", str(pe.ROOT / "lagice" / "cli.py"), 1)
    marker = {"command": line, "git_commit": head, "git_modified_files": [], "fingerprint": "x"}
    (tmp_path / name / "lagice_run.json").write_text(json.dumps(marker))
    pe.check_settings(name, pe.command("closed", ["rheology.friction=0.9"], 10e3, 28, tmp_path / name))
    with pytest.raises(SystemExit, match="rheology.friction: 0.9 then, 0.8 now"):
        pe.check_settings(name, pe.command("closed", ["rheology.friction=0.8"], 10e3, 28, tmp_path / name))
    # the scene file of another folder (today's is copied there with one value changed): refused too
    other = tmp_path / "scenes-other"
    pe.write_scenes("HEAD", other)
    text = (other / "winter_basin_pack.toml").read_text()
    (other / "winter_basin_pack.toml").write_text(text.replace("air_drag = 2.0e-3", "air_drag = 1.5e-3"))
    with pytest.raises(SystemExit, match="forcing.drag.air_drag"):
        pe.check_settings(name, pe.command("closed", ["rheology.friction=0.9"], 10e3, 28, tmp_path / name,
                                           other / "winter_basin_pack.toml"))
    # made from a work tree whose scene files were modified: not checked
    marker["git_modified_files"] = ["examples/winter_basin_pack.toml"]
    (tmp_path / name / "lagice_run.json").write_text(json.dumps(marker))
    pe.check_settings(name, pe.command("closed", ["rheology.friction=0.8"], 10e3, 28, tmp_path / name))


def test_beta_components_separate_a_coherent_convergence_from_cancelling_shear():
    """benchmarks/beta_components.py on two synthetic gradient fields on 8 km cells over 400 km:
    (1) a uniform convergence (∂u/∂x = ∂v/∂y = −a) under shear bands of alternating sense
    (∂v/∂x = b cos(2π x / 40 km)): the net-divergence ratio is −1, the divergence part does not
    cancel between scales (β = 0: every box holds the same divergence) and the shear part does
    (β > 0.2), and the whole lies between; (2) opening and closing bands (∂u/∂x = b cos(2π x /
    40 km)): the ratio is near 0 and the divergence part cancels (β > 0.2)."""
    from beta_components import window_components

    from lagice.diagnostics.strain import ElementStrainRates

    h = 8e3
    cx, cy = np.meshgrid(np.arange(50) * h + h / 2, np.arange(50) * h + h / 2)
    cen = np.column_stack([cx.ravel(), cy.ravel()])
    area = np.full(len(cen), h * h)
    wave = np.cos(2.0 * np.pi * cen[:, 0] / 40e3)
    a, b = 1e-7, 1e-6

    def components(grad):
        return window_components(ElementStrainRates(grad, area, cen, np.array([0.0, 0.0, 400e3, 400e3])))

    g = np.zeros((len(cen), 2, 2))
    g[:, 0, 0] = g[:, 1, 1] = -a
    g[:, 1, 0] = b * wave
    conv = components(g)
    assert conv["net_divergence_ratio"] == pytest.approx(-1.0, abs=1e-12)
    assert abs(conv["beta_divergence_part"]) < 1e-9
    assert conv["beta_shear_part"] > 0.2
    assert conv["beta_divergence_part"] < conv["beta"] < conv["beta_shear_part"]
    g = np.zeros((len(cen), 2, 2))
    g[:, 0, 0] = b * wave
    bands = components(g)
    assert abs(bands["net_divergence_ratio"]) < 0.1
    assert bands["beta_divergence_part"] > 0.2


def test_a_remeshed_patch_is_added_back_with_the_gradient_of_its_boundary():
    """beta_components.patch_cells: a patch of triangles whose inner nodes are gone (NaN end
    positions, as after a remesh) gets the area-mean gradient of a linear velocity field
    exactly, from its boundary nodes alone, with its mid-window area and centroid; a patch
    with a boundary node gone is left out and its start area counted."""
    import shapely
    from beta_components import patch_cells

    from lagice.mesh import generate_mesh

    mesh = generate_mesh(shapely.box(0.0, 0.0, 200e3, 200e3), 10e3)
    xy0, tri = mesh.nodes, mesh.triangles
    grad = np.array([[2e-7, -1e-7], [3e-7, -0.5e-7]])
    dt = 86400.0
    xy1 = xy0 + dt * (xy0 - 100e3) @ grad.T
    cen = xy0[tri].mean(axis=1)
    in_patch = np.hypot(cen[:, 0] - 100e3, cen[:, 1] - 100e3) < 35e3
    inner = np.setdiff1d(np.unique(tri[in_patch]), np.unique(tri[~in_patch]))
    assert inner.size > 3
    end = xy1.copy()
    end[inner] = np.nan
    g, a, c, used, dropped = patch_cells(xy0, end, tri[in_patch], dt)
    assert g.shape == (1, 2, 2) and dropped == 0.0
    # the gradient on the mid-window geometry x_mid = x0 + Δt/2 · u (as lagrangian_velocity_gradients)
    assert np.allclose(g[0], grad @ np.linalg.inv(np.eye(2) + 0.5 * dt * grad), rtol=1e-9, atol=0)

    def areas(p):
        return 0.5 * np.abs((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                            - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0]))

    mid = 0.5 * (xy0 + xy1)[tri[in_patch]]
    assert a[0] == pytest.approx(areas(mid).sum(), rel=1e-12)
    assert np.allclose(c[0], (areas(mid)[:, None] * mid.mean(axis=1)).sum(axis=0) / areas(mid).sum(), rtol=1e-9)
    assert used == pytest.approx(areas(xy0[tri[in_patch]]).sum(), rel=1e-12)
    boundary = np.setdiff1d(np.unique(tri[in_patch]), inner)
    end[boundary[0]] = np.nan
    g, a, c, used2, dropped2 = patch_cells(xy0, end, tri[in_patch], dt)
    assert g.shape == (0, 2, 2) and used2 == 0.0 and dropped2 == pytest.approx(used)


def test_archipelago_basin_keeps_the_shipped_coast_and_meshes_with_its_islands():
    """The archipelago diagnostic (physics_experiments.py, sixteenth session) changes only the
    islands: the outer ring is the shipped coastline vertex for vertex (the strait scene's
    open segment runs through those vertices), the shipped island stays, the seven new islands
    keep the stated clearances, and gmsh meshes the basin with every island as a hole."""
    import json

    import physics_experiments as pe
    from shapely.geometry import Polygon, shape

    from lagice.mesh.generate import generate_mesh

    shipped = json.loads((pe.ROOT / "data_stubs" / "winter_basin_coast.geojson").read_text())
    ship_rings = shipped["features"][0]["geometry"]["coordinates"]
    g = pe.archipelago_basin()
    rings = g["features"][0]["geometry"]["coordinates"]
    assert len(rings) == 2 + len(pe.ARCHIPELAGO)
    np.testing.assert_array_equal(np.asarray(rings[0]), np.asarray(ship_rings[0]))
    assert Polygon(rings[1]).equals(Polygon(ship_rings[1]))
    basin = shape(g["features"][0]["geometry"])
    assert basin.is_valid
    outer = Polygon(rings[0])
    islands = [Polygon(r) for r in rings[1:]]
    for i, isl in enumerate(islands[1:]):
        assert isl.distance(outer.exterior) >= 20e3
        assert min(isl.distance(o) for j, o in enumerate(islands) if j != i + 1) >= 40e3
        # radius as stated: area of the perturbed circle within 10 % of pi R^2
        r = pe.ARCHIPELAGO[i][1]
        assert abs(isl.area / (np.pi * r * r) - 1.0) < 0.1
    mesh = generate_mesh(basin, 40e3, algorithm=5)
    e1 = mesh.nodes[mesh.triangles[:, 1]] - mesh.nodes[mesh.triangles[:, 0]]
    e2 = mesh.nodes[mesh.triangles[:, 2]] - mesh.nodes[mesh.triangles[:, 0]]
    area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum()
    assert abs(area / basin.area - 1.0) < 0.01
    centroids = mesh.nodes[mesh.triangles].mean(axis=1)
    for isl in islands:  # no element inside an island
        c = np.asarray(isl.centroid.coords[0])
        assert np.hypot(*(centroids - c).T).min() > 0.3 * np.sqrt(isl.area / np.pi)


def test_beta_by_rate_pools_windows_by_rate_and_rheology_and_skips_old_estimators():
    """``physics_experiments.py beta-by-rate``: each window's β goes to the bin of its own rate;
    EVP apart; records fitted with every width (no ``beta_min_boxes``) or at another resolution
    are left out; the fraction at or above 0.17 counts windows."""
    import physics_experiments as pe

    def rec(betas, rates, overrides=(), res=10e3, boxes=10):
        r = {"resolution_m": res, "overrides": list(overrides), "window_rates_per_day": list(rates),
             "per_window": [{"beta_space": b} for b in betas]}
        if boxes is not None:
            r["beta_min_boxes"] = boxes
        return r

    records = {"a": rec([0.01, 0.20, 0.05], [5e-4, 0.02, 0.02]),
               "b": rec([0.30, float("nan")], [0.02, 0.02]),
               "e": rec([0.10, 0.02], [0.02, 2e-4], overrides=["solver.name=evp"]),
               "old": rec([0.9, 0.9], [0.02, 0.02], boxes=None),
               "coarse": rec([0.9], [0.02], res=20e3)}
    res = pe.beta_by_rate(records)
    meb = {tuple(r["rate_per_day"]): r for r in res["maxwell_eb"]["bins"]}
    assert res["maxwell_eb"]["windows"] == 4 and res["maxwell_eb"]["runs"] == 2
    quiet, observed = meb[(0.0, 1e-3)], meb[(1e-2, 5e-2)]
    assert quiet["windows"] == 1 and quiet["beta_median"] == 0.01
    assert observed["windows"] == 3 and observed["runs"] == 2
    assert observed["beta_median"] == 0.20 and observed["fraction_at_least_0_17"] == 2 / 3
    evp = {tuple(r["rate_per_day"]): r for r in res["evp"]["bins"]}
    assert evp[(1e-2, 5e-2)]["beta_median"] == 0.10 and evp[(0.0, 1e-3)]["windows"] == 1
    assert "| Maxwell-EB | 0.01–0.05 | 3 (2) | 0.200 |" in pe.beta_by_rate_table(res)


def test_beta_components_region_keeps_elements_inside_another_basins_interior(tmp_path):
    """``beta_components.py --region``: the region is the polygon less a ``buffer_m`` band along
    every boundary (islands included), and an element counts if its centroid lies in it."""
    import json

    from beta_components import load_region, region_mask
    from shapely.geometry import Point, box, mapping

    poly = box(0, 0, 1000e3, 1000e3).difference(Point(500e3, 500e3).buffer(50e3))
    f = tmp_path / "basin.geojson"
    f.write_text(json.dumps({"type": "FeatureCollection",
                             "features": [{"type": "Feature", "properties": {}, "geometry": mapping(poly)}]}))
    region = load_region(f, 100e3)
    # centroids: near the outer coast, near the island, in between, and far out
    xy = np.array([[50e3, 500e3], [620e3, 500e3], [300e3, 300e3], [800e3, 800e3], [2e6, 2e6]], float)
    tri = np.array([[i, i, i] for i in range(len(xy))])  # degenerate triangles: centroid = the point
    np.testing.assert_array_equal(region_mask(xy, tri, region), [False, False, True, True, False])
    with pytest.raises(Exception, match="km from its boundary"):
        load_region(f, 600e3)


def _band_velocity(nodes, angle_to_y_deg, speed=1e-3, width=5e3):
    """A smoothed slip across a straight band through the plate's centre at ``angle_to_y_deg``
    from the y axis: the nodes on one side move along the band at ``speed``."""
    a = np.radians(90.0 + angle_to_y_deg)
    t = np.array([np.cos(a), np.sin(a)])
    n = np.array([-t[1], t[0]])
    d = (nodes - nodes.mean(axis=0)) @ n
    return np.outer(0.5 * (1.0 + np.tanh(d / width)), t * speed)


def _plate_grid(nx, ny, dx):
    """A structured triangulation of an nx × ny plate of dx squares: nodes, triangles, centroids."""
    xs, ys = np.meshgrid(np.arange(nx + 1) * dx, np.arange(ny + 1) * dx)
    nodes = np.column_stack([xs.ravel(), ys.ravel()])
    idx = np.arange((nx + 1) * (ny + 1)).reshape(ny + 1, nx + 1)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    tri = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return nodes, tri, nodes[tri].mean(axis=1)


def test_compression_analysis_reports_the_faults_of_the_post_peak_phase(tmp_path):
    """``analyse_compression``: a plate that softens gradually after its peak (a band at 30° to
    the load) and drops most, later, in a small event on another band (60°). The largest-drop
    block is the late event; the post-peak phase (from the peak until the strain has grown by
    a fifth) finds the 30° band in the rate and in the damage it made."""
    from validate import POST_PEAK_STRAIN_FRACTION, analyse_compression

    nx, ny, dx = 40, 80, 2.5e3
    nodes, tri, cen = _plate_grid(nx, ny, dx)
    n_blocks, block, peak_block, late_block = 50, 2, 10, 40
    s_end = np.concatenate([np.linspace(10e3, 100e3, peak_block + 1),           # loading to the peak
                            100e3 - 0.4e3 * np.arange(1, 4),                    # gradual softening
                            np.full(late_block - peak_block - 4, 98.8e3),       # plateau
                            [96.8e3], np.full(n_blocks - late_block - 1, 96.8e3)])  # the late 2 kPa drop
    stress = np.repeat(s_end, block)
    vel = np.zeros((n_blocks, nodes.shape[0], 2))
    n_post = max(1, int(POST_PEAK_STRAIN_FRACTION * (peak_block + 1)))
    for k in range(peak_block, peak_block + n_post):
        vel[k] = _band_velocity(nodes, 30.0)
    vel[late_block] = _band_velocity(nodes, 60.0)
    damage = np.zeros((n_blocks, tri.shape[0]), np.float32)
    a30 = np.radians(120.0)
    dist30 = np.abs((cen - nodes.mean(axis=0)) @ np.array([-np.sin(a30), np.cos(a30)]))
    damage[peak_block:] = np.where(dist30 < 3e3, 0.8, 0.0)
    a60 = np.radians(150.0)
    dist60 = np.abs((cen - nodes.mean(axis=0)) @ np.array([-np.sin(a60), np.cos(a60)]))
    damage[late_block:] = np.maximum(damage[late_block], np.where(dist60 < 3e3, 0.5, 0.0))  # the late event's
    path = tmp_path / "compression.npz"
    rec = dict(stress_pa=stress, dt_s=5.0, block_steps=block, nodes=nodes, triangles=tri,
               velocity_block_mean=vel, damage_block_end=damage, width_m=nx * dx, n_across=nx,
               length_m=ny * dx, push_speed_m_s=1e-3, friction=0.7, wall_s=1.0)
    np.savez(path, **rec)
    res = analyse_compression(path)
    assert res["ruptured"]
    assert res["rupture_block"] == late_block and res["rupture_blocks_after_peak"] == late_block - peak_block
    assert abs(res["fault_angles_rate_deg"][0] - 60.0) < 3.0
    assert abs(res["fault_angles_damage_deg"][0] - 60.0) < 3.0
    # the same drop with no damage made in its block (an elastic wave) is not a rupture
    undamaged = damage.copy()
    undamaged[late_block:] = undamaged[late_block - 1]
    np.savez(tmp_path / "elastic.npz", **(rec | {"damage_block_end": undamaged}))
    res_el = analyse_compression(tmp_path / "elastic.npz")
    assert res_el["rupture_block"] == late_block and not res_el["ruptured"]
    assert res_el["fault_angles_rate_deg"] is None
    post = res["post_peak"]
    assert post["blocks"] == [peak_block, peak_block + n_post]
    assert abs(post["fault_angles_rate_deg"][0] - 30.0) < 3.0
    assert abs(post["fault_angles_damage_deg"][0] - 30.0) < 3.0
    assert n_post == 2 and abs(post["stress_drop_kpa"] - 0.4) < 1e-9  # peak to the phase's last block


def test_final_damage_faults_find_one_straight_band_and_the_analysis_reports_the_damage_band_angle(tmp_path):
    """``mesh_imprint.final_damage_faults``: a plate whose final damage is one straight band at
    35° to the load gives that direction as its main fault, and the axis of its damaged
    elements is long and thin; ``analyse_compression`` reports the damage-band angle θ* only
    for a record that names ν and the origin correction."""
    from mesh_imprint import final_damage_faults
    from validate import analyse_compression

    from lagice.diagnostics.faults import damage_mode_fault_angle_deg

    nx, ny, dx = 40, 80, 2.5e3
    nodes, tri, cen = _plate_grid(nx, ny, dx)
    n_blocks, block, peak_block = 20, 2, 10
    band = np.radians(90.0 - 35.0)  # a direction 35° from the y axis
    dist = np.abs((cen - nodes.mean(axis=0)) @ np.array([-np.sin(band), np.cos(band)]))
    damage = np.zeros((n_blocks, tri.shape[0]), np.float32)
    damage[peak_block:] = np.where(dist < 3e3, 0.9, 0.0)
    stress = np.repeat(np.concatenate([np.linspace(10e3, 100e3, peak_block + 1),
                                       100e3 - 1e3 * np.arange(1, n_blocks - peak_block)]), block)
    vel = np.zeros((n_blocks, nodes.shape[0], 2))
    vel[peak_block:] = _band_velocity(nodes, 55.0)
    common = dict(stress_pa=stress, dt_s=5.0, block_steps=block, nodes=nodes, triangles=tri,
                  velocity_block_mean=vel, damage_block_end=damage, width_m=nx * dx, n_across=nx,
                  length_m=ny * dx, push_speed_m_s=1e-3, friction=0.7, wall_s=1.0)
    old, new = tmp_path / "old.npz", tmp_path / "new.npz"
    np.savez(old, **common)
    np.savez(new, **common, poisson=0.3, stress_correction="origin")
    r = final_damage_faults(new)
    assert abs(r["angles_deg"][0] - 35.0) < 2.0
    assert abs(r["axis_d8"]["angle_deg"] - 35.0) < 2.0 and r["axis_d8"]["aspect"] > 5.0
    assert r["scores"][0] > 3 * r["median_trial_score"]
    assert analyse_compression(old)["damage_mode_angle_deg"] is None
    assert analyse_compression(new)["damage_mode_angle_deg"] == pytest.approx(
        damage_mode_fault_angle_deg(0.7, poisson_ratio=0.3))


def test_leads_table_counts_bands_and_scales_rates_by_the_reference():
    """``physics_experiments.py leads``: each change's rate is shown and divided by the reference
    row's of the same basin, bands are counted against the observed ranges, a run not recorded shows
    "–", and every LEADS run is an experiment of the script (a typo would show "–" for ever)."""
    import physics_experiments as pe

    inside = {"beta_space": 0.18, "pdf_tail_exponent_shear": 2.0, "pdf_tail_exponent_divergence": 2.5,
              "localisation_half_shear_area_fraction": 0.05, "shear_divergence_r2": 0.8,
              "mean_total_deformation_rate_per_day": 0.02}
    outside = {**inside, "beta_space": 0.04, "mean_total_deformation_rate_per_day": 0.002}
    assert pe.bands_inside(inside) == 6 and pe.bands_inside(outside) == 4
    records = {"ref": {"median": outside}, "refs": {"median": inside}, "new": {"median": inside}}
    fits = {"new": {"fit": {"factor": 0.0071}}}
    leads = (("reference", "ref", "refs", "S"), ("a change", "new", "missing", "T"))
    row = pe.leads_table(records, fits, leads).splitlines()[3]
    assert row == "| a change | 0.180 / – | 0.0200 (×10.00) / – | 0.0071 / – | 6 / – | T |"
    for _, c, s, _ in pe.LEADS:
        assert c in pe.EXPERIMENTS and (s is None or s in pe.EXPERIMENTS)


def test_envelope_branch_classes_are_the_branches_dcrit_scales_onto():
    """benchmarks/envelope_branches.py classes a stress by the branch of Maxwell-EB's envelope
    that the correction towards the origin meets: the tensile cut-off exactly where the minor
    principal stress is tensile (s2 >= 0). Checked against the model's own d_crit on random
    stresses outside the envelope: the corrected stress sits on s1 = sigma_T exactly for the
    class 'cutoff', and on the Coulomb line for the two others, split by the mean stress's sign.
    The class does not change when the stress is scaled (relaxation), so the end-of-step stress
    keeps the class of the step's last event."""
    from envelope_branches import CLASSES, classify, window_sums

    from lagice.rheology.maxwell_eb import dcrit

    rng = np.random.default_rng(3)
    C, mu = 1.0e4, 0.98
    s = np.sqrt(mu * mu + 1.0)
    q, sigma_c = (s + mu) ** 2, 2.0 * C / (s - mu)
    sigma_t = sigma_c / q
    sig = rng.normal(0.0, 2.0e5, (4000, 3))
    dc = dcrit(sig, C, mu)
    out = dc < 1.0
    assert out.mean() > 0.9
    fixed = sig[out] * dc[out, None]
    m = 0.5 * (fixed[:, 0] + fixed[:, 1])
    r = np.sqrt(0.25 * (fixed[:, 0] - fixed[:, 1]) ** 2 + fixed[:, 2] ** 2)
    s1, s2 = m + r, m - r
    on_cutoff = np.isclose(s1, sigma_t, rtol=1e-9, atol=0.0)
    on_coulomb = np.isclose(q * s1 - s2, sigma_c, rtol=1e-9, atol=0.0)
    cls = classify(sig[out])
    assert set(np.unique(cls)) == {0, 1, 2}  # all three classes occur
    assert np.array_equal(cls == 0, on_cutoff)
    assert np.all(on_coulomb[cls > 0])
    assert np.array_equal(cls == 2, (m < 0.0) & (cls > 0))
    assert np.array_equal(classify(0.3 * sig), classify(sig))
    steps = [{"day": d, "area_m2": [1.0, 2.0, 3.0], "gain_m2": [0.0, 1.0, 3.0], "compressed_fraction": 0.5}
             for d in (0.5, 1.0, 2.9, 3.1)]
    w = window_sums(steps, 2, start_day=0.0)  # (0, 3] and (3, 6]
    assert [x["steps"] for x in w] == [3, 1] and w[1]["days"] == [3.0, 6.0]
    assert [x["steps"] for x in window_sums(steps, 1)] == [2]  # the validation's first window, (1, 4]
    assert w[0]["event_area_fraction"] == dict(zip(CLASSES, [round(1 / 6, 4), round(2 / 6, 4), 0.5]))
    assert w[0]["damage_gain_fraction"]["coulomb_compression"] == 0.75 and w[0]["damage_gain_m2"] == 12.0


def test_half_scale_weather_halves_every_length_and_keeps_the_winds():
    """physics_experiments.HALF_SCALE_WEATHER (a mechanism diagnostic of docs/physics.md §4): the
    weather of a basin twice as wide shrunk by 2. Every length of the climatology is halved, the
    speeds that carry the weather too (the same time for a system to cross its own width), the
    births per area are x4 (the same cover of the domain), and a cyclone's wind, which scales as
    depth/radius, is unchanged: the median cyclone of each set has the same largest wind. The
    records are fine enough for the shortest wave (the scene refuses fewer than 8 points per
    wavelength)."""
    import physics_experiments as pe

    from forcing.climatology import ClimatologyParams, CycloneTrack
    from lagice.scenes.config import _split

    sets = dict(_split(s) for s in pe.HALF_SCALE_WEATHER)
    wind = {k.removeprefix("forcing.wind."): v for k, v in sets.items() if k.startswith("forcing.wind.")}
    half, full = ClimatologyParams(**{k: tuple(v) if isinstance(v, list) else v for k, v in wind.items()}), \
        ClimatologyParams()
    for name in ("correlation_length_m", "shortest_wavelength_m", "cyclone_radius_median_m",
                 "cyclone_depth_mean_hpa", "cyclone_depth_max_hpa", "cyclone_speed_std_m_s"):
        assert getattr(half, name) == 0.5 * getattr(full, name), name
    for name in ("cyclone_radius_range_m", "steering_m_s"):
        assert np.allclose(getattr(half, name), 0.5 * np.asarray(getattr(full, name))), name
    assert half.cyclone_rate_per_mkm2_day == 4.0 * full.cyclone_rate_per_mkm2_day
    assert half.decorrelation_time_s == full.decorrelation_time_s and half.background_wind_std_m_s == \
        full.background_wind_std_m_s
    median = [CycloneTrack(0, 0, 0, 0, 0, p.cyclone_depth_mean_hpa, p.cyclone_radius_median_m, 1.0)
              for p in (half, full)]
    assert median[0].max_surface_wind_m_s(half) == pytest.approx(median[1].max_surface_wind_m_s(full), rel=1e-12)
    assert half.shortest_wavelength_m / sets["forcing.grid_spacing_m"] >= 8.0
    assert set(wind) <= {f.name for f in dataclasses.fields(ClimatologyParams)}


def _still_square(tmp_path, side=400e3):
    """A free ``side`` square of 1 m ice that does not move (zero prescribed velocity), run through
    Model/Simulation with daily snapshots in ``tmp_path/run/snapshots``. Returns (mesh, its
    element areas [m2], the simulation); the caller sets the damage and runs it."""
    from lagice.mesh import generate_mesh, rectangle_domain
    from lagice.model import Model
    from lagice.simulation import Simulation
    from lagice.solvers import PrescribedStepper
    from lagice.state import IceState

    poly, _ = rectangle_domain(side, side)
    mesh = generate_mesh(poly, 25e3, exterior_tag="free")
    st = IceState.uniform(mesh, thickness_m=1.0, concentration=1.0, cohesion_pa=1e9)
    model = Model(st, solver=PrescribedStepper(mesh=mesh, velocity=lambda t, x, y: (0 * x, 0 * y)))
    sim = Simulation(model, dt="6h", stop="2d", progress=False)
    sim.output(every="1d", path=tmp_path / "run" / "snapshots", crs=None)
    p = mesh.nodes[mesh.triangles]
    area = 0.5 * np.abs((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                        - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))
    return mesh, area, sim


def test_beta_vs_damage_reads_the_interiors_damage_at_the_window_start(tmp_path):
    """``beta_vs_damage.py``: the area-weighted mean damage and broken share of the elements
    >= 100 km from the boundary, read from a real run's snapshot, against the same numbers
    computed here from the mesh with shapely."""
    import shapely
    from beta_vs_damage import start_damage

    from lagice.errors import ConfigError

    side = 400e3
    mesh, area, sim = _still_square(tmp_path, side)
    cen = mesh.nodes[mesh.triangles].mean(axis=1)
    damage = np.where(cen[:, 0] < 0.5 * side, 0.95, 0.2)  # broken west, sound east
    sim.model.state.damage = damage.copy()
    sim.run(n_steps=4)
    res = start_damage(tmp_path / "run", 0.0)
    inner = shapely.distance(shapely.points(cen), shapely.box(0, 0, side, side).exterior) >= 100e3
    a, d = area[inner], damage[inner]
    assert 0.3 < a[d > 0.9].sum() / a.sum() < 0.7  # the interior straddles the split
    assert res["broken_area_share"] == pytest.approx(a[d > 0.9].sum() / a.sum(), rel=1e-12)
    assert res["damaged_area_share"] == pytest.approx(a[d > 0.5].sum() / a.sum(), rel=1e-12)
    assert res["mean_damage"] == pytest.approx(np.sum(a * d) / a.sum(), rel=1e-12)
    assert res["snapshot_day"] == 0.0
    with pytest.raises(ConfigError, match="no snapshot within an hour of day 0.5"):
        start_damage(tmp_path / "run", 0.5)


def test_damage_budget_takes_the_net_change_from_the_snapshots(tmp_path):
    """``envelope_branches.py --budget``: per window, net = the change of the interior's Σ d·A
    between the snapshots at the window's ends, and healed = gain − net. A real run whose damage
    is set between its two days: the first window has no change (healed = gain), the second the
    change made here."""
    from envelope_branches import budget_table, damage_budget

    from lagice.diagnostics.faults import interior_triangles

    mesh, area, sim = _still_square(tmp_path)
    sim.model.state.damage = np.full(mesh.n_elements, 0.5)
    sim.run(n_steps=4)  # day 1 written with d = 0.5
    sim.model.state.damage = np.full(mesh.n_elements, 0.8)
    sim.run()
    rec = {"windows": [{"days": [0.0, 1.0], "damage_gain_m2": 7.0e9}, {"days": [1.0, 2.0], "damage_gain_m2": 9.0e10}]}
    rows = damage_budget(rec, tmp_path / "run")
    a_in = area[interior_triangles(mesh.nodes, mesh.triangles, 100e3)].sum()
    assert rows[0]["net_m2"] == pytest.approx(0.0, abs=1e-6 * a_in) and rows[0]["healed_m2"] == pytest.approx(7.0e9)
    assert rows[1]["net_m2"] == pytest.approx(0.3 * a_in, rel=1e-12)
    assert rows[1]["healed_m2"] == pytest.approx(9.0e10 - 0.3 * a_in, rel=1e-12)
    assert rows[1]["mean_damage_start"] == pytest.approx(0.5) and rows[1]["mean_damage_end"] == pytest.approx(0.8)
    assert "| 1–2 |" in budget_table("t", rows) and f"| {9.0e10 / 1e9 + 7.0:.0f} |" in budget_table("t", rows)


def test_compression_cycle_measures_on_known_series():
    """benchmarks/compression_cycles.py: on a flat plateau after one drop, neither measure finds a
    cycle; on a sawtooth of slow 3 % rises and falls spread over 5 blocks (0.01 t_h), the
    block-to-block measure finds none (each block falls 0.6 % of the peak, under its 1 %) and the
    windowed measure finds every fall after the first (rise of 3 % between them), 0.5 t_h apart."""
    from compression_cycles import HEALING_TIME_S, cycles, windowed_cycles

    dt_block = 0.002 * HEALING_TIME_S
    t = np.arange(1, 3001) * dt_block  # 6 t_h
    peak = 100.0
    flat = np.full(t.size, 96.0)
    flat[:200] = np.linspace(0.0, peak, 200)
    flat[200] = 90.0  # one drop of 10 % right after the peak, then a plateau
    assert cycles(flat, peak)["n_cycles"] == 0
    w = windowed_cycles(t, flat, peak)
    assert (w["n_relaxations"], w["n_windowed_cycles"]) == (1, 0)
    saw = np.empty(t.size)
    period = 250  # blocks: 0.5 t_h
    for k in range(t.size):
        j = k % period
        saw[k] = 97.0 + 3.0 * j / (period - 5) if j < period - 5 else 100.0 - 3.0 * (j - period + 6) / 5
    assert cycles(saw, peak)["n_events"] == 0
    w = windowed_cycles(t, saw, peak)
    assert w["n_relaxations"] == t.size // period
    assert w["n_windowed_cycles"] == w["n_relaxations"] - 1
    gaps = np.diff(w["relaxation_times_t_h"])
    assert np.allclose(gaps, 0.5)


def test_load_ratio_and_activity_split_on_known_stresses():
    """``beta_vs_damage.load_ratio`` is 1 on both branches of the nominal envelope (uniaxial
    compression at σc, uniaxial tension at σT), k for k times those stresses, and ≤ 0 under an
    isotropic compression; ``split_by_rate`` takes the most active elements until their area
    reaches the share asked, whatever their order."""
    from beta_vs_damage import load_ratio, split_by_rate

    from lagice.rheology.maxwell_eb import envelope

    coh, mu = np.array([2e4, 3e4]), 0.7
    q, sc, st = envelope(coh, mu)
    for k in (0.5, 1.0, 2.0):
        comp = np.array([[0.0, -k * sc[0], 0.0], [-k * sc[1], 0.0, 0.0]])  # along y, along x
        tens = np.array([[k * st[0], 0.0, 0.0], [0.0, k * st[1], 0.0]])
        assert np.allclose(load_ratio(comp, coh, mu), k, rtol=1e-12)
        assert np.allclose(load_ratio(tens, coh, mu), k, rtol=1e-12)
        rot = np.array([[-0.5 * k * sc[0], -0.5 * k * sc[0], 0.5 * k * sc[0]]] * 2)  # the first, turned 45°
        assert np.allclose(load_ratio(rot, coh[:1].repeat(2), mu), k, rtol=1e-12)
    assert np.all(load_ratio(np.array([[-5e4, -5e4, 0.0]] * 2), coh, mu) <= 0.0)
    rate = np.array([0.1, 5.0, 0.3, 4.0, 0.2])
    area = np.array([1.0, 1.0, 1.0, 2.0, 1.0])  # total 6
    assert split_by_rate(rate, area, 0.1).tolist() == [False, True, False, False, False]
    assert split_by_rate(rate, area, 0.4).tolist() == [False, True, False, True, False]  # 3 of 6 reached at 0.5
    assert split_by_rate(rate, area, 0.5).tolist() == [False, True, False, True, False]
    assert split_by_rate(rate, area, 0.51).tolist() == [False, True, True, True, False]


def test_benchmark_runs_without_outputs_take_any_step_and_runs_with_outputs_keep_the_whole_step_check():
    """A benchmark sets its own solver.dt (sub-steps × a stability limit), which rarely divides the
    scene's output interval ("6h"). Without outputs the writing activities are left out, so their
    schedules must not stop the build (bench_explicit was refused after the whole-step check came
    in); with outputs the builder's refusal must still name the key."""
    from scene_runs import scene_simulation

    from lagice.errors import ConfigError

    ov = {"domain.resolution_m": 100e3, "solver.dt": 198.009, "run.duration": 2 * 198.009}
    sim = scene_simulation("wind_square", ov)
    assert sim.dt == pytest.approx(198.009)
    assert not {"snapshots", "timeseries", "checkpointer"} & set(sim.activities)
    sim.run(n_steps=1)
    assert sim.model.clock.iteration == 1
    with pytest.raises(ConfigError, match=r"output\.every = '6h'.*whole number"):
        scene_simulation("wind_square", ov, outputs=True)


def test_a_run_made_again_from_its_folder_record_is_the_same_bit_for_bit(tmp_path):
    """benchmarks/rerun_check.py makes a finished run again from the command its folder's marker
    records and compares every snapshot: a real `lagice run` is reproduced bit for bit (and
    validate.py reads who made it), while one changed value in a copy is found."""
    import json
    import shutil
    import subprocess

    import xarray as xr
    from rerun_check import RECORD, check, compare_runs
    from validate import reuse_notice

    from lagice.io.cf import git_commit

    run = tmp_path / "run"
    cmd = [sys.executable, "-m", "lagice.cli", "run", "shear_box", "--out", str(run)]
    for s in ("run.duration=800.0", "solver.dt=40.0", "output.every=400.0", "domain.resolution_m=50e3",
              "run.progress=false", "output.plot=false"):
        cmd += ["--set", s]
    subprocess.run(cmd, check=True, capture_output=True, cwd=tmp_path)
    res = check(run)
    assert res["max_abs_difference"] == 0 and res["snapshots"] == 3 and res["differ"] == []
    assert json.loads((run / RECORD).read_text())["reproduced_by"] == git_commit()
    assert reuse_notice(run)["made_by"] == git_commit()
    # a copy with one stress value changed by 1 Pa in the last snapshot: found, and named
    copy = tmp_path / "copy"
    shutil.copytree(run, copy)
    last = copy / "snapshots" / json.loads((copy / "snapshots" / "index.json").read_text())[-1]["file"]
    with xr.open_dataset(last, decode_times=False) as ds:
        ds = ds.load()
    name = next(v for v in ds.data_vars if "stress" in v and np.issubdtype(ds[v].dtype, np.floating))
    ds[name].values.flat[0] += 1.0
    ds.to_netcdf(last)
    diff = compare_runs(run, copy)
    assert diff["differ"] == [name] and diff["max_abs_difference"] == pytest.approx(1.0, rel=1e-6)


def test_a_run_is_made_again_from_the_scene_files_of_its_commit(tmp_path):
    """rerun_check.rerun_command: a run whose recorded scene is a file of examples/ is made again from that
    file as the run's commit had it (from git), not as the work tree has it now; a run made from a work
    tree whose scene files were modified reads today's file (said)."""
    import json
    import subprocess

    from rerun_check import ROOT, rerun_command

    head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True,
                          check=True).stdout.strip()
    scene = ROOT / "examples" / "winter_basin_pack.toml"
    run = tmp_path / "run"
    run.mkdir()
    marker = {"command": f"{ROOT / 'lagice' / 'cli.py'} run {scene} --out {run} --set run.duration=1d",
              "git_commit": head, "git_modified_files": []}
    (run / "lagice_run.json").write_text(json.dumps(marker))
    cmd = rerun_command(run, tmp_path / "again" / "run")
    assert cmd[4] == str(tmp_path / "again" / "examples" / "winter_basin_pack.toml")
    committed = subprocess.run(["git", "show", f"{head}:examples/winter_basin_pack.toml"], cwd=ROOT,
                               capture_output=True, check=True).stdout
    assert Path(cmd[4]).read_bytes() == committed
    assert (tmp_path / "again" / "examples" / "winter_basin_pack_strait.toml").exists()   # its `extends` base too
    assert cmd[cmd.index("--out") + 1] == str(tmp_path / "again" / "run") and "--set" in cmd
    marker["git_modified_files"] = ["examples/winter_basin_pack.toml"]
    (run / "lagice_run.json").write_text(json.dumps(marker))
    assert rerun_command(run, tmp_path / "again2" / "run")[4] == str(scene)


def test_rotation_summary_carries_the_ensemble_verdicts_and_their_intervals():
    """validate.py's mesh-imprint summary takes each variant's ensemble rotation test
    (mesh_imprint.py turn) with its verdict and the interval of D at each turn, and names it in the
    summary line; a file without the ensembles gives no such key."""
    from validate import rotation_test_summary

    t15 = {"d": 0.61, "d_low": 0.27, "d_high": 0.74, "corr_at_zero": -0.03, "corr_at_exact_rotation": 0.58,
           "split_half_corr_ref": 0.55}
    t30 = {"d": -0.58, "d_low": -0.66, "d_high": -0.50, "corr_at_zero": 0.97, "corr_at_exact_rotation": 0.39}
    mi = {"rotation_turn": {"delaunay": {"damage": {"verdict": "follows the mesh", "turns": {"15": t15}},
                                         "shear": {"verdict": "does not follow the mesh", "turns": {"30": t30}},
                                         "seeds": {"0": list(range(12, 24))}, "git_commit": "abc"}}}
    out = rotation_test_summary(mi)
    et = out["ensemble_turn"]["delaunay"]
    assert set(et) == {"damage", "shear"}
    assert et["damage"]["verdict"] == "follows the mesh" and et["damage"]["turns"]["15"]["d_low"] == 0.27
    assert et["shear"]["turns"]["30"] == {k: t30[k] for k in ("d", "d_low", "d_high", "corr_at_zero",
                                                              "corr_at_exact_rotation")}
    assert "delaunay, ensembles of 12 draws at exactly the turn: damage follows the mesh, shear does not follow" \
        in out["summary"]
    assert "ensemble_turn" not in rotation_test_summary({})


def test_band_set_holds_the_share_of_the_shear():
    """benchmarks/band_persistence.py: the fastest elements that hold half of Σ rate·area (the one
    that crosses the share included)."""
    from band_persistence import band_set

    area = np.ones(6)
    assert band_set(np.array([1.0, 10.0, 1.0, 1.0, 1.0, 1.0]), area).tolist() == [False, True] + [False] * 4
    # equal rates: the first three hold exactly half, so three elements; the choice among ties is stable
    assert band_set(np.ones(6), area).sum() == 3
    # the set is taken by rate, and an element's share of the shear is rate × area
    assert band_set(np.array([3.0, 2.0, 1.0]), np.ones(3)).tolist() == [True, False, False]
    assert band_set(np.array([3.0, 2.0, 1.0]), np.array([1.0, 4.0, 1.0])).tolist() == [True, True, False]


def test_turn_figure_keeps_the_published_name_for_the_published_variants_only():
    """benchmarks/mesh_imprint.py turn: another set of variants must not overwrite the published
    figure mesh_imprint_turn.png (it did once, in the thirty-eighth session)."""
    from mesh_imprint import turn_figure_name

    assert turn_figure_name(["delaunay", "base"]) == "mesh_imprint_turn"
    assert turn_figure_name(["delaunay+h40"]) == "mesh_imprint_turn_delaunay-h40"
    assert turn_figure_name(["base"]) != "mesh_imprint_turn"


def test_strain_fit_recovers_a_linear_field_and_fits_a_rough_strain_by_least_squares():
    """benchmarks/cr_node_motion.py: the node motion whose strain is nearest a given element strain.
    A continuous linear field's own strain, with its boundary values held, gives the field back;
    for any strain the fit's residual is orthogonal to every admissible change (the normal
    equations), so no other node motion with the same held values fits better."""
    from cr_node_motion import strain_fit

    from lagice.fem import shape_gradients, strain_rate

    nx = 7
    gx, gy = np.meshgrid(np.linspace(0.0, 6e3, nx), np.linspace(0.0, 6e3, nx))
    xy = np.column_stack([gx.ravel(), gy.ravel()])
    xy[:, 0] += 150.0 * np.sin(xy[:, 1] / 900.0)  # not a lattice
    idx = np.arange(nx * nx).reshape(nx, nx)
    a, b_, c_, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
    tri = np.concatenate([np.column_stack([a, b_, d]), np.column_stack([a, d, c_])])
    b, c, area = shape_gradients(xy, tri)
    assert np.all(area > 0)
    boundary = (gx.ravel() == 0) | (gx.ravel() == 6e3) | (gy.ravel() == 0) | (gy.ravel() == 6e3)
    fixed = np.repeat(boundary[:, None], 2, axis=1).astype(np.int8)
    u = np.column_stack([1e-3 * np.sin(xy[:, 0] / 2e3) + 2e-4 * np.cos(xy[:, 1] / 1.5e3),
                         5e-4 * np.cos(xy[:, 0] / 2.5e3) * np.sin(xy[:, 1] / 3e3)])
    eps = strain_rate(tri, b, c, u)
    got = strain_fit(xy, tri, eps, fixed, u)
    assert np.allclose(got, u, rtol=0, atol=1e-12)
    # a strain no node motion has: the fit's misfit cannot be lowered by moving any free node
    rng = np.random.default_rng(3)
    rough = eps + 1e-7 * rng.standard_normal(eps.shape)
    fit = strain_fit(xy, tri, rough, fixed, u)

    def misfit(v):
        e = strain_rate(tri, b, c, v) - rough
        return float(np.sum(area * (e[:, 0] ** 2 + e[:, 1] ** 2 + 2.0 * e[:, 2] ** 2)))

    base = misfit(fit)
    for _ in range(5):
        dv = 1e-6 * rng.standard_normal(u.shape)
        dv[boundary] = 0.0
        assert misfit(fit + dv) > base
    assert np.allclose(fit[boundary], u[boundary], rtol=0, atol=0)


@pytest.mark.parametrize("moves", [False, True])
def test_band_persistence_tells_a_band_that_stays_from_one_that_moves(tmp_path, moves):
    """benchmarks/band_persistence.py on a real run with daily snapshots: a shear band prescribed
    at one place for two days keeps its half-shear set (overlap near 1, far above chance); one that
    moves by 100 km after the first day keeps none of it."""
    from band_persistence import day_pair

    from lagice.lagrangian import MeshMotion
    from lagice.mesh import generate_mesh, rectangle_domain
    from lagice.model import Model
    from lagice.simulation import Simulation
    from lagice.solvers import PrescribedStepper
    from lagice.state import IceState

    side = 400e3
    poly, _ = rectangle_domain(side, side)
    mesh = generate_mesh(poly, 20e3, exterior_tag="free")

    def velocity(t, x, y):
        y0 = 150e3 if (not moves or t < 86400.0) else 250e3
        return 0.05 * np.tanh((y - y0) / 10e3), 0.0 * x

    st = IceState.uniform(mesh, thickness_m=1.0, concentration=1.0, cohesion_pa=1e9)
    sim = Simulation(Model(st, solver=PrescribedStepper(mesh=mesh, velocity=velocity), mover=MeshMotion()), dt="3h",
                     stop="2d", progress=False)
    sim.output(every="1d", path=tmp_path / "run" / "snapshots", crs=None)
    sim.run()
    r = day_pair(tmp_path / "run", 0.0)
    assert r["chance"] < 0.3
    if moves:
        assert r["overlap"] < 0.05
    else:
        assert r["overlap"] > 0.9 and r["spearman"] > 0.9


def test_drift_beta_plane_families_points_and_counts():
    """drift_beta_plane.py: a run's family is the first rule its overrides meet (Crouzeix–Raviart
    before the effective envelope it may also carry; the nominal set catches the rest); only runs
    with both a median β and a wind-factor fit become points; the summary counts the runs inside
    each band and inside both."""
    from drift_beta_plane import family_of, plane_points, summary

    assert family_of(["initial.state_file=x.npz"]) == "nominal"
    assert family_of(["solver.name=evp", "rheology.law=viscous_plastic"]) == "evp"
    assert family_of(["rheology.failure_stress=effective", "rheology.alpha=3"]) == "effective"
    assert family_of(["rheology.failure_stress=effective", "rheology.strength_lab_pa=8.4e6"]) == "effective"
    assert family_of(["rheology.failure_stress=effective", "rheology.strength_lab_pa=14e6"]) == "strong_floes"
    assert family_of(["rheology.strength_lab_pa=14e6"]) == "nominal"
    assert family_of(["rheology.failure_stress=energy", "rheology.strength_lab_pa=14e6"]) == "energy"
    assert family_of(["rheology.failure_stress=energy", "rheology.max_pressure_pa=1e4"]) == "energy"
    assert family_of(["rheology.failure_stress=effective", "solver.velocity_element=crouzeix_raviart"]) == \
        "crouzeix_raviart"
    assert family_of(["rheology.max_pressure_pa=10e3"]) == "pressure"
    assert family_of(["rheology.relax_mean_stress=false", "solver.volumetric_strain=nodal"]) == "nodal"
    assert family_of(["rheology.damage_nonlocal_radius_m=14e3"]) == "nonlocal"
    assert family_of(["rheology.damage_nonlocal_radius_m=0"]) == "nominal"

    def rec(beta, overrides, inside):
        return {"median": {"beta_space": beta}, "overrides": overrides, "resolution_m": 20e3,
                "inside": {f"k{i}": i < inside for i in range(6)}}

    records = {"a": rec(0.18, ["rheology.failure_stress=effective"], 2),   # β in, drift out
               "b": rec(0.19, ["solver.velocity_element=crouzeix_raviart"], 3),  # both in
               "c": rec(0.05, [], 4),                                            # drift in, β out
               "d": rec(0.19, [], 1)}                                            # no fit: left out
    fits = {"observed_thorndike_colony_1982_winter": {"factor": [0.006, 0.010]},
            "a": {"fit": {"factor": 0.013}}, "b": {"fit": {"factor": 0.007}}, "c": {"fit": {"factor": 0.008}},
            "e": {"fit": {"factor": 0.008}}}                                     # no record: left out
    points = plane_points(records, fits)
    assert sorted(p["name"] for p in points) == ["a", "b", "c"]
    assert {p["name"]: p["bands_inside"] for p in points} == {"a": 2, "b": 3, "c": 4}
    s = summary(points)
    assert s["effective"]["beta_in_band"] == 1 and s["effective"]["wind_factor_in_band"] == 0
    assert s["crouzeix_raviart"]["both_in_band_runs"] == ["b"]
    assert s["nominal"]["both_in_band"] == 0 and s["nominal"]["wind_factor_in_band"] == 1
    assert s["nominal"]["most_bands_inside"] == 4


def test_band_geometry_groups_bands_by_shared_nodes_and_measures_their_length():
    """benchmarks/band_geometry.py on a real gmsh mesh: the elements near two separate segments make
    two bands, each about as long as its segment; a shear layer across the whole box makes one band
    as long as the box; the shear-weighted median is the length holding half of the weight."""
    from band_geometry import band_lengths, bands, weighted_median, window_bands

    from lagice.diagnostics.strain import triangle_geometry
    from lagice.mesh import generate_mesh, rectangle_domain

    side = 400e3
    poly, _ = rectangle_domain(side, side)
    mesh = generate_mesh(poly, 10e3, exterior_tag="free")
    xy, tri = mesh.nodes, mesh.triangles
    area, cen = triangle_geometry(xy, tri)[:2]
    x, y = cen[:, 0], cen[:, 1]
    seg_a = (np.abs(y - 100e3) < 8e3) & (x > 50e3) & (x < 250e3)  # 200 km long
    seg_b = (np.abs(x - 300e3) < 8e3) & (y > 200e3) & (y < 300e3)  # 100 km long, 100 km away
    n, labels = bands(tri, seg_a | seg_b)
    assert n == 2
    lengths = np.sort(band_lengths(cen[seg_a | seg_b], area[seg_a | seg_b], labels, n))
    assert abs(lengths[0] - 100e3) < 15e3 and abs(lengths[1] - 200e3) < 15e3
    # the weighted median: half of the weight lies at or above it
    assert weighted_median(np.array([10.0, 20.0, 30.0]), np.array([1.0, 1.0, 2.0])) == 30.0
    assert weighted_median(np.array([10.0, 20.0, 30.0]), np.array([1.0, 2.0, 0.5])) == 20.0
    # a shear layer across the box: one band, as long as the box
    day = 86400.0
    xy1 = xy + np.column_stack([5e3 * np.tanh((xy[:, 1] - 200e3) / 10e3), 0.0 * xy[:, 1]])
    r = window_bands(xy, xy1, tri, 3 * day)
    assert r["n_bands"] == 1
    assert abs(r["weighted_median_length_km"] - 400.0) < 20.0
    assert 0.01 < r["set_area_fraction"] < 0.1
    # the split (rule BB): a simple shear of one sense everywhere does not cancel, so at every box
    # width the whole rate is the band set's plus the background's, and the band set's is the larger
    r = window_bands(xy, xy1, tri, 3 * day, split=True)
    c = r["curves"]
    assert c["whole"]["width_m"] == c["bands"]["width_m"] == c["background"]["width_m"]
    whole, bands_, back = (np.array(c[p]["rate_s"]) for p in ("whole", "bands", "background"))
    assert np.allclose(whole, bands_ + back, rtol=1e-9) and np.all(bands_ > back)


def test_beta_origin_spread_starts_from_the_validations_grid_and_moves_it(tmp_path):
    """beta_estimator.origin_spread on a real run (a prescribed shear layer, daily snapshots): the
    first grid is the validation's own (its window median is window_summary's β to round-off), the
    offsets move the grid within [0, 92 km), and the fit moves with where the boxes fall."""
    from beta_estimator import ORIGIN_RANGE_M, origin_spread

    from lagice.diagnostics.windows import window_starts_days, window_summary
    from lagice.lagrangian import MeshMotion
    from lagice.mesh import generate_mesh, rectangle_domain
    from lagice.model import Model
    from lagice.simulation import Simulation
    from lagice.solvers import PrescribedStepper
    from lagice.state import IceState

    poly, _ = rectangle_domain(600e3, 600e3)
    mesh = generate_mesh(poly, 20e3, exterior_tag="free")

    def velocity(t, x, y):
        return 0.02 * np.tanh((y - 310e3) / 15e3), 0.0 * x

    st = IceState.uniform(mesh, thickness_m=1.0, concentration=1.0, cohesion_pa=1e9)
    sim = Simulation(Model(st, solver=PrescribedStepper(mesh=mesh, velocity=velocity), mover=MeshMotion()), dt="3h",
                     stop="4d", progress=False)
    sim.output(every="1d", path=tmp_path / "run" / "snapshots", crs=None)
    sim.run()
    o = origin_spread(tmp_path / "run", 3, window_days=3.0, start_day=1.0, coast_buffer_m=100e3)
    off = np.asarray(o["offsets_m"])
    assert off.shape == (4, 2) and np.all(off[0] == 0) and np.all((off[1:] >= 0) & (off[1:] < ORIGIN_RANGE_M))
    (s0,) = window_starts_days(tmp_path / "run", 3.0, 1.0)
    published = window_summary(tmp_path / "run", s0 * 86400.0, 3 * 86400.0, 100e3)["interior"]["beta_space"]
    assert o["median_beta"][0] == pytest.approx(published, abs=1e-12)
    # one straight band of one sense: a box's rate is the band's slip over the box's width, and the
    # share of boxes that hold it grows with the width, so the mean does not cancel (β near 0)
    assert abs(o["median_beta"][0]) < 0.1
    assert o["span"] == pytest.approx(max(o["median_beta"]) - min(o["median_beta"]))
    assert o["span"] > 1e-3  # where the boxes fall against the band moves the fit


def test_less_uniform_leaves_the_cancelling_part_of_a_field_and_raises_its_beta():
    """beta_estimator.less_uniform (rule UM) on a field with an analytic split: a uniform strain G plus
    eight alternating slip lines in a 72 km square. The lines' area-weighted mean gradient is the
    boundary integral (1/A)∮u n ds, zero with an even number of alternating lines, so removing the
    mean leaves exactly the lines. Boxes of 18 and 36 km hold an even number of lines whose slips cancel,
    so the lines' β is large; the uniform part, which does not cancel, pulls it down."""
    from beta_estimator import less_uniform

    from lagice.diagnostics import grid_averaged_beta, velocity_gradients
    from lagice.diagnostics.synthetic import jittered_grid_mesh, slip_line_velocity

    length, spacing = 72e3, 9e3
    xy, tri = jittered_grid_mesh(160, 160, length, length, jitter=0.2, seed=2)
    lines = slip_line_velocity(xy, spacing, 0.1, alternating=True)
    g = np.array([[2e-6, 1e-6], [0.0, -1e-6]])  # s-1: a uniform strain of the order of the lines' mean rate
    both = velocity_gradients(xy, tri, lines + xy @ g.T)
    alone = velocity_gradients(xy, tri, lines)
    a = both.area_m2
    assert np.allclose((alone.gradient_s * a[:, None, None]).sum(0) / a.sum(), 0.0, atol=1e-18)
    rest = less_uniform(both)
    np.testing.assert_allclose(rest.gradient_s, alone.gradient_s, atol=1e-15)
    sizes = np.array([4.5, 9, 18, 36]) * 1e3
    b_rest = grid_averaged_beta(rest, box_sizes_m=sizes, include_element_scale=False, min_boxes=1).mean
    b_alone = grid_averaged_beta(alone, box_sizes_m=sizes, include_element_scale=False, min_boxes=1).mean
    b_both = grid_averaged_beta(both, box_sizes_m=sizes, include_element_scale=False, min_boxes=1).mean
    assert b_rest == pytest.approx(b_alone, abs=1e-9)
    assert b_both < b_rest - 0.1   # the uniform part does not cancel, so it lowers β


def test_pooled_windows_resamples_months_not_windows():
    """validate.pooled_windows: the median over every window of every month, and a 90 % interval from
    resampling whole months. Identical months leave no spread; months that differ give an interval
    that holds the pooled median and stays inside the months' range; a month without the statistic
    (an old record) gives None."""
    import validate

    same = validate.pooled_windows([[0.05, 0.1, 0.15]] * 4)
    assert same["median"] == pytest.approx(0.1) and same["interval_90"] == pytest.approx([0.1, 0.1])
    assert same["n_windows"] == 12 and same["n_months"] == 4
    months = [[0.02] * 9, [0.05] * 9, [0.08] * 9, [0.11] * 9, [0.14] * 9]
    p = validate.pooled_windows(months)
    assert p["median"] == pytest.approx(0.08)
    lo, hi = p["interval_90"]
    assert 0.02 <= lo < 0.08 < hi <= 0.14
    # nine windows that split inside each month give a narrower interval than months that differ whole
    mixed = validate.pooled_windows([[0.02, 0.05, 0.08, 0.11, 0.14, 0.02, 0.05, 0.08, 0.11]] * 5)
    assert mixed["interval_90"][1] - mixed["interval_90"][0] < hi - lo
    assert validate.pooled_windows([[0.1, None], [0.2, 0.3]]) is None
    assert validate.pooled_windows([]) is None


def test_pooled_months_pool_every_box_and_resample_months():
    """validate.pooled_months: β of one curve over every box of every window of every month (the
    observations' estimator), with a 90 % interval from resampling months. Months that fall as L^−b
    with the same b give b and no spread, whatever their rates; a calm month and a storm month with
    different b give the storm's b nearly (the storm weighs most), inside the interval; a month
    without curves gives None."""
    import validate

    widths = [10e3, 20e3, 40e3, 80e3]

    def window(rate, b, n=40):
        curve = {"box_size_m": [None] + widths, "scale_m": [5e3] + widths,
                 "mean_total_s": [rate * (s / 5e3) ** -b for s in [5e3] + widths],
                 "n_boxes": [n * 16] + [max(n // 4 ** k, 10) for k in range(4)]}
        return {"interior": {"scaling_space": curve, "scaling_space_grids": [curve, curve]}}

    same = validate.pooled_months([[window(1e-7, 0.2)] * 3, [window(1e-9, 0.2)] * 3])
    assert same["beta_space"] == pytest.approx(0.2, abs=1e-9)
    assert same["beta_space_grids"] == pytest.approx(0.2, abs=1e-9)
    assert same["beta_space_interval_90"] == pytest.approx([0.2, 0.2], abs=1e-9)
    assert same["n_windows"] == 6 and same["n_months"] == 2
    mixed = validate.pooled_months([[window(1e-7, 0.2)] * 3, [window(1e-10, 0.0)] * 3])
    assert 0.19 < mixed["beta_space"] < 0.2
    lo, hi = mixed["beta_space_interval_90"]
    assert 0.0 <= lo <= mixed["beta_space"] <= hi <= 0.2 + 1e-9
    assert validate.pooled_months([[window(1e-7, 0.2)], [{"interior": {"scaling_space": None}}]]) is None
    assert validate.pooled_months([]) is None


def test_pooled_months_resamples_equal_pooling_each_resample_curve_by_curve():
    """validate._resampled_betas (each month's sums made once) gives the β that pooling every curve of
    each resample one by one gives (lagice.diagnostics.scaling.pooled_spatial_scaling), to round-off:
    on random months of 3–9 windows with heavy-tailed rates, a month whose curves hold one width fewer
    (the resamples without it keep that width) and widths counted in fewer than 10 boxes by some curve
    (left out of the fit only where such a curve is drawn)."""
    import validate

    from lagice.diagnostics.scaling import pooled_spatial_scaling

    rng = np.random.default_rng(5)
    widths = [10e3, 20e3, 40e3, 80e3, 160e3]

    def curve(k):
        n = [int(rng.integers(300, 900))] + [int(rng.integers(9, 200)) for _ in range(k)]   # 9: below 10
        return {"box_size_m": [None] + widths[:k], "scale_m": [5e3 * rng.uniform(0.9, 1.1)] + widths[:k],
                "mean_total_s": list(rng.lognormal(-14, 1.5, k + 1)), "n_boxes": n}

    months = [[curve(4 if i == 2 else 5) for _ in range(int(rng.integers(3, 10)))] for i in range(6)]
    picks = rng.integers(0, len(months), size=(200, len(months)))
    fast = validate._resampled_betas(months, picks)
    slow = [pooled_spatial_scaling([c for i in row for c in months[i]]).fit.exponent for row in picks]
    assert np.allclose(fast, slow, rtol=1e-11, atol=1e-13, equal_nan=True)
    # the cases the test is for occur: resamples with and without the short month, widths left out
    assert 0 < sum(2 in row for row in picks) < len(picks)
    assert len({round(b, 6) for b in slow if np.isfinite(b)}) > 100


def test_ensemble_figure_draws_the_analysed_groups_and_the_report_links_it(tmp_path):
    """validate.figure_ensemble_bands: a PNG of the ensembles analysed in this report, none when every
    group was carried from an older report (their numbers are not re-read); the ensemble section of the
    report links the figure it is given, and no figure when given none."""
    import matplotlib.image as mpimg
    import validate

    def member(k):
        med = {m: (lo + hi) / 2 * (0.5 + 0.1 * k) for m, (lo, hi, _s, _n) in validate.TARGETS.items()}
        med[validate.GRID_BETA] = med["beta_space"]
        return {"median": med, "drift_response": {"wind_factor": 0.004 + 0.0005 * k}, "remesh_events": k}

    group = {"members": {f"R{k}": member(k) for k in range(4)},
             "metrics": {m: {"median": 0.1, "n_inside": 1, "n_members": 4} for m in
                         [*validate.TARGETS, validate.GRID_BETA]},
             "pooled_curve": {"beta_space_grids": 0.06, "beta_space_grids_interval_90": [0.05, 0.07],
                              "beta_space": 0.06, "n_months": 4}}
    basin = {"closed": {"evp": member(9)}}
    carried = {"closed, older": {**group, "carried_from": {"date": "2026-11-01", "git_commit": "abc"}}}
    assert validate.figure_ensemble_bands(carried, basin, tmp_path) is None
    p = validate.figure_ensemble_bands({"closed": group, **carried}, basin, tmp_path)
    assert p == tmp_path / "validation_ensemble_bands.png"
    img = mpimg.imread(p)
    assert img.shape[0] > 500 and img.shape[1] > 1000 and img[..., :3].std() > 0.05   # drawn, not blank
    assert f"![every month against the observed bands](figures/{p.name})" in validate.ensemble_lines(
        {"closed": group}, p)
    assert not any("validation_ensemble_bands" in line for line in validate.ensemble_lines({"closed": group}))


def test_provenance_line_says_where_a_modified_tree_was_modified():
    """validate.provenance_line: runs made from modified work trees whose recorded files are all outside
    the model code are labelled so, with the model code the same; where a run's model code changed, the
    label stays "a modified work tree" and the files are named."""
    from validate import provenance_line

    prov = {"by_commit": {"abc1234567-dirty": ["A", "B"], "def7654321": ["C"]}, "changed": [], "unknown": [],
            "files": []}
    line = provenance_line(prov)
    assert "`abc1234567` (a work tree modified outside the model code) (2 runs)" in line
    assert "`def7654321` (1 run)" in line and "is the same in this commit" in line
    changed = {**prov, "changed": ["A"], "files": ["lagice/fem.py"]}
    line = provenance_line(changed)
    assert "`abc1234567` (a modified work tree) (2 runs)" in line
    assert "differs from that of 1 of the runs, in `lagice/fem.py`" in line


def test_a_clean_reproduction_names_the_code_of_a_run_made_from_a_modified_tree(tmp_path):
    """validate.reuse_notice: a run made from a modified work tree (its files recorded, none of them
    model code) and made again bit for bit from a clean checkout is attributed to the clean commit,
    the first maker kept as made_first_by; a reproduction from a modified tree, or one that differs,
    leaves the first maker."""
    import json

    from validate import reuse_notice

    from lagice.io.cf import git_commit

    head = git_commit().removesuffix("-dirty")
    run = tmp_path / "run"
    run.mkdir()
    (run / "lagice_run.json").write_text(json.dumps({"git_commit": head + "-dirty",
                                                     "git_modified_files": ["README.md"]}))
    (run / "reproduced.json").write_text(json.dumps({"max_abs_difference": 0.0, "reproduced_by": head,
                                                     "modified_files": []}))
    got = reuse_notice(run)
    assert got["made_by"] == head and got["made_first_by"] == head + "-dirty"
    assert isinstance(got["model_code_changed"], list)   # the code that made it is known
    (run / "reproduced.json").write_text(json.dumps({"max_abs_difference": 0.0, "reproduced_by": head + "-dirty",
                                                     "modified_files": ["docs/x.md"]}))
    assert reuse_notice(run)["made_by"] == head + "-dirty"
    (run / "reproduced.json").write_text(json.dumps({"max_abs_difference": 1e-9, "reproduced_by": head,
                                                     "modified_files": []}))
    assert reuse_notice(run)["made_by"] == head + "-dirty"   # not the same run: not a reproduction


def test_disk_convergence_same_pa_gives_every_mesh_the_20km_cohesion():
    """benchmarks/disk_convergence.py (rule RD): under ``same_pa`` every mesh gets the cohesion in
    pascals of the 20 km mesh; under ``scaled`` (neXtSIM's law) a mesh √2 finer is √2 stronger."""
    from disk_convergence import FAMILIES, KM, lab_cohesion_pa

    from lagice.strength import StrengthLaw

    for family in FAMILIES:
        c = {km: lab_cohesion_pa(family, "same_pa", km) * StrengthLaw().scale_factor(km * 1e3) for km in KM}
        assert np.allclose(list(c.values()), c[20], rtol=1e-12), family
        s = {km: lab_cohesion_pa(family, "scaled", km) * StrengthLaw().scale_factor(km * 1e3) for km in (20, 10, 5)}
        assert s[10] / s[20] == pytest.approx(np.sqrt(2)) and s[5] / s[10] == pytest.approx(np.sqrt(2))


def _curve(dx_m, beta, n_widths, first_flat=True, boxes0=20000):
    """A scaling curve on a mesh of element scale ``dx_m``: ⟨ε̇tot⟩ ∝ L^−β from 2Δx on, the first
    octave flat when ``first_flat``; box counts fall 4× per octave."""
    L = dx_m * 2.0 ** np.arange(n_widths)
    m = 1e-7 * (L / 1e4) ** (-beta)
    if first_flat:
        m[0] = m[1]
    n = (boxes0 / 4.0 ** np.arange(n_widths)).astype(int)
    return {"box_size_m": [None] + [float(x) for x in L[1:]], "scale_m": list(L), "mean_total_s": list(m),
            "n_boxes": [int(x) for x in n]}


def test_disk_convergence_fits_the_common_widths_and_finds_the_flat_first_octave():
    """β on the widths every mesh resolves is the curve's exponent there, whatever the mesh adds
    below (a flat first octave) or above (a width with fewer than 10 boxes, left out); the pooled
    slopes per octave show the flat first octave (rule RD2 (b)) and the verdicts read them."""
    import disk_convergence as dc

    # 20 km, 10 km and 5 km meshes, β 0.2 above 2Δx, first octave flat; a wild last width with 5 boxes
    runs = {}
    for km, n in ((20, 6), (10, 7), (5, 8)):
        for seed in (1, 2):
            c = _curve(km * 658.0, 0.2, n, boxes0=int(20000 * (20 / km) ** 2))
            c["n_boxes"][-1] = 5
            c["mean_total_s"][-1] *= 50.0
            assert dc.common_beta(c) == pytest.approx(0.2, abs=1e-12)
            runs[f"{km}-{seed}"] = {"km": float(km), "curve": c}
    pool = dc.pooled(runs)
    for row in pool.values():
        assert row["beta_common"] == pytest.approx(0.2, abs=1e-12)
        assert row["slope_per_octave"][0] == pytest.approx(0.0, abs=1e-12)
        assert row["slope_per_octave"][2] == pytest.approx(0.2, abs=1e-12)
        assert row["beta_own"] < 0.2  # the flat octave enters each mesh's own fit
    v = dc.verdict_pooled(pool)
    assert v["a_no_trend"] and not v["a_falls"] and v["b_holds"]
    # a curve whose first octave is steeper than the rest fails (b)
    steep = _curve(5 * 658.0, 0.2, 8, first_flat=False, boxes0=320000)
    steep["mean_total_s"][0] *= 1.5
    runs["5-1"]["curve"] = runs["5-2"]["curve"] = steep
    assert dc.verdict_pooled(dc.pooled(runs))["b_first_octave_flatter"]["5"] is False


def test_disk_convergence_month_verdict_pairs_the_months_by_wind_seed():
    """Rule RD5: the fall is the 20 km pooled β on the common widths less the 10 km one, and the months
    are paired by wind seed (a month run on one mesh only is left out of the count)."""
    import disk_convergence as dc

    assert dc.run_name("lead", "same_pa", 10, 2027, "month") == "month-lead-same_pa-10km-w2027"
    assert dc.run_name("lead", "same_pa", 10, 17) == "lead-same_pa-10km-s17"
    cmd = dc.command("lead", "same_pa", 10, 2027, "month")
    assert str(dc.MONTH_SCENE) in cmd and "forcing.wind.seed=2027" in cmd and "run.seed=2027" not in cmd
    spun = dc.command("lead", "same_pa", 10, 2027, "month", "spun")
    assert f"initial.state_file={dc.spinup_path('lead', 'same_pa', 10)}" in spun
    assert {"initial.thickness_m=from_state", "initial.damage=from_state"} <= set(spun)
    # rule RD10: the thick-and-thin pack is in the spin-up, not in the months, and has a state file of its own
    pack = dc.command("lead", "same_pa", 10, 2027, "month", "packspun")
    assert f"initial.state_file={dc.spinup_path('lead', 'same_pa', 10, 'packspun')}" in pack
    assert dc.spinup_path("lead", "same_pa", 10, "packspun") != dc.spinup_path("lead", "same_pa", 10)
    assert not set(dc.PACK_SETS) & set(pack) and not set(dc.PACK_SETS) & set(dc.spinup_command("lead", "same_pa", 10))
    assert set(dc.PACK_SETS) <= set(dc.spinup_command("lead", "same_pa", 10, "packspun"))
    assert set(dc.MEAN_PACK_SETS) <= set(dc.spinup_command("lead", "same_pa", 10, "meanspun"))
    # rule RD14: one factor of the means at a time, the other as RD9's compact 1 m ice
    assert {"initial.thickness_m=1.6", "initial.concentration=1.0"} <= set(dc.spinup_command("lead", "same_pa", 10,
                                                                                             "thickspun"))
    assert {"initial.thickness_m=1.0", "initial.concentration=0.92"} <= set(dc.spinup_command("lead", "same_pa", 20,
                                                                                              "concspun"))
    assert len({dc.spinup_path("lead", "same_pa", 10, v) for v in dc.SPUN_VARIANTS}) == len(dc.SPUN_VARIANTS)
    assert "healing.law=none" in dc.command("lead", "same_pa", 20, 2027, "month", "noheal")
    assert dc.run_name("lead", "same_pa", 20, 2027, "month", "noheal") == "month-noheal-lead-same_pa-20km-w2027"
    coarse = {"beta_common": 0.18, "beta_common_per_run": {f"month-lead-same_pa-20km-w{s}": 0.18 for s in range(8)}}
    fine = {"beta_common": 0.15, "beta_common_per_run": {f"month-lead-same_pa-10km-w{s}": 0.15 + 0.04 * (s < 3)
                                                          for s in range(7)}}
    v = dc.verdict_month(coarse, fine)
    assert v["fall_pooled_common"] == pytest.approx(0.03) and v["e_falls"]
    assert v["months_paired"] == 7 and v["months_lower_at_10km"] == 4 and not v["f_lower_in_6_of_8"]
    assert v["median_paired_change"] == pytest.approx(-0.03)
    fine["beta_common"] = 0.165
    assert not dc.verdict_month(coarse, fine)["e_falls"]


def _square_mesh_snapshot(run_dir, h_m, band_damage, time_s, band_width_m=None):
    """A run folder with one snapshot: squares of side ``h_m`` cut into two triangles over ±450 km, the
    columns of squares with 0 ≤ x ≤ ``band_width_m`` (default ``h_m``) carrying ``band_damage`` and every
    other element 0.3."""
    import xarray as xr

    n = int(round(900e3 / h_m))
    xs = -450e3 + h_m * np.arange(n + 1)
    X, Y = np.meshgrid(xs, xs, indexing="ij")
    nid = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a, b, c, d = nid[:-1, :-1].ravel(), nid[1:, :-1].ravel(), nid[1:, 1:].ravel(), nid[:-1, 1:].ravel()
    tri = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    cx = X.ravel()[tri].mean(axis=1)
    damage = np.where((cx > 0) & (cx < (band_width_m or h_m)), band_damage, 0.3)
    snap = Path(run_dir) / "snapshots"
    snap.mkdir(parents=True)
    xr.Dataset({"mesh_node_x": ("mesh_node", X.ravel()), "mesh_node_y": ("mesh_node", Y.ravel()),
                "mesh_face_nodes": (("mesh_face", "mesh_nmax_face"), tri),
                "damage": (("time", "mesh_face"), damage[None, :])}).to_netcdf(snap / "snapshot_00000001.nc")
    (snap / "index.json").write_text(json.dumps([{"file": "snapshot_00000001.nc", "time_s": time_s, "step": 1,
                                                  "mesh_epoch": 0}]))


def test_disk_convergence_band_length_is_the_same_band_on_two_meshes(tmp_path):
    """Rule RD6's band length per area: one straight band across the disk's interior (radius 400 km) gives
    √2 × its length over the interior's area on a mesh of right triangles, whatever the element size, and
    elements at or below the band damage are not counted."""
    import disk_convergence as dc

    day = 28
    for h in (10e3, 5e3):
        _square_mesh_snapshot(tmp_path / f"h{h:g}", h, 0.95, day * dc.DAY_S)
        _square_mesh_snapshot(tmp_path / f"h{h:g}-weak", h, dc.BAND_DAMAGE, day * dc.DAY_S)
    r = 400.0  # km
    expected = np.sqrt(2.0) * 2 * r / (np.pi * r ** 2)
    got = {h: dc.band_length_per_km(tmp_path / f"h{h:g}", days=(day,))[0] for h in (10e3, 5e3)}
    assert got[10e3] == pytest.approx(expected, rel=0.03) and got[5e3] == pytest.approx(expected, rel=0.03)
    assert got[5e3] == pytest.approx(got[10e3], rel=0.02)
    assert dc.band_length_per_km(tmp_path / "h5000-weak", days=(day,)) == [0.0]


def test_disk_convergence_band_perimeter_counts_a_wide_band_once_and_splits_the_floes(tmp_path):
    """Rule RD11: one straight band 20 km wide across the interior (radius 400 km) is two elements wide on a
    10 km mesh and four on a 5 km one. The √area count doubles; the perimeter length (half the band's
    rim) is its length on both meshes, its width 20 km, and it cuts the interior into two floes of equal
    area. A band at the band damage (not above it) is no band: no rim, one floe."""
    import disk_convergence as dc

    day, r_km, w_km = 28, 400.0, 20.0
    for h in (10e3, 5e3):
        _square_mesh_snapshot(tmp_path / f"h{h:g}", h, 0.95, day * dc.DAY_S, band_width_m=w_km * 1e3)
    _square_mesh_snapshot(tmp_path / "weak", 5e3, dc.BAND_DAMAGE, day * dc.DAY_S, band_width_m=w_km * 1e3)
    got = {h: dc.band_perimeter_and_floes(tmp_path / f"h{h:g}", days=(day,)) for h in (10e3, 5e3)}
    counted = {h: dc.band_length_per_km(tmp_path / f"h{h:g}", days=(day,))[0] for h in (10e3, 5e3)}
    assert counted[5e3] == pytest.approx(2 * counted[10e3], rel=0.03)
    interior = np.pi * r_km ** 2
    for h in (10e3, 5e3):
        g = {k: v[0] for k, v in got[h].items()}
        assert g["perimeter_per_km"] == pytest.approx(2 * r_km / interior, rel=0.03)
        assert g["band_width_km"] == pytest.approx(w_km, rel=0.05)
        assert g["floe_area_km2"] == pytest.approx((interior - 2 * r_km * w_km) / 2, rel=0.03)
        assert g["n_floes_per_1e5_km2"] == pytest.approx(2 / interior * 1e5, rel=0.03)
    weak = {k: v[0] for k, v in dc.band_perimeter_and_floes(tmp_path / "weak", days=(day,)).items()}
    assert weak["perimeter_per_km"] == 0.0 and weak["floe_area_km2"] == pytest.approx(interior, rel=0.03)


def test_disk_convergence_healing_part_needs_an_interval_below_zero():
    """Rule RD12 (s): the resampled 90 % interval of the mean brackets the mean, is seeded (the same values
    give the same interval) and narrows as the months add up; healing's part is shown only when the interval
    lies below 0."""
    import disk_convergence as dc

    rng = np.random.default_rng(3)
    few = -0.01 + 0.02 * rng.standard_normal(8)
    many = np.concatenate([few, -0.01 + 0.02 * rng.standard_normal(56)])
    m, lo, hi = dc.mean_interval(few)
    assert lo < m < hi and m == pytest.approx(few.mean())
    assert dc.mean_interval(few) == (m, lo, hi)
    assert dc.mean_interval(many)[2] - dc.mean_interval(many)[1] < hi - lo
    assert not dc.verdict_healing(np.array([-0.03, 0.02, -0.01, 0.01]))["s_shown"]
    shown = dc.verdict_healing(np.array([-0.012, -0.015, -0.009, -0.011, -0.02, -0.008]))
    assert shown["s_shown"] and shown["interval_90"][1] < 0 and shown["n_months"] == 6


def test_disk_convergence_month_groups_keep_to_their_seeds(tmp_path, monkeypatch):
    """Adding months of other wind seeds leaves a set's eight-month record alone: only the seeds asked for are
    read, and a set with a mesh missing is refused by name."""
    import disk_convergence as dc

    monkeypatch.setattr(dc, "OUT", tmp_path)
    for km in (20, 10):
        for seed in (2026, 2027, 2035):
            snap = tmp_path / dc.run_name("lead", "same_pa", km, seed, "month") / "snapshots"
            snap.mkdir(parents=True)
            (snap / "index.json").write_text("[]")
    got = dc.month_groups("lead", "same_pa", "", dc.MONTH_SEEDS)
    assert {k: [dc._seed_of(p) for p in v] for k, v in got.items()} == {"20": [2026, 2027], "10": [2026, 2027]}
    assert [dc._seed_of(p) for p in dc.month_groups("lead", "same_pa", "", (2035,))["10"]] == [2035]
    with pytest.raises(SystemExit, match="month-noheal-lead-same_pa"):
        dc.month_groups("lead", "same_pa", "noheal", dc.MONTH_SEEDS)


def test_disk_convergence_element_neighbours_are_the_shared_edges():
    """Two triangles sharing one edge, and a third touching them at a node only: one pair, its edge's nodes."""
    import disk_convergence as dc

    pairs, nodes = dc.element_neighbours(np.array([[0, 1, 2], [2, 1, 3], [3, 4, 5]]))
    assert np.sort(pairs, axis=1).tolist() == [[0, 1]] and nodes.tolist() == [[1, 2]]


def test_disk_convergence_fragmentation_verdict_needs_agreement_and_a_fall_with_cutting():
    """Rule RD7 (k): the meshes must agree within 0.02 in every bin both fill with at least 8 windows, and
    each mesh's β must fall by at least 0.03 from its least to its most cut filled bin."""
    import disk_convergence as dc

    def row(*cells):
        return [{"n_windows": n, "beta_common": b} for n, b in cells]

    bins = {"20": row((27, 0.16), (38, 0.14), (7, 0.10), (0, None)),
            "10": row((37, 0.15), (16, 0.145), (56, 0.12), (35, 0.11))}
    v = dc.verdict_fragmentation(bins)
    assert v["bins_shared"] == 2 and v["largest_gap_shared"] == pytest.approx(0.01) and v["meshes_agree"]
    assert v["drop_least_to_most_cut"]["20"] == pytest.approx(0.02)  # the 7-window bin is not filled
    assert v["drop_least_to_most_cut"]["10"] == pytest.approx(0.04)
    assert not v["beta_falls_with_cutting"] and not v["k_fragmentation_sets_beta"]
    bins["20"][1]["beta_common"] = 0.12
    v = dc.verdict_fragmentation(bins)
    assert v["beta_falls_with_cutting"] and not v["meshes_agree"] and not v["k_fragmentation_sets_beta"]
    bins["10"][1]["beta_common"] = 0.125
    assert dc.verdict_fragmentation(bins)["k_fragmentation_sets_beta"]


def test_disk_convergence_factors_pair_each_variant_with_the_spun_up_months():
    """Rule RD14: a variant's change is paired by wind seed with the spun-up set on the same mesh (a month only
    one set has is left out), its fall is its own 10 km less 20 km month by month, and a factor raises the
    20 km β only when the change is at least +0.015 with its interval above 0."""
    import disk_convergence as dc

    def record(variant, beta20, beta10):
        return {"meshes": {km: {"beta_common": float(np.mean(list(b.values()))),
                                "beta_common_per_run": {f"month-{variant}-lead-same_pa-{km}km-w{sd}": v
                                                        for sd, v in b.items()}}
                           for km, b in (("20", beta20), ("10", beta10))}}

    seeds = range(2026, 2034)
    base = record("spun", {sd: 0.14 + 0.002 * (sd % 3) for sd in seeds}, {sd: 0.12 for sd in seeds})
    thick = record("thickspun", {sd: 0.165 + 0.002 * (sd % 3) + 0.001 * (sd % 2) for sd in seeds},
                   {sd: 0.12 for sd in list(seeds) + [2040]})
    c = dc.paired_changes(thick, base)
    assert c["months_20km"] == 8 and c["months_10km"] == 8
    assert c["change_20km"][0] == pytest.approx(0.0255) and c["change_10km"][0] == pytest.approx(0.0, abs=1e-12)
    assert c["change_20km"][1] > 0.0
    assert c["fall_10_less_20"][0] == pytest.approx(-(0.165 + np.mean([0.002 * (sd % 3) + 0.001 * (sd % 2)
                                                                       for sd in seeds]) - 0.12))
    noisy = record("concspun", {sd: 0.14 + 0.002 * (sd % 3) + 0.03 * (-1) ** sd for sd in seeds},
                   {sd: 0.12 for sd in seeds})
    mean = record("meanspun", {sd: 0.17 + 0.002 * (sd % 3) for sd in seeds}, {sd: 0.12 for sd in seeds})
    v = dc.verdict_factors({"thickspun": c, "concspun": dc.paired_changes(noisy, base),
                            "meanspun": dc.paired_changes(mean, base)})
    assert v["u_thickness_raises_20km"] and not v["v_concentration_raises_20km"]
    assert v["meanspun_20km"] == pytest.approx(0.03) and v["factors_add_up"]


def test_disk_convergence_spinup_state_reads_the_interior(tmp_path, monkeypatch):
    """The state a spin-up hands to its months is read over the interior only (100 km from the coast): a broken,
    thin rim is left out, and the band fraction counts damage above 0.9."""
    import disk_convergence as dc

    monkeypatch.setattr(dc, "OUT", tmp_path)
    r = np.array([0.0, 100e3, 200e3, 300e3, 450e3, 480e3])
    np.savez(dc.spinup_path("lead", "same_pa", 20, "thickspun"), centroid_x_m=r, centroid_y_m=np.zeros_like(r),
             damage=np.array([0.0, 0.95, 0.5, 0.0, 1.0, 1.0]), thickness=np.array([1.6, 1.6, 1.6, 1.6, 0.2, 0.2]),
             concentration=np.array([1.0, 0.99, 0.98, 0.97, 0.5, 0.5]))
    got = dc.spinup_state("lead", "same_pa")
    assert list(got) == ["thickspun"] and list(got["thickspun"]) == ["20"]
    m = got["thickspun"]["20"]
    assert m["mean_damage"] == pytest.approx(1.45 / 4) and m["band_fraction"] == pytest.approx(0.25)
    assert m["mean_thickness_m"] == pytest.approx(1.6) and m["mean_concentration"] == pytest.approx(0.985)


def test_disk_convergence_fine_mesh_verdict_needs_every_month():
    """Rule RD15: β keeps falling (or turns back) below 10 km only if every month moves by at least 0.015 the
    same way; one month within 0.015 leaves it untold. The 5 km months are their own runs."""
    import disk_convergence as dc

    def row(b5, b10):
        return {"seed": 0, "beta_5km": b5, "beta_10km": b10, "beta_20km": 0.17}

    falling = dc.verdict_fine([row(0.10, 0.12), row(0.12, 0.14)])
    assert falling["w_keeps_falling"] and not falling["x_turns_back"]
    assert falling["change_5_less_10"] == pytest.approx([-0.02, -0.02])
    assert dc.verdict_fine([row(0.15, 0.12), row(0.16, 0.14)])["x_turns_back"]
    untold = dc.verdict_fine([row(0.10, 0.12), row(0.135, 0.14)])
    assert not untold["w_keeps_falling"] and not untold["x_turns_back"]
    assert not dc.verdict_fine([])["w_keeps_falling"]
    name = dc.run_name("lead", "same_pa", dc.FINE_KM, 2026, "month", "meanspun")
    assert name == "month-meanspun-lead-same_pa-5km-w2026"
    assert "domain.resolution_m=5000" in dc.command("lead", "same_pa", dc.FINE_KM, 2026, "month", "meanspun")


def test_disk_convergence_realisations_replace_the_spin_up_wind_seed():
    """Rule RD16: a realisation's spin-up runs under its own wind seed, given once (the scene refuses a key set
    twice), with RD9's state file names kept apart; (y) needs a span of 0.03 in the 20 km β."""
    import disk_convergence as dc

    cmd = dc.spinup_command("lead", "same_pa", 20, "spun2023")
    seeds = [x for x in cmd if x.startswith("forcing.wind.seed=")]
    assert seeds == ["forcing.wind.seed=2023"]
    assert "forcing.wind.seed=2025" in dc.spinup_command("lead", "same_pa", 20)
    assert dc.spinup_path("lead", "same_pa", 20, "spun2023") != dc.spinup_path("lead", "same_pa", 20)
    assert f"initial.state_file={dc.spinup_path('lead', 'same_pa', 20, 'spun2023')}" in dc.command(
        "lead", "same_pa", 20, 2027, "month", "spun2023")
    assert dc.verdict_realisations({"spun": 0.139, "spun2022": 0.15, "spun2023": 0.171})["y_realisation_moves_beta"]
    small = dc.verdict_realisations({"spun": 0.139, "spun2022": 0.15, "spun2023": 0.16})
    assert not small["y_realisation_moves_beta"] and small["span_20km"] == pytest.approx(0.021)


def test_disk_convergence_second_pack_fine_mesh_and_realisation_at_10km():
    """Rules RD17 and RD18: ``fine`` reads a named spun-up variant's 5 km months, RD18's verdict separates
    "keeps its β" (within 0.015), "follows the realisation" (0.02 higher) and neither, and the command line
    refuses a mesh or variant no rule names before any work."""
    import disk_convergence as dc

    assert dc.run_name("lead", "same_pa", dc.FINE_KM, 2026, "month", "spun") == "month-spun-lead-same_pa-5km-w2026"
    kept = dc.verdict_realisation_10km(0.128, 0.120)
    assert kept["z_10km_keeps_its_beta"] and not kept["follows_realisation"]
    assert kept["change_10km"] == pytest.approx(0.008)
    follows = dc.verdict_realisation_10km(0.141, 0.120)
    assert follows["follows_realisation"] and not follows["z_10km_keeps_its_beta"]
    between = dc.verdict_realisation_10km(0.137, 0.120)
    assert not between["follows_realisation"] and not between["z_10km_keeps_its_beta"]
    lower = dc.verdict_realisation_10km(0.100, 0.120)
    assert not lower["follows_realisation"] and not lower["z_10km_keeps_its_beta"]
    with pytest.raises(SystemExit):
        dc.main(["realisations", "--km", "5"])
    with pytest.raises(SystemExit):
        dc.main(["fine", "--variant", "noheal"])


def test_disk_convergence_thermodynamics_variant_and_verdict():
    """Rule RD19: variant ``nothermo`` switches thermodynamics off in the month's command (and nothing else), and
    the verdict separates a fall without thermodynamics (interval below 0) from none, and a part shown (interval
    excluding 0, either side) from noise."""
    import disk_convergence as dc

    def sets_of(cmd):
        return [cmd[i + 1] for i, x in enumerate(cmd) if x == "--set"]

    cmd = dc.command("lead", "same_pa", 10, 2030, "month", "nothermo")
    assert cmd[cmd.index("--out") + 1].endswith("month-nothermo-lead-same_pa-10km-w2030")
    assert sets_of(cmd) == sets_of(dc.command("lead", "same_pa", 10, 2030, "month")) + ["thermo.enabled=false"]
    falls = [-0.02, -0.03, -0.01, -0.025, -0.015, -0.02, -0.03, -0.01]
    v = dc.verdict_thermodynamics(falls, [0.004, -0.006, 0.002, -0.003, 0.005, -0.004, 0.001, -0.002])
    assert v["t_fall_without_thermo"] and not v["t_prime_part_shown"]
    assert v["dbeta_without_thermo"] == pytest.approx(np.mean(falls))
    lo, hi = v["dbeta_without_interval_90"]
    assert lo < v["dbeta_without_thermo"] < hi < 0.0
    none = dc.verdict_thermodynamics([0.02, -0.03, 0.01, -0.01, 0.015, -0.02, 0.0, 0.01], [0.0] * 8)
    assert not none["t_fall_without_thermo"]
    parts = [0.01, 0.02, 0.015, 0.012, 0.018, 0.011, 0.02, 0.016]
    above = dc.verdict_thermodynamics(falls, parts)
    below = dc.verdict_thermodynamics(falls, [-x for x in parts])
    assert above["t_prime_part_shown"] and above["thermo_part"] > 0.0
    assert below["t_prime_part_shown"] and below["thermo_part"] < 0.0


def test_disk_convergence_mechanics_variant_and_verdict():
    """Rule RD20: variant ``mechanics`` takes thermodynamics, healing, mesh motion and remeshing out of the month
    (and changes nothing else), and its verdict needs both a month-by-month fall and a pooled one of 0.015."""
    import disk_convergence as dc

    def sets_of(cmd):
        return [cmd[i + 1] for i, x in enumerate(cmd) if x == "--set"]

    extra = sets_of(dc.command("lead", "same_pa", 20, 2026, "month", "mechanics"))[
        len(sets_of(dc.command("lead", "same_pa", 20, 2026, "month"))):]
    assert sorted(extra) == ["healing.law=none", "lagrangian.enabled=false", "remesh.enabled=false",
                             "thermo.enabled=false"]
    falls = [-0.02, -0.03, -0.01, -0.025, -0.015, -0.02, -0.03, -0.01]
    assert dc.verdict_mechanics(falls, 0.02)["u_fall_with_mechanics_alone"]
    assert not dc.verdict_mechanics(falls, 0.010)["u_fall_with_mechanics_alone"]
    mixed = dc.verdict_mechanics([0.02, -0.03, 0.01, -0.01, 0.015, -0.02, 0.0, 0.01], 0.02)
    assert not mixed["u_fall_with_mechanics_alone"] and mixed["dbeta_interval_90"][1] > 0.0


def test_disk_convergence_restoring_variants_and_verdict():
    """Rule RD21: ``mechheal`` and ``mechmove`` each put one piece back into ``mechanics`` (healing; mesh motion and
    remeshing), and the verdict needs both a month-by-month fall and a pooled one of 0.010; the part is paired."""
    import disk_convergence as dc

    def sets_of(cmd):
        return [cmd[i + 1] for i, x in enumerate(cmd) if x == "--set"]

    n = len(sets_of(dc.command("lead", "same_pa", 20, 2026, "month")))
    mech = set(sets_of(dc.command("lead", "same_pa", 20, 2026, "month", "mechanics"))[n:])
    heal = set(sets_of(dc.command("lead", "same_pa", 20, 2026, "month", "mechheal"))[n:])
    move = set(sets_of(dc.command("lead", "same_pa", 20, 2026, "month", "mechmove"))[n:])
    assert mech - heal == {"healing.law=none"} and heal <= mech
    assert mech - move == {"lagrangian.enabled=false", "remesh.enabled=false"} and move <= mech
    falls = [-0.02, -0.03, -0.01, -0.025, -0.015, -0.02, -0.03, -0.01]
    v = dc.verdict_restoring(falls, 0.015, [x + 0.004 for x in falls])
    assert v["brings_fall_back"] and abs(v["part"] - (-0.02 + 0.004)) < 1e-12 and v["part_interval_90"][1] < 0.0
    assert not dc.verdict_restoring(falls, 0.008, falls)["brings_fall_back"]
    mixed = dc.verdict_restoring([0.02, -0.03, 0.01, -0.01, 0.015, -0.02, 0.0, 0.01], 0.02, falls)
    assert not mixed["brings_fall_back"] and mixed["dbeta_interval_90"][1] > 0.0


def test_disk_convergence_counted_verdict():
    """Rule RD22: (p) needs the pieces' joint part below 0 over its whole interval; (q) needs healing alone's
    month-by-month fall below 0 and a pooled fall of 0.010, as RD21's (x)."""
    import disk_convergence as dc

    joint = [-0.02, -0.03, -0.01, -0.025, -0.015, -0.02, -0.03, -0.01]
    v = dc.verdict_counted(joint, joint, 0.012)
    assert v["p_pieces_make_the_fall"] and v["q_healing_alone"] and v["n_months"] == 8
    assert abs(v["joint_part"] - sum(joint) / 8) < 1e-12 and v["joint_part_interval_90"][1] < 0.0
    assert not dc.verdict_counted(joint, joint, 0.008)["q_healing_alone"]
    mixed = [0.02, -0.03, 0.01, -0.01, 0.015, -0.02, 0.0, 0.01]
    w = dc.verdict_counted(mixed, mixed, 0.02)
    assert not w["p_pieces_make_the_fall"] and not w["q_healing_alone"]


def test_disk_convergence_moved_verdict():
    """Rule RD23: (y') needs the moving mesh's month-by-month fall below 0 and a pooled fall of 0.010; (y'') needs
    its part against the mechanics below 0 over its whole interval, independently of (y')."""
    import disk_convergence as dc

    falls = [-0.02, -0.03, -0.01, -0.025, -0.015, -0.02, -0.03, -0.01]
    small = [0.01, -0.01, 0.005, -0.005, 0.0, 0.01, -0.01, 0.0]
    v = dc.verdict_moved(falls, 0.012, small)
    assert v["y1_moving_mesh_alone_keeps_fall"] and not v["y2_moving_mesh_part_shown"] and v["n_months"] == 8
    assert abs(v["dbeta"] - sum(falls) / 8) < 1e-12 and abs(v["part"]) < 1e-12
    assert not dc.verdict_moved(falls, 0.008, small)["y1_moving_mesh_alone_keeps_fall"]
    w = dc.verdict_moved(small, 0.02, falls)
    assert not w["y1_moving_mesh_alone_keeps_fall"] and w["y2_moving_mesh_part_shown"]


def test_disk_convergence_correlated_verdict_and_cohesion():
    """Rule RD24: (v) needs the disorder's part above 0 over its whole interval, (v') the correlated set's fall
    below 0; the variant keeps each element's cohesion on [C, 2C]: C_lab × 1.5 with g on [2/3, 4/3] and the white
    disorder off, and only in the month stage."""
    import disk_convergence as dc

    falls = [-0.02, -0.03, -0.01, -0.025, -0.015, -0.02, -0.03, -0.01]
    rises = [-x for x in falls]
    v = dc.verdict_correlated(falls, rises)
    assert v["v_fall_with_white_disorder"] and v["v2_fall_without_white_disorder"] and v["n_months"] == 8
    w = dc.verdict_correlated(rises, falls)
    assert not w["v_fall_with_white_disorder"] and not w["v2_fall_without_white_disorder"]
    sets = dict(x.split("=") for x in dc.command("lead", "same_pa", 10, 2030, "month", "mechcorr")[8::2])
    base = dict(x.split("=") for x in dc.command("lead", "same_pa", 10, 2030, "month", "mechanics")[8::2])
    amp = float(sets["rheology.strength_correlated_amplitude"])
    assert float(sets["rheology.strength_disorder"]) == 0.0 and float(sets["rheology.strength_correlation_m"]) == 40e3
    lab, lab0 = float(sets["rheology.strength_lab_pa"]), float(base["rheology.strength_lab_pa"])
    assert abs(lab * (1 - amp) - lab0) < 1e-5 * lab0 and abs(lab * (1 + amp) - 2 * lab0) < 1e-5 * lab0
    assert {k: x for k, x in base.items() if k != "rheology.strength_lab_pa"}.items() <= sets.items()


def test_disk_convergence_banded_verdict_and_overrides():
    """Rule RD25: (r) needs the regularisation's part above 0 over its whole interval, (r') the regularised set's
    fall below 0; the variant is the mechanics with both lengths at 20 km and nothing else changed."""
    import disk_convergence as dc

    falls = [-0.02, -0.03, -0.01, -0.025, -0.015, -0.02, -0.03, -0.01]
    v = dc.verdict_banded(falls, [-x for x in falls])
    assert v["r_regularisation_reduces_fall"] and v["r2_fall_survives"]
    w = dc.verdict_banded([-x for x in falls], falls)
    assert not w["r_regularisation_reduces_fall"] and not w["r2_fall_survives"]
    extra = set(dc.MONTH_VARIANTS["mechband"]) - set(dc.MONTH_VARIANTS["mechanics"])
    assert extra == {"rheology.damage_length_m=20e3", "rheology.crack_band_length_m=20e3"}
    assert set(dc.MONTH_VARIANTS["mechanics"]) <= set(dc.MONTH_VARIANTS["mechband"])


def test_disk_convergence_averaged_verdict_and_overrides():
    """Rule RD26: (a) needs the averaging's part above 0 over its whole interval, (a') the averaged set's fall
    below 0; the variant is the mechanics with R = 40 km and nothing else changed, and its analysis reads the
    eight months chosen in the rule by default."""
    import disk_convergence as dc

    falls = [-0.02, -0.03, -0.01, -0.025, -0.015, -0.02, -0.03, -0.01]
    v = dc.verdict_averaged(falls, [-x for x in falls])
    assert v["a_averaging_reduces_fall"] and v["a2_fall_survives"]
    w = dc.verdict_averaged([-x for x in falls], falls)
    assert not w["a_averaging_reduces_fall"] and not w["a2_fall_survives"]
    extra = set(dc.MONTH_VARIANTS["mechnl"]) - set(dc.MONTH_VARIANTS["mechanics"])
    assert extra == {"rheology.damage_nonlocal_radius_m=40e3"}
    assert set(dc.MONTH_VARIANTS["mechanics"]) <= set(dc.MONTH_VARIANTS["mechnl"])
    cmd = dc.command("lead", "same_pa", 10, 2034, "month", "mechnl")
    assert "rheology.failure_stress=effective" in cmd and "rheology.damage_nonlocal_radius_m=40e3" in cmd
    assert dc.averaged.__defaults__[-1] == tuple(range(2034, 2042))
