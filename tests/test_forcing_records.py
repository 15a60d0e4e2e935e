"""Record interpolation in time and space, weight caching (forcing/records.py)."""
import numpy as np
import pytest

from forcing import ConstantField, Forcing, InMemoryRecords, RecordField, RegularGrid, as_field, open_gridded
from lagice.errors import ConfigError, ForcingError

H6 = 6 * 3600.0


def bilinear(x, y, t):
    """A field bilinear in space and linear in time (reproduced exactly)."""
    return (1.5 + 2e-6 * x - 3e-6 * y + 4e-12 * x * y) + t * (1e-5 - 2e-11 * x + 5e-12 * x * y / 1e6)


def make_records(kind="scalar"):
    # non-uniform axes: bilinear interpolation is exact on any rectilinear grid
    gx = np.array([-2e5, -1.2e5, 0.0, 3e4, 1.5e5, 4e5, 5e5])
    gy = np.array([-3e5, -1e5, 2e4, 2.5e5, 6e5])
    grid = RegularGrid(gx, gy)
    times = np.array([0.0, H6, 2 * H6, 3 * H6, 4 * H6])
    X, Y = grid.mesh()
    f = np.stack([bilinear(X, Y, t) for t in times])
    if kind == "scalar":
        data = f[:, None]
        names = ("T",)
    else:
        data = np.stack([f, -2.0 * f + 1.0], axis=1)
        names = ("u", "v")
    units = "degC" if kind == "scalar" else "m s-1"
    return InMemoryRecords(times, grid, data, names, units=units, name="<test records>")


def nodes(n=500, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-1.5e5, 3.5e5, n), rng.uniform(-2e5, 4e5, n)


@pytest.mark.parametrize("kind", ["scalar", "vector"])
def test_time_and_space_interpolation_exact_on_moving_mesh(kind):
    field = RecordField(make_records(kind))
    x, y = nodes()
    field.prepare(0.0, 4 * H6, x, y)
    version = 0
    for step, t in enumerate(np.linspace(0.0, 4 * H6, 23)):
        # move the nodes (Lagrangian mesh), in place, and tell the field
        x += 800.0 * np.sin(0.3 * step + y / 1e5)
        y += 600.0 * np.cos(0.2 * step + x / 1e5)
        version += 1
        val = field.evaluate(t, x, y, mesh_version=version)
        exact = bilinear(x, y, t)
        if kind == "scalar":
            assert val.shape == x.shape
            np.testing.assert_allclose(val, exact, rtol=1e-12, atol=1e-12)
        else:
            assert val.shape == (2, x.size)
            np.testing.assert_allclose(val[0], exact, rtol=1e-12, atol=1e-12)
            np.testing.assert_allclose(val[1], -2.0 * exact + 1.0, rtol=1e-12, atol=1e-12)
    # records were read once each (5 records), never re-read for the weights
    assert field.n_record_reads == 5


def test_weight_rebuild_trigger():
    field = RecordField(make_records())
    x, y = nodes()
    field.evaluate(100.0, x, y)
    assert field.n_weight_builds == 1
    field.evaluate(200.0, x, y)  # same positions, no version: compared, no rebuild
    assert field.n_weight_builds == 1
    x += 10.0  # moved in place: detected by the comparison
    np.testing.assert_allclose(field.evaluate(200.0, x, y), bilinear(x, y, 200.0), rtol=1e-12)
    assert field.n_weight_builds == 2
    field.evaluate(300.0, x, y, mesh_version=7)  # new version: rebuilt without comparing
    assert field.n_weight_builds == 3
    x += 5.0
    field.evaluate(400.0, x, y, mesh_version=7)  # same version: trusted, no check at all
    assert field.n_weight_builds == 3
    x2, y2 = nodes(300, seed=3)  # new mesh (remesh), other size
    np.testing.assert_allclose(field.evaluate(400.0, x2, y2, mesh_version=8), bilinear(x2, y2, 400.0),
                               rtol=1e-12)
    assert field.n_weight_builds == 4

    tol = RecordField(make_records(), rebuild_tolerance_m=50.0)
    x, y = nodes()
    tol.evaluate(0.0, x, y)
    x += 20.0
    tol.evaluate(0.0, x, y)
    assert tol.n_weight_builds == 1  # moved less than the tolerance
    x += 40.0
    tol.evaluate(0.0, x, y)
    assert tol.n_weight_builds == 2


def test_record_pair_cache():
    field = RecordField(make_records())
    x, y = nodes()
    for t in np.linspace(0.1, H6 - 1, 10):
        field.evaluate(t, x, y)
    assert field.n_record_reads == 2
    field.evaluate(1.5 * H6, x, y)
    assert field.n_record_reads == 3
    assert len(field._records) == 2


