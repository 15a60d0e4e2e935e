"""Viscous-plastic (Hibler 1979) comparison rheology solved by modified EVP
iterations (mEVP: Bouillon et al. 2013, Kimmritz et al. 2015), on the same
P1 velocity / P0 stress mesh and with the same forcing as the Maxwell-EB
solvers (GitHub issue 7; docs/evp.md).

Rheology (seed 000 eqs. 10-14), vertically integrated stress S [N m-1]:

    P = P* h exp(−C*(1−A)),   Δ = sqrt(ε̇I² + (ε̇II/e)²),
    ζ = P / (2 max(Δ, Δmin)),  η = ζ/e²,
    S = 2η ε̇' + (ζ ε̇I − Pr/2) I,

with ε̇I = ε̇xx + ε̇yy, ε̇II = sqrt((ε̇xx − ε̇yy)² + 4ε̇xy²) (the invariants of
:mod:`lagice.deformation`), ε̇' = ε̇ − ½ε̇I I the deviator, and Pr = P
(standard Hibler, default) or Pr = 2ζΔ = P Δ/max(Δ, Δmin) (replacement
pressure: no stress at rest).

mEVP, per outer step Δt from u^n, S^n, for p = 0 … N−1:

1. **element kernel**: S^{p+1} = S^p + (S_VP(u^p) − S^p)/α_e
2. **node kernel**: β_i (u^{p+1} − u^p) = −(u^{p+1} − u^n)
   + (Δt/m_i)(f_i(S^{p+1}) + a_i τa + τw(u^{p+1}) − m_i f k×(u^{p+1} + u^n)/2),

   the ocean drag with the coefficient c_d = a ρw Cw |Uw − u^p| of the previous
   iterate and implicit in u^{p+1}, Coriolis Crank–Nicolson (half at u^{p+1},
   half at u^n: inertial oscillations keep their amplitude), a 2×2 solve per
   node, as in :mod:`lagice.solvers.explicit`; f_i = −Σ_e area_e S_e·∇φ_i gathered through
   the node→element adjacency. Prescribed components (coast no-slip,
   :class:`VelocityBC`) take their value at the end of the outer step.

At convergence (u^{p+1} = u^p) this is the backward-Euler VP momentum
equation; the fixed point does not depend on α, β. ``adaptive=True`` (default)
uses the aEVP choice of Kimmritz et al. (2016) to keep the iteration stable
where the viscosity is large: α_e = max(α, sqrt(c γ_e)) with
γ_e = ζ_e Δt Σ_k|∇φ_k|² / (ρ h_e) and β_i = max(β, max over its elements of α_e).

The state stores the *depth-averaged* stress S/h [Pa] in ``state.stress``
(the Maxwell-EB convention, internal force ∝ h σ); damage is left untouched.
"""
from __future__ import annotations

import math
import time

import numpy as np
from numba import njit, prange

from .._numba import PARALLEL_MIN_SIZE, serial_copy
from ..errors import ConfigError, SolverError
from ..fem import element_strain_rate, strain_rate, strain_rate_serial
from ..forces import explicit_terms
from ..state import IceState
from .base import LumpedMassSolver, StepInfo
from .explicit import solve_node_2x2

#: P* [N m-2], C* [-], e [-], Δmin [s-1] defaults
P_STAR = 27.5e3
C_STAR = 20.0
ELLIPSE = 2.0
DELTA_MIN = 2e-9
#: safety factor c of the adaptive α (α_e = sqrt(c γ_e))
ADAPTIVE_SAFETY = 4.0


def _vp_stress(exx, eyy, exy, P, e2inv, delta_min, repl):
    """Hibler VP stress (S_xx, S_yy, S_xy) [N m-1] and ζ [kg s-1] for strain rate
    (ε̇xx, ε̇yy, ε̇xy) [s-1] and strength P [N m-1]."""
    div = exx + eyy
    shear2 = (exx - eyy) ** 2 + 4.0 * exy * exy
    delta = math.sqrt(div * div + shear2 * e2inv)
    dd = delta if delta > delta_min else delta_min
    zeta = 0.5 * P / dd
    eta = zeta * e2inv
    pr = P * delta / dd if repl else P
    iso = zeta * div - 0.5 * pr
    hd = 0.5 * div
    return (2.0 * eta * (exx - hd) + iso, 2.0 * eta * (eyy - hd) + iso, 2.0 * eta * exy, zeta)


vp_stress = njit(cache=True, inline="always")(_vp_stress)


