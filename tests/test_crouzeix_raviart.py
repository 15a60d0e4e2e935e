"""Crouzeix–Raviart velocities in the explicit stepper (``solver.velocity_element =
"crouzeix_raviart"``; :mod:`lagice.solvers.crouzeix_raviart`).

A stable pair with the one stress per element: it must reproduce linear velocity fields
exactly (the patch test), leave room for divergence-free flow on a closed mesh with a discrete
inf–sup constant that does not fall with the element size (no volumetric locking), run with
sub-steps short enough for its highest frequency, free broken ice that keeps its mean stress
in the gyre test, and resume bit for bit."""
import shutil

import numpy as np
import pytest
import scipy.linalg as sl
from test_volumetric_locking import SCENE, _box_mesh, _gyre_run

from lagice.errors import ConfigError
from lagice.solvers.crouzeix_raviart import SUBSTEP_FACTOR, CREdges


def _operators(mesh):
    """(CR strain operator, P1 strain operator, CR edges, free CR columns, free P1 columns, CR
    lumped area per edge, P1 lumped area per node, element areas): rows ε̇xx, ε̇yy, 2ε̇xy per
    element, columns the interleaved velocity components; free = not on the closed box's
    boundary."""
    from lagice.fem import shape_gradients

    tri, n = mesh.triangles, mesh.n_nodes
    b, c, area = shape_gradients(mesh.nodes, tri)
    m = len(tri)
    boundary_nodes = np.unique(mesh.boundary_edges)
    fixed = np.zeros((n, 2), np.int8)
    fixed[boundary_nodes] = 1
    cr = CREdges(mesh, fixed)
    rows = np.arange(m)

    def strain(idx, gb, gc, ndof):
        S = np.zeros((3 * m, 2 * ndof))
        for k in range(3):
            j = idx[:, k]
            np.add.at(S, (3 * rows, 2 * j), gb[:, k])
            np.add.at(S, (3 * rows + 1, 2 * j + 1), gc[:, k])
            np.add.at(S, (3 * rows + 2, 2 * j), gc[:, k])
            np.add.at(S, (3 * rows + 2, 2 * j + 1), gb[:, k])
        return S

    S_cr = strain(cr.elem_edges, -2.0 * b, -2.0 * c, cr.n_edges)
    S_p1 = strain(tri, b, c, n)
    free_cr = np.flatnonzero(cr.fixed.reshape(-1) == 0)
    free_p1 = np.flatnonzero(fixed.reshape(-1) == 0)
    a_cr = np.zeros(cr.n_edges)
    np.add.at(a_cr, cr.elem_edges.ravel(), np.repeat(area / 3.0, 3))
    a_p1 = np.zeros(n)
    np.add.at(a_p1, tri.ravel(), np.repeat(area / 3.0, 3))
    return S_cr, S_p1, cr, free_cr, free_p1, a_cr, a_p1, area


def test_edges_reproduce_a_linear_velocity_field():
    """A velocity linear in x and y, taken at the edge midpoints, has in every element exactly
    its strain rate, and averaged back at the nodes it is the node field again (round-off)."""
    from lagice.fem import shape_gradients, strain_rate

    mesh = _box_mesh(60e3, 8e3)
    b, c, area = shape_gradients(mesh.nodes, mesh.triangles)
    G = np.array([[2e-7, -1e-7], [3e-7, -4e-7]])
    vel = mesh.nodes @ G.T + np.array([0.1, -0.05])
    cr = CREdges(mesh, np.zeros((mesh.n_nodes, 2), np.int8))
    assert cr.n_edges == len(np.unique(np.sort(np.r_[mesh.triangles[:, [0, 1]], mesh.triangles[:, [1, 2]],
                                                       mesh.triangles[:, [2, 0]]], axis=1), axis=0))
    ve = cr.at_edges(vel)
    eps = strain_rate(cr.elem_edges, -2.0 * b, -2.0 * c, ve)
    want = np.array([G[0, 0], G[1, 1], 0.5 * (G[0, 1] + G[1, 0])])
    assert np.allclose(eps, want[None, :], rtol=1e-9, atol=1e-9 * np.abs(G).max())
    back = cr.at_nodes(ve, mesh.triangles, area, mesh.n_nodes)
    assert np.allclose(back, vel, rtol=0, atol=1e-12 * np.abs(vel).max())
    # every continuous linear field is a Crouzeix–Raviart one (node → edge → node is the identity),
    # but not the converse: an edge field that jumps across edges is smoothed by the node average
    rng = np.random.default_rng(0)
    rough = rng.normal(0.0, 1.0, (mesh.n_nodes, 2))
    assert np.allclose(cr.at_nodes(cr.at_edges(rough), mesh.triangles, area, mesh.n_nodes), rough, atol=1e-12)
    rough_e = rng.normal(0.0, 1.0, (cr.n_edges, 2))
    assert np.abs(cr.at_edges(cr.at_nodes(rough_e, mesh.triangles, area, mesh.n_nodes)) - rough_e).max() > 0.5


