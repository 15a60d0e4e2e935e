"""Implicit Maxwell-EB time stepper (docs/design.md §4.1, Dansereau et al. 2016 §4).

Per step (Δt), with P1 velocity and P0 stress/damage:

1. Backward Euler for momentum and constitutive law together. Substituting
   σ^{n+1} = γ (σ^n + Δt E K:ε̇(u^{n+1})), γ = λ/(λ+Δt), into
   M (u^{n+1} − u^n)/Δt = −∫ h σ^{n+1}:∇φ + F_ext(u^{n+1})
   gives one sparse linear system in velocity, assembled on a fixed sparsity
   pattern by a numba kernel.
2. External forces that depend on u (quadratic ocean drag, Coriolis) are
   linearised about the latest iterate: a fixed-point loop repeats step 1
   until the constitutive residual ‖σ_k − σ_{k−1}‖/‖σ_k‖ (and the same for
   velocity) is below ``tol``. Without such forces the system is linear and
   one iteration is exact (reported as 1 iteration, residual 0).
3. Damage explicit (Dansereau et al. 2016 eq. 11): d_crit from the new stress, damage
   increment and stress correction, healing.
4. Optional (``damage_iterations`` > 1): Dansereau et al. (2016, §4)'s fixed point between
   steps 1-2 and step 3. Where step 3 damaged some element, steps 1-2 are solved again with
   the moduli of the new damage (the old stress σ^n and velocity u^n unchanged), and the
   damage is computed again from d^n with the new stress, until the damage changes by less
   than ``damage_tol`` between two passes (or ``damage_iterations`` passes). The damage,
   stress and velocity of the last pass are kept. Off by default: the published lagice
   runs use one pass (the damage of step n+1 from the stress solved with d^n).

Iterations, residual and timings (assembly, solve, damage) are reported in
:class:`~lagice.solvers.base.StepInfo`.
"""
from __future__ import annotations

import logging

import numpy as np

from .._numba import pick
from ..errors import ConfigError, SolverError
from ..fem import LUMPED_MASS, NODAL_FORCE, SHAPE_GRADIENTS, STRAIN_RATE, SparsityPattern, assemble_elasticity
from ..rheology import MaxwellEB
from ..state import IceState
from .base import DirichletSet, StepInfo, Timer
from .linear import LinearSolver


