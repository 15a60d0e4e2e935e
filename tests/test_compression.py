"""Seed 004 uniaxial compression test at N = 10 (issue 2)."""
import numpy as np
import pytest
import xarray as xr

from lagice.errors import ConfigError
from lagice.scenes import compression

N = 10


@pytest.fixture(scope="module")
def heal_run(tmp_path_factory):
    return compression.run(tmp_path_factory.mktemp("heal"), n_across=N, seed=0, max_strain=4.5e-4,
                           progress=False, plot=False)


@pytest.fixture(scope="module")
def noheal_run(tmp_path_factory):
    return compression.run(tmp_path_factory.mktemp("noheal"), n_across=N, seed=0, max_strain=4.5e-4,
                           healing=False, progress=False, plot=False)


def first_drop(stress_c, frac):
    """Index of the peak preceding the first drawdown larger than ``frac`` and of
    the minimum after it (compressive stress, positive)."""
    runmax = np.maximum.accumulate(stress_c)
    dd = (runmax - stress_c) / np.maximum(runmax, 1e-30)
    dd[runmax < 0.5 * stress_c.max()] = 0.0  # ignore the elastic start-up transient
    k = int(np.argmax(dd > frac))
    assert dd[k] > frac, "no macroscopic stress drop"
    ipk = int(np.argmax(stress_c[:k]))
    # the drop ends where the stress starts to rise again
    j = k
    while j + 1 < len(stress_c) and stress_c[j + 1] <= stress_c[j]:
        j += 1
    return ipk, j


def test_initial_slope_is_plate_modulus(heal_run):
    """Top pushed, bottom fixed in y only, sides free: uniaxial stress, so the
    macroscopic modulus is E0 (Maxwell relaxation over t << λ0 is < 0.1 %)."""
    ts = heal_run["timeseries"]
    s = -ts["stress"]
    E0 = heal_run["scene"].solver.rheology.E0
    sel = (s > 0.1 * s.max()) & (s < 0.5 * s.max()) & (np.cumsum(ts["n_damaged"]) == 0)
    assert sel.sum() > 100
    slope = np.polyfit(ts["strain"][sel], s[sel], 1)[0]
    assert slope == pytest.approx(E0, rel=0.02)


def test_damage_peak_drop_and_localisation(noheal_run):
    ts = noheal_run["timeseries"]
    s = -ts["stress"]
    ipk, imin = first_drop(s, 0.02)
    first_damage = int(np.argmax(ts["n_damaged"] > 0))
    assert 0 < first_damage < ipk, "damage starts before the macroscopic peak"
    assert ts["damage_rate"][ipk:imin + 1].max() > 10 * ts["damage_rate"][:first_damage + 50].max()
    st = noheal_run["scene"].state
    area = noheal_run["scene"].solver.area
    dmg = np.sort(st.damage * area)[::-1]
    frac = (np.searchsorted(np.cumsum(dmg), 0.5 * dmg.sum()) + 1) / len(dmg)
    assert frac <= 0.20, f"half of the damage in {frac:.1%} of the elements"


def test_healing_rebuilds_stress_after_drop(heal_run, noheal_run):
    s_h = -heal_run["timeseries"]["stress"]
    s_n = -noheal_run["timeseries"]["stress"]
    ipk, imin = first_drop(s_h, 0.01)
    rebuild_h = s_h[imin:].max() - s_h[imin]
    assert rebuild_h > 0.05 * s_h[ipk]
    assert s_h[-1] > s_h[ipk], "with healing the stress climbs past the first peak"
    _, imin_n = first_drop(s_n, 0.01)
    rebuild_n = s_n[imin_n:].max() - s_n[imin_n]
    assert rebuild_h > 1.5 * rebuild_n
    assert heal_run["timeseries"]["mean_damage"][-1] < noheal_run["timeseries"]["mean_damage"][-1]


def test_seed_reproducible_and_seed_dependent(tmp_path):
    kw = dict(n_across=N, max_strain=3.0e-4, healing=False, progress=False, plot=False)
    a = compression.run(tmp_path / "a", seed=7, **kw)
    b = compression.run(tmp_path / "b", seed=7, **kw)
    c = compression.run(tmp_path / "c", seed=8, **kw)
    sa, sb, sc = (r["scene"].state for r in (a, b, c))
    assert sa.damage.max() > 0.5
    assert np.array_equal(sa.damage, sb.damage) and np.array_equal(sa.stress, sb.stress)
    assert np.array_equal(a["timeseries"]["stress"], b["timeseries"]["stress"])
    assert not np.array_equal(sa.cohesion, sc.cohesion)
    assert np.corrcoef(sa.damage, sc.damage)[0, 1] < 0.9


def test_netcdf_output_readable(heal_run):
    ds = xr.load_dataset(heal_run["netcdf"])
    assert ds["macro_stress"].attrs["units"] == "Pa"
    assert ds.sizes["time"] == len(heal_run["timeseries"]["time"])
    assert ds["damage"].dims == ("snapshot", "mesh_face")
    assert ds["damage"].shape[1] == heal_run["scene"].mesh.n_elements
    assert np.array_equal(ds["macro_stress"].values, heal_run["timeseries"]["stress"])
    assert ds["mesh"].attrs["cf_role"] == "mesh_topology"
    assert np.all(ds["strain_rate_total"].values >= 0)


@pytest.mark.parametrize("kw,match", [
    ({"n_across": 0}, "n_across"), ({"n_across": 2.5}, "n_across"),
    ({"dt_s": -1.0}, "dt_s"), ({"solver": "magic"}, "solver = 'magic'"),
    ({"rheology": {"poisson": 0.5}}, "poisson"), ({"rheology": {"alpha": 1.0}}, "alpha"),
    ({"rheology": {"cohesion_min_pa": -5.0}}, "cohesion_min_pa"),
])
def test_bad_input_fails_before_meshing(kw, match, monkeypatch):
    import lagice.scenes.compression as mod

    def no_mesh(*a, **k):
        raise AssertionError("meshing started before validation")

    monkeypatch.setattr(mod, "generate_mesh", no_mesh)
    with pytest.raises(ConfigError, match=match):
        compression.build(**kw)
