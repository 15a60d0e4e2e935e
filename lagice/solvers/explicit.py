"""Explicit Maxwell-EB time stepper, neXtSIM BBM style (docs/design.md §4.2).

One outer step Δt (forcing evaluated, lumped mass, geometry, moduli) is split
into N elastic sub-steps Δt_s = Δt/N. Each sub-step is two numba kernels,
both parallel over their *own* entities so that no loop scatters:

1. **node kernel** (velocity): the internal force f_i = −Σ_e area h σ_e·∇φ_i is
   gathered through the node→element adjacency, then momentum with lumped
   mass m_i is advanced semi-implicitly,

       (m/Δt_s + a c_d Rθ + ½ m f J) u^{k+1}
           = (m/Δt_s − ½ m f J) u^k + f_i + a (τa + c_d Rθ Uw),

   with c_d = ρw Cw |Uw − u^k| (drag coefficient from the previous sub-step,
   drag itself implicit), J = k× = [[0, −1], [1, 0]] and the Coriolis term
   Crank–Nicolson, so pure inertial oscillations keep their speed exactly
   (the update is a Cayley rotation). a is the node's lumped area. A 2×2
   solve per node; prescribed components (VelocityBC, coast) are set to their
   value, linearly interpolated in time across the outer step.

2. **element kernel** (stress and damage): strain rate ε̇(u^{k+1}), Maxwell
   update σ ← (σ + Δt_s E K:ε̇) λ/(λ+Δt_s) (Dansereau et al. 2016 eq. 1, same
   discretisation as the implicit solver), then the damage/stress correction
   and healing of Dansereau et al. 2016 eqs. 9-11 with Δt_s — the same arithmetic as
   :func:`lagice.rheology.damage_update_kernel`, built on its numba core
   ``_dcrit`` (a test checks both agree to round-off, 1e-13 relative:
   the kernels fuse multiply-adds, see ``KERNEL_FASTMATH``). E = E0 (1−d) g and
   λ = λ0 ((1−d) g)^(α−1), g = exp(−c*(1−A)) (the rheology's formulas; a test
   checks them against ``MaxwellEB.moduli``) are recomputed only where damage
   changed.

Stability: the sub-step is limited by elastic waves, Δt_s ≲ C Δx / sqrt(E/ρ);
C was measured (``benchmarks/stability.py``) and ships in
``lagice/data/stability_limits.json`` (see :mod:`lagice.stability`).
``substeps=None`` picks N from that limit with a safety factor.
"""
from __future__ import annotations

import math
import time

import numpy as np
from numba import njit, prange

from .._numba import PARALLEL_MIN_SIZE, autotune, serial_copy, specialised_copy
from ..errors import ConfigError
from ..fem import STRAIN_RATE, NodeSystem, element_strain_rate
from ..forces import explicit_terms
from ..params import FAILURE_EXPONENT
from ..rheology import MaxwellEB, _dcrit, damage_step
from ..rheology.maxwell_eb import _dcrit_towards, closed_crack_mean
from ..stability import effective_dx
from ..state import IceState
from .base import StepInfo
from .crouzeix_raviart import (
    jump_impulse_kernel,
    jump_impulse_kernel_serial,
    jump_update_kernel,
    jump_update_kernel_serial,
)
from .nonlocal_damage import NonlocalWeights

#: how the measured sub-step limit C Δx/sqrt(E/ρ) is applied (:mod:`lagice.stability`):
#: "mesh" (default): the smallest element size with the stiffest modulus of the whole mesh;
#: "element": element by element, C min_e Δx_e/sqrt(E_e/ρ) (Irons' bound; fewer, longer
#: sub-steps where the smallest elements are soft). Both are stable; "element" is 1.1-1.3x
#: faster on the winter scenes, but on the flagship its longer sub-steps lowered the mean
#: deformation rate by 14 % against 170 and 250 sub-steps, which agree to 1.5 %
#: (docs/physics.md §4, "Sub-step length"), so it is not the default.
SUBSTEP_LIMITS = ("mesh", "element")

#: the volumetric strain rate the element kernel's stress update uses (:func:`_node_divergence`):
#: "element" (default): each element's own; "nodal": the mean of its nodes' area-weighted
#: averages (Bonet and Burton 1998's average nodal pressure), against the volumetric locking of
#: linear triangles whose mean stress is kept while the deviator relaxes (docs/solvers.md)
VOLUMETRIC_STRAIN = ("element", "nodal")


#: the velocity space of the explicit stepper: "linear" (default; continuous, linear per triangle,
#: one value per node, as neXtSIM) or "crouzeix_raviart" (linear per triangle, continuous at the edge
#: midpoints, one value per edge: :mod:`lagice.solvers.crouzeix_raviart`; a stable pair with the
#: one stress per element, so ice whose mean stress is kept is not locked by the mesh)
VELOCITY_ELEMENTS = ("linear", "crouzeix_raviart")


def check_velocity_element(velocity_element: str) -> str:
    if velocity_element not in VELOCITY_ELEMENTS:
        raise ConfigError(f"solver.velocity_element = {velocity_element!r}: expected one of "
                          f"{list(VELOCITY_ELEMENTS)}")
    return velocity_element


def check_volumetric_strain(volumetric_strain: str) -> str:
    if volumetric_strain not in VOLUMETRIC_STRAIN:
        raise ConfigError(f"solver.volumetric_strain = {volumetric_strain!r}: expected one of "
                          f"{list(VOLUMETRIC_STRAIN)}")
    return volumetric_strain


def check_substep_limit(substep_limit: str) -> str:
    if substep_limit not in SUBSTEP_LIMITS:
        raise ConfigError(f"solver.substep_limit = {substep_limit!r}: expected one of {list(SUBSTEP_LIMITS)}")
    return substep_limit


#: keys of ``ExplicitSolver.kernel_timings`` / ``StepInfo.kernel_timings`` [s]
KERNELS = ("forcing", "setup", "substeps", "node_velocity", "element_stress_damage")

#: sub-steps per autotuning trial: about this many element-sub-steps (a few ms)
AUTOTUNE_WORK = 300_000
#: with ``parallel="auto"`` the choice is measured again after this much wall time [s]
#: (the load of a shared machine changes during a long run; a measurement costs ~0.05 s,
#: 0.1 % of a minute); the second measurement comes sooner, after
#: :data:`AUTOTUNE_FIRST_INTERVAL_S`: on the idle 2-vCPU VM, 3 of 12 start-up measurements
#: took the serial build (a parallel trial as slow as the serial one, a passing
#: disturbance) for runs that then went 1.8x slower than with the parallel build
#: (docs/benchmarks.md, 2026-11-26). Serial and parallel builds give identical results, so
#: a change of choice mid-run changes only the speed.
AUTOTUNE_INTERVAL_S = 60.0
AUTOTUNE_FIRST_INTERVAL_S = 10.0


#: the kernels below are compiled with ``fastmath={"contract"}``: a·b + c may be fused into
#: one FMA (one rounding instead of two). Nothing else of fast-math (no reassociation, no
#: assumption about NaN or infinity). +17 % for the element kernel, +10 % for the sub-step
#: loop (docs/benchmarks.md); the price is that the explicit damage update now agrees with
#: the rheology's (implicit solver) to round-off (1e-13 relative, tests/test_explicit.py)
#: instead of bit for bit. Serial and parallel builds compile the same per-entity code.
KERNEL_FASTMATH = {"contract"}


#: columns of the per-node constants array ``nc`` (n, 8) of :func:`_node_velocity`: one row
#: of 64 B per node instead of five arrays (m/Δt_s, a ρw Cw, ½ m f, a τ (2), Uw (2); the last
#: column is padding). +1.5 % for the node kernel on 2 threads (docs/benchmarks.md).
NODE_CONSTANTS = ("m_dt", "cda", "half_mf", "fext_x", "fext_y", "current_x", "current_y", "pad")


def _node_setup(ptr, elems, local, area, h, b, c, rho, dt_sub, tau, drag_coef, coriolis, current):
    """The per-node set-up of one outer step in one pass over the node→element adjacency:
    the adjacency weights ``w`` (nnz, 2) of :func:`lagice.fem._adjacency_weights` (thickness
    weighted), the per-node constants ``nc`` (n, 8) (:data:`NODE_CONSTANTS`) and the lumped
    mass [kg] (n,), from thickness h [m], ρ [kg m-3], the sub-step Δt_s [s], the wind stress
    τ [N m-2] (n, 2), ρw Cw (n,), f [s-1] (n,) and the current [m s-1] (n, 2).

    Every value is computed with the same operations, in the same order, as the separate
    passes it replaces (:meth:`lagice.fem.NodeSystem.setup`: two lumped masses, the weights,
    m/Δt_s, a τ, a ρw Cw; then the constants, ½ m f among them), so the results are the same bit for
    bit (compiled without ``fastmath``: no fused multiply-adds); a test checks it. One pass
    reads the adjacency once instead of three times and writes no temporary arrays:
    docs/benchmarks.md, "2026-11-28, twenty-ninth session"."""
    n = ptr.shape[0] - 1
    w = np.empty((elems.shape[0], 2))
    nc = np.empty((n, 8))
    mass = np.empty(n)
    for i in prange(n):
        sm = 0.0
        sa = 0.0
        for p in range(ptr[i], ptr[i + 1]):
            e = elems[p]
            k = local[p]
            ae = area[e]
            sm += (rho * h[e]) * ae
            sa += 1.0 * ae
            a = ae * h[e]
            w[p, 0] = a * b[e, k]
            w[p, 1] = a * c[e, k]
        mi = sm / 3.0
        na = sa / 3.0
        mass[i] = mi
        nc[i, 0] = mi / dt_sub
        nc[i, 1] = drag_coef[i] * na
        nc[i, 2] = 0.5 * mi * coriolis[i]
        nc[i, 3] = tau[i, 0] * na
        nc[i, 4] = tau[i, 1] * na
        nc[i, 5] = current[i, 0]
        nc[i, 6] = current[i, 1]
        nc[i, 7] = 0.0
    return w, nc, mass