class ImplicitSolver:
    """Backward-Euler Maxwell-EB solver.

    Args:
        rheology: :class:`~lagice.rheology.MaxwellEB`.
        mesh: the mesh (node positions are read at each step).
        bcs: list of :class:`~lagice.solvers.base.VelocityBC`.
        forces: list of external-force objects with ``linearise(t, nodes, vel,
            mass_per_area) -> (A (n,2,2) [kg m-2 s-1], b (n,2) [N m-2])`` so that
            the force per unit area is ``b − A·u`` (see ``lagice.forces``).
        linear_solver: ``"cg"`` (default, measured fastest), ``"superlu"``, ``"amg"``.
        tol: fixed-point tolerance on the relative constitutive residual.
        max_iter: fixed-point iteration limit (reaching it is reported, not an error).
        heal_rate: callable ``(state, t_s) -> (m,) [s-1]`` or None for the rheology's constant rate.
        damage_iterations: passes of the damage fixed point (module doc, step 4); 1 (default):
            one pass, no fixed point.
        damage_tol: the fixed point stops when no element's damage moved by more than this
            between two passes [-].

    ``last_damage_passes`` is the number of passes of the last step; ``damage_passes_total``
    and ``damage_unconverged_steps`` (steps that used every pass without meeting
    ``damage_tol``) are counted over the run; the first such step, and every 1000th, is
    logged as a warning.

    The transport velocity is the end-of-step velocity u^{n+1} (backward Euler:
    x^{n+1} = x^n + Δt u^{n+1}); :attr:`last_strain_rate` is its strain rate.
    """

    name = "implicit"

    def __init__(self, rheology: MaxwellEB, mesh, bcs=(), forces=(), linear_solver: str = "cg",
                 tol: float = 1e-8, max_iter: int = 30, linear_rtol: float = 1e-10, heal_rate=None,
                 damage_iterations: int = 1, damage_tol: float = 1e-6):
        if not isinstance(rheology, MaxwellEB):
            raise ConfigError(f"the implicit stepper solves the Maxwell-EB rheology; got "
                              f"{type(rheology).__name__} (use solver 'evp' for viscous-plastic)")
        rheology.require_stepper("implicit")
        if not tol > 0:
            raise ConfigError(f"tol = {tol!r} must be > 0")
        if int(max_iter) < 1:
            raise ConfigError(f"max_iter = {max_iter!r} must be >= 1")
        if int(damage_iterations) != damage_iterations or int(damage_iterations) < 1:
            raise ConfigError(f"solver.damage_iterations = {damage_iterations!r} must be an integer >= 1 "
                              f"(1: one damage pass per step)")
        if not 0.0 < damage_tol < 1.0:
            raise ConfigError(f"solver.damage_tol = {damage_tol!r} must be in (0, 1)")
        self.damage_iterations = int(damage_iterations)
        self.damage_tol = float(damage_tol)
        self.last_damage_passes = 0
        self.damage_passes_total = 0
        self.damage_unconverged_steps = 0
        self.rheology = rheology
        self.bcs = list(bcs)
        self.forces = list(forces)
        self.tol = float(tol)
        self.max_iter = int(max_iter)
        self.heal_rate = heal_rate
        self.linear = LinearSolver(linear_solver, rtol=linear_rtol)
        self._transport = None
        self.reset_topology(mesh)

    @property
    def transport_velocity(self):
        return self._transport

    # -- geometry/topology caches ------------------------------------------------
    def reset_topology(self, mesh) -> None:
        """Rebuild everything that depends on connectivity (after a remesh)."""
        self.mesh = mesh
        self.last_strain_rate = None  # belonged to the old mesh
        self._transport = None
        self.pattern = SparsityPattern(mesh.triangles, mesh.n_nodes)
        self.dirichlet = DirichletSet(mesh, self.bcs)
        self.entry_prescribed = (self.dirichlet.mask[self.pattern.row_of]
                                 | self.dirichlet.mask[self.pattern.indices])
        self.linear.nodes = mesh.nodes
        self.update_geometry()

    def update_geometry(self) -> None:
        """Recompute shape gradients and td after nodes moved (Lagrangian step)."""
        m = self.mesh
        self.b, self.c, self.area = pick(SHAPE_GRADIENTS, m.n_elements)(m.nodes, m.triangles)
        if np.any(self.area <= 0):
            raise SolverError(f"{int(np.sum(self.area <= 0))} inverted elements in the mesh")
        self.td = self.rheology.damage_time(np.sqrt(2.0 * self.area))

    # -- one step -----------------------------------------------------------------
    def step(self, state: IceState, t_s: float, dt: float) -> StepInfo:
        if not dt > 0:
            raise ConfigError(f"dt = {dt!r} s must be > 0")
        info = StepInfo()
        tm = info.timings
        mesh = self.mesh
        with Timer(tm, "damage"):
            heal = (self.heal_rate(state, t_s) if self.heal_rate is not None
                    else self.rheology.constant_heal_rate(mesh.n_elements))
        d_old = state.damage
        d_use = d_old
        n_capped_before = self.rheology.n_capped_total
        passes = 0
        for passes in range(1, self.damage_iterations + 1):  # noqa: B007 (reported after the loop)
            vel, sigma, eps = self._solve(state, d_use, t_s, dt, info)
            with Timer(tm, "damage"):
                damage = d_old.copy()
                self.rheology.n_capped_total = n_capped_before  # the kept pass's caps only
                dc = self.rheology.damage_update(sigma, damage, state.cohesion, dt, self.td, heal)
            if self.damage_iterations == 1 or not np.any(dc < 1.0):
                break
            change = float(np.max(np.abs(damage - d_use))) if passes > 1 else np.inf
            if change < self.damage_tol:
                break
            d_use = damage
        else:
            self.damage_unconverged_steps += 1
            n = self.damage_unconverged_steps
            if n == 1 or n % 1000 == 0:  # reported, not hidden; not a line for every step
                logging.getLogger("lagice").warning(
                    f"implicit solver: the damage fixed point used all solver.damage_iterations = "
                    f"{self.damage_iterations} passes without the damage settling to solver.damage_tol = "
                    f"{self.damage_tol:g} on {n} step(s) so far (the last pass is kept)")
        self.last_damage_passes = passes
        self.damage_passes_total += passes
        info.n_damaged = int(np.sum(dc < 1.0))
        info.n_capped = self.rheology.n_capped_total - n_capped_before
        state.velocity = vel
        state.stress = sigma
        state.damage = damage
        self._transport = vel
        self.last_strain_rate = eps
        return info

    def _solve(self, state: IceState, damage, t_s: float, dt: float, info: StepInfo):
        """Steps 1-2 of the module doc with the moduli of ``damage``, from the state's σ^n and
        u^n: returns (u^{n+1}, σ^{n+1} before the damage update, ε̇(u^{n+1}))."""
        tm = info.timings
        mesh, p = self.mesh, self.rheology.params
        t_new = t_s + dt
        ptr, elems, local = mesh.node_elements
        h = state.thickness
        n_el = mesh.n_elements
        lumped_mass = pick(LUMPED_MASS, n_el)
        nodal_force_from_stress = pick(NODAL_FORCE, n_el)
        strain_rate = pick(STRAIN_RATE, n_el)
        with Timer(tm, "assembly"):
            E, lam = self.rheology.moduli(damage, state.concentration)
            gamma = lam / (lam + dt)
            coef = self.area * h * gamma * dt * E
            data0 = assemble_elasticity(self.pattern.entry_map, self.b, self.c, coef, p.poisson,
                                        self.pattern.nnz)
            mass = lumped_mass(ptr, elems, self.area, p.rho_ice * h)
            node_area = lumped_mass(ptr, elems, self.area, np.ones_like(h))
            rhs0 = np.zeros((mesh.n_nodes, 2))
            nodal_force_from_stress(mesh.triangles, self.b, self.c, self.area, h, state.stress,
                                    gamma, ptr, elems, local, rhs0)
            rhs0 += (mass / dt)[:, None] * state.velocity
            diag_mass = np.repeat(mass / dt, 2)
        up = self.dirichlet.values(t_new)
        vel = state.velocity.copy()
        sigma_prev = None
        residual = 0.0
        it = 0
        for it in range(1, self.max_iter + 1):  # noqa: B007 (it is reported after the loop)
            with Timer(tm, "assembly"):
                data = data0.copy()
                data[self.pattern.diag_pos] += diag_mass
                rhs = rhs0.copy()
                if self.forces:
                    blocks = np.zeros((mesh.n_nodes, 2, 2))
                    for f in self.forces:
                        A_f, b_f = f.linearise(t_new, mesh.nodes, vel, mass / node_area)
                        blocks += A_f
                        rhs += b_f * node_area[:, None]
                    blocks *= node_area[:, None, None]
                    _add_node_blocks(self.pattern, data, blocks)
                A, b = self._apply_dirichlet(data, rhs.ravel(), up)
            with Timer(tm, "solve"):
                x = self.linear.solve(A, b, x0=vel.ravel())
                info.linear_iterations += self.linear.last_iterations
            vel_new = x.reshape(-1, 2)
            with Timer(tm, "damage"):
                eps = strain_rate(mesh.triangles, self.b, self.c, vel_new)
                sigma = gamma[:, None] * (state.stress + (dt * E)[:, None] * (eps @ self.rheology.K.T))
            if not self.forces:
                residual = 0.0
                vel = vel_new
                break
            if sigma_prev is not None:
                ns = np.linalg.norm(sigma)
                nv = np.linalg.norm(vel_new)
                rs = np.linalg.norm(sigma - sigma_prev) / ns if ns > 0 else 0.0
                rv = np.linalg.norm(vel_new - vel) / nv if nv > 0 else 0.0
                residual = max(rs, rv)
            else:
                residual = np.inf
            vel, sigma_prev = vel_new, sigma
            if residual < self.tol:
                break
        info.iterations = it
        info.residual = float(residual)
        if not np.all(np.isfinite(vel)):
            raise SolverError(f"non-finite velocity at t = {t_new:.6g} s")
        return vel, sigma, eps

    def _apply_dirichlet(self, data, rhs, up):
        """Symmetric elimination of prescribed dofs keeping the sparsity pattern."""
        dset = self.dirichlet
        A = self.pattern.matrix(data)
        if len(dset.dofs) == 0:
            return A, rhs
        full = np.zeros_like(rhs)
        full[dset.dofs] = up
        rhs = rhs - A @ full
        diag = data[self.pattern.diag_pos][dset.dofs].copy()
        data[self.entry_prescribed] = 0.0
        data[self.pattern.diag_pos[dset.dofs]] = diag
        rhs[dset.dofs] = diag * up
        return self.pattern.matrix(data), rhs


def _add_node_blocks(pattern: SparsityPattern, data, blocks):
    """Add per-node 2×2 blocks (n, 2, 2) to the matrix data."""
    d = pattern.diag_pos
    data[d[0::2]] += blocks[:, 0, 0]
    data[d[1::2]] += blocks[:, 1, 1]
    if np.any(blocks[:, 0, 1]) or np.any(blocks[:, 1, 0]):
        off01, off10 = pattern.node_offdiag_pos()
        data[off01] += blocks[:, 0, 1]
        data[off10] += blocks[:, 1, 0]