def test_time_and_space_extrapolation_opt_in():
    x, y = nodes()
    field = RecordField(make_records())
    with pytest.raises(ForcingError, match="outside the records"):
        field.prepare(0.0, 5 * H6, x, y)
    with pytest.raises(ForcingError, match="outside the records"):
        field.evaluate(-1.0, x, y)
    hold = RecordField(make_records(), time_extrapolation="hold")
    hold.prepare(-H6, 6 * H6, x, y)
    np.testing.assert_allclose(hold.evaluate(6 * H6, x, y), bilinear(x, y, 4 * H6), rtol=1e-12)
    xo = np.append(x, 9e5)
    yo = np.append(y, 0.0)
    with pytest.raises(ForcingError, match="outside the forcing grid"):
        field.prepare(0.0, H6, xo, yo)
    clamp = RecordField(make_records(), space_extrapolation="clamp")
    clamp.prepare(0.0, H6, xo, yo)
    v = clamp.evaluate(0.0, xo, yo)
    assert v[-1] == pytest.approx(bilinear(5e5, 0.0, 0.0))


def test_steady_single_record():
    rec = make_records()
    one = InMemoryRecords(rec.times_s[:1], rec.grid, rec.data[:1], rec.variables)
    field = RecordField(one)
    x, y = nodes()
    field.prepare(-1e9, 1e9, x, y)
    np.testing.assert_allclose(field.evaluate(1e8, x, y), bilinear(x, y, 0.0), rtol=1e-12)


def test_callables_and_constants_adapted():
    x, y = nodes(50)
    wind = as_field(lambda t, x, y: (3.0, -y * 1e-6), "vector")
    v = wind.evaluate(10.0, x, y)
    assert v.shape == (2, 50) and np.all(v[0] == 3.0)
    np.testing.assert_array_equal(v[1], -y * 1e-6)
    arr_wind = as_field(lambda t, x, y: np.vstack([x * 0 + t, y * 0]), "vector")
    assert arr_wind.evaluate(2.0, x, y)[0, 0] == 2.0
    temp = as_field(lambda t, x, y: -10.0, "scalar")
    assert temp.evaluate(0.0, x, y).shape == (50,)
    const = as_field((1.0, 2.0), "vector")
    assert isinstance(const, ConstantField) and np.all(const.evaluate(0, x, y)[1] == 2.0)
    with pytest.raises(ConfigError):
        as_field((1.0, 2.0), "scalar")
    bad = as_field(lambda t, x, y: np.full(x.size, np.nan), "scalar")
    with pytest.raises(ForcingError, match="non-finite"):
        bad.prepare(0.0, 1.0, x, y)
    wrong = as_field(lambda t, x, y: np.zeros(3), "scalar")
    with pytest.raises(ForcingError, match="shape"):
        wrong.evaluate(0.0, x, y)


def test_forcing_bundle(tmp_path):
    x, y = nodes(100)
    rec = make_records("vector")
    path = rec.to_netcdf(tmp_path / "wind_xy.nc")
    wind = open_gridded(path, ("u", "v"), quantity="wind", reference_time="2000-01-01")
    np.testing.assert_allclose(wind.evaluate(1.3 * H6, x, y), RecordField(rec).evaluate(1.3 * H6, x, y),
                               rtol=1e-12, atol=1e-12)
    f = Forcing(wind=wind, ocean=(0.1, 0.0), air_temperature=lambda t, x, y: -5.0 + 0 * x)
    f.prepare(0.0, 4 * H6, x, y)
    vals = f.evaluate(H6, x, y, mesh_version=1)
    assert vals.wind.shape == (2, 100) and vals.ocean.shape == (2, 100)
    assert np.all(vals.air_temperature == -5.0)
    none = Forcing()
    assert none.components() == {}
    assert none.evaluate(0.0, x, y).wind is None


def test_parallel_kernels_match_serial(monkeypatch):
    """The parallel builds (used from PARALLEL_MIN_SIZE points) give identical values."""
    import forcing._numba_util as nu

    x, y = nodes(2000, seed=9)
    serial = RecordField(make_records("vector"))
    ref = serial.evaluate(1.7 * H6, x, y)
    monkeypatch.setattr(nu, "PARALLEL_MIN_SIZE", 0)
    par = RecordField(make_records("vector"))
    np.testing.assert_array_equal(par.evaluate(1.7 * H6, x, y), ref)
    x += 1.0
    par.evaluate(1.7 * H6, x, y)
    assert par.n_weight_builds == 2


def test_restore_weight_positions_bit_identical():
    """With a rebuild tolerance, a resumed run restores the weight positions."""
    x, y = nodes()
    a = RecordField(make_records(), rebuild_tolerance_m=100.0)
    a.evaluate(0.0, x, y)
    saved = a.weight_positions()
    x2 = x + 30.0  # within tolerance: a keeps its old weights
    ref = a.evaluate(H6, x2, y)
    b = RecordField(make_records(), rebuild_tolerance_m=100.0)
    b.restore_weight_positions(saved)
    np.testing.assert_array_equal(b.evaluate(H6, x2, y), ref)