node_setup_kernel = njit(cache=True, parallel=True)(_node_setup)
node_setup_kernel_serial = serial_copy(_node_setup)
#: (serial, parallel) builds of :func:`_node_setup`
NODE_SETUP = (node_setup_kernel_serial, node_setup_kernel)


def _node_velocity(vel, vel_sum, sigma, ptr, elems, w, nc, cos_t, sin_t, fixed, pres0, pres1, w_time):
    """One semi-implicit momentum sub-step in place on ``vel`` (n, 2) (module doc, step 1).

    w (nnz, 2): adjacency weights (:func:`lagice.fem._adjacency_weights`); nc (n, 8): the
    per-node constants (:data:`NODE_CONSTANTS`): m_dt = m/Δt_s [kg s-1], cda = a ρw Cw
    [kg m-1], half_mf = ½ m f [kg s-1], fext = a τ [N] (velocity-independent), current Uw
    [m s-1]; fixed (n, 2) int8 flags of prescribed components; pres0/pres1 their values at
    the start/end of the outer step, weighted (1 − w_time, w_time). The new velocity is
    also added to ``vel_sum`` (outer-step mean velocity).

    The 2×2 matrix is a scaled rotation, [[a, −s], [s, a]] with a = m/Δt_s + c_d cosθ and
    s = c_d sinθ + ½ m f, so it is solved as (a r_x + s r_y, a r_y − s r_x)/(a² + s²): the
    solution of :func:`lagice.fem.solve_node_2x2` with a22 = a11 and a21 = −a12 (a > 0: the
    lumped mass is positive), bit for bit on the kernel arguments of the benchmark box and
    the flagship (docs/benchmarks.md); a test checks it to 1e-13.
    """
    n = ptr.shape[0] - 1
    for i in prange(n):
        fx0 = fixed[i, 0]
        fx1 = fixed[i, 1]
        if fx0 and fx1:
            vel[i, 0] = pres0[i, 0] + w_time * (pres1[i, 0] - pres0[i, 0])
            vel[i, 1] = pres0[i, 1] + w_time * (pres1[i, 1] - pres0[i, 1])
            vel_sum[i, 0] += vel[i, 0]
            vel_sum[i, 1] += vel[i, 1]
            continue
        fx = 0.0
        fy = 0.0
        for p in range(ptr[i], ptr[i + 1]):
            e = elems[p]
            sxx = sigma[e, 0]
            syy = sigma[e, 1]
            sxy = sigma[e, 2]
            wb = w[p, 0]
            wc = w[p, 1]
            fx -= wb * sxx + wc * sxy
            fy -= wb * sxy + wc * syy
        u = vel[i, 0]
        v = vel[i, 1]
        md = nc[i, 0]
        uwx = nc[i, 5]
        uwy = nc[i, 6]
        ru = uwx - u
        rv = uwy - v
        cd = nc[i, 1] * math.sqrt(ru * ru + rv * rv)
        hf = nc[i, 2]
        a11 = md + cd * cos_t
        a12 = -cd * sin_t - hf
        rx = md * u + fx + nc[i, 3] + cd * (cos_t * uwx - sin_t * uwy) + hf * v
        ry = md * v + fy + nc[i, 4] + cd * (sin_t * uwx + cos_t * uwy) - hf * u
        if fx0:
            un = pres0[i, 0] + w_time * (pres1[i, 0] - pres0[i, 0])
            vn = (ry + a12 * un) / a11
        elif fx1:
            vn = pres0[i, 1] + w_time * (pres1[i, 1] - pres0[i, 1])
            un = (rx - a12 * vn) / a11
        else:
            det = a11 * a11 + a12 * a12
            un = (a11 * rx - a12 * ry) / det
            vn = (a11 * ry + a12 * rx) / det
        vel[i, 0] = un
        vel[i, 1] = vn
        vel_sum[i, 0] += un
        vel_sum[i, 1] += vn


def mean_relaxation_ratio(params) -> float:
    """r = λ_m/λ [-] for ``rheology.bulk_shear_viscosity_ratio`` ζ/η: the bulk viscosity K λ_m
    over the shear viscosity G λ is ζ/η, with K/G = (1 + ν)/(1 − ν) in plane stress, so
    r = (ζ/η)(1 − ν)/(1 + ν) (r = 1: one λ, the default Maxwell-EB)."""
    nu = params.poisson
    return float(params.bulk_shear_viscosity_ratio) * (1.0 - nu) / (1.0 + nu)


def stability_modulus(params, E, concentration):
    """The modulus [Pa] per element that sets the sub-step limit: the damaged E of the
    Maxwell update, or with ``crack_closure`` the undamaged E0 exp(−c*(1 − A)), with which the
    mean stress of closed cracks responds (a pack broken everywhere would otherwise get
    sub-steps too long for that stiffness). The default path returns ``E`` itself."""
    if not params.crack_closure:
        return E
    return params.E0 * np.exp(-params.concentration_c * (1.0 - np.asarray(concentration, np.float64)))


def envelope_factors(rheology):
    """(kc, kt) [-] of the element kernel's cheap inside-the-envelope test: σc = 2C/denom and
    σT = σc/q (Dansereau et al. 2016 eqs. 4, 6) are taken as C·kc and C·kt, lowered by
    1e-12 relative so that the test is strictly conservative (an element it passes is
    inside the exact envelope; the rest go to ``_dcrit``, which decides exactly)."""
    kc = 2.0 / rheology._denom * (1.0 - 1e-12)
    return kc, kc / rheology.q


#: False in the general element kernel; True in its α = 4 builds (:func:`lagice._numba.specialised_copy`),
#: where numba then compiles λ = λ0 x³ without the branch on α. Healing ice refreshes its moduli
#: every sub-step, and a branch on α there cost the kernel 3-4 % on 2 threads (docs/benchmarks.md)
_ALPHA_IS_4 = False


