"""numba.cuda kernels of the GPU explicit Maxwell-EB stepper (issue 15; see
:mod:`lagice.solvers.cuda_explicit` and ``docs/gpu.md``).

Same arithmetic as the CPU kernels, operation for operation:

* :func:`lagice.fem.solve_node_2x2` and
  :func:`lagice.rheology._principal` are the CPU solver's own numba functions:
  numba compiles a CPU ``@njit`` function called from a CUDA kernel for the
  CUDA target, so there is one source;
* the array helpers are compiled from the CPU helpers' Python source
  (``element_strain_rate.py_func``, ``forcing.records._bilinear.py_func``);
* ``rheology._dcrit`` and ``rheology.damage_step`` are repeated here
  (:func:`dcrit_dev`, :func:`damage_step_dev`) because they call the builtin
  ``min``, which numba 0.68's CUDA target cannot compile; so are the bodies of
  the node and element sub-step updates, lumped mass, adjacency weights,
  moduli, shape gradients and bilinear weights: the CPU expressions in the
  same order (``tests/test_cuda_explicit.py`` checks the results against the
  CPU solver in numba's CUDA simulator; ``tests/test_cuda_explicit.py`` also
  compiles every kernel to PTX where NVVM is installed).

Every kernel is a grid-stride loop over its own entities (nodes, elements,
grid points), so any launch size is correct; nothing scatters except the
counters (atomics, once per thread). Importing this module compiles nothing
and needs no GPU (numba compiles a kernel at its first launch).

Counters (int64) and scalars (float64) are small device arrays read once or
twice per outer step; their slots are the ``C_*`` and ``S_*`` constants.
"""
from __future__ import annotations

import math

from numba import cuda

from forcing.records import _bilinear

from ..fem import element_strain_rate, solve_node_2x2
from ..rheology.maxwell_eb import _dcrit_towards, _principal, closed_crack_mean

# counter slots (int64): C_NONFINITE counts nodes with a non-finite velocity,
# C_NONFINITE_ELEM elements with a non-finite stress or damage (end of the step)
C_CAPPED, C_DAMAGED, C_NONFINITE, C_INVERTED = 0, 1, 2, 3
C_WIND_OUT, C_WIND_BAD, C_OCEAN_OUT, C_OCEAN_BAD = 4, 5, 6, 7
C_NONFINITE_ELEM = 8
N_COUNTERS = 9
# scalar slots (float64): S_SPEED2_MAX = largest u² + v² [m2 s-2] of the finite
# end-of-step velocities (the NaN checker's speed bound, checked on the device)
# S_STIFF_MAX = max over elements of E/area [Pa m-2] (the element-wise stability bound,
# lagice.stability.effective_dx)
S_E_MAX, S_AREA_MIN, S_SPEED2_MAX, S_STIFF_MAX = 0, 1, 2, 3
N_SCALARS = 4

strain_rate_dev = cuda.jit(device=True)(element_strain_rate.py_func)
bilinear_dev = cuda.jit(device=True)(_bilinear.py_func)


# ----------------------------------------------------------------------------
# min/max and the two rheology helpers that use them. numba 0.68's built-in
# CUDA target cannot compile the builtin min()/max() (their generic overload
# takes *args: "Signature mismatch: 2 argument types given, but function takes
# 1 arguments" when compiled to PTX), so rheology._dcrit and
# rheology.damage_step are repeated here with min2 (numba's and Python's
# min(a, b): b if b < a else a). Everything else is the CPU code.
# ----------------------------------------------------------------------------
@cuda.jit(device=True)
def min2(a, b):
    """``min(a, b)`` as numba and Python compute it: ``b if b < a else a``."""
    return b if b < a else a  # noqa: FURB136 - builtin min does not compile for CUDA (numba 0.68)


@cuda.jit(device=True)
def max2(a, b):
    """``max(a, b)`` as numba and Python compute it: ``b if b > a else a``."""
    return b if b > a else a  # noqa: FURB136 - builtin max does not compile for CUDA (numba 0.68)


@cuda.jit(device=True)
def dcrit_dev(sxx, syy, sxy, cohesion, q, denom):
    """:func:`lagice.rheology._dcrit` (same expressions, ``min`` → :func:`min2`)."""
    s1, s2 = _principal(sxx, syy, sxy)
    sigma_c = 2.0 * cohesion / denom
    sigma_t = sigma_c / q
    dc = 1.0
    if s1 > 0.0:
        dc = min2(dc, sigma_t / s1)
    mc = q * s1 - s2
    if mc > 0.0:
        dc = min2(dc, sigma_c / mc)
    return dc


