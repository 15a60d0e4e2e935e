"""mEVP time stepper (modified elastic-viscous-plastic iterations: Bouillon et al.
2013, Kimmritz et al. 2015) of the Hibler (1979) viscous-plastic rheology
(:mod:`lagice.rheology.viscous_plastic`), on the same P1 velocity / P0 stress mesh
and with the same forcing as the Maxwell-EB steppers (docs/evp.md).

mEVP, per outer step Δt from u^n, S^n (S the vertically integrated stress
[N m-1]), for p = 0 … N−1:

1. **element kernel**: S^{p+1} = S^p + (S_VP(u^p) − S^p)/α_e
2. **node kernel**: β_i (u^{p+1} − u^p) = −(u^{p+1} − u^n)
   + (Δt/m_i)(f_i(S^{p+1}) + a_i τa + τw(u^{p+1}) − m_i f k×(u^{p+1} + u^n)/2),

   the ocean drag with the coefficient c_d = a ρw Cw |Uw − u^p| of the previous
   iterate and implicit in u^{p+1}, Coriolis Crank–Nicolson (half at u^{p+1},
   half at u^n: inertial oscillations keep their amplitude), a 2×2 solve per
   node (:func:`lagice.fem.solve_node_2x2`); f_i = −Σ_e area_e S_e·∇φ_i gathered
   through the node→element adjacency. Prescribed components (coast no-slip,
   :class:`~lagice.boundary.VelocityBC`) take their value at the end of the outer step.

At convergence (u^{p+1} = u^p) this is the backward-Euler VP momentum
equation; the fixed point does not depend on α, β. ``adaptive=True`` (default)
uses the aEVP choice of Kimmritz et al. (2016) to keep the iteration stable
where the viscosity is large: α_e = max(α, sqrt(c γ_e)) with
γ_e = ζ_e Δt Σ_k|∇φ_k|² / (ρ h_e) and β_i = max(β, max over its elements of α_e).

The state stores the *depth-averaged* stress S/h [Pa] in ``state.stress``
(the Maxwell-EB convention, internal force ∝ h σ); damage is left untouched.
The transport velocity is the end-of-step velocity u^{n+1} (backward Euler).
"""
from __future__ import annotations

import math
import time

import numpy as np
from numba import njit, prange

from .._numba import PARALLEL_MIN_SIZE, serial_copy
from ..errors import ConfigError
from ..fem import STRAIN_RATE, NodeSystem, element_strain_rate, solve_node_2x2
from ..forces import explicit_terms
from ..rheology.viscous_plastic import (
    C_STAR,
    DELTA_MIN,
    ELLIPSE,
    P_STAR,
    ViscousPlastic,
    ice_strength,
    vp_stress,
    vp_stress_of,
)
from ..state import IceState
from .base import StepInfo

__all__ = ["EVPSolver", "P_STAR", "C_STAR", "ELLIPSE", "DELTA_MIN", "ice_strength", "vp_stress_of"]

#: safety factor c of the adaptive α (α_e = sqrt(c γ_e))
ADAPTIVE_SAFETY = 4.0


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