def _element_stress_damage(tri, b, c, vel, sigma, damage, conc_factor, cohesion, kc, kt,
                           td, heal_rate, e_dt, gamma, pmax, keep_mean, theta, dilat, eff, closure, dt_s, kxx, kxy,
                           kss, q, denom, max_damage, E0, lambda0, alpha, damaged_flag, divn, lam_scale=None):
    """Maxwell stress update and damage/healing of one sub-step, in place (module doc, step 2).

    e_dt = Δt_s E [Pa s], gamma = λ/(λ+Δt_s) per element, refreshed here where damage
    changes from E = E0 (1−d) g, λ = λ0 ((1−d) g)^(α−1) with g = conc_factor =
    exp(−c*(1−A)) (rheology.young_modulus/relaxation_time; an integer α−1 is taken as
    repeated products; the set-up fills them from ``MaxwellEB.moduli``). Computing them
    from the damage every sub-step instead ran 8 % faster on 2 threads but changes the
    results at round-off, and a 28-day month then ends elsewhere (docs/benchmarks.md), so
    the published runs would no longer be reproduced bit for bit. kxx = 1/(1−ν²),
    kxy = ν/(1−ν²), kss = (1−ν)/(1−ν²) are the entries of K; kc, kt: :func:`envelope_factors`.
    pmax [Pa]: neXtSIM's compressive term (rheology.max_pressure; None: off, and numba
    prunes the branch when it compiles the NoneType signature, so the default path pays
    nothing for it): where the mean stress σn of the previous sub-step is compressive, the
    relaxation factor is λ/(λ + Δt_s (1 − P̃)), P̃ = min(1, pmax/(−σn)), computed from γ
    as γ/(γ + (1 − γ)(1 − P̃)) (neXtSIM's ``updateSigmaDamage``).
    keep_mean: None (rheology.relax_mean_stress true, the default; pruned as pmax is): the
    relaxation factor scales the whole stress. A float r: it scales the deviatoric stress
    σ − m I only (m = (σxx + σyy)/2 after the elastic increment), and the mean m relaxes with
    λ_m = r λ (rheology.bulk_shear_viscosity_ratio), or, for r = inf
    (relax_mean_stress false), is kept or, with pmax, scaled by the compressive term's factor
    (it creeps in tension and above P_max). A finite r with pmax: the deviator relaxes with
    λ/(λ + Δt_s (1 − P̃)) and the mean with λ_m/(λ_m + Δt_s (1 − P̃)), neXtSIM's factor applied to
    each part with its own relaxation time (thirty-eighth session).
    theta: None (rheology.stress_correction = "origin", the default; pruned as pmax is): a
    super-critical stress is scaled towards the origin. A float θ ∈ (0, 2]
    (``"mean_stress"``, θ = ``stress_correction_mean_fraction``): it is brought back along
    the straight path towards P = θ m I, σ ← P + f (σ − P), with d_crit the factor of
    ``rheology._dcrit_towards`` (the origin path where that factor does not exist), as
    ``rheology.damage_update_kernel`` does for the implicit solver.
    dilat: None (rheology.dilatancy_angle_deg unset or 0, the default; pruned as pmax is). A
    float k_ψ = sin ψ (1 + ν)/(1 − ν): the Maxwell viscous flow dilates (Reynolds dilatancy of
    broken ice): to the viscous strain rate K⁻¹σ/(Eλ) it adds δ I with 2δ = sin ψ times its
    shear rate 2(1 + ν) r/(Eλ), r the radius of Mohr's circle. Backward Euler, like the
    relaxation: σ ← γ σ* − (1 − γ) k_ψ r I, r that of the relaxed stress γ σ* (exact, since
    the isotropic term leaves r unchanged). Only with the whole stress relaxing and no
    compressive term (params refuse the rest).
    eff: None (rheology.failure_stress = "nominal", the default; pruned as pmax is): the envelope
    judges σ with the element's cohesion C. 1.0 (``"effective"``): it judges the effective
    stress σ/(1 − d), i.e. σ against the envelope of cohesion C (1 − d) (the friction is
    kept), d the damage at the start of the sub-step. 0.5 (``"energy"``): the effective stress
    of strain-energy equivalence σ/√(1 − d), i.e. the envelope of cohesion C √(1 − d).
    closure: None (rheology.crack_closure false, the default; pruned as pmax is). True: only with
    keep_mean (params refuse the rest), quasi-unilateral damage: the mean normal stress m changes
    with the undamaged Δt_s E0 exp(−c*(1−A)) where m ≤ 0 (the cracks closed) and with the
    damaged e_dt where m ≥ 0; a sub-step that crosses m = 0 takes each modulus for its part of
    the volumetric strain. Intact ice (d = 0) is unchanged to round-off (ed0/ed = 1 up to the
    rounding of the two products).
    divn: None (solver.volumetric_strain = "element", the default; pruned as pmax is): the
    element's own strain rate. An (n,) array (``"nodal"``): the nodal volumetric strain rates of
    :func:`_node_divergence` this sub-step; the element's volumetric rate ε̇xx + ε̇yy is replaced
    by the mean of its three nodes' values, its deviatoric rate kept (the average nodal pressure
    of Bonet and Burton 1998: no volumetric locking of linear triangles where the mean stress
    is kept and the deviator relaxes).
    lam_scale: None (rheology.crack_band_length_m unset, the default; pruned as pmax is). An (m,)
    array Δx/ℓ (``MaxwellEB.relaxation_scale``): the refreshed λ is multiplied by it, as the set-up
    multiplies the λ it fills γ from (the crack-band scaling of the viscous flow).
    Returns the number of elements whose damage hit the cap.
    """
    m = tri.shape[0]
    n_capped = 0
    for e in prange(m):
        exx, eyy, exy = element_strain_rate(tri, b, c, vel, e)
        if divn is not None:  # pruned when None, as pmax is
            dv = 0.5 * ((divn[tri[e, 0]] + divn[tri[e, 1]] + divn[tri[e, 2]]) * (1.0 / 3.0) - (exx + eyy))
            exx += dv
            eyy += dv
        ed = e_dt[e]
        g = gamma[e]
        gp = g
        omp = 1.0  # 1 − P̃ of the compressive term (1: it does not act)
        if pmax is not None:
            sn = -0.5 * (sigma[e, 0] + sigma[e, 1])
            if sn > 0.0:
                pt = min(1.0, pmax[e] / sn)
                omp = 1.0 - pt
                gp = g / (g + (1.0 - g) * omp)
        if keep_mean is None:
            sxx = (sigma[e, 0] + ed * (kxx * exx + kxy * eyy)) * gp
            syy = (sigma[e, 1] + ed * (kxy * exx + kxx * eyy)) * gp
            sxy = (sigma[e, 2] + ed * (kss * exy)) * gp
            if dilat is not None:  # only with pmax None (MaxwellEBParams refuses both), so gp == g here
                pd = (1.0 - g) * dilat * math.sqrt(0.25 * (sxx - syy) ** 2 + sxy * sxy)
                sxx -= pd
                syy -= pd
        else:
            axx = sigma[e, 0] + ed * (kxx * exx + kxy * eyy)
            ayy = sigma[e, 1] + ed * (kxy * exx + kxx * eyy)
            am = 0.5 * (axx + ayy)
            if closure is not None:  # pruned when None, as pmax is
                # the mean with the undamaged modulus wherever the cracks are closed (m ≤ 0)
                mc = closed_crack_mean(0.5 * (sigma[e, 0] + sigma[e, 1]), am, ed, dt_s * E0 * conc_factor[e])
                axx += mc - am
                ayy += mc - am
                am = mc
            gd = g
            if pmax is not None:
                if keep_mean == math.inf:  # the kept mean: only the compressive term's factor
                    gm = gp
                else:  # ζ/η with the compressive term: each part's λ, both times 1 − P̃
                    gmr = keep_mean * g / (keep_mean * g + (1.0 - g))
                    gm = gmr if omp == 1.0 else gmr / (gmr + (1.0 - gmr) * omp)
                    gd = gp
            elif keep_mean == math.inf:  # relax_mean_stress = false: the mean is kept
                gm = 1.0
            else:  # rheology.bulk_shear_viscosity_ratio: λ_m = r λ, so γ_m = r γ/(r γ + 1 − γ)
                gm = keep_mean * g / (keep_mean * g + (1.0 - g))
            sxx = (axx - am) * gd + am * gm
            syy = (ayy - am) * gd + am * gm
            sxy = (sigma[e, 2] + ed * (kss * exy)) * gd
        # damage and stress correction: rheology.damage_step (both healing forms, by the sign of
        # heal_rate), as in rheology.damage_update_kernel.
        # Cheap test first: strictly inside the envelope (s1 < σT and q s1 − s2 < σc) _dcrit
        # returns exactly 1. With s1,2 = m ± r the two conditions are r < σT − m and
        # (q + 1) r < σc − (q − 1) m, tested on squares (no square root for the ~all elements
        # inside: +7 % for the kernel), with σc, σT slightly lowered (envelope_factors).
        mm = 0.5 * (sxx + syy)
        r2 = 0.25 * (sxx - syy) ** 2 + sxy * sxy
        ce = cohesion[e]
        if eff is not None:
            if eff == 1.0:  # "effective": C (1 − d)
                ce = ce * (1.0 - damage[e])
            elif eff == 0.5:  # "energy": C √(1 − d)
                ce = ce * math.sqrt(1.0 - damage[e])
            else:  # any other power of params.FAILURE_EXPONENT
                ce = ce * (1.0 - damage[e]) ** eff
        at = ce * kt - mm
        ac = ce * kc - (q - 1.0) * mm
        if at > 0.0 and ac > 0.0 and r2 < at * at and (q + 1.0) * (q + 1.0) * r2 < ac * ac:
            dc = 1.0
        else:
            dc = _dcrit(sxx, syy, sxy, ce, q, denom)
        towards = False
        pm = 0.0
        if theta is not None:
            if dc < 1.0:
                fm = _dcrit_towards(sxx, syy, sxy, ce, q, denom, theta)
                if fm >= 0.0:
                    dc = fm
                    pm = theta * mm
                    towards = True
        d0 = damage[e]
        d, f, capped = damage_step(d0, dc, dt_s, td[e], heal_rate[e], max_damage)
        if dc < 1.0:
            if towards:  # False whenever theta is None (the branch above is pruned)
                sxx = pm + f * (sxx - pm)
                syy = pm + f * (syy - pm)
            else:
                sxx *= f
                syy *= f
            sxy *= f
            damaged_flag[e] = 1
        n_capped += capped
        sigma[e, 0] = sxx
        sigma[e, 1] = syy
        sigma[e, 2] = sxy
        if d != d0:
            damage[e] = d
            x = (1.0 - d) * conc_factor[e]
            if _ALPHA_IS_4 or alpha == 4.0:  # _ALPHA_IS_4: a compile-time constant, True in the α = 4 builds
                lam = lambda0 * (x * x * x)
            elif alpha == 5.0:
                lam = lambda0 * (x * x) * (x * x)
            else:
                lam = lambda0 * x ** (alpha - 1.0)
            if lam_scale is not None:  # pruned when None, as pmax is
                lam *= lam_scale[e]
            e_dt[e] = dt_s * (E0 * x)
            gamma[e] = lam / (lam + dt_s)
    return n_capped


