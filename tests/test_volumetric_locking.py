"""Volumetric locking of ice whose mean stress is kept, and its cure
(``solver.volumetric_strain = "nodal"``: :func:`lagice.solvers.explicit._node_divergence`).

Broken ice whose deviator relaxes and whose mean stress does not
(``rheology.relax_mean_stress = false``, ``crack_closure``) is close to incompressible. With
constant-strain triangles the element divergences are about as many constraints as there are
free velocity components, and on gmsh's Delaunay mesh of a closed box they admit no non-zero
divergence-free velocity at all. Averaged at the nodes, they leave room for one."""
import numpy as np
import pytest

from lagice.errors import ConfigError


def _box_mesh(side_m, res_m):
    import shapely

    from lagice.mesh import generate_mesh

    return generate_mesh(shapely.box(0, 0, side_m, side_m), res_m, algorithm=5)


def _divergence_operators(mesh):
    """(element, nodal) discrete divergence operators on the free velocity components of a
    closed box (every boundary node no-slip): element rows ε̇xx + ε̇yy of each triangle,
    nodal rows their area-weighted mean over each interior node's elements."""
    from lagice.fem import shape_gradients

    tri, n = mesh.triangles, mesh.n_nodes
    b, c, area = shape_gradients(mesh.nodes, tri)
    m = len(tri)
    D = np.zeros((m, 2 * n))
    for k in range(3):
        D[np.arange(m), 2 * tri[:, k]] += b[:, k]
        D[np.arange(m), 2 * tri[:, k] + 1] += c[:, k]
    boundary = np.unique(mesh.boundary_edges)
    interior = np.setdiff1d(np.arange(n), boundary)
    free = np.sort(np.concatenate([2 * interior, 2 * interior + 1]))
    A = np.zeros((n, m))  # node ← element, area-weighted mean
    for k in range(3):
        A[tri[:, k], np.arange(m)] += area
    A /= A.sum(axis=1, keepdims=True)
    return D[:, free], (A @ D)[interior][:, free]


def test_element_divergence_locks_a_delaunay_box_and_the_nodal_one_does_not():
    """On a Delaunay mesh of a closed 100 km box (10 km) the element divergence operator has
    full column rank over the free components: the only velocity with zero divergence in every
    element is zero. The nodal one has one row per interior node, so at least half the free
    components span divergence-free fields."""
    mesh = _box_mesh(100e3, 10e3)
    De, Dn = _divergence_operators(mesh)
    n_free = De.shape[1]
    rank_e = np.linalg.matrix_rank(De)
    rank_n = np.linalg.matrix_rank(Dn)
    assert De.shape[0] > n_free  # more triangles than free components
    assert rank_e == n_free  # no non-zero discretely divergence-free field: locking
    assert n_free - rank_n >= n_free // 2  # the nodal constraint leaves half the space free


SCENE = """
[scene]
name = "gyre_lock"
description = "broken ice in a closed square under a stationary gyre wind"
[domain]
kind = "rectangle"
width_m = 250e3
height_m = 250e3
resolution_m = 12.5e3
exterior_tag = "coast"
mesh_algorithm = 5
renumber = true
[initial]
thickness_m = 1.0
concentration = 1.0
damage = 0.99
cohesion_pa = "random"
[solver]
name = "explicit"
dt = 600.0
[healing]
law = "none"
[forcing.wind]
kind = "function"
function = "lagice.scenes.hooks.gyre:gyre"
params = { speed_m_s = 15.0, width_m = 250e3, height_m = 250e3, ramp_h = 3.0 }
[forcing.ocean]
kind = "rest"
[forcing.coriolis]
latitude_deg = 75.0
[run]
duration = "3d"
seed = 0
progress = false
[output]
every = "3d"
plot = false
"""


def _gyre_run(tmp_path, name, overrides):
    """Mean |mean stress| [Pa] after days 1 and 3 and the mean ice speed [m s-1] after day 3."""
    from lagice.scenes.builder import build_simulation
    from lagice.scenes.config import load_scene

    path = tmp_path / "gyre.toml"
    path.write_text(SCENE)
    sim = build_simulation(load_scene(path, overrides), tmp_path / name)
    out = []
    for steps in (144, 288):
        sim.run(n_steps=steps)
        st = sim.model.state
        out.append(float(np.abs(0.5 * (st.stress[:, 0] + st.stress[:, 1])).mean()))
    speed = float(np.hypot(*sim.model.state.velocity.T).mean())
    return out[0], out[1], speed


