"""Maxwell-Elasto-Brittle rheology as functions of state (no mesh, no solver).

Conventions (docs/design.md §2-3): stress is tension positive, stored per element as
(σxx, σyy, σxy) [Pa]; damage d ∈ [0, 1), 0 undamaged, 1 fully damaged
(Dansereau et al. 2016 uses d_seed = 1 − d).

* stiffness   E = E0 (1−d) exp(−c*(1−A))                 (Dansereau et al. 2016 eqs. 12, 17)
* relaxation  λ = λ0 [(1−d) exp(−c*(1−A))]^(α−1)         (Dansereau et al. 2016 eq. 12)
* constitutive law  dσ/dt + σ/λ = E K:ε̇                   (Dansereau et al. 2016 eq. 1)
* Mohr–Coulomb envelope with tensile cut-off, d_crit        (Dansereau et al. 2016 eqs. 2-8)
* damage  dd/dt = (1−d_crit)(1−d)/td − H_heal, stress scaled onto the envelope
                                                             (Dansereau et al. 2016 eqs. 9-11)
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .._numba import pick, serial_copy
from ..errors import ConfigError
from ..params import FAILURE_EXPONENT, STRESS_CORRECTIONS, MaxwellEBParams


def plane_stress_matrix(poisson: float) -> np.ndarray:
    """K of docs/design.md §3 acting on (ε̇xx, ε̇yy, ε̇xy) (tensor shear component)."""
    nu = poisson
    return np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 1.0 - nu]]) / (1.0 - nu * nu)


def young_modulus(E0, damage, concentration, c_star):
    """E = E0 (1−d) exp(−c*(1−A)) [Pa]."""
    return E0 * (1.0 - damage) * np.exp(-c_star * (1.0 - concentration))


def relaxation_time(lambda0, damage, concentration, c_star, alpha):
    """λ = λ0 [(1−d) exp(−c*(1−A))]^(α−1) [s]; η = Eλ ∝ (1−d)^α."""
    return lambda0 * ((1.0 - damage) * np.exp(-c_star * (1.0 - concentration))) ** (alpha - 1.0)


def envelope(cohesion, friction):
    """(q, σc, σT) of Dansereau et al. 2016 eqs. 3, 4, 6: slope, uniaxial compressive strength
    [Pa] and tensile strength [Pa, positive]."""
    s = math.sqrt(friction * friction + 1.0)
    q = (s + friction) ** 2
    sigma_c = 2.0 * np.asarray(cohesion) / (s - friction)
    return q, sigma_c, sigma_c / q


@njit(cache=True, inline="always")
def _principal(sxx, syy, sxy):
    m = 0.5 * (sxx + syy)
    r = math.sqrt(0.25 * (sxx - syy) ** 2 + sxy * sxy)
    return m + r, m - r


@njit(cache=True, inline="always")
def _dcrit(sxx, syy, sxy, cohesion, q, denom):
    """d_crit of Dansereau et al. 2016 eq. 8 in tension-positive form (docs/design.md §3)."""
    s1, s2 = _principal(sxx, syy, sxy)
    sigma_c = 2.0 * cohesion / denom
    sigma_t = sigma_c / q
    dc = 1.0
    if s1 > 0.0:
        dc = min(dc, sigma_t / s1)
    mc = q * s1 - s2
    if mc > 0.0:
        dc = min(dc, sigma_c / mc)
    return dc


def principal_stresses(sigma: np.ndarray):
    """Principal stresses (s1 ≥ s2) [Pa] of (m, 3) stresses."""
    sxx, syy, sxy = sigma[..., 0], sigma[..., 1], sigma[..., 2]
    m = 0.5 * (sxx + syy)
    r = np.sqrt(0.25 * (sxx - syy) ** 2 + sxy**2)
    return m + r, m - r


def dcrit(sigma: np.ndarray, cohesion, friction: float) -> np.ndarray:
    """d_crit ∈ (0, 1] for (m, 3) stresses: 1 inside the envelope, the factor that
    scales σ back onto it outside (Dansereau et al. 2016 eq. 8)."""
    sigma = np.atleast_2d(np.asarray(sigma, dtype=np.float64))
    C = np.broadcast_to(np.asarray(cohesion, np.float64), (len(sigma),))
    out = np.empty(len(sigma))
    s = math.sqrt(friction * friction + 1.0)
    _dcrit_kernel(sigma, np.ascontiguousarray(C), (s + friction) ** 2, s - friction, out)
    return out


@njit(cache=True, parallel=True)
def _dcrit_kernel(sigma, cohesion, q, denom, out):
    for e in prange(sigma.shape[0]):
        out[e] = _dcrit(sigma[e, 0], sigma[e, 1], sigma[e, 2], cohesion[e], q, denom)


@njit(cache=True, inline="always")
def damage_step(d, dc, dt, td, heal_rate, max_damage):
    """One element's damage update (Dansereau et al. 2016 eqs. 9-11), shared by the kernels.

    Returns ``(d_new, f, capped)``: r = min(1, dt/td)(1 − dc), 1 − d ← (1 − d)(1 − r)
    where dc < 1; the stress factor f = 1 − r (1 without a damage event); then
    healing, floored at d = 0 (a fully healed element), and the cap at ``max_damage``
    (capped = 1 when it acted).

    The sign of ``heal_rate`` [s-1] selects the healing form (one array per element,
    so the kernels' signatures serve both):

    * ``heal_rate >= 0``: damage form, d ← d − dt·H (neXtSIM since 2017);
    * ``heal_rate < 0``: compliance form, χ = 1/(1 − d) ← χ − dt·|H| (neXtSIM before
      2017, :class:`lagice.strength.NextsimHealing` ``form = "compliance"``): the
      compliance excess of a cracked element shrinks at a constant rate, so nearly
      broken ice (χ ≫ 1) heals slowly and lightly damaged ice quickly."""
    f = 1.0
    if dc < 1.0:
        r = min(1.0, dt / td) * (1.0 - dc)
        d = 1.0 - (1.0 - d) * (1.0 - r)
        f = 1.0 - r
    if heal_rate >= 0.0:
        d -= dt * heal_rate
    elif d < 1.0:
        chi = 1.0 / (1.0 - d) + dt * heal_rate
        d = 1.0 - 1.0 / chi if chi > 1.0 else 0.0
    if d < 0.0:
        d = 0.0
    capped = 0
    if d > max_damage:
        d = max_damage
        capped = 1
    return d, f, capped


@njit(cache=True, inline="always")
def closed_crack_mean(m0, am, ed, ed0):
    """The mean normal stress after one sub-step with closed cracks (``crack_closure``): from
    m0, with ``am`` the mean the damaged modulus ``ed`` = Δt_s E would give, the undamaged
    ``ed0`` = Δt_s E0 exp(−c*(1−A)) acting wherever m ≤ 0 (the cracks closed) and ``ed`` where
    m ≥ 0, the volumetric strain split where the step crosses 0. Shared by the explicit CPU
    kernel and the CUDA kernel (numba compiles it for the device as it does
    :func:`_dcrit_towards`)."""
    if m0 < 0.0:
        mc = m0 + (ed0 / ed) * (am - m0)
        if mc > 0.0:
            mc *= ed / ed0
    elif am < 0.0:
        mc = am * (ed0 / ed)
    else:
        mc = am
    return mc


@njit(cache=True, inline="always")
def _dcrit_towards(sxx, syy, sxy, cohesion, q, denom, theta):
    """The factor f ∈ [0, 1] that brings a stress onto the envelope along the straight path
    towards the isotropic stress P = θ m I (m = (σ1 + σ2)/2, 0 < θ ≤ 2): σ' = P + f (σ − P).
    θ = 1 scales only the deviatoric part (the mean kept); θ > 1 raises the pressure of a
    compressed element (a dilatant return); θ → 0 is the origin path of
    :func:`_dcrit`. With σ1,2 = m ± r, the corrected mean is θ m + f (1 − θ) m and the
    radius f r, so q σ1' − σ2' = σc gives f = (σc − (q − 1) θ m)/((q − 1)(1 − θ) m + (q + 1) r)
    and σ1' = σT gives f = (σT − θ m)/((1 − θ) m + r), each where the path crosses that
    branch. Returns −1 where P itself lies outside the envelope or r = 0 (the caller then
    corrects towards the origin)."""
    m = 0.5 * (sxx + syy)
    r = math.sqrt(0.25 * (sxx - syy) ** 2 + sxy * sxy)
    sigma_c = 2.0 * cohesion / denom
    sigma_t = sigma_c / q
    p = theta * m
    if r <= 0.0 or (q - 1.0) * p >= sigma_c or p >= sigma_t:
        return -1.0
    f = 1.0
    d_mc = (q - 1.0) * (1.0 - theta) * m + (q + 1.0) * r
    if d_mc > 0.0:
        lim = (sigma_c - (q - 1.0) * p) / d_mc
        if lim < f:
            f = lim
    d_t = (1.0 - theta) * m + r
    if d_t > 0.0:
        lim = (sigma_t - p) / d_t
        if lim < f:
            f = lim
    if f < 0.0:
        return -1.0
    return f


@njit(cache=True, inline="always")
def _dcrit_associated(sxx, syy, sxy, cohesion, q, denom, nu):
    """The associated (normal) path: ``(f, p)`` such that σ' = P + f (σ − P), P = p I, lies on
    the envelope and σ − σ' is parallel to K n, n the outward normal of the envelope branch
    the stress is past (K of :func:`plane_stress_matrix`). That is the return of an associated
    plasticity in the metric of the elastic energy: the inelastic strain rate it implies is
    normal to the envelope (docs/physics.md §4, compression test).

    In principal axes σ = (m + r, m − r). Mohr–Coulomb branch (q σ1 − σ2 = σc): n = (q, −1),
    K n ∝ (c + 1, c − 1) with c = (q − 1)(1 + ν)/((q + 1)(1 − ν)), so the path meets the
    isotropic axis at p = m − c r, and f = (σc − (q − 1) p)/((q − 1)(m − p) + (q + 1) r).
    Tensile branch (σ1 = σT): n = (1, 0), c = (1 + ν)/(1 − ν), f = (σT − p)/(m − p + r).
    Returns f = −1 where neither branch gives a point of the envelope (the corner, or r = 0):
    the caller then corrects towards the origin."""
    m = 0.5 * (sxx + syy)
    r = math.sqrt(0.25 * (sxx - syy) ** 2 + sxy * sxy)
    sigma_c = 2.0 * cohesion / denom
    sigma_t = sigma_c / q
    if r <= 0.0:
        return -1.0, 0.0
    tol = 1e-12 * sigma_c
    c = (q - 1.0) * (1.0 + nu) / ((q + 1.0) * (1.0 - nu))
    p = m - c * r
    if (q - 1.0) * p < sigma_c and p < sigma_t:
        f = (sigma_c - (q - 1.0) * p) / ((q - 1.0) * (m - p) + (q + 1.0) * r)
        if 0.0 <= f < 1.0 and p + f * (m - p + r) <= sigma_t + tol:
            return f, p
    c = (1.0 + nu) / (1.0 - nu)
    p = m - c * r
    if (q - 1.0) * p < sigma_c and p < sigma_t:
        f = (sigma_t - p) / (m - p + r)
        if 0.0 <= f < 1.0 and (q - 1.0) * (p + f * (m - p)) + (q + 1.0) * f * r <= sigma_c + tol:
            return f, p
    return -1.0, 0.0


@njit(cache=True, parallel=True)
def damage_update_kernel(sigma, damage, cohesion, dt, td, heal_rate, q, denom, max_damage,
                         dcrit_out, mean_fraction=0.0, associated_nu=-1.0):
    """Explicit damage update with stress correction, in place (Dansereau et al. 2016 eqs. 9-11).

    Per element: r = min(1, dt/td_e)(1 − d_crit);  1 − d ← (1 − d)(1 − r);
    σ ← σ (1 − r);  then healing d ← d − dt·H_e, floored at 0 (a fully healed
    element). With dt = td this is Dansereau et al. (2016)'s d_{n+1} = d_crit d_n. Damage is
    capped at ``max_damage`` (< 1, keeps E > 0); the number of capped elements
    is returned so the caller can report it.

    ``heal_rate`` is an array (m,) [s-1] (zeros: no healing).

    ``mean_fraction`` θ > 0 (``rheology.stress_correction = "mean_stress"``, θ =
    ``stress_correction_mean_fraction``, default 1): a super-critical stress is brought back
    towards P = θ m I instead of the origin, σ ← P + (1 − r)(σ − P) with m = (σxx + σyy)/2,
    and d_crit is the factor of :func:`_dcrit_towards` (the origin path where that factor
    does not exist). θ = 1 keeps the mean stress. With dt = td the stress lands on the
    envelope on every path. θ = 0 is the origin path, bit for bit.

    ``associated_nu`` ν ≥ 0 (``rheology.stress_correction = "associated"``): the path of
    :func:`_dcrit_associated` (towards the envelope along K n), with P = p I from that
    function; the origin path where it gives none. Negative: not used.
    """
    n_capped = 0
    for e in prange(sigma.shape[0]):
        dc = _dcrit(sigma[e, 0], sigma[e, 1], sigma[e, 2], cohesion[e], q, denom)
        towards_point = False
        p = 0.0
        if associated_nu >= 0.0 and dc < 1.0:
            fa, pa = _dcrit_associated(sigma[e, 0], sigma[e, 1], sigma[e, 2], cohesion[e], q, denom, associated_nu)
            if fa >= 0.0:
                dc = fa
                p = pa
                towards_point = True
        elif mean_fraction > 0.0 and dc < 1.0:
            fm = _dcrit_towards(sigma[e, 0], sigma[e, 1], sigma[e, 2], cohesion[e], q, denom, mean_fraction)
            if fm >= 0.0:
                dc = fm
                p = mean_fraction * 0.5 * (sigma[e, 0] + sigma[e, 1])
                towards_point = True
        dcrit_out[e] = dc
        d, f, capped = damage_step(damage[e], dc, dt, td[e], heal_rate[e], max_damage)
        if towards_point:
            sigma[e, 0] = p + f * (sigma[e, 0] - p)
            sigma[e, 1] = p + f * (sigma[e, 1] - p)
            sigma[e, 2] *= f
        elif dc < 1.0:
            sigma[e, 0] *= f
            sigma[e, 1] *= f
            sigma[e, 2] *= f
        n_capped += capped
        damage[e] = d
    return n_capped


DAMAGE_UPDATE = (serial_copy(damage_update_kernel), damage_update_kernel)


#: the stress-correction paths (``rheology.stress_correction``) each stepper implements
#: (the prescribed-velocity stepper updates no damage: only the default is not an ignored setting)
CORRECTION_PATHS = {"implicit": STRESS_CORRECTIONS, "explicit": ("origin", "mean_stress"),
                    "explicit_cuda": ("origin", "mean_stress"),
                    "prescribed": ("origin",)}
#: the optional terms of :class:`lagice.params.MaxwellEBParams` that each stepper implements.
#: A term set away from its default (:meth:`MaxwellEBParams.optional_terms`) is refused by a
#: stepper that does not list it, so no stepper silently runs without it
OPTIONAL_TERMS = {"implicit": ("failure_stress", "damage_length_m"),
                  "explicit": ("max_pressure_pa", "relax_mean_stress", "dilatancy_angle_deg",
                               "damage_nonlocal_radius_m", "failure_stress", "crack_closure",
                               "bulk_shear_viscosity_ratio", "damage_length_m", "crack_band_length_m"),
                  "explicit_cuda": ("max_pressure_pa", "relax_mean_stress", "dilatancy_angle_deg", "failure_stress",
                                    "crack_closure"), "prescribed": ()}
#: the values of ``rheology.failure_stress`` each stepper implements beyond the default (a
#: stepper that lists the key in :data:`OPTIONAL_TERMS` but not a value refuses that value)
FAILURE_STRESS_PATHS = {"implicit": ("effective", "energy"), "explicit": ("effective", "energy"),
                        "explicit_cuda": ("effective",), "prescribed": ()}
STEPPER_LABELS = {"implicit": "the implicit solver (solver.name = 'implicit')",
                  "prescribed": "the prescribed-velocity stepper (solver.name = 'prescribed', no damage update)",
                  "explicit": "the explicit CPU stepper (solver.name = 'explicit', solver.device = 'cpu')",
                  "explicit_cuda": "the CUDA explicit stepper (solver.name = 'explicit', solver.device = 'cuda')"}


def draw_cohesion(n_elements: int, params: MaxwellEBParams, rng: np.random.Generator) -> np.ndarray:
    """Cohesion C [Pa] per element, uniform in [C_min, C_max] from a seeded generator
    (quenched disorder, Dansereau et al. 2016 §2.2)."""
    if n_elements < 0:
        raise ConfigError(f"n_elements = {n_elements} must be >= 0")
    return rng.uniform(params.cohesion_min_pa, params.cohesion_max_pa, size=n_elements)


class MaxwellEB:
    """The Maxwell-EB rheology: parameters plus the element-wise laws.

    The solvers (``lagice.solvers``) call :meth:`moduli` for E and λ and
    :meth:`damage_update` after each step; nothing here knows about meshes.
    """

    name = "maxwell_eb"

    def __init__(self, params: MaxwellEBParams | None = None, **overrides):
        params = params or MaxwellEBParams()
        self.params = params.replace(**overrides) if overrides else params
        p = self.params
        s = math.sqrt(p.friction**2 + 1.0)
        self.q = (s + p.friction) ** 2
        self._denom = s - p.friction
        self.K = plane_stress_matrix(p.poisson)
        self.n_capped_total = 0

    @property
    def E0(self) -> float:
        return self.params.E0

    def concentration_factor(self, concentration):
        """g = exp(−c*(1−A)) [-] per element, as :func:`young_modulus` computes it."""
        return np.exp(-self.params.concentration_c * (1.0 - np.asarray(concentration, np.float64)))

    def moduli(self, damage, concentration, conc_factor=None):
        """(E [Pa], λ [s]) per element. ``conc_factor``: g of :meth:`concentration_factor`
        when the caller has it (the explicit stepper: one exponential per step instead of
        three); the same numbers bit for bit as :func:`young_modulus` and
        :func:`relaxation_time`, which evaluate the same expression for g."""
        p = self.params
        if conc_factor is None:
            E = young_modulus(p.E0, damage, concentration, p.concentration_c)
            lam = relaxation_time(p.relaxation_time_s, damage, concentration, p.concentration_c, p.alpha)
            return E, lam
        x = 1.0 - damage
        E = p.E0 * x * conc_factor
        lam = p.relaxation_time_s * (x * conc_factor) ** (p.alpha - 1.0)
        return E, lam

    def damage_time(self, element_size_m):
        """td [s] per element: Δx / cs (Dansereau et al. 2016 §3.1.1), or ℓ / cs for every element
        when ``damage_length_m`` = ℓ is set (:class:`lagice.params.MaxwellEBParams`)."""
        size = np.asarray(element_size_m, np.float64)
        ell = self.params.damage_length_m
        if ell:
            return np.full(size.shape, float(ell) / self.params.shear_wave_speed)
        return size / self.params.shear_wave_speed

    def relaxation_scale(self, element_size_m):
        """Δx/ℓ [-] per element, the factor of the relaxation time λ when ``crack_band_length_m``
        = ℓ is set (:class:`lagice.params.MaxwellEBParams`), or None when it is not (off: the
        kernels then take λ unchanged, bit for bit)."""
        ell = self.params.crack_band_length_m
        if not ell:
            return None
        return np.asarray(element_size_m, np.float64) / float(ell)

    def constant_heal_rate(self, n: int) -> np.ndarray:
        th = self.params.healing_time_s
        rate = 0.0 if th is None or not np.isfinite(th) else 1.0 / th
        return np.full(n, rate)

    def require_stepper(self, stepper: str):
        """Raise :class:`ConfigError` unless ``stepper`` (a key of :data:`STEPPER_LABELS`)
        implements the stress correction asked for (``rheology.stress_correction``,
        :data:`CORRECTION_PATHS`) and every optional term that is set (:data:`OPTIONAL_TERMS`).
        The scene builder calls this before meshing, and each stepper again when it is built."""
        sc = self.params.stress_correction
        paths = CORRECTION_PATHS[stepper]
        if sc not in paths:
            raise ConfigError(f"rheology.stress_correction = {sc!r}: {STEPPER_LABELS[stepper]} implements "
                              f"{', '.join(paths)} only (the implicit solver implements every path)")
        for key, value in self.params.optional_terms().items():
            if key not in OPTIONAL_TERMS[stepper]:
                where = [STEPPER_LABELS[k] for k, terms in OPTIONAL_TERMS.items() if key in terms]
                shown = str(value).lower() if isinstance(value, bool) else repr(value)  # as the scene file has it
                raise ConfigError(f"rheology.{key} = {shown}: {STEPPER_LABELS[stepper]} does not implement it "
                                  f"(implemented in {' and '.join(where)}); use one of those, or leave "
                                  f"{key} at its default")
        fs = self.params.failure_stress
        if fs != "nominal" and fs not in FAILURE_STRESS_PATHS[stepper]:
            where = [STEPPER_LABELS[k] for k, values in FAILURE_STRESS_PATHS.items() if fs in values]
            raise ConfigError(f"rheology.failure_stress = {fs!r}: {STEPPER_LABELS[stepper]} does not implement it "
                              f"(implemented in {' and '.join(where)})")

    def max_pressure(self, thickness, concentration):
        """P_max = P* (h / 1 m)^k exp(−c*(1−A)) [Pa] per element (neXtSIM's compressive term;
        :class:`lagice.params.MaxwellEBParams`), or None when ``max_pressure_pa`` is unset or 0
        (off: the kernels then take the relaxation factor unchanged, bit for bit)."""
        p = self.params
        if not p.max_pressure_pa:
            return None
        h = np.maximum(np.asarray(thickness, np.float64), 0.0)
        return (p.max_pressure_pa * h ** p.max_pressure_thickness_exponent
                * np.exp(-p.concentration_c * (1.0 - np.asarray(concentration, np.float64))))

    def damage_update(self, sigma, damage, cohesion, dt, td, heal_rate):
        """Apply the damage/healing update in place; returns d_crit per element. With
        ``failure_stress = "effective"`` the envelope is that of the cohesion C (1 − d), with
        ``"energy"`` that of C √(1 − d), d the damage passed in (the step's starting damage), as
        the explicit kernel takes it."""
        power = FAILURE_EXPONENT[self.params.failure_stress]  # as the explicit kernel takes it
        if power is not None:
            x = 1.0 - np.asarray(damage, np.float64)
            factor = x if power == 1.0 else np.sqrt(x) if power == 0.5 else x ** power
            cohesion = np.asarray(cohesion, np.float64) * factor
        out = np.empty(len(damage))
        kernel = pick(DAMAGE_UPDATE, len(damage))
        n = kernel(sigma, damage, cohesion, float(dt), np.ascontiguousarray(td),
                   np.ascontiguousarray(heal_rate), self.q, self._denom,
                   self.params.max_damage, out, self.params.mean_fraction,
                   self.params.poisson if self.params.stress_correction == "associated" else -1.0)
        self.n_capped_total += int(n)
        return out