def _node_divergence(vel, ptr, elems, tri, b, c, area, divn):
    """Nodal volumetric strain rate [s-1] into ``divn`` (n,): the area-weighted mean of
    ε̇xx + ε̇yy over the elements around each node (solver.volumetric_strain = "nodal").

    Why: a constant-strain triangle whose mean stress is kept while its deviator relaxes
    (rheology.relax_mean_stress = false, crack_closure) is close to incompressible, and on a
    triangle mesh the element divergences are about as many constraints as there are free
    velocity components: on gmsh's Delaunay mesh of a closed box no non-zero velocity field
    has zero divergence in every element, so such ice can only flow by building a spurious
    pressure (volumetric locking; Nagtegaal, Parks and Rice 1974, "On numerically accurate
    finite element solutions in the fully plastic range", Comput. Methods Appl. Mech. Eng. 4).
    Averaged at the nodes there is one constraint per node, half the free components, which
    leaves room for divergence-free flow: the average nodal pressure triangle of Bonet and
    Burton (1998, "A simple average nodal pressure tetrahedral element for incompressible and
    nearly incompressible dynamic explicit applications", Commun. Numer. Meth. Eng. 14). The
    element→node→element averaging is symmetric in the area-weighted inner product, so the
    elastic energy stays a positive quadratic form and no sub-step limit grows. But it leaves
    the velocity fields whose element divergences alternate in sign, and average to zero at
    every node, with no volumetric stiffness: where broken ice's deviator relaxes in seconds
    they carry the deformation (20 km basin screens: noisy shear, β 0.59–0.84), so the option is
    a diagnostic of the locking, not a cure (docs/solvers.md, "Volumetric locking")."""
    n = ptr.shape[0] - 1
    for i in prange(n):
        s = 0.0
        a = 0.0
        for p in range(ptr[i], ptr[i + 1]):
            e = elems[p]
            exx, eyy, _ = element_strain_rate(tri, b, c, vel, e)
            s += area[e] * (exx + eyy)
            a += area[e]
        divn[i] = s / a


def _element_trial_load(tri, b, c, vel, sigma, e_dt, gamma, cohesion, damage, eff, kxx, kxy, kss, q, denom, load):
    """First pass of a sub-step with the nonlocal damage (rheology.damage_nonlocal_radius_m;
    :mod:`lagice.solvers.nonlocal_damage`): the Maxwell stress update of
    :func:`_element_stress_damage` (the default path: the whole stress relaxes, origin
    correction, no compressive term) and the element's load ratio
    L = max(0, s1/σT, (q s1 − s2)/σc) into ``load``; no damage yet. ``eff`` as in
    :func:`_element_stress_damage` (None: σT and σc of the cohesion C; a power p: of
    C (1 − d)^p, d the damage at the start of the sub-step, so L is the effective stress's
    ratio, (1 − d)^−p times the nominal one)."""
    m = tri.shape[0]
    for e in prange(m):
        exx, eyy, exy = element_strain_rate(tri, b, c, vel, e)
        ed = e_dt[e]
        g = gamma[e]
        sxx = (sigma[e, 0] + ed * (kxx * exx + kxy * eyy)) * g
        syy = (sigma[e, 1] + ed * (kxy * exx + kxx * eyy)) * g
        sxy = (sigma[e, 2] + ed * (kss * exy)) * g
        sigma[e, 0] = sxx
        sigma[e, 1] = syy
        sigma[e, 2] = sxy
        mm = 0.5 * (sxx + syy)
        r = math.sqrt(0.25 * (sxx - syy) ** 2 + sxy * sxy)
        s1 = mm + r
        s2 = mm - r
        ce = cohesion[e]
        if eff is not None:  # pruned when None (rheology.failure_stress = "nominal")
            if eff == 1.0:
                ce = ce * (1.0 - damage[e])
            elif eff == 0.5:
                ce = ce * math.sqrt(1.0 - damage[e])
            else:
                ce = ce * (1.0 - damage[e]) ** eff
        sc = 2.0 * ce / denom
        st = sc / q
        ld = 0.0
        if s1 > 0.0:
            ld = s1 / st
        mc = q * s1 - s2
        if mc > 0.0:
            ld = max(ld, mc / sc)
        load[e] = ld


@njit(cache=True, error_model="numpy")
def mark_overloaded_neighbourhoods(nl_ptr, nl_idx, load, mark):
    """mark[e] = 1 where some element within R of e has a load ratio above 1 (the
    neighbourhoods are symmetric), else 0: only there can the mean load ratio exceed 1, so
    the second pass sums the others' rows not at all. Serial (a scatter); it reads the
    loads once and writes the rows of the overloaded elements only."""
    mark[:] = 0
    for j in range(load.shape[0]):
        if load[j] > 1.0:
            for k in range(nl_ptr[j], nl_ptr[j + 1]):
                mark[nl_idx[k]] = 1


def _element_nonlocal_damage(nl_ptr, nl_idx, nl_w, load, mark, sigma, damage, conc_factor, td, heal_rate, e_dt,
                             gamma, dt_s, max_damage, E0, lambda0, alpha, damaged_flag):
    """Second pass: d̄_crit = min(1, 1/L̄) from the neighbourhood's mean load ratio
    L̄_e = Σ w_ej L_j (summed where ``mark`` says some neighbour is overloaded; elsewhere
    L̄ ≤ 1), then :func:`lagice.rheology.damage_step` and the stress factor on the element's
    own stress, as the local kernel does with its own d_crit. Returns the number of
    elements whose damage hit the cap."""
    m = damage.shape[0]
    n_capped = 0
    for e in prange(m):
        dc = 1.0
        if mark[e]:
            # four partial sums (a fixed order: the sum is the same wherever the row is read),
            # so the adds do not wait on each other: 2.5x faster than one running sum
            k0 = nl_ptr[e]
            k1 = nl_ptr[e + 1]
            a0 = a1 = a2 = a3 = 0.0
            k = k0
            while k + 4 <= k1:
                a0 += nl_w[k] * load[nl_idx[k]]
                a1 += nl_w[k + 1] * load[nl_idx[k + 1]]
                a2 += nl_w[k + 2] * load[nl_idx[k + 2]]
                a3 += nl_w[k + 3] * load[nl_idx[k + 3]]
                k += 4
            while k < k1:
                a0 += nl_w[k] * load[nl_idx[k]]
                k += 1
            lb = (a0 + a1) + (a2 + a3)
            if lb > 1.0:
                dc = 1.0 / lb
        d0 = damage[e]
        d, f, capped = damage_step(d0, dc, dt_s, td[e], heal_rate[e], max_damage)
        if dc < 1.0:
            sigma[e, 0] *= f
            sigma[e, 1] *= f
            sigma[e, 2] *= f
            damaged_flag[e] = 1
        n_capped += capped
        if d != d0:
            damage[e] = d
            x = (1.0 - d) * conc_factor[e]
            if alpha == 4.0:
                lam = lambda0 * (x * x * x)
            else:
                lam = lambda0 * x ** (alpha - 1.0)
            e_dt[e] = dt_s * (E0 * x)
            gamma[e] = lam / (lam + dt_s)
    return n_capped


def _serial(func):
    """Serial numba variant of a prange kernel (see :mod:`lagice._numba`)."""
    return serial_copy(func, error_model="numpy", fastmath=KERNEL_FASTMATH)


#: compiled variants: parallel (numba prange over own entities, no races) and serial
#: (cheaper below ~PARALLEL_MIN_ELEMENTS, and on a loaded machine where fork/join waits)
node_velocity_kernel = njit(cache=True, parallel=True, error_model="numpy", fastmath=KERNEL_FASTMATH)(_node_velocity)
node_velocity_kernel_serial = _serial(_node_velocity)
element_stress_damage_kernel = njit(cache=True, parallel=True, error_model="numpy", fastmath=KERNEL_FASTMATH)(
    _element_stress_damage)
element_stress_damage_kernel_serial = _serial(_element_stress_damage)
node_divergence_kernel = njit(cache=True, parallel=True, error_model="numpy", fastmath=KERNEL_FASTMATH)(
    _node_divergence)
node_divergence_kernel_serial = _serial(_node_divergence)
PARALLEL_MIN_ELEMENTS = PARALLEL_MIN_SIZE