@cuda.jit(device=True)
def damage_step_dev(d, dc, dt, td, heal_rate, max_damage):
    """:func:`lagice.rheology.damage_step` (same expressions, ``min`` → :func:`min2`)."""
    f = 1.0
    if dc < 1.0:
        r = min2(1.0, dt / td) * (1.0 - dc)
        d = 1.0 - (1.0 - d) * (1.0 - r)
        f = 1.0 - r
    if heal_rate >= 0.0:  # damage form (sign convention of rheology.damage_step)
        d -= dt * heal_rate
    elif d < 1.0:  # compliance form: 1/(1 − d) ← 1/(1 − d) − dt·|H|
        chi = 1.0 / (1.0 - d) + dt * heal_rate
        d = 1.0 - 1.0 / chi if chi > 1.0 else 0.0
    if d < 0.0:  # noqa: PLR1730 - no builtin max on CUDA (numba 0.68)
        d = 0.0
    capped = 0
    if d > max_damage:
        d = max_damage
        capped = 1
    return d, f, capped


# ----------------------------------------------------------------------------
# per-entity device functions (the sub-step arithmetic)
# ----------------------------------------------------------------------------
@cuda.jit(device=True)
def node_update(i, vel, vel_sum, sigma, ptr, elems, wb, wc, m_dt, fext, cda, current, cos_t, sin_t,
                half_mf, fixed, pres0, pres1, w_time):
    """One node of :func:`lagice.solvers.explicit._node_velocity`: the same expressions, with
    the weights and per-node constants in separate arrays and the general 2×2 solve
    (:func:`lagice.fem.solve_node_2x2`; the CPU kernel's rotation form gives the same numbers)."""
    fx0 = fixed[i, 0]
    fx1 = fixed[i, 1]
    if fx0 and fx1:
        vel[i, 0] = pres0[i, 0] + w_time * (pres1[i, 0] - pres0[i, 0])
        vel[i, 1] = pres0[i, 1] + w_time * (pres1[i, 1] - pres0[i, 1])
        vel_sum[i, 0] += vel[i, 0]
        vel_sum[i, 1] += vel[i, 1]
        return
    fx = 0.0
    fy = 0.0
    for p in range(ptr[i], ptr[i + 1]):
        e = elems[p]
        sxx = sigma[e, 0]
        syy = sigma[e, 1]
        sxy = sigma[e, 2]
        fx -= wb[p] * sxx + wc[p] * sxy
        fy -= wb[p] * sxy + wc[p] * syy
    u = vel[i, 0]
    v = vel[i, 1]
    md = m_dt[i]
    uwx = current[i, 0]
    uwy = current[i, 1]
    ru = uwx - u
    rv = uwy - v
    cd = cda[i] * math.sqrt(ru * ru + rv * rv)
    hf = half_mf[i]
    a11 = md + cd * cos_t
    a12 = -cd * sin_t - hf
    a21 = cd * sin_t + hf
    a22 = md + cd * cos_t
    rx = md * u + fx + fext[i, 0] + cd * (cos_t * uwx - sin_t * uwy) + hf * v
    ry = md * v + fy + fext[i, 1] + cd * (sin_t * uwx + cos_t * uwy) - hf * u
    pu = pres0[i, 0] + w_time * (pres1[i, 0] - pres0[i, 0]) if fx0 else 0.0
    pv = pres0[i, 1] + w_time * (pres1[i, 1] - pres0[i, 1]) if fx1 else 0.0
    un, vn = solve_node_2x2(a11, a12, a21, a22, rx, ry, fx0, fx1, pu, pv)
    vel[i, 0] = un
    vel[i, 1] = vn
    vel_sum[i, 0] += un
    vel_sum[i, 1] += vn


#: False in the kernels of this module, which the default launch uses: numba freezes a module
#: global when it compiles, so the optional terms' code (``element_update``'s ``keep_mean``,
#: ``theta``, ``dilat``) is removed from them, and their PTX is the one compiled before those
#: terms existed (``tests/cuda_ptx_check.py``; docs/gpu.md). True in the copies of
#: :func:`optional_kernels`, which a run with any of the terms launches.
_OPTIONAL_TERMS = False


