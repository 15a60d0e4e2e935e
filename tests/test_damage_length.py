"""A damage time of fixed length (``rheology.damage_length_m`` = ℓ, docs/physics.md §4, "A damage
time of fixed length"): td = ℓ/cs on every element whatever its size, through a remesh, on the
steppers that implement it, and refused with a clear error where it is not."""
import numpy as np
import pytest

from lagice.errors import ConfigError
from lagice.rheology import MaxwellEB
from lagice.strength import element_size

from helpers import global_remesh, shear_inner_nodes


def test_damage_time_of_fixed_length_against_the_element_size():
    """Default: td = Δx/cs per element (Dansereau et al. 2016); with ℓ set: ℓ/cs for every size."""
    sizes = np.array([2e3, 9.3e3, 18.6e3, 55e3])
    cs = MaxwellEB().params.shear_wave_speed
    np.testing.assert_array_equal(MaxwellEB().damage_time(sizes), sizes / cs)
    td = MaxwellEB(damage_length_m=20e3).damage_time(sizes)
    assert td.shape == sizes.shape
    np.testing.assert_array_equal(td, np.full(4, 20e3 / cs))
    assert MaxwellEB(damage_length_m=20e3).params.optional_terms() == {"damage_length_m": 20e3}
    assert MaxwellEB(damage_length_m=None).params.optional_terms() == {}


@pytest.mark.parametrize("bad", [-5e3, 2e6, float("nan")])
def test_bad_damage_length_is_refused_by_name(bad):
    with pytest.raises(ConfigError, match="damage_length_m"):
        MaxwellEB(damage_length_m=bad)


@pytest.mark.parametrize("stepper", ["explicit_cuda", "prescribed"])
def test_damage_length_is_refused_where_it_is_not_implemented(stepper):
    rh = MaxwellEB(damage_length_m=20e3)
    rh.require_stepper("explicit")  # implemented there and in the implicit solver
    rh.require_stepper("implicit")
    with pytest.raises(ConfigError, match=r"rheology.damage_length_m = 20000.0: .* does not implement it"):
        rh.require_stepper(stepper)


@pytest.mark.parametrize("solver", ["explicit", "implicit"])
def test_fixed_damage_time_holds_on_every_element_through_a_remesh(solver):
    """winter_basin_pack at 60 km (a coast-refined mesh whose element sizes differ by more than
    2×), through the scene builder: every element's td is ℓ/cs before and after a global remesh
    (which makes new elements), while the default's td follows each element's size."""
    from lagice.scenes.builder import build_model
    from lagice.scenes.config import load_scene

    ov = {"domain.resolution_m": 60e3, "run.duration": "1h", "solver.dt": "1h", "solver.name": solver}
    default = build_model(load_scene("winter_basin_pack", ov))
    m = default.state.mesh
    dx = np.sqrt(2.0) * element_size(m.nodes, m.triangles)  # td's Δx = √(2 A), sqrt(A) for the strength
    assert dx.max() / dx.min() > 2.0
    np.testing.assert_allclose(default.stepper.td, dx / 500.0, rtol=1e-12)

    model = build_model(load_scene("winter_basin_pack", {**ov, "rheology.damage_length_m": 25e3}))
    np.testing.assert_array_equal(model.stepper.td, np.full(model.state.mesh.n_elements, 50.0))
    m = model.state.mesh
    shear_inner_nodes(m)
    ev = global_remesh(model)
    assert model.state.mesh is not m and len(ev.kept_elements) < model.state.mesh.n_elements  # new elements
    np.testing.assert_array_equal(model.stepper.td, np.full(model.state.mesh.n_elements, 50.0))