def test_divergence_is_stable_on_a_closed_box():
    """Closed Delaunay boxes at 10 and 6 km: the linear velocity's element divergences have full
    column rank (locked: no non-zero divergence-free field), the Crouzeix–Raviart ones rank m − 1
    (only the constant pressure is free), and their smallest non-zero singular value in the
    mass-weighted norms, the discrete inf–sup constant, is the same at both sizes within 10 %
    (measured 4.45e-5 and 4.46e-5 s-1 per m s-1: a stable pair)."""
    infsup = []
    for res in (10e3, 6e3):
        mesh = _box_mesh(100e3, res)
        S_cr, S_p1, cr, free_cr, free_p1, a_cr, a_p1, area = _operators(mesh)
        m = mesh.n_elements
        D_cr = (S_cr[0::3] + S_cr[1::3])[:, free_cr]
        D_p1 = (S_p1[0::3] + S_p1[1::3])[:, free_p1]
        assert np.linalg.matrix_rank(D_p1) == D_p1.shape[1] < m  # locked
        assert np.linalg.matrix_rank(D_cr) == m - 1 < D_cr.shape[1]
        W = np.sqrt(area)[:, None] * D_cr / np.sqrt(np.repeat(a_cr, 2)[free_cr])[None, :]
        s = np.sort(sl.svdvals(W))
        assert s[0] < 1e-12 * s[-1]  # the constant pressure
        infsup.append(s[1])
    assert infsup[1] == pytest.approx(infsup[0], rel=0.1)


def _spectrum(mesh, kappas):
    """{"linear": (lowest, highest), κ: (lowest, highest)} eigenvalues of the lumped linear and
    Crouzeix–Raviart systems of a closed mesh (the latter with the jump penalty κ; 0: none):
    plane-stress stiffness (E = 1, ν = 0.3, unit thickness; the penalty's k = κ μ L²/6 per interior
    edge, from :class:`JumpPenalty`'s ∂J/∂u) over the lumped areas (sparse, ARPACK)."""
    import scipy.sparse as sp
    from scipy.sparse.linalg import eigsh

    from lagice.fem import shape_gradients
    from lagice.solvers.crouzeix_raviart import JumpPenalty

    nu = 0.3
    D = np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 0.5 * (1.0 - nu)]]) / (1.0 - nu * nu)
    S_cr, S_p1, cr, free_cr, free_p1, a_cr, a_p1, area = _operators(mesh)
    Dfull = sp.kron(sp.diags(area), sp.csr_matrix(D))
    b, c, _ = shape_gradients(mesh.nodes, mesh.triangles)

    def extremes(K, free, a):
        Mi = sp.diags(1.0 / np.sqrt(np.repeat(a, 2)[free]))
        A = (Mi @ K[free][:, free] @ Mi).tocsc()
        hi = eigsh(A, k=1, which="LA", return_eigenvectors=False)[0]
        lo = eigsh(A, k=1, sigma=0.0, which="LM", return_eigenvectors=False)[0]
        return lo, hi

    S1, S2 = sp.csr_matrix(S_p1), sp.csr_matrix(S_cr)
    out = {"linear": extremes((S1.T @ Dfull @ S1).tocsr(), free_p1, a_p1)}
    K0 = (S2.T @ Dfull @ S2).tocsr()
    for kappa in kappas:
        K = K0
        if kappa:
            jp = JumpPenalty(cr, kappa, nu)
            jp.update_geometry(mesh.nodes, b, c)
            rows = np.repeat(np.arange(jp.n_inner), 6)
            for comp in range(2):
                Pm = sp.csr_matrix((jp.coef.ravel(), (rows, 2 * jp.dofs.ravel() + comp)),
                                   shape=(jp.n_inner, 2 * cr.n_edges))
                K = K + Pm.T @ sp.diags(jp.kfac) @ Pm
        out[kappa] = extremes(K.tocsr(), free_cr, a_cr)
    return out