@cuda.jit(device=True)
def element_update(e, tri, b, c, vel, sigma, damage, conc_factor, cohesion, sigma_c, sigma_t, td,
                   heal_rate, e_dt, gamma, pmax, use_pmax, keep_mean, theta, dilat, dt_s, kxx, kxy, kss, q, denom,
                   max_damage, E0, lambda0, alpha, damaged_flag):
    """One element of :func:`lagice.solvers.explicit._element_stress_damage`
    (same expressions; ``use_pmax`` = 1: neXtSIM's compressive term with ``pmax``);
    returns 1 when the damage cap acted. The envelope test reads σc, σT per element (the
    CPU kernel scales the cohesion since 2026-11-26; both only shortcut ``_dcrit``, which
    decides, so the results are the same).

    ``keep_mean`` (int, bit flags: 1 the relaxation keeps the mean stress, 2 the envelope judges
    the effective stress σ/(1 − d) (``failure_stress = "effective"``), 4 closed cracks build the
    mean stress with the undamaged modulus (``crack_closure``, with bit 1)), ``theta`` (θ of the
    return towards θ m I; 0: the origin path) and ``dilat`` (k_ψ of the dilatant viscous flow;
    0: off) are the CPU kernel's optional terms (its None is 0 here: numba's CUDA launch cannot
    pass None; ``keep_mean``, ``eff`` and ``closure`` share one integer, so the default kernels'
    signature and PTX stay those from before the last two existed), with its expressions in its
    order. Their code is compiled only into the copies of
    :func:`optional_kernels` (:data:`_OPTIONAL_TERMS`); the default launch ignores them."""
    exx, eyy, exy = strain_rate_dev(tri, b, c, vel, e)
    ed = e_dt[e]
    g = gamma[e]
    gp = g
    if use_pmax:
        sn = -0.5 * (sigma[e, 0] + sigma[e, 1])
        if sn > 0.0:
            pt = min2(1.0, pmax[e] / sn)
            gp = g / (g + (1.0 - g) * (1.0 - pt))
    if not (_OPTIONAL_TERMS and (keep_mean & 1) != 0):
        sxx = (sigma[e, 0] + ed * (kxx * exx + kxy * eyy)) * gp
        syy = (sigma[e, 1] + ed * (kxy * exx + kxx * eyy)) * gp
        sxy = (sigma[e, 2] + ed * (kss * exy)) * gp
        if _OPTIONAL_TERMS and dilat != 0.0:  # only without pmax (MaxwellEBParams refuses both), so gp == g here
            pd = (1.0 - g) * dilat * math.sqrt(0.25 * (sxx - syy) ** 2 + sxy * sxy)
            sxx -= pd
            syy -= pd
    else:
        axx = sigma[e, 0] + ed * (kxx * exx + kxy * eyy)
        ayy = sigma[e, 1] + ed * (kxy * exx + kxx * eyy)
        am = 0.5 * (axx + ayy)
        if _OPTIONAL_TERMS and (keep_mean & 4) != 0:
            # closed cracks: the CPU kernel's ``closure``, the same device function
            mc = closed_crack_mean(0.5 * (sigma[e, 0] + sigma[e, 1]), am, ed, dt_s * E0 * conc_factor[e])
            axx += mc - am
            ayy += mc - am
            am = mc
        gm = gp if use_pmax else 1.0
        sxx = (axx - am) * g + am * gm
        syy = (ayy - am) * g + am * gm
        sxy = (sigma[e, 2] + ed * (kss * exy)) * g
    mm = 0.5 * (sxx + syy)
    rr = math.sqrt(0.25 * (sxx - syy) ** 2 + sxy * sxy)
    s1 = mm + rr
    if _OPTIONAL_TERMS and (keep_mean & 2) != 0:  # the effective stress: C (1 − d), d at the sub-step's start
        fe = 1.0 - damage[e]
        if s1 < sigma_t[e] * fe and q * s1 - (mm - rr) < sigma_c[e] * fe:
            dc = 1.0
        else:
            dc = dcrit_dev(sxx, syy, sxy, cohesion[e] * fe, q, denom)
    elif s1 < sigma_t[e] and q * s1 - (mm - rr) < sigma_c[e]:
        dc = 1.0
    else:
        dc = dcrit_dev(sxx, syy, sxy, cohesion[e], q, denom)
    towards = False
    pm = 0.0
    if _OPTIONAL_TERMS and theta > 0.0:
        if dc < 1.0:
            ce = cohesion[e] * (1.0 - damage[e]) if (keep_mean & 2) != 0 else cohesion[e]
            fm = _dcrit_towards(sxx, syy, sxy, ce, q, denom, theta)
            if fm >= 0.0:
                dc = fm
                pm = theta * mm
                towards = True
    d0 = damage[e]
    d, f, capped = damage_step_dev(d0, dc, dt_s, td[e], heal_rate[e], max_damage)
    if dc < 1.0:
        if towards:  # False without the optional terms or with theta = 0
            sxx = pm + f * (sxx - pm)
            syy = pm + f * (syy - pm)
        else:
            sxx *= f
            syy *= f
        sxy *= f
        damaged_flag[e] = 1
    sigma[e, 0] = sxx
    sigma[e, 1] = syy
    sigma[e, 2] = sxy
    if d != d0:
        damage[e] = d
        x = (1.0 - d) * conc_factor[e]
        if alpha == 4.0:
            lam = lambda0 * (x * x * x)
        elif alpha == 5.0:
            lam = lambda0 * (x * x) * (x * x)
        else:
            lam = lambda0 * x ** (alpha - 1.0)
        e_dt[e] = dt_s * (E0 * x)
        gamma[e] = lam / (lam + dt_s)
    return capped