def test_nodal_volumetric_strain_frees_broken_ice_that_keeps_its_mean_stress(tmp_path):
    """Broken ice (d = 0.99) under a stationary gyre wind, fixed mesh. Keeping its mean stress
    with the element divergence, the pack builds a pressure that grows with time (locking: the
    turning flow compresses every triangle a little); with the nodal divergence the pressure
    settles within a day, an order of magnitude lower, and the gyre turns at the speed of the
    pack whose whole stress relaxes. (Measured: element 24.6 → 58.6 kPa from day 1 to day 3;
    nodal 0.66 kPa on both days; relaxing 0.03 kPa.)"""
    keep = {"rheology.relax_mean_stress": False}
    e1, e3, e_speed = _gyre_run(tmp_path, "element", keep)
    n1, n3, n_speed = _gyre_run(tmp_path, "nodal", {**keep, "solver.volumetric_strain": "nodal"})
    _, _, r_speed = _gyre_run(tmp_path, "relax", {})
    assert e3 > 1.5 * e1  # the element pack's pressure keeps growing
    assert abs(n3 - n1) < 0.05 * n1  # the nodal pack's has settled
    assert n3 < 0.2 * e3
    assert abs(n_speed - r_speed) < 0.03 * r_speed  # measured: 0.9 %
    assert e_speed < 0.9 * r_speed  # measured: the element pack 23 % slower after 3 days


def test_nodal_volumetric_strain_changes_nothing_under_an_affine_flow():
    """Under a velocity field linear in x and y every element and every node has the same
    divergence, so the nodal variant's stress update equals the element one to round-off
    (serial and parallel builds alike), and the kernel passes of the nodal loop are the
    element loop's plus the node divergence."""
    from lagice.fem import shape_gradients
    from lagice.rheology import MaxwellEB
    from lagice.solvers.explicit import (
        element_kernels,
        envelope_factors,
        node_divergence_kernel,
        node_divergence_kernel_serial,
    )

    mesh = _box_mesh(60e3, 8e3)
    m, n = mesh.n_elements, mesh.n_nodes
    b, c, area = shape_gradients(mesh.nodes, mesh.triangles)
    tri = mesh.triangles.astype(np.int32)
    ptr, elems, _ = mesh.node_elements
    ptr, elems = ptr.astype(np.int32), elems.astype(np.int32)
    G = np.array([[2e-7, -1e-7], [3e-7, -4e-7]])
    vel = mesh.nodes @ G.T
    rheo = MaxwellEB(relax_mean_stress=False)
    p = rheo.params
    kc, kt = envelope_factors(rheo)
    rng = np.random.default_rng(1)
    d = rng.uniform(0.5, 0.99, m)
    E, lam = rheo.moduli(d, np.ones(m))
    sigma0 = rng.normal(0, 1e3, (m, 3))
    dt_s = 5.0
    for par, kernel in enumerate(element_kernels(4.0)):
        divn = np.empty(n)
        (node_divergence_kernel if par else node_divergence_kernel_serial)(vel, ptr, elems, tri, b, c, area, divn)
        assert np.allclose(divn, G[0, 0] + G[1, 1], rtol=1e-12, atol=0)
        out = []
        for dv in (None, divn):
            sg, dm, flag = sigma0.copy(), d.copy(), np.zeros(m, np.int8)
            kernel(tri, b, c, vel, sg, dm, np.ones(m), np.full(m, 1e15), kc, kt, np.full(m, 20.0), np.zeros(m),
                   dt_s * E, lam / (lam + dt_s), None, np.inf, None, None, None, None, dt_s, *rheo.K[0, :2],
                   rheo.K[2, 2], rheo.q, rheo._denom, p.max_damage, p.E0, p.relaxation_time_s, 4.0, flag, dv)
            out.append(sg)
        assert np.allclose(out[1], out[0], rtol=1e-10, atol=1e-10 * np.abs(out[0]).max())
        assert not np.allclose(out[0], sigma0, rtol=1e-3)  # the strain rate acted


def test_nodal_volumetric_strain_refusals(tmp_path):
    """Where the nodal volumetric strain is not implemented, the run is refused before any
    mesh work, naming the key: on the CUDA stepper (even without a GPU), with the nonlocal
    damage, with the implicit solver; and an unknown value is refused."""
    from lagice.scenes.builder import solver_options, validate_config
    from lagice.scenes.config import load_scene

    path = tmp_path / "gyre.toml"
    path.write_text(SCENE)
    with pytest.raises(ConfigError, match="solver.volumetric_strain = 'nodal'.*CUDA"):
        validate_config(load_scene(path, {"solver.volumetric_strain": "nodal", "solver.device": "cuda"}))
    with pytest.raises(ConfigError, match="solver.volumetric_strain = 'nodal' is not implemented with "
                                          "rheology.damage_nonlocal_radius_m"):
        solver_options(load_scene(path, {"solver.volumetric_strain": "nodal",
                                         "rheology.damage_nonlocal_radius_m": 20e3}))
    with pytest.raises(ConfigError, match="solver.volumetric_strain does not apply to solver 'implicit'"):
        solver_options(load_scene(path, {"solver.volumetric_strain": "nodal", "solver.name": "implicit"}))
    with pytest.raises(ConfigError, match="solver.volumetric_strain = 'patch': expected one of"):
        solver_options(load_scene(path, {"solver.volumetric_strain": "patch"}))