def test_jump_penalty_restores_the_softest_mode():
    """The plain Crouzeix–Raviart element fails the discrete Korn inequality: on the 10 km box its
    softest mode is 500x softer than the linear element's (local rotations about interior
    vertices; measured 0.002x, and 0.05x at 6 km). Hansbo and Larson's jump penalty with κ = 0.1
    brings it within 1 % of the linear element's at both sizes (measured 0.994x and 0.997x)."""
    for res, plain_below in ((10e3, 0.01), (6e3, 0.2)):
        mesh = _box_mesh(100e3, res)
        sp = _spectrum(mesh, (0.0, 0.1))
        assert sp[0.0][0] < plain_below * sp["linear"][0]
        assert sp[0.1][0] == pytest.approx(sp["linear"][0], rel=0.01)


def test_substep_factor_covers_the_highest_frequency():
    """The highest frequency² of the lumped Crouzeix–Raviart system is at most SUBSTEP_FACTOR²
    times the linear one's on Delaunay meshes of two sizes and on a jittered mesh, without the
    jump penalty and with κ = 0.1 and 1 (measured 5.1–7.4 against 9), so sub-steps
    SUBSTEP_FACTOR times shorter keep the measured linear limit's margin."""
    import shapely

    from lagice.mesh import generate_mesh

    meshes = [_box_mesh(100e3, 10e3), _box_mesh(100e3, 6e3),
              generate_mesh(shapely.box(0, 0, 100e3, 100e3), 8e3, algorithm=5)]
    rng = np.random.default_rng(3)
    inner = np.setdiff1d(np.arange(meshes[2].n_nodes), np.unique(meshes[2].boundary_edges))
    meshes[2].nodes[inner] += rng.uniform(-1.5e3, 1.5e3, (len(inner), 2))
    for mesh in meshes:
        sp = _spectrum(mesh, (0.0, 0.1, 1.0))
        for kappa in (0.0, 0.1, 1.0):
            assert 3.0 < sp[kappa][1] / sp["linear"][1] <= SUBSTEP_FACTOR ** 2


def test_crouzeix_raviart_frees_broken_ice_that_keeps_its_mean_stress(tmp_path):
    """The gyre test of tests/test_volumetric_locking.py: broken ice (d = 0.99) keeping its mean
    stress locks with linear velocities (its pressure grows from day 1 to day 3); with
    Crouzeix–Raviart velocities it settles within a day at a small fraction of the locked
    pressure, and the gyre turns within 5 % of the speed of the linear pack whose whole stress
    relaxes, with and without the jump penalty (κ = 0.1: it relaxes with the deviator, so it does not
    lock either). (Measured: 0.56 kPa on both days against 24.6 → 58.6 kPa; 0.146 against 0.141
    m s-1.)"""
    keep = {"rheology.relax_mean_stress": False}
    e1, e3, _ = _gyre_run(tmp_path, "element", keep)
    _, _, r_speed = _gyre_run(tmp_path, "relax", {})
    assert e3 > 1.5 * e1
    cr = {**keep, "solver.velocity_element": "crouzeix_raviart"}
    for name, ov in (("cr", cr), ("cr_jump", {**cr, "solver.jump_penalty": 0.1})):
        c1, c3, c_speed = _gyre_run(tmp_path, name, ov)
        assert abs(c3 - c1) < 0.05 * c1, name
        assert c3 < 0.05 * e3, name
        assert abs(c_speed - r_speed) < 0.05 * r_speed, name