@cuda.jit(device=True)
def finish_node(i, vel, vel_sum, n_sub, mean_vel):
    """Mean velocity over the sub-steps (``vel_sum / n_sub``); returns (1, 0) when the
    last sub-step's velocity is not finite, else (0, u² + v²)."""
    mean_vel[i, 0] = vel_sum[i, 0] / n_sub
    mean_vel[i, 1] = vel_sum[i, 1] / n_sub
    u = vel[i, 0]
    v = vel[i, 1]
    if math.isnan(u) or math.isinf(u) or math.isnan(v) or math.isinf(v):
        return 1, 0.0
    return 0, u * u + v * v


@cuda.jit(device=True)
def finish_element(e, tri, b, c, mean_vel, strain, damaged_flag, sigma, damage):
    """Strain rate of the mean velocity; returns the element's damaged flag and 1
    when its stress or damage is not finite (else 0)."""
    exx, eyy, exy = strain_rate_dev(tri, b, c, mean_vel, e)
    strain[e, 0] = exx
    strain[e, 1] = eyy
    strain[e, 2] = exy
    bad = 0
    for k in range(3):
        if math.isnan(sigma[e, k]) or math.isinf(sigma[e, k]):
            bad = 1
    if math.isnan(damage[e]) or math.isinf(damage[e]):
        bad = 1
    return damaged_flag[e], bad