@njit(cache=True, error_model="numpy")
def substeps_serial(n_sub, vel, vel_sum, sigma, ptr, elems, w, nc, cos_t, sin_t, fixed, pres0, pres1, tri, b,
                      c, damage, conc_factor, coh, kc, kt, td, heal, e_dt, gamma, pmax, keep_mean, theta, dilat,
                      eff, closure, dt_s, kxx, kxy, kss, q, denom, max_damage, E0, lambda0, alpha, flag, divn, area,
                      lam_scale):
    """All ``n_sub`` sub-steps of one outer step in compiled code (one call per outer
    step, no Python per sub-step): the node kernel then the element kernel, serial
    builds; the same calls as a Python loop over the kernels, bit-identical results."""
    n_capped = 0
    for k in range(n_sub):
        node_velocity_kernel_serial(vel, vel_sum, sigma, ptr, elems, w, nc, cos_t, sin_t, fixed, pres0, pres1,
                                    (k + 1) / n_sub)
        if divn is not None:  # solver.volumetric_strain = "nodal" (pruned when None)
            node_divergence_kernel_serial(vel, ptr, elems, tri, b, c, area, divn)
        n_capped += element_stress_damage_kernel_serial(
            tri, b, c, vel, sigma, damage, conc_factor, coh, kc, kt, td, heal, e_dt, gamma, pmax, keep_mean, theta,
            dilat, eff, closure, dt_s, kxx, kxy, kss, q, denom, max_damage, E0, lambda0, alpha, flag, divn, lam_scale)
    return n_capped


@njit(cache=True, error_model="numpy")
def substeps_parallel(n_sub, vel, vel_sum, sigma, ptr, elems, w, nc, cos_t, sin_t, fixed, pres0, pres1, tri, b,
                      c, damage, conc_factor, coh, kc, kt, td, heal, e_dt, gamma, pmax, keep_mean, theta, dilat,
                      eff, closure, dt_s, kxx, kxy, kss, q, denom, max_damage, E0, lambda0, alpha, flag, divn, area,
                      lam_scale):
    """:func:`substeps_serial` with the parallel kernel builds (one fork/join per
    kernel and sub-step, launched from compiled code)."""
    n_capped = 0
    for k in range(n_sub):
        node_velocity_kernel(vel, vel_sum, sigma, ptr, elems, w, nc, cos_t, sin_t, fixed, pres0, pres1,
                             (k + 1) / n_sub)
        if divn is not None:  # solver.volumetric_strain = "nodal" (pruned when None)
            node_divergence_kernel(vel, ptr, elems, tri, b, c, area, divn)
        n_capped += element_stress_damage_kernel(
            tri, b, c, vel, sigma, damage, conc_factor, coh, kc, kt, td, heal, e_dt, gamma, pmax, keep_mean, theta,
            dilat, eff, closure, dt_s, kxx, kxy, kss, q, denom, max_damage, E0, lambda0, alpha, flag, divn, lam_scale)
    return n_capped


SUBSTEPS = (substeps_serial, substeps_parallel)

element_trial_load_kernel = njit(cache=True, parallel=True, error_model="numpy", fastmath=KERNEL_FASTMATH)(
    _element_trial_load)
element_trial_load_kernel_serial = _serial(_element_trial_load)
element_nonlocal_damage_kernel = njit(cache=True, parallel=True, error_model="numpy", fastmath=KERNEL_FASTMATH)(
    _element_nonlocal_damage)
element_nonlocal_damage_kernel_serial = _serial(_element_nonlocal_damage)


@njit(cache=True, error_model="numpy")
def substeps_nonlocal_serial(n_sub, vel, vel_sum, sigma, ptr, elems, w, nc, cos_t, sin_t, fixed, pres0, pres1, tri,
                             b, c, damage, conc_factor, coh, eff, td, heal, e_dt, gamma, dt_s, kxx, kxy, kss, q,
                             denom, max_damage, E0, lambda0, alpha, flag, nl_ptr, nl_idx, nl_w, load, mark):
    """The sub-step loop with the nonlocal damage (:mod:`lagice.solvers.nonlocal_damage`):
    node kernel, then the two element passes (serial builds)."""
    n_capped = 0
    for k in range(n_sub):
        node_velocity_kernel_serial(vel, vel_sum, sigma, ptr, elems, w, nc, cos_t, sin_t, fixed, pres0, pres1,
                                    (k + 1) / n_sub)
        element_trial_load_kernel_serial(tri, b, c, vel, sigma, e_dt, gamma, coh, damage, eff, kxx, kxy, kss, q,
                                         denom, load)
        mark_overloaded_neighbourhoods(nl_ptr, nl_idx, load, mark)
        n_capped += element_nonlocal_damage_kernel_serial(nl_ptr, nl_idx, nl_w, load, mark, sigma, damage,
                                                          conc_factor, td, heal, e_dt, gamma, dt_s, max_damage, E0,
                                                          lambda0, alpha, flag)
    return n_capped


#: :func:`substeps_nonlocal_serial` with the parallel kernel builds (the same loop, its kernels swapped)
substeps_nonlocal_parallel = specialised_copy(
    substeps_nonlocal_serial, "_parallel",
    {"node_velocity_kernel_serial": node_velocity_kernel,
     "element_trial_load_kernel_serial": element_trial_load_kernel,
     "element_nonlocal_damage_kernel_serial": element_nonlocal_damage_kernel}, error_model="numpy")


SUBSTEPS_NONLOCAL = (substeps_nonlocal_serial, substeps_nonlocal_parallel)


@njit(cache=True, error_model="numpy")
def substeps_jump_serial(n_sub, vel, vel_sum, sigma, ptr, elems, w, nc, cos_t, sin_t, fixed, pres0, pres1, tri, b,
                         c, damage, conc_factor, coh, kc, kt, td, heal, e_dt, gamma, pmax, keep_mean, theta, dilat,
                         eff, closure, dt_s, kxx, kxy, kss, q, denom, max_damage, E0, lambda0, alpha, flag, divn,
                         area, lam_scale, j_dofs, j_coef, j_left, j_right, h, j_kfac, j_T, j_ptr, j_idx, j_c,
                         dt_over_m):
    """:func:`substeps_serial` for Crouzeix–Raviart velocities with the jump penalty
    (:class:`lagice.solvers.crouzeix_raviart.JumpPenalty`): each sub-step adds the penalty's
    impulse from the last tractions, runs the node kernel over the edges, updates the tractions
    from the new velocities and runs the element kernel."""
    n_capped = 0
    for k in range(n_sub):
        jump_impulse_kernel_serial(vel, fixed, j_ptr, j_idx, j_c, j_T, dt_over_m)
        node_velocity_kernel_serial(vel, vel_sum, sigma, ptr, elems, w, nc, cos_t, sin_t, fixed, pres0, pres1,
                                    (k + 1) / n_sub)
        jump_update_kernel_serial(vel, j_dofs, j_coef, j_left, j_right, h, e_dt, gamma, j_kfac, j_T)
        n_capped += element_stress_damage_kernel_serial(
            tri, b, c, vel, sigma, damage, conc_factor, coh, kc, kt, td, heal, e_dt, gamma, pmax, keep_mean, theta,
            dilat, eff, closure, dt_s, kxx, kxy, kss, q, denom, max_damage, E0, lambda0, alpha, flag, divn, lam_scale)
    return n_capped


#: :func:`substeps_jump_serial` with the parallel kernel builds
substeps_jump_parallel = specialised_copy(
    substeps_jump_serial, "_parallel",
    {"node_velocity_kernel_serial": node_velocity_kernel,
     "jump_impulse_kernel_serial": jump_impulse_kernel,
     "jump_update_kernel_serial": jump_update_kernel,
     "element_stress_damage_kernel_serial": element_stress_damage_kernel}, error_model="numpy")
SUBSTEPS_JUMP = (substeps_jump_serial, substeps_jump_parallel)

#: the α = 4 builds (Dansereau et al. 2016's value, the default): the element kernel with
#: λ = λ0 x³ compiled in, and sub-step loops that call it
element_stress_damage_kernel_a4 = specialised_copy(
    _element_stress_damage, "_a4", {"_ALPHA_IS_4": True}, parallel=True, error_model="numpy",
    fastmath=KERNEL_FASTMATH)
element_stress_damage_kernel_a4_serial = specialised_copy(
    _element_stress_damage, "_a4_serial", {"_ALPHA_IS_4": True}, error_model="numpy", fastmath=KERNEL_FASTMATH)
SUBSTEPS_A4 = (
    specialised_copy(substeps_serial, "_a4", {"element_stress_damage_kernel_serial":
                                              element_stress_damage_kernel_a4_serial}, error_model="numpy"),
    specialised_copy(substeps_parallel, "_a4", {"element_stress_damage_kernel": element_stress_damage_kernel_a4},
                     error_model="numpy"))


def substep_loops(alpha: float):
    """(serial, parallel) sub-step loops for the rheology's α: the α = 4 builds or the
    general ones (identical results where both apply; a test checks it)."""
    return SUBSTEPS_A4 if alpha == 4.0 else SUBSTEPS


def element_kernels(alpha: float):
    """(serial, parallel) element kernels for the rheology's α (see :func:`substep_loops`)."""
    if alpha == 4.0:
        return element_stress_damage_kernel_a4_serial, element_stress_damage_kernel_a4
    return element_stress_damage_kernel_serial, element_stress_damage_kernel