def test_resume_with_crouzeix_raviart_is_bit_identical(tmp_path):
    """A checkpoint holds the edge velocities (``stepper.cr_edge_velocity``) and the jump
    penalty's tractions (``stepper.cr_jump_traction``), so a run resumed half-way ends bit for bit
    where the uninterrupted one does; without them (the edge velocities rebuilt from the nodes,
    the tractions zero) it would not."""
    from lagice.io.checkpoint import list_checkpoints, read_checkpoint
    from lagice.scenes.builder import build_simulation
    from lagice.scenes.config import load_scene
    from lagice.simulation import Simulation

    path = tmp_path / "gyre.toml"
    path.write_text(SCENE)
    ov = {"solver.velocity_element": "crouzeix_raviart", "solver.jump_penalty": 0.1, "run.duration": "12h",
          "checkpoint.every": "6h", "output.every": "6h", "initial.damage": 0.5}
    full = build_simulation(load_scene(path, ov), tmp_path / "full")
    full.run()
    part = build_simulation(load_scene(path, ov), tmp_path / "part")
    part.run(n_steps=36)
    arrays, _ = read_checkpoint(list_checkpoints(tmp_path / "part" / "checkpoints")[-1])
    assert arrays["stepper.cr_edge_velocity"].shape == (part.model.stepper._cr_edges().n_edges, 2)
    assert arrays["stepper.cr_jump_traction"].shape == (part.model.stepper._jump.n_inner, 2)
    assert np.abs(arrays["stepper.cr_jump_traction"]).max() > 0
    shutil.copytree(tmp_path / "part", tmp_path / "part2")
    resumed = Simulation.resume(tmp_path / "part" / "checkpoints")
    resumed.run()
    a, b = full.model.state, resumed.model.state
    assert full.model.clock.iteration == resumed.model.clock.iteration == 72
    for k in ("velocity", "stress", "damage"):
        assert np.array_equal(getattr(a, k), getattr(b, k)), f"{k} differs after resume"
    assert np.abs(a.velocity).max() > 1e-3  # the wind moved the ice (measured 4.8 mm s-1)
    # the node velocities alone do not carry the edge field: rebuilt from them, the run differs
    again = Simulation.resume(tmp_path / "part2" / "checkpoints")
    assert again.model.clock.iteration == 36
    again.model.stepper._cr_vel = "remeshed"
    again.run()
    assert not np.array_equal(again.model.state.velocity, a.velocity)


def test_crouzeix_raviart_refusals(tmp_path):
    """Where Crouzeix–Raviart velocities are not implemented the run is refused before any mesh
    work, naming the key: on the CUDA stepper (even without a GPU), with the nonlocal damage,
    with the nodal volumetric strain, with the implicit solver; an unknown value is refused, and so
    are a jump penalty without them and a negative one."""
    from lagice.scenes.builder import solver_options, validate_config
    from lagice.scenes.config import load_scene

    path = tmp_path / "gyre.toml"
    path.write_text(SCENE)
    cr = {"solver.velocity_element": "crouzeix_raviart"}
    with pytest.raises(ConfigError, match="solver.velocity_element = 'crouzeix_raviart'.*CUDA"):
        validate_config(load_scene(path, {**cr, "solver.device": "cuda"}))
    with pytest.raises(ConfigError, match="solver.velocity_element = 'crouzeix_raviart' is not implemented with "
                                          "rheology.damage_nonlocal_radius_m"):
        solver_options(load_scene(path, {**cr, "rheology.damage_nonlocal_radius_m": 20e3}))
    with pytest.raises(ConfigError, match="solver.volumetric_strain = 'nodal'.*crouzeix_raviart"):
        solver_options(load_scene(path, {**cr, "solver.volumetric_strain": "nodal"}))
    with pytest.raises(ConfigError, match="solver.velocity_element does not apply to solver 'implicit'"):
        solver_options(load_scene(path, {**cr, "solver.name": "implicit"}))
    with pytest.raises(ConfigError, match="solver.jump_penalty = 0.1 penalises the jumps of Crouzeix-Raviart"):
        solver_options(load_scene(path, {"solver.jump_penalty": 0.1}))
    with pytest.raises(ConfigError, match="solver.jump_penalty = -1.0: expected a number >= 0"):
        solver_options(load_scene(path, {**cr, "solver.jump_penalty": -1.0}))
    with pytest.raises(ConfigError, match="solver.velocity_element = 'P2': expected one of"):
        solver_options(load_scene(path, {"solver.velocity_element": "P2"}))