# ----------------------------------------------------------------------------
# sub-step loop: one cooperative launch per outer step ...
# ----------------------------------------------------------------------------
@cuda.jit
def substeps_cooperative(n_sub, dt_s, vel, vel_sum, sigma, ptr, elems, wb, wc, m_dt, fext, cda, current,
                         cos_t, sin_t, half_mf, fixed, pres0, pres1, tri, b, c, damage, conc_factor,
                         cohesion, sigma_c, sigma_t, td, heal_rate, e_dt, gamma, pmax, use_pmax, keep_mean, theta,
                         dilat, kxx, kxy, kss, q, denom, max_damage, E0, lambda0, alpha, damaged_flag, mean_vel,
                         strain, counters, scalars):
    """All ``n_sub`` sub-steps, then the mean velocity and its strain rate, in one
    launch: the node and element phases are separated by a grid-wide barrier
    (cooperative groups), so the grid must be co-resident (launch with at most
    ``max_cooperative_grid_blocks`` blocks)."""
    grid = cuda.cg.this_grid()
    start = cuda.grid(1)
    stride = cuda.gridsize(1)
    n = ptr.shape[0] - 1
    m = tri.shape[0]
    capped = 0
    for k in range(n_sub):
        w_time = (k + 1) / n_sub
        for i in range(start, n, stride):
            node_update(i, vel, vel_sum, sigma, ptr, elems, wb, wc, m_dt, fext, cda, current, cos_t, sin_t,
                        half_mf, fixed, pres0, pres1, w_time)
        grid.sync()
        for e in range(start, m, stride):
            capped += element_update(e, tri, b, c, vel, sigma, damage, conc_factor, cohesion, sigma_c,
                                     sigma_t, td, heal_rate, e_dt, gamma, pmax, use_pmax, keep_mean, theta,
                                     dilat, dt_s, kxx, kxy, kss, q, denom, max_damage, E0, lambda0, alpha,
                                     damaged_flag)
        grid.sync()
    bad = 0
    s2max = 0.0
    for i in range(start, n, stride):
        nb, s2 = finish_node(i, vel, vel_sum, n_sub, mean_vel)
        bad += nb
        s2max = max2(s2max, s2)
    grid.sync()
    ndam = 0
    bad_e = 0
    for e in range(start, m, stride):
        fl, nb = finish_element(e, tri, b, c, mean_vel, strain, damaged_flag, sigma, damage)
        ndam += fl
        bad_e += nb
    if capped:
        cuda.atomic.add(counters, C_CAPPED, capped)
    if bad:
        cuda.atomic.add(counters, C_NONFINITE, bad)
    if bad_e:
        cuda.atomic.add(counters, C_NONFINITE_ELEM, bad_e)
    if ndam:
        cuda.atomic.add(counters, C_DAMAGED, ndam)
    if s2max > 0.0:
        cuda.atomic.max(scalars, S_SPEED2_MAX, s2max)


_CAPPED = {}
_OPTIONAL = {}


def _copy(kernel, constants: dict, suffix: str, **jit_kw):
    """``kernel``'s Python function compiled again with the module globals in ``constants``
    replaced (frozen at compile time, as :func:`lagice._numba.specialised_copy` does on the CPU)."""
    import types

    py = kernel.py_func
    f = types.FunctionType(py.__code__, {**py.__globals__, **constants}, py.__name__ + suffix, py.__defaults__,
                           py.__closure__)
    f.__qualname__ = py.__qualname__ + suffix
    f.__doc__ = py.__doc__
    return cuda.jit(**jit_kw)(f)


def optional_kernels() -> dict:
    """The sub-step kernels compiled with the optional rheology terms (:data:`_OPTIONAL_TERMS`
    True): ``"substeps_cooperative"`` and ``"element_substep_kernel"``, made once."""
    if not _OPTIONAL:
        upd = _copy(element_update, {"_OPTIONAL_TERMS": True}, "_optional", device=True)
        _OPTIONAL["element_update"] = upd
        for k in (substeps_cooperative, element_substep_kernel):
            _OPTIONAL[k.py_func.__name__] = _copy(k, {"element_update": upd}, "_optional")
    return _OPTIONAL


def cooperative_kernel(max_registers=None, optional: bool = False):
    """:func:`substeps_cooperative` (``optional``: its copy with the optional rheology terms,
    :func:`optional_kernels`), or the same function compiled with a register cap per thread
    (``cuda.jit(max_registers=...)``; one dispatcher per cap, made once). The cap changes
    register allocation only, not what is computed; numba's CUDA simulator has no registers
    (and no such option), so there the kernel is uncapped."""
    from numba import config

    base = optional_kernels()["substeps_cooperative"] if optional else substeps_cooperative
    if max_registers is None or config.ENABLE_CUDASIM:
        return base
    key = (int(max_registers), optional)
    if key not in _CAPPED:
        _CAPPED[key] = cuda.jit(max_registers=int(max_registers))(base.py_func)
    return _CAPPED[key]


# ----------------------------------------------------------------------------
# ... or two launches per sub-step (fallback) plus two to finish
# ----------------------------------------------------------------------------
@cuda.jit
def node_substep_kernel(w_time, vel, vel_sum, sigma, ptr, elems, wb, wc, m_dt, fext, cda, current,
                        cos_t, sin_t, half_mf, fixed, pres0, pres1):
    n = ptr.shape[0] - 1
    for i in range(cuda.grid(1), n, cuda.gridsize(1)):
        node_update(i, vel, vel_sum, sigma, ptr, elems, wb, wc, m_dt, fext, cda, current, cos_t, sin_t,
                    half_mf, fixed, pres0, pres1, w_time)