class ExplicitSolver:
    """Explicit (sub-stepped, lumped-mass) Maxwell-EB time stepper.

    Args:
        rheology: :class:`~lagice.rheology.MaxwellEB`.
        mesh: the mesh (node positions are read at each :meth:`update_geometry`).
        bcs: list of :class:`~lagice.boundary.VelocityBC`; coast nodes are no-slip.
        forces: external forces (:mod:`lagice.forces`: ``WindStress``,
            ``OceanDrag``, ``Coriolis`` or anything with ``add_explicit_terms``).
        substeps: N elastic sub-steps per outer step, or None: the smallest N with
            Δt/N ≤ ``safety`` × the measured stability limit (:mod:`lagice.stability`).
        heal_rate: callable ``(state, t_s) -> (m,) [s-1]`` or None for the rheology's
            constant rate.
        safety: fraction of the measured sub-step limit used when ``substeps`` is None.
        allow_unstable: run (with a :class:`~lagice.stability.StabilityWarning`)
            when Δt_s is beyond the measured limit instead of raising ConfigError.
        parallel: True/False, or None / ``"auto"`` (default): serial or parallel kernel
            builds and the numba thread count chosen by measurement on this mesh at
            the first step (:func:`lagice._numba.autotune`), again after
            :data:`AUTOTUNE_FIRST_INTERVAL_S` and then every :data:`AUTOTUNE_INTERVAL_S`
            of wall time; the choice is logged and kept
            in :attr:`kernel_choice`.
        volumetric_strain: ``"element"`` (default) or ``"nodal"``: the volumetric strain
            rate of each element's stress update is the mean of its nodes' area-weighted
            averages (:func:`_node_divergence`; one more node pass per sub-step), which frees
            ice whose mean stress does not relax from volumetric locking (a diagnostic: its
            spurious modes carry the deformation of broken ice in the winter basin).
        jump_penalty: κ ≥ 0 of the Crouzeix–Raviart velocities' interior-edge jump penalty
            (:class:`~lagice.solvers.crouzeix_raviart.JumpPenalty`; 0, the default: none). Its
            tractions are kept between steps like the edge velocities, and set to zero at a remesh.
        velocity_element: ``"linear"`` (default) or ``"crouzeix_raviart"``: velocities at the
            edge midpoints (:mod:`lagice.solvers.crouzeix_raviart`; the same kernels run over the
            edges, with sub-steps :data:`~lagice.solvers.crouzeix_raviart.SUBSTEP_FACTOR` times
            shorter). ``state.velocity`` holds their average at the nodes (the nodes move with
            it); the edge velocities are kept between steps and in checkpoints (a resume is bit
            for bit), and rebuilt from the node velocities after a remesh.
        profile_kernels: time the node and element kernels separately (a Python
            loop over the sub-steps, two kernel calls each) instead of running the
            whole sub-step loop in one compiled call (the default; same results).

    After a step, ``state.velocity`` is the last sub-step's velocity (the dynamic
    state, carried in checkpoints), :attr:`transport_velocity` the mean over the
    sub-steps (the velocity whose Δt-integral is the displacement the sub-steps
    integrated: nodes and drifters move with it) and :attr:`last_strain_rate` its
    strain rate.

    Connectivity is passed to the kernels as int32 copies (cached per mesh).
    Per-kernel wall times [s] are accumulated in :attr:`kernel_timings` (``substeps``:
    the whole sub-step loop; ``node_velocity``/``element_stress_damage`` only with
    ``profile_kernels``) and
    returned per step in ``StepInfo.kernel_timings``; ``StepInfo.timings`` maps
    them onto the implicit solver's keys (assembly = forcing + setup,
    solve = node_velocity, damage = element_stress_damage).
    ``StepInfo.iterations`` is the number of sub-steps.
    """

    name = "explicit"

    def __init__(self, rheology: MaxwellEB, mesh, bcs=(), forces=(), substeps: int | None = None,
                 heal_rate=None, safety: float = 0.7, allow_unstable: bool = False,
                 parallel: bool | str | None = None, profile_kernels: bool = False, substep_limit: str = "mesh",
                 volumetric_strain: str = "element", velocity_element: str = "linear", jump_penalty: float = 0.0):
        if not isinstance(rheology, MaxwellEB):
            raise ConfigError(f"the explicit stepper solves the Maxwell-EB rheology; got "
                              f"{type(rheology).__name__} (use solver 'evp' for viscous-plastic)")
        rheology.require_stepper("explicit")
        if substeps is not None:
            if int(substeps) != substeps or int(substeps) < 1:
                raise ConfigError(f"substeps = {substeps!r} must be an integer >= 1 (or None: automatic)")
            substeps = int(substeps)
        if not 0.0 < safety <= 1.0:
            raise ConfigError(f"safety = {safety!r} must be in (0, 1]")
        self.substep_limit = check_substep_limit(substep_limit)
        self.volumetric_strain = check_volumetric_strain(volumetric_strain)
        self.velocity_element = check_velocity_element(velocity_element)
        if self.velocity_element != "linear" and self.volumetric_strain != "element":
            raise ConfigError(f"solver.volumetric_strain = {volumetric_strain!r} averages linear velocities at the "
                              f"nodes; with solver.velocity_element = {velocity_element!r} use \"element\"")
        if not (isinstance(jump_penalty, (int, float)) and math.isfinite(jump_penalty) and jump_penalty >= 0.0):
            raise ConfigError(f"solver.jump_penalty = {jump_penalty!r}: expected a number >= 0 (Hansbo and Larson's "
                              f"penalty factor κ; 0: none)")
        if jump_penalty and self.velocity_element != "crouzeix_raviart":
            raise ConfigError(f"solver.jump_penalty = {jump_penalty!r} penalises the jumps of Crouzeix-Raviart "
                              f"velocities; set solver.velocity_element = \"crouzeix_raviart\" or leave it unset")
        self.jump_penalty = float(jump_penalty)
        self._jump = None  # the JumpPenalty of the current mesh (jump_penalty > 0)
        self._cr = None  # the CREdges of the current mesh (crouzeix_raviart)
        self._cr_vel = None  # (edge velocities, the node velocities written with them, jump tractions or None)
        self.rheology = rheology
        self.forces = list(forces)
        self.substeps = substeps
        self.safety = float(safety)
        self.allow_unstable = bool(allow_unstable)
        self.heal_rate = heal_rate
        self.kernel_timings = {k: 0.0 for k in KERNELS}
        self._checked = set()
        self._transport = None
        self._strain_rate = None
        self.last_substeps = None
        if isinstance(parallel, str):
            if parallel != "auto":
                raise ConfigError(f"solver.parallel = {parallel!r}; expected true, false or \"auto\"")
            parallel = None
        self.parallel_setting = parallel
        self.profile_kernels = bool(profile_kernels)
        #: the kernel build and thread count in use ({"parallel", "threads", "method", ...}),
        #: set at the first step (None before)
        self.kernel_choice = None
        self._tuned_at = 0.0
        self._idx = (None, None)
        radius = rheology.params.damage_nonlocal_radius_m
        #: the nonlocal damage's averaging weights (rheology.damage_nonlocal_radius_m), or None
        self.nonlocal_weights = NonlocalWeights(radius) if radius else None
        if self.nonlocal_weights is not None and self.volumetric_strain != "element":
            raise ConfigError(f"solver.volumetric_strain = {volumetric_strain!r} is not implemented with "
                              f"rheology.damage_nonlocal_radius_m = {radius!r}; use \"element\"")
        if self.nonlocal_weights is not None and self.velocity_element != "linear":
            raise ConfigError(f"solver.velocity_element = {velocity_element!r} is not implemented with "
                              f"rheology.damage_nonlocal_radius_m = {radius!r}; use \"linear\"")
        if self.jump_penalty and profile_kernels:
            raise ConfigError("profile_kernels times the sub-step loop without the jump penalty; it is not "
                              f"implemented with solver.jump_penalty = {jump_penalty!r}")
        if self.nonlocal_weights is not None and profile_kernels:
            raise ConfigError("profile_kernels times the local element kernel; it is not implemented with "
                              f"rheology.damage_nonlocal_radius_m = {radius!r}")
        self.nodes = NodeSystem(mesh, bcs, parallel, geometry_hook=self._geometry_extras)

    # -- geometry/topology (the node system owns the caches) ----------------------------
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
        """Rebuild everything that depends on connectivity (after a remesh)."""
        self._transport = None
        self._strain_rate = None
        self._cr = None
        self._jump = None
        self._cr_vel = "remeshed"  # the next step rebuilds the edge velocities, as expected
        self.nodes.reset_topology(mesh)

    def update_geometry(self) -> None:
        """Recompute shape gradients, areas, td after nodes moved (Lagrangian step)."""
        self.nodes.update_geometry()

    def _geometry_extras(self, ns) -> None:
        """td and the smallest element size after nodes moved."""
        area = ns.area
        dx = np.sqrt(2.0 * area)
        self.td = self.rheology.damage_time(dx)
        #: Δx/ℓ per element (rheology.crack_band_length_m), or None (off)
        self.lam_scale = self.rheology.relaxation_scale(dx)
        self.dx_min = float(np.sqrt(2.0 * area.min()))
        #: the element size the sub-step limit is applied with: dx_min ("mesh"), or with
        #: substep_limit = "element" that of the element-wise bound (lagice.stability.effective_dx),
        #: set at each step from the moduli
        self.dx_eff = self.dx_min

    # -- sub-step choice -------------------------------------------------------------
    def substeps_for(self, dt: float, E_max: float | None = None) -> int:
        """N for an outer step dt [s]: the fixed ``substeps``, or the smallest N with
        dt/N <= safety × the measured limit for ``dx_eff`` and E_max [Pa] (default E0):
        the smallest element with the stiffest modulus, or with ``substep_limit =
        "element"`` the element-wise bound (:data:`SUBSTEP_LIMITS`)."""
        if self.substeps is not None:
            return self.substeps
        from ..stability import explicit_substep_limit

        E_max = self.rheology.params.E0 if E_max is None else E_max
        lim = explicit_substep_limit(self.dx_eff, E_max, self.rheology.params) / self._substep_factor()
        return max(1, int(math.ceil(dt / (self.safety * lim) - 1e-9)))

    def _substep_factor(self) -> float:
        """How many times shorter than the measured linear limit the sub-step must be."""
        if self.velocity_element == "linear":
            return 1.0
        from .crouzeix_raviart import SUBSTEP_FACTOR

        return SUBSTEP_FACTOR

    def _check_stability(self, dt_s: float, E_max: float) -> None:
        dt_s = dt_s * self._substep_factor()  # the linear limit's equivalent
        key = (round(dt_s, 9), round(self.dx_eff, 3), round(E_max, 3))
        if key in self._checked:
            return
        from ..stability import check_explicit_substep

        check_explicit_substep(dt_s, self.dx_eff, E_max, self.rheology.params,
                               allow_unstable=self.allow_unstable)
        if len(self._checked) > 1000:
            self._checked.clear()
        self._checked.add(key)

    # -- kernels ----------------------------------------------------------------------
    def _indices(self, mesh):
        """int32 copies of the connectivity the kernels read (ptr, elems, tri), cached
        for ``mesh`` (half the index bytes of the int64 originals)."""
        if self._idx[0] is not mesh:
            ptr, elems, _ = mesh.node_elements
            if len(elems) >= 2**31:
                raise ConfigError(f"{mesh.n_elements} elements: too many for int32 connectivity")
            self._idx = (mesh, (ptr.astype(np.int32), elems.astype(np.int32), mesh.triangles.astype(np.int32)))
        return self._idx[1]

    def _choose_kernels(self, args) -> None:
        """Fix :attr:`kernel_choice` at the first step: the setting ``parallel`` if given,
        else measured on this mesh (:func:`lagice._numba.autotune`) with the step's own
        arrays (scratch copies: the state is not touched)."""
        import logging

        import numba

        m = self.mesh.n_elements
        if self.parallel_setting is not None:
            par = bool(self.parallel_setting)
            self.kernel_choice = {"parallel": par, "threads": numba.get_num_threads() if par else 1,
                                  "method": f"solver.parallel = {str(par).lower()}", "n_elements": m,
                                  "timings_ms": {}}
            how = f"parallel on {self.kernel_choice['threads']} threads" if par else "serial"
            logging.getLogger("lagice").info(f"explicit kernels: {how} for {m} elements "
                                             f"({self.kernel_choice['method']})")
        else:
            scratch = tuple(a.copy() if isinstance(a, np.ndarray) and a.flags.writeable else a for a in args)
            n_trial = int(min(20, max(2, math.ceil(AUTOTUNE_WORK / max(m, 1)))))

            loops = substep_loops(float(self.rheology.params.alpha))

            def trial(par):
                loops[int(par)](n_trial, *scratch)

            n_tunes = self.kernel_choice["n_measurements"] if self.kernel_choice else 0
            self.kernel_choice = autotune(trial, m, what="explicit kernels")
            self.kernel_choice["trial_substeps"] = n_trial
            self.kernel_choice["n_measurements"] = n_tunes + 1
        self.nodes.parallel = self.kernel_choice["parallel"]
        self._tuned_at = time.perf_counter()

    def _profiled_substeps(self, par, n_sub, args):
        """The sub-step loop in Python with each kernel timed (``profile_kernels``)."""
        (vel, vel_sum, sigma, ptr, elems, w, nc, cos_t, sin_t, fixed, pres0, pres1, tri, b, c, damage, conc_factor,
         coh, kc, kt, td, heal, e_dt, gamma, pmax, keep_mean, theta, dilat, eff, closure, dt_s, kxx, kxy, kss, q, denom,
         max_damage, E0, lambda0, alpha, flag, divn, area, lam_scale) = args
        node_k = node_velocity_kernel if par else node_velocity_kernel_serial
        elem_k = element_kernels(alpha)[int(par)]
        n_capped = 0
        tn = tm = 0.0
        for k in range(n_sub):
            ta = time.perf_counter()
            node_k(vel, vel_sum, sigma, ptr, elems, w, nc, cos_t, sin_t, fixed, pres0, pres1, (k + 1) / n_sub)
            if divn is not None:
                (node_divergence_kernel if par else node_divergence_kernel_serial)(vel, ptr, elems, tri, b, c, area,
                                                                                   divn)
            tb = time.perf_counter()
            n_capped += elem_k(tri, b, c, vel, sigma, damage, conc_factor, coh, kc, kt, td, heal, e_dt, gamma,
                               pmax, keep_mean, theta, dilat, eff, closure, dt_s, kxx, kxy, kss, q, denom,
                               max_damage, E0, lambda0, alpha, flag, divn, lam_scale)
            tc = time.perf_counter()
            tn += tb - ta
            tm += tc - tb
        return n_capped, tn, tm

    # -- Crouzeix–Raviart velocities (velocity_element = "crouzeix_raviart") -------------
    def _cr_edges(self):
        from .crouzeix_raviart import CREdges, JumpPenalty

        if self._cr is None:
            self._cr = CREdges(self.mesh, self.nodes.fixed)
            if self.jump_penalty > 0.0:
                self._jump = JumpPenalty(self._cr, self.jump_penalty, self.rheology.params.poisson)
        return self._cr

    def _cr_start_velocity(self, cr, state, t_s: float):
        """The edge velocities this step starts from, and the jump penalty's tractions (None without
        it): those of the last step, if the node velocities are still the ones written with them,
        else rebuilt from the nodes (the mean of each edge's two nodes; tractions zero): after a
        remesh, and (logged) after a resume without them or a change of the velocity outside the
        stepper."""
        kept = self._cr_vel
        n_jump = self._jump.n_inner if self._jump is not None else 0
        if isinstance(kept, tuple) and kept[1].shape == state.velocity.shape and np.array_equal(kept[1],
                                                                                                state.velocity):
            return kept[0].copy(), (None if self._jump is None else kept[2].copy())
        if t_s > 0.0 and kept != "remeshed":
            import logging

            logging.getLogger("lagice").info(f"explicit (crouzeix_raviart): edge velocities rebuilt from the node "
                                             f"velocities at t = {t_s:.0f} s (a resume, or the velocity changed "
                                             f"outside the stepper)")
        return (np.ascontiguousarray(cr.at_edges(np.asarray(state.velocity, np.float64))),
                None if self._jump is None else np.zeros((n_jump, 2)))

    def checkpoint_arrays(self) -> dict:
        """Arrays a checkpoint holds for this stepper beyond the state's fields: with
        Crouzeix–Raviart velocities, the edge velocities of the last step and the node velocities
        written with them (so that a resume continues bit for bit); none otherwise."""
        if self.velocity_element == "linear" or not isinstance(self._cr_vel, tuple):
            return {}
        out = {"cr_edge_velocity": self._cr_vel[0], "cr_node_velocity": self._cr_vel[1]}
        if self._cr_vel[2] is not None:
            out["cr_jump_traction"] = self._cr_vel[2]
        return out

    def restore_arrays(self, arrays: dict) -> None:
        """Take back what :meth:`checkpoint_arrays` wrote (after :meth:`reset_topology`)."""
        if not arrays:
            return
        if self.velocity_element == "linear":
            raise ConfigError(f"the checkpoint holds Crouzeix-Raviart edge velocities ({sorted(arrays)}) but "
                              f"solver.velocity_element = \"linear\"")
        e, nv = arrays["cr_edge_velocity"], arrays["cr_node_velocity"]
        if e.shape != (self._cr_edges().n_edges, 2):
            raise ConfigError(f"checkpoint array stepper.cr_edge_velocity has shape {e.shape}; the mesh has "
                              f"{self._cr_edges().n_edges} edges")
        jt = arrays.get("cr_jump_traction")
        if (jt is None) != (self.jump_penalty == 0.0):
            raise ConfigError(f"the checkpoint {'lacks' if jt is None else 'holds'} the jump penalty's tractions "
                              f"(stepper.cr_jump_traction) but solver.jump_penalty = {self.jump_penalty!r}")
        self._cr_vel = (np.array(e, np.float64), np.array(nv, np.float64),
                        None if jt is None else np.array(jt, np.float64))

    @staticmethod
    def _cr_nodes(cr, edge_vel, pres_nodes, ns) -> np.ndarray:
        out = cr.at_nodes(edge_vel, ns.mesh.triangles, ns.area, ns.mesh.n_nodes)
        fx = ns.fixed.astype(bool)
        out[fx] = pres_nodes[fx]
        return out

    # -- one step -----------------------------------------------------------------
    def step(self, state: IceState, t_s: float, dt: float) -> StepInfo:
        if not dt > 0:
            raise ConfigError(f"dt = {dt!r} s must be > 0")
        kt = {k: 0.0 for k in KERNELS}
        ns = self.nodes
        mesh, p = ns.mesh, self.rheology.params
        t0 = time.perf_counter()
        # g = exp(−c*(1−A)) once: the moduli and the element kernel share it
        conc_factor = self.rheology.concentration_factor(state.concentration)
        E, lam = self.rheology.moduli(state.damage, state.concentration, conc_factor)
        if self.lam_scale is not None:  # rheology.crack_band_length_m: λ Δx/ℓ
            lam = lam * self.lam_scale
        E_stab = stability_modulus(p, E, state.concentration)
        E_max = float(E_stab.max()) if len(E) else p.E0
        self.dx_eff = (effective_dx(self.dx_min, E_max, float((E_stab / ns.area).max()))
                       if len(E) and self.substep_limit == "element" else self.dx_min)
        n_sub = self.substeps_for(dt, E_max)
        dt_s = dt / n_sub
        self._check_stability(dt_s, E_max)
        t_new = t_s + dt
        pres0 = ns.prescribed_velocity(t_s)
        pres1 = ns.prescribed_velocity(t_new)
        cr = self._cr_edges() if self.velocity_element == "crouzeix_raviart" else None
        if cr is None:
            terms = explicit_terms(self.forces, t_new, mesh.nodes)
            ptr, elems, local = mesh.node_elements
            gb, gc, fixed = ns.b, ns.c, ns.fixed
        else:  # the same kernels over the edges (lagice.solvers.crouzeix_raviart): forcing at the midpoints
            terms = explicit_terms(self.forces, t_new, cr.midpoints(mesh.nodes))
            pres0n, pres1n = pres0, pres1
            pres0, pres1 = cr.at_edges(pres0n), cr.at_edges(pres1n)
            ptr, elems, local = cr.ptr, cr.elems, cr.local
            gb, gc, fixed = -2.0 * ns.b, -2.0 * ns.c, cr.fixed  # ∇ψ_k = −2 ∇φ_k
        t1 = time.perf_counter()
        kt["forcing"] = t1 - t0

        tri = mesh.triangles
        par = ns.parallel_for(mesh)
        # NodeSystem.setup and the per-node constants in one pass, bit for bit (_node_setup)
        w_adj, nc, _mass = NODE_SETUP[int(par)](ptr, elems, local, ns.area,
                                                np.ascontiguousarray(state.thickness, np.float64), gb, gc,
                                                float(p.rho_ice), dt_s, terms.tau, terms.drag_coef, terms.coriolis,
                                                terms.current)
        e_dt = dt_s * E
        gamma = lam / (lam + dt_s)
        rh = self.rheology
        pmax = rh.max_pressure(state.thickness, state.concentration)  # None: off
        pmax = None if pmax is None else np.ascontiguousarray(pmax, np.float64)
        # None: the whole stress relaxes; inf: the mean is kept; r: the mean relaxes with λ_m = r λ
        keep_mean = (math.inf if not p.relax_mean_stress else None if p.bulk_shear_viscosity_ratio is None
                     else mean_relaxation_ratio(p))
        theta = None if p.stress_correction == "origin" else float(p.mean_fraction)
        dilat = p.dilatancy_factor  # None: off
        eff = FAILURE_EXPONENT[p.failure_stress]
        closure = True if p.crack_closure else None
        heal = (self.heal_rate(state, t_s) if self.heal_rate is not None
                else self.rheology.constant_heal_rate(mesh.n_elements))
        heal = np.ascontiguousarray(heal, np.float64)
        nu = p.poisson
        kxx, kxy, kss = 1.0 / (1.0 - nu * nu), nu / (1.0 - nu * nu), (1.0 - nu) / (1.0 - nu * nu)
        if cr is None:
            vel = np.ascontiguousarray(state.velocity, np.float64).copy()
        else:
            vel, jump_T = self._cr_start_velocity(cr, state, t_s)
        sigma = np.array(state.stress, np.float64, order="C")  # copies: the state is left
        damage = np.array(state.damage, np.float64)  # untouched if the step fails
        coh = np.ascontiguousarray(state.cohesion, np.float64)
        k_c, k_t = envelope_factors(rh)
        flag = np.zeros(mesh.n_elements, np.int8)
        vel_sum = np.zeros_like(vel)
        t2 = time.perf_counter()
        kt["setup"] = t2 - t1

        ptr32, elems32, tri32 = self._indices(mesh) if cr is None else (cr.ptr, cr.elems, cr.elem_edges)
        args = (vel, vel_sum, sigma, ptr32, elems32, w_adj, nc, terms.cos_turn, terms.sin_turn, fixed, pres0,
                pres1, tri32, gb, gc, damage, conc_factor, coh, k_c, k_t, self.td, heal, e_dt, gamma, pmax,
                keep_mean, theta, dilat, eff, closure, dt_s, kxx, kxy, kss, rh.q, rh._denom, p.max_damage, p.E0,
                p.relaxation_time_s, float(p.alpha), flag,
                np.empty(mesh.n_nodes, np.float64) if self.volumetric_strain == "nodal" else None, ns.area,
                self.lam_scale)
        if self.kernel_choice is None or (
                self.parallel_setting is None
                and time.perf_counter() - self._tuned_at > (
                    AUTOTUNE_FIRST_INTERVAL_S if self.kernel_choice.get("n_measurements", 0) == 1
                    else AUTOTUNE_INTERVAL_S)):
            self._choose_kernels(args)
            par = ns.parallel
        ta = time.perf_counter()
        if self.nonlocal_weights is not None:
            nl_ptr, nl_idx, nl_w = self.nonlocal_weights.update(tri, mesh.nodes, ns.area)
            n_capped = SUBSTEPS_NONLOCAL[int(par)](
                n_sub, vel, vel_sum, sigma, ptr32, elems32, w_adj, nc, terms.cos_turn, terms.sin_turn, ns.fixed,
                pres0, pres1, tri32, ns.b, ns.c, damage, conc_factor, coh, eff, self.td, heal, e_dt, gamma, dt_s, kxx,
                kxy, kss, rh.q, rh._denom, p.max_damage, p.E0, p.relaxation_time_s, float(p.alpha), flag, nl_ptr,
                nl_idx, nl_w, np.empty(mesh.n_elements, np.float64), np.empty(mesh.n_elements, np.int8))
        elif cr is not None and self._jump is not None:
            jp = self._jump
            jp.update_geometry(mesh.nodes, ns.b, ns.c)
            n_capped = SUBSTEPS_JUMP[int(par)](
                n_sub, *args, jp.dofs, jp.coef, jp.left, jp.right, np.ascontiguousarray(state.thickness, np.float64),
                jp.kfac, jump_T, jp.ptr, jp.idx, jp.c, 1.0 / nc[:, 0])
        elif self.profile_kernels:
            n_capped, tn, tm = self._profiled_substeps(par, n_sub, args)
            kt["node_velocity"] = tn
            kt["element_stress_damage"] = tm
        else:
            n_capped = substep_loops(float(p.alpha))[int(par)](n_sub, *args)
        kt["substeps"] = time.perf_counter() - ta
        state.stress = sigma
        state.damage = damage
        if cr is None:
            state.velocity = vel
            self._transport = vel_sum / n_sub
            self._strain_rate = STRAIN_RATE[int(par)](tri, ns.b, ns.c, self._transport)
        else:
            mean_e = vel_sum / n_sub
            self._strain_rate = STRAIN_RATE[int(par)](cr.elem_edges, gb, gc, mean_e)
            # the nodes: the mean of their elements' linear fields; prescribed components as the
            # linear stepper has them (the last sub-step's value, and the mean over the sub-steps)
            w_mean = (n_sub + 1) / (2.0 * n_sub)
            node_vel = self._cr_nodes(cr, vel, pres1n, ns)
            self._transport = self._cr_nodes(cr, mean_e, pres0n + w_mean * (pres1n - pres0n), ns)
            state.velocity = node_vel
            self._cr_vel = (vel, node_vel.copy(), jump_T)
        self.last_substeps = n_sub
        rh.n_capped_total += int(n_capped)
        for k, v in kt.items():
            self.kernel_timings[k] += v
        info = StepInfo(iterations=n_sub, residual=0.0, n_damaged=int(flag.sum()), n_capped=int(n_capped))
        info.timings = {"assembly": kt["forcing"] + kt["setup"],
                        "solve": kt["node_velocity"] if self.profile_kernels else kt["substeps"],
                        "damage": kt["element_stress_damage"]}
        info.kernel_timings = kt
        return info