def _element_evp(tri, b, c, vel, S, P, alpha_e, alpha, adapt_coef, e2inv, delta_min, repl):
    """One mEVP stress relaxation S ← S + (S_VP(u) − S)/α_e in place; refreshes
    α_e = max(α, sqrt(adapt_coef_e ζ_e)) where adapt_coef_e > 0 (adaptive)."""
    m = tri.shape[0]
    for e in prange(m):
        exx, eyy, exy = element_strain_rate(tri, b, c, vel, e)
        sxx, syy, sxy, zeta = vp_stress(exx, eyy, exy, P[e], e2inv, delta_min, repl)
        a = alpha
        ac = adapt_coef[e]
        if ac > 0.0:
            a2 = math.sqrt(ac * zeta)
            if a2 > a:
                a = a2
        alpha_e[e] = a
        inv = 1.0 / a
        S[e, 0] += (sxx - S[e, 0]) * inv
        S[e, 1] += (syy - S[e, 1]) * inv
        S[e, 2] += (sxy - S[e, 2]) * inv


def _node_evp(vel, vel_n, S, ptr, elems, wb, wc, alpha_e, beta, m_dt, fext, cda, current, cos_t, sin_t,
              mf, fixed, pres):
    """One mEVP velocity update in place on ``vel`` (n, 2) (module doc, step 2).

    m_dt = m/Δt [kg s-1]; fext = a τa [N]; cda = a ρw Cw [kg m-1]; mf = m f
    [kg s-1] (Coriolis Crank–Nicolson: ½ m f k×(u^{p+1} + u^n)); wb, wc = area ∂φ/∂x,
    area ∂φ/∂y per adjacency entry [m]; β_i =
    max(beta, α_e of its elements). Returns max |u^{p+1} − u^p| [m s-1]."""
    n = ptr.shape[0] - 1
    dmax = 0.0
    for i in prange(n):
        fx0 = fixed[i, 0]
        fx1 = fixed[i, 1]
        u = vel[i, 0]
        v = vel[i, 1]
        if fx0 and fx1:
            vel[i, 0] = pres[i, 0]
            vel[i, 1] = pres[i, 1]
            continue
        fx = 0.0
        fy = 0.0
        bi = beta
        for p in range(ptr[i], ptr[i + 1]):
            e = elems[p]
            fx -= wb[p] * S[e, 0] + wc[p] * S[e, 2]
            fy -= wb[p] * S[e, 2] + wc[p] * S[e, 1]
            if alpha_e[e] > bi:
                bi = alpha_e[e]
        md = m_dt[i]
        uwx = current[i, 0]
        uwy = current[i, 1]
        ru = uwx - u
        rv = uwy - v
        cd = cda[i] * math.sqrt(ru * ru + rv * rv)
        hf = 0.5 * mf[i]
        diag = (bi + 1.0) * md + cd * cos_t
        a11 = diag
        a12 = -cd * sin_t - hf
        a21 = cd * sin_t + hf
        a22 = diag
        rx = (bi * md * u + md * vel_n[i, 0] + fx + fext[i, 0] + cd * (cos_t * uwx - sin_t * uwy)
              + hf * vel_n[i, 1])
        ry = (bi * md * v + md * vel_n[i, 1] + fy + fext[i, 1] + cd * (sin_t * uwx + cos_t * uwy)
              - hf * vel_n[i, 0])
        un, vn = solve_node_2x2(a11, a12, a21, a22, rx, ry, fx0, fx1, pres[i, 0], pres[i, 1])
        dmax = max(dmax, max(abs(un - u), abs(vn - v)))  # prange max-reduction form
        vel[i, 0] = un
        vel[i, 1] = vn
    return dmax


def _serial(func):
    return serial_copy(func, error_model="numpy")


element_evp_kernel = njit(cache=True, parallel=True, error_model="numpy")(_element_evp)
element_evp_kernel_serial = _serial(_element_evp)
node_evp_kernel = njit(cache=True, parallel=True, error_model="numpy")(_node_evp)
node_evp_kernel_serial = _serial(_node_evp)
PARALLEL_MIN_ELEMENTS = PARALLEL_MIN_SIZE


def ice_strength(thickness, concentration, p_star: float = P_STAR, c_star: float = C_STAR):
    """P = P* h exp(−C*(1−A)) [N m-1]."""
    return p_star * np.asarray(thickness, np.float64) * np.exp(-c_star * (1.0 - np.asarray(concentration,
                                                                                              np.float64)))