@cuda.jit
def element_substep_kernel(dt_s, tri, b, c, vel, sigma, damage, conc_factor, cohesion, sigma_c, sigma_t,
                           td, heal_rate, e_dt, gamma, pmax, use_pmax, keep_mean, theta, dilat, kxx, kxy, kss, q,
                           denom, max_damage, E0, lambda0, alpha, damaged_flag, counters):
    capped = 0
    for e in range(cuda.grid(1), tri.shape[0], cuda.gridsize(1)):
        capped += element_update(e, tri, b, c, vel, sigma, damage, conc_factor, cohesion, sigma_c, sigma_t,
                                 td, heal_rate, e_dt, gamma, pmax, use_pmax, keep_mean, theta, dilat, dt_s, kxx,
                                 kxy, kss, q, denom, max_damage, E0, lambda0, alpha, damaged_flag)
    if capped:
        cuda.atomic.add(counters, C_CAPPED, capped)


@cuda.jit
def finish_nodes_kernel(n_sub, vel, vel_sum, mean_vel, counters, scalars):
    bad = 0
    s2max = 0.0
    for i in range(cuda.grid(1), vel.shape[0], cuda.gridsize(1)):
        nb, s2 = finish_node(i, vel, vel_sum, n_sub, mean_vel)
        bad += nb
        s2max = max2(s2max, s2)
    if bad:
        cuda.atomic.add(counters, C_NONFINITE, bad)
    if s2max > 0.0:
        cuda.atomic.max(scalars, S_SPEED2_MAX, s2max)


@cuda.jit
def finish_elements_kernel(tri, b, c, mean_vel, strain, damaged_flag, sigma, damage, counters):
    ndam = 0
    bad_e = 0
    for e in range(cuda.grid(1), tri.shape[0], cuda.gridsize(1)):
        fl, nb = finish_element(e, tri, b, c, mean_vel, strain, damaged_flag, sigma, damage)
        ndam += fl
        bad_e += nb
    if ndam:
        cuda.atomic.add(counters, C_DAMAGED, ndam)
    if bad_e:
        cuda.atomic.add(counters, C_NONFINITE_ELEM, bad_e)


# ----------------------------------------------------------------------------
# per-geometry and per-outer-step setup
# ----------------------------------------------------------------------------
@cuda.jit
def geometry_kernel(nodes, tri, b, c, area, td, shear_wave_speed, scalars, counters):
    """P1 gradients and areas (:func:`lagice.fem.shape_gradients`), damage time
    td = sqrt(2 area)/cs (``MaxwellEB.damage_time``); smallest area and the count
    of non-positive areas into ``scalars``/``counters``."""
    amin = math.inf
    bad = 0
    for e in range(cuda.grid(1), tri.shape[0], cuda.gridsize(1)):
        i = tri[e, 0]
        j = tri[e, 1]
        k = tri[e, 2]
        x0 = nodes[i, 0]
        y0 = nodes[i, 1]
        x1 = nodes[j, 0]
        y1 = nodes[j, 1]
        x2 = nodes[k, 0]
        y2 = nodes[k, 1]
        a2 = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
        ar = 0.5 * a2
        area[e] = ar
        inv = 1.0 / a2
        b[e, 0] = (y1 - y2) * inv
        b[e, 1] = (y2 - y0) * inv
        b[e, 2] = (y0 - y1) * inv
        c[e, 0] = (x2 - x1) * inv
        c[e, 1] = (x0 - x2) * inv
        c[e, 2] = (x1 - x0) * inv
        td[e] = math.sqrt(2.0 * ar) / shear_wave_speed
        if ar <= 0.0:
            bad += 1
        amin = min2(amin, ar)
    cuda.atomic.min(scalars, S_AREA_MIN, amin)
    if bad:
        cuda.atomic.add(counters, C_INVERTED, bad)


@cuda.jit
def max_pressure_kernel(h, conc_factor, p_star, exponent, pmax):
    """P_max = P* h^k exp(−c*(1−A)) per element (``MaxwellEB.max_pressure``; h < 0 as 0)."""
    for e in range(cuda.grid(1), h.shape[0], cuda.gridsize(1)):
        pmax[e] = p_star * max2(h[e], 0.0) ** exponent * conc_factor[e]