def _node_evp(vel, vel_n, S, ptr, elems, w, alpha_e, beta, m_dt, fext, cda, current, cos_t, sin_t,
              mf, fixed, pres):
    """One mEVP velocity update in place on ``vel`` (n, 2) (module doc, step 2).

    m_dt = m/Δt [kg s-1]; fext = a τa [N]; cda = a ρw Cw [kg m-1]; mf = m f
    [kg s-1] (Coriolis Crank–Nicolson: ½ m f k×(u^{p+1} + u^n)); w (nnz, 2) = (area ∂φ/∂x,
    area ∂φ/∂y) per adjacency entry [m]; β_i =
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
            wb = w[p, 0]
            wc = w[p, 1]
            fx -= wb * S[e, 0] + wc * S[e, 2]
            fy -= wb * S[e, 2] + wc * S[e, 1]
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


class EVPSolver:
    """mEVP stepper of the Hibler VP rheology (elliptical yield curve).

    Args:
        rheology: :class:`~lagice.rheology.ViscousPlastic` (P*, C*, e, Δmin,
            replacement pressure, ice density); default parameters if None.
        mesh: the mesh (node positions read at each :meth:`update_geometry`).
        bcs: list of :class:`~lagice.boundary.VelocityBC`; coast nodes are no-slip.
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
        heal_rate: must be None (the VP rheology has no damage to heal).
        parallel: True/False, or None: parallel kernels from ``PARALLEL_MIN_ELEMENTS`` up.

    ``state.stress`` holds the depth-averaged stress S/h [Pa] (0 where h = 0);
    :attr:`last_stress_integrated` the vertically integrated S [N m-1].
    ``StepInfo.iterations`` = iterations done (N without ``tol``), ``StepInfo.residual`` =
    max |u^p − u^{p−1}| of the last one [m s-1].
    """

    name = "evp"

    def __init__(self, rheology: ViscousPlastic | None = None, mesh=None, bcs=(), forces=(),
                 substeps: int | None = None, alpha: float = 300.0, beta: float = 300.0,
                 adaptive: bool = True, heal_rate=None, parallel: bool | None = None,
                 tol: float | None = None):
        if mesh is None:
            raise ConfigError("EVPSolver needs a mesh")
        rheology = ViscousPlastic() if rheology is None else rheology
        if not isinstance(rheology, ViscousPlastic):
            raise ConfigError(f"the evp (mEVP) stepper solves the viscous-plastic rheology "
                              f"(rheology.law = 'viscous_plastic'); got {type(rheology).__name__}")
        if heal_rate is not None:
            raise ConfigError("the viscous-plastic rheology has no damage: a healing law does not apply "
                              "(healing.law = 'none')")
        if substeps is None:
            substeps = 300
        if int(substeps) != substeps or int(substeps) < 1:
            raise ConfigError(f"substeps = {substeps!r} (mEVP iterations) must be an integer >= 1")
        for nm, val, lo in (("alpha", alpha, 1.0), ("beta", beta, 0.0)):
            if not (np.isfinite(val) and val > lo):
                raise ConfigError(f"{nm} = {val!r} must be > {lo:g}")
        if tol is not None and not (np.isfinite(tol) and tol > 0):
            raise ConfigError(f"tol = {tol!r} m s-1 (mEVP convergence) must be > 0, or None")
        self.rheology = rheology
        self.forces = list(forces)
        self.substeps = int(substeps)
        self.tol = None if tol is None else float(tol)
        self.alpha, self.beta, self.adaptive = float(alpha), float(beta), bool(adaptive)
        self.last_stress_integrated = None
        self._transport = None
        self._strain_rate = None
        self.last_substeps = None
        self.kernel_timings = {"forcing": 0.0, "setup": 0.0, "node_velocity": 0.0, "element_stress": 0.0}
        self.nodes = NodeSystem(mesh, bcs, parallel, geometry_hook=self._geometry_extras)

    @property
    def mesh(self):
        return self.nodes.mesh

    @property
    def area(self):
        return self.nodes.area

    @property
    def transport_velocity(self):
        return self._transport

    @property
    def last_strain_rate(self):
        return self._strain_rate

    def reset_topology(self, mesh) -> None:
        self._transport = None
        self._strain_rate = None
        self.nodes.reset_topology(mesh)

    def update_geometry(self) -> None:
        self.nodes.update_geometry()

    def _geometry_extras(self, ns) -> None:
        """Σ|∇φ|² per element (adaptive mEVP relaxation) after nodes moved."""
        self.grad2 = np.sum(ns.b ** 2 + ns.c ** 2, axis=1)

    def strength(self, state: IceState) -> np.ndarray:
        """Ice strength P [N m-1] per element."""
        return self.rheology.strength(state.thickness, state.concentration)

    def step(self, state: IceState, t_s: float, dt: float) -> StepInfo:
        if not dt > 0:
            raise ConfigError(f"dt = {dt!r} s must be > 0")
        kt = dict.fromkeys(self.kernel_timings, 0.0)
        ns = self.nodes
        mesh = ns.mesh
        vp = self.rheology.params
        t0 = time.perf_counter()
        t_new = t_s + dt
        terms = explicit_terms(self.forces, t_new, mesh.nodes)
        pres = ns.prescribed_velocity(t_new)
        t1 = time.perf_counter()
        kt["forcing"] = t1 - t0

        ptr, elems, _ = mesh.node_elements
        tri = mesh.triangles
        # S is vertically integrated: adjacency weights without h
        su = ns.setup(state.thickness, terms, vp.rho_ice, dt, False)
        h, par = su.h, su.parallel
        mf = su.mass * terms.coriolis
        P = self.strength(state)
        if self.adaptive:
            with np.errstate(divide="ignore", invalid="ignore"):
                adapt = np.where(h > 0, ADAPTIVE_SAFETY * dt * self.grad2 / (vp.rho_ice * h), 0.0)
        else:
            adapt = np.zeros_like(h)
        alpha_e = np.full(mesh.n_elements, self.alpha)
        vel_n = np.ascontiguousarray(state.velocity, np.float64).copy()
        vel = vel_n.copy()
        S = np.array(state.stress, np.float64, order="C") * h[:, None]  # vertically integrated
        e2inv = 1.0 / vp.ellipse ** 2
        t2 = time.perf_counter()
        kt["setup"] = t2 - t1

        node_k = node_evp_kernel if par else node_evp_kernel_serial
        elem_k = element_evp_kernel if par else element_evp_kernel_serial
        tn = tm = 0.0
        res = 0.0
        used = 0
        b, c = ns.b, ns.c
        for _ in range(self.substeps):
            ta = time.perf_counter()
            elem_k(tri, b, c, vel, S, P, alpha_e, self.alpha, adapt, e2inv, vp.delta_min,
                   vp.replacement_pressure)
            tb = time.perf_counter()
            res = node_k(vel, vel_n, S, ptr, elems, su.w, alpha_e, self.beta, su.m_dt, su.fext, su.cda,
                         terms.current, terms.cos_turn, terms.sin_turn, mf, ns.fixed, pres)
            tc = time.perf_counter()
            tm += tb - ta
            tn += tc - tb
            used += 1
            if self.tol is not None and res < self.tol:
                break
        kt["element_stress"] = tm
        kt["node_velocity"] = tn
        state.velocity = vel
        with np.errstate(divide="ignore", invalid="ignore"):
            state.stress = np.where(h[:, None] > 0, S / h[:, None], 0.0)
        self.last_stress_integrated = S
        self._transport = vel.copy()
        self._strain_rate = STRAIN_RATE[int(par)](tri, b, c, vel)
        self.last_substeps = used
        for k, v in kt.items():
            self.kernel_timings[k] += v
        info = StepInfo(iterations=used, residual=float(res))
        info.timings = {"assembly": kt["forcing"] + kt["setup"], "solve": tn + tm, "damage": 0.0}
        info.kernel_timings = kt
        return info