def vp_stress_of(eps, P, ellipse: float = ELLIPSE, delta_min: float = DELTA_MIN,
                 replacement_pressure: bool = False):
    """Hibler VP stress (m, 3) [N m-1] and ζ (m,) of strain rates ``eps`` (m, 3)
    (ε̇xx, ε̇yy, ε̇xy) and strengths ``P`` (m,) (numpy, for tests and diagnostics)."""
    eps = np.asarray(eps, np.float64)
    P = np.broadcast_to(np.asarray(P, np.float64), eps.shape[:1])
    exx, eyy, exy = eps[:, 0], eps[:, 1], eps[:, 2]
    div = exx + eyy
    delta = np.sqrt(div ** 2 + ((exx - eyy) ** 2 + 4 * exy ** 2) / ellipse ** 2)
    dd = np.maximum(delta, delta_min)
    zeta = 0.5 * P / dd
    eta = zeta / ellipse ** 2
    pr = P * delta / dd if replacement_pressure else P
    iso = zeta * div - 0.5 * pr
    out = np.empty_like(eps)
    out[:, 0] = eta * (exx - eyy) + iso
    out[:, 1] = eta * (eyy - exx) + iso
    out[:, 2] = 2 * eta * exy
    return out, zeta


class EVPSolver(LumpedMassSolver):
    """Hibler VP rheology (elliptical yield curve) by mEVP iterations.

    Args:
        rheology: accepted for interface compatibility with the Maxwell-EB
            solvers (``Model`` passes it); only ``rheology.params.rho_ice`` is
            used (ice density of the lumped mass; 900 kg m-3 without one).
        mesh: the mesh (node positions read at each :meth:`update_geometry`).
        bcs: list of :class:`~lagice.solvers.base.VelocityBC`; coast nodes are no-slip.
        forces: external forces (``WindStress``, ``OceanDrag``, ``Coriolis``: anything
            with ``add_explicit_terms``; :func:`lagice.forces.explicit_terms`).
        substeps: N, the number of mEVP iterations per outer step (default 300); the
            most iterations when ``tol`` is set.
        tol: stop the iterations of a step once max |u^{p+1} − u^p| < ``tol`` [m s-1]
            (None, the default: always N iterations, the usual fixed-N mEVP).
        alpha, beta: mEVP relaxation parameters α, β (default 300 each); with
            ``adaptive`` they are lower bounds.
        adaptive: aEVP (Kimmritz et al. 2016): α_e = max(α, sqrt(4 γ_e)), β_i =
            max(β, max α_e of the node's elements), γ_e = ζ_e Δt Σ_k|∇φ_k|²/(ρ h_e);
            keeps the iteration stable on fine meshes/long steps.
        p_star [N m-2], c_star [-], ellipse e [-], delta_min Δmin [s-1]: VP parameters.
        replacement_pressure: Pr = P Δ/max(Δ, Δmin) instead of P (no stress at rest).
        heal_rate: ignored (no damage, no healing); accepted because ``Model`` passes it.
        parallel: True/False, or None: parallel kernels from ``PARALLEL_MIN_ELEMENTS`` up.

    ``state.stress`` holds the depth-averaged stress S/h [Pa] (0 where h = 0);
    :attr:`last_stress_integrated` the vertically integrated S [N m-1].
    ``StepInfo.iterations`` = iterations done (N without ``tol``), ``StepInfo.residual`` =
    max |u^p − u^{p−1}| of the last one [m s-1].
    """

    name = "evp"

    def __init__(self, rheology=None, mesh=None, bcs=(), forces=(), substeps: int | None = None,
                 alpha: float = 300.0, beta: float = 300.0, adaptive: bool = True,
                 p_star: float = P_STAR, c_star: float = C_STAR, ellipse: float = ELLIPSE,
                 delta_min: float = DELTA_MIN, replacement_pressure: bool = False,
                 heal_rate=None, parallel: bool | None = None, tol: float | None = None):
        if mesh is None:
            raise ConfigError("EVPSolver needs a mesh")
        if substeps is None:
            substeps = 300
        if int(substeps) != substeps or int(substeps) < 1:
            raise ConfigError(f"substeps = {substeps!r} (mEVP iterations) must be an integer >= 1")
        for nm, val, lo in (("alpha", alpha, 1.0), ("beta", beta, 0.0), ("p_star", p_star, 0.0),
                            ("ellipse", ellipse, 0.0), ("delta_min", delta_min, 0.0)):
            if not (np.isfinite(val) and val > lo):
                raise ConfigError(f"{nm} = {val!r} must be > {lo:g}")
        if tol is not None and not (np.isfinite(tol) and tol > 0):
            raise ConfigError(f"tol = {tol!r} m s-1 (mEVP convergence) must be > 0, or None")
        if not (np.isfinite(c_star) and c_star >= 0):
            raise ConfigError(f"c_star = {c_star!r} must be >= 0")
        self.rheology = rheology
        params = getattr(rheology, "params", None)
        self.rho_ice = float(getattr(params, "rho_ice", 900.0))
        self.bcs = list(bcs)
        self.forces = list(forces)
        self.substeps = int(substeps)
        self.tol = None if tol is None else float(tol)
        self.alpha, self.beta, self.adaptive = float(alpha), float(beta), bool(adaptive)
        self.p_star, self.c_star = float(p_star), float(c_star)
        self.ellipse, self.delta_min = float(ellipse), float(delta_min)
        self.replacement_pressure = bool(replacement_pressure)
        self.heal_rate = heal_rate
        self.parallel = parallel
        self.last_strain_rate = None
        self.last_stress_integrated = None
        self.mean_velocity = None
        self.last_substeps = None
        self.kernel_timings = {"forcing": 0.0, "setup": 0.0, "node_velocity": 0.0, "element_stress": 0.0}
        self.reset_topology(mesh)

    def _geometry_extras(self) -> None:
        """Σ|∇φ|² per element (adaptive mEVP relaxation) after nodes moved."""
        self.grad2 = np.sum(self.b ** 2 + self.c ** 2, axis=1)

    def strength(self, state: IceState) -> np.ndarray:
        """Ice strength P [N m-1] per element."""
        return ice_strength(state.thickness, state.concentration, self.p_star, self.c_star)

    def step(self, state: IceState, dt: float) -> StepInfo:
        if not dt > 0:
            raise ConfigError(f"dt = {dt!r} s must be > 0")
        kt = dict.fromkeys(self.kernel_timings, 0.0)
        mesh = self.mesh
        t0 = time.perf_counter()
        t_new = state.time_s + dt
        terms = explicit_terms(self.forces, t_new, mesh.nodes)
        pres = self._prescribed_velocity(t_new)
        t1 = time.perf_counter()
        kt["forcing"] = t1 - t0

        ptr, elems, _ = mesh.node_elements
        tri = mesh.triangles
        # S is vertically integrated: adjacency weights without h
        h, mass, wb, wc, m_dt, fext, cda, par = self._node_setup(state, terms, self.rho_ice, dt, False)
        mf = mass * terms.coriolis
        P = self.strength(state)
        if self.adaptive:
            with np.errstate(divide="ignore", invalid="ignore"):
                adapt = np.where(h > 0, ADAPTIVE_SAFETY * dt * self.grad2 / (self.rho_ice * h), 0.0)
        else:
            adapt = np.zeros_like(h)
        alpha_e = np.full(mesh.n_elements, self.alpha)
        vel_n = np.ascontiguousarray(state.velocity, np.float64).copy()
        vel = vel_n.copy()
        S = np.array(state.stress, np.float64, order="C") * h[:, None]  # vertically integrated
        e2inv = 1.0 / self.ellipse ** 2
        t2 = time.perf_counter()
        kt["setup"] = t2 - t1

        node_k = node_evp_kernel if par else node_evp_kernel_serial
        elem_k = element_evp_kernel if par else element_evp_kernel_serial
        tn = tm = 0.0
        res = 0.0
        used = 0
        for _ in range(self.substeps):
            ta = time.perf_counter()
            elem_k(tri, self.b, self.c, vel, S, P, alpha_e, self.alpha, adapt, e2inv, self.delta_min,
                   self.replacement_pressure)
            tb = time.perf_counter()
            res = node_k(vel, vel_n, S, ptr, elems, wb, wc, alpha_e, self.beta, m_dt, fext, cda,
                         terms.current, terms.cos_turn, terms.sin_turn, mf, self.fixed, pres)
            tc = time.perf_counter()
            tm += tb - ta
            tn += tc - tb
            used += 1
            if self.tol is not None and res < self.tol:
                break
        kt["element_stress"] = tm
        kt["node_velocity"] = tn
        if not (np.all(np.isfinite(vel)) and np.all(np.isfinite(S))):
            raise SolverError(f"non-finite velocity or stress at t = {t_new:.6g} s (EVP solver, Δt = {dt:g} s, "
                              f"{used} iterations, α = {self.alpha:g}, β = {self.beta:g})")
        state.velocity = vel
        with np.errstate(divide="ignore", invalid="ignore"):
            state.stress = np.where(h[:, None] > 0, S / h[:, None], 0.0)
        state.time_s = t_new
        state.step += 1
        self.last_stress_integrated = S
        self.mean_velocity = vel.copy()
        self.last_strain_rate = (strain_rate if par else strain_rate_serial)(tri, self.b, self.c, vel)
        self.last_substeps = used
        for k, v in kt.items():
            self.kernel_timings[k] += v
        info = StepInfo(iterations=used, residual=float(res))
        info.timings = {"assembly": kt["forcing"] + kt["setup"], "solve": tn + tm, "damage": 0.0}
        info.kernel_timings = kt
        return info