@cuda.jit
def prepare_elements_kernel(damage, sigma, concentration, cohesion, area, E0, lambda0, c_star, alpha, denom, q,
                            damage_w, sigma_w, e_buf, lam_buf, conc_factor, sigma_c, sigma_t, damaged_flag,
                            scalars):
    """Start of an outer step, per element: working copies of σ and d (the
    committed state stays untouched until the step succeeds), E and λ
    (``MaxwellEB.moduli``) into ``e_buf``/``lam_buf``, g = exp(−c*(1−A)),
    σc = 2C/denom, σT = σc/q, flags cleared; E_max and max E/area into ``scalars``."""
    emax = -math.inf
    kmax = -math.inf
    for e in range(cuda.grid(1), damage.shape[0], cuda.gridsize(1)):
        d = damage[e]
        damage_w[e] = d
        sigma_w[e, 0] = sigma[e, 0]
        sigma_w[e, 1] = sigma[e, 1]
        sigma_w[e, 2] = sigma[e, 2]
        cf = math.exp(-c_star * (1.0 - concentration[e]))
        E = E0 * (1.0 - d) * cf
        e_buf[e] = E
        lam_buf[e] = lambda0 * ((1.0 - d) * cf) ** (alpha - 1.0)
        conc_factor[e] = cf
        sc = 2.0 * cohesion[e] / denom
        sigma_c[e] = sc
        sigma_t[e] = sc / q
        damaged_flag[e] = 0
        emax = max2(emax, E)
        kmax = max2(kmax, E / area[e])
    cuda.atomic.max(scalars, S_E_MAX, emax)
    cuda.atomic.max(scalars, S_STIFF_MAX, kmax)


@cuda.jit
def finish_moduli_kernel(e_buf, lam_buf, dt_s):
    """In place: e_buf ← Δt_s E, lam_buf ← λ/(λ+Δt_s) (once Δt_s is known)."""
    for e in range(cuda.grid(1), e_buf.shape[0], cuda.gridsize(1)):
        e_buf[e] = dt_s * e_buf[e]
        lam = lam_buf[e]
        lam_buf[e] = lam / (lam + dt_s)


@cuda.jit
def prepare_nodes_kernel(ptr, elems, local, area, h, b, c, rho, dt_s, wind, has_wind, c_air, drag_coef,
                         coriolis_f, vel, vel_w, vel_sum, m_dt, fext, cda, half_mf, wb, wc):
    """Per node: lumped mass and area (``fem.lumped_mass``), adjacency weights
    (``fem._adjacency_weights``, thickness-weighted), m/Δt_s, wind force
    a·τa with τa = (ρa Ca |Ua|) Ua (``WindStress.stress``), drag coefficient
    a·ρw·Cw, ½ m f; working copy of the velocity, zeroed velocity sum."""
    n = ptr.shape[0] - 1
    for i in range(cuda.grid(1), n, cuda.gridsize(1)):
        sm = 0.0
        sa = 0.0
        for p in range(ptr[i], ptr[i + 1]):
            e = elems[p]
            k = local[p]
            sm += (rho * h[e]) * area[e]
            sa += 1.0 * area[e]
            w = area[e] * h[e]
            wb[p] = w * b[e, k]
            wc[p] = w * c[e, k]
        mass = sm / 3.0
        na = sa / 3.0
        m_dt[i] = mass / dt_s
        tx = 0.0
        ty = 0.0
        if has_wind:
            u = wind[i, 0]
            v = wind[i, 1]
            s = math.hypot(u, v)
            tx = 0.0 + (c_air * s) * u
            ty = 0.0 + (c_air * s) * v
        fext[i, 0] = tx * na
        fext[i, 1] = ty * na
        cda[i] = drag_coef * na
        half_mf[i] = 0.5 * mass * coriolis_f
        vel_w[i, 0] = vel[i, 0]
        vel_w[i, 1] = vel[i, 1]
        vel_sum[i, 0] = 0.0
        vel_sum[i, 1] = 0.0


@cuda.jit
def scatter_prescribed_kernel(dofs, vals0, vals1, pres0, pres1):
    """pres.reshape(-1)[dofs] = vals (``fem.NodeSystem.prescribed_velocity``)."""
    for j in range(cuda.grid(1), dofs.shape[0], cuda.gridsize(1)):
        d = dofs[j]
        pres0[d // 2, d % 2] = vals0[j]
        pres1[d // 2, d % 2] = vals1[j]


@cuda.jit
def fill_kernel(out, value):
    """out[...] = value for a 1-D array."""
    for j in range(cuda.grid(1), out.shape[0], cuda.gridsize(1)):
        out[j] = value


@cuda.jit
def fill_pair_kernel(out, u, v):
    """out[:, 0] = u, out[:, 1] = v for an (n, 2) array."""
    for j in range(cuda.grid(1), out.shape[0], cuda.gridsize(1)):
        out[j, 0] = u
        out[j, 1] = v


# ----------------------------------------------------------------------------
# forcing records (forcing.records on the device)
# ----------------------------------------------------------------------------
@cuda.jit(device=True)
def cell_dev(ax, p, uniform, inv_d):
    """:func:`forcing.records._cell`: arithmetic on a uniform axis, binary search
    (``searchsorted(side='right') - 1``) otherwise."""
    n = ax.shape[0]
    if uniform:
        i = max2(min2(int((p - ax[0]) * inv_d), n - 2), 0)
        if p < ax[i] and i > 0:
            i -= 1
        elif p >= ax[i + 1] and i < n - 2:
            i += 1
        return i
    lo = 0
    hi = n
    while lo < hi:
        mid = (lo + hi) // 2
        if ax[mid] <= p:
            lo = mid + 1
        else:
            hi = mid
    return max2(min2(lo - 1, n - 2), 0)


@cuda.jit
def blend_records_kernel(r0, r1, a, out):
    """out = (1 − a) r0 + a r1 on the record grid (records ``(nc, ny, nx)``)."""
    nc = r0.shape[0]
    ny = r0.shape[1]
    nx = r0.shape[2]
    for k in range(cuda.grid(1), nc * ny * nx, cuda.gridsize(1)):
        cc = k // (ny * nx)
        rem = k - cc * (ny * nx)
        j = rem // nx
        i = rem - j * nx
        out[cc, j, i] = (1.0 - a) * r0[cc, j, i] + a * r1[cc, j, i]


@cuda.jit
def record_field_kernel(nodes, ax, ay, ux, uy, clamp, r0, r1, a, two_records, out, counters, c_out, c_bad):
    """A vector record field at the nodes (:class:`forcing.records.RecordField`
    on a :class:`~forcing.records.RegularGrid`): bilinear weights as
    ``_bilinear_weights``, then one record (``two_records`` = 0: a single record
    or a grid already blended in time) or ``(1−a)·bilinear(r0) + a·bilinear(r1)``
    (``_interp_records``). Points outside the grid (when not clamping) and
    non-finite values are counted into ``counters[c_out]``/``counters[c_bad]``."""
    nx = ax.shape[0]
    ny = ay.shape[0]
    inv_dx = (nx - 1) / (ax[nx - 1] - ax[0])
    inv_dy = (ny - 1) / (ay[ny - 1] - ay[0])
    n_out = 0
    n_bad = 0
    for k in range(cuda.grid(1), nodes.shape[0], cuda.gridsize(1)):
        px = nodes[k, 0]
        py = nodes[k, 1]
        bad = 0
        if not (px >= ax[0] and px <= ax[nx - 1]):
            bad = 1
            if px > ax[nx - 1]:
                px = ax[nx - 1]
            else:
                px = ax[0]
        if not (py >= ay[0] and py <= ay[ny - 1]):
            bad = 1
            if py > ay[ny - 1]:
                py = ay[ny - 1]
            else:
                py = ay[0]
        n_out += bad
        i = cell_dev(ax, px, ux, inv_dx)
        j = cell_dev(ay, py, uy, inv_dy)
        fx = (px - ax[i]) / (ax[i + 1] - ax[i])
        fy = (py - ay[j]) / (ay[j + 1] - ay[j])
        nonfinite = 0
        for cc in range(r0.shape[0]):
            if two_records:
                v = ((1.0 - a) * bilinear_dev(r0, cc, i, j, fx, fy)
                     + a * bilinear_dev(r1, cc, i, j, fx, fy))
            else:
                v = bilinear_dev(r0, cc, i, j, fx, fy)
            if math.isnan(v) or math.isinf(v):
                nonfinite = 1
            out[k, cc] = v
        n_bad += nonfinite
    if n_out and not clamp:
        cuda.atomic.add(counters, c_out, n_out)
    if n_bad:
        cuda.atomic.add(counters, c_bad, n_bad)
