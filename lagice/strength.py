"""Cohesion that scales with element size, plus quenched disorder (issue 12).

Law (neXtSIM, ``model/finiteelement.cpp`` lines 6993–6999 and 3909–3913 at
``nansencenter/nextsim@7bd58b15``): the cohesion measured on a laboratory sample of
size L_lab = 0.1 m falls with the scale of observation as

    C_e = C_lab · sqrt(L_lab / Δx_e) · f_e,     Δx_e = sqrt(area_e),

per element, from the element's own size (neXtSIM uses one mean resolution for the
whole mesh, sqrt of the mean element area; lagice meshes are not uniform, so each
element uses its own), and f_e = 1 + ``disorder`` · U_e, U_e uniform in [0, 1) is the
disorder (neXtSIM's ``C_fix + C_alea·U`` with ``C_alea = alea_factor·C_fix``;
Dansereau et al. 2016's cohesion uniform in [C, 2C] is ``disorder = 1``).

Criterion form. lagice's envelope is Dansereau et al. (2016) eq. 8 in principal
stresses (tension positive), q σ1 − σ2 ≤ σc, with q = (sqrt(μ²+1) + μ)² and
σc = 2C/(sqrt(μ²+1) − μ): the Coulomb criterion |τ| + μ σn ≤ C on the most
critical plane. neXtSIM writes σ_s + tanφ σ_mean ≤ C_N with σ_s = (σ1 − σ2)/2 and
σ_mean = (σ1 + σ2)/2 (``finiteelement.cpp`` line 4226), i.e. a Coulomb envelope in
the (σ_mean, σ_s) plane. The two describe the same envelope exactly when
μ = tanφ/sqrt(1 − tan²φ) and C = C_N/sqrt(1 − tan²φ) (derivation in
docs/physics.md §2; :func:`from_nextsim`): neXtSIM's tanφ = 0.7 and C_lab = 2 MPa are
μ = 0.980 and C_lab = 2.80 MPa in lagice's form.

Disorder and remeshing. U_e is a deterministic hash of the run seed and the
persistent ids of the element's three nodes (``IceState.node_id``). An element that
survives a remesh keeps its nodes, hence its U_e; a new element gets a fresh,
independent draw from the same distribution. The disorder is white (uncorrelated
from element to element), so a fresh draw keeps exactly what characterises it: its
distribution (mean and spread) and its lack of spatial correlation. Remapping it
as an area-weighted mean would instead shrink its spread in every remeshed patch
(averaging several independent values) until the pack became homogeneous. No extra
field is stored: C is saved with the state, U_e is recomputed from the ids.

Correlated heterogeneity (optional, ``strength_correlation_m`` ℓ > 0). Sea-ice
strength also varies smoothly over tens to hundreds of kilometres (ice age, brine
volume and temperature: first-year against multi-year ice; Timco & Weeks 2010, "A
review of the engineering properties of sea ice", Cold Reg. Sci. Technol. 60). A factor
g_e = 1 + a·(2Φ(G(x_e)) − 1) then multiplies C_e, with G a stationary Gaussian random
field of unit variance and covariance exp(−r²/(2ℓ²)) (random Fourier features,
Rahimi & Recht 2007, "Random features for large-scale kernel machines", NIPS 20;
deterministic from the run seed), Φ the standard normal distribution function and a =
``strength_correlated_amplitude``: g is uniform on [1 − a, 1 + a], mean 1, so the mean
strength is unchanged. g is laid on the ice at the start of a run (element centroids
at t = 0) and is then a material property: it is stored in the state
(``state.strength_factor``), checkpointed, and remapped at each remesh as an
area-weighted mean (∫ g da conserved exactly). Unlike the white disorder, remapping
does not erase it: over a new element (Δx ≪ ℓ) g hardly varies, so the mean equals
the point value to O((Δx/ℓ)²).

After every remesh :meth:`StrengthLaw.apply` sets C of every element from its
current size and its factors (a hook of the ``remeshing`` component,
:attr:`lagice.remesh.Remesher.after_remesh`, set by the scene builder). Between
remeshes C is a material property of the element and is not changed by the
Lagrangian motion.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .components import RateComponent
from .errors import ConfigError, check_range

#: keys of ``[rheology]`` handled here, not by MaxwellEBParams
RHEOLOGY_KEYS = ("strength_law", "strength_lab_pa", "strength_lab_scale_m", "strength_disorder",
                 "strength_correlation_m", "strength_correlated_amplitude", "strength_after_remesh")
#: which elements :meth:`StrengthLaw.apply` sets after a remesh (``rheology.strength_after_remesh``)
AFTER_REMESH = ("all", "new")
#: random Fourier modes of the correlated strength field (the sample variance of G at a
#: point is 1 ± O(1/sqrt(N)) over the domain)
N_MODES = 512
LAWS = ("uniform", "scaled")


def from_nextsim(cohesion_pa: float, tan_phi: float):
    """(C, μ) of lagice's envelope q σ1 − σ2 ≤ σc that equals neXtSIM's
    σ_s + tanφ σ_mean ≤ C_N exactly: μ = tanφ/√(1 − tan²φ), C = C_N/√(1 − tan²φ)."""
    check_range("tan_phi", tan_phi, 0.0, 1.0, high_open=True)
    check_range("cohesion_pa", cohesion_pa, 0.0, None, unit="Pa")
    k = math.sqrt(1.0 - tan_phi * tan_phi)
    return cohesion_pa / k, tan_phi / k


def element_size(nodes: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Δx_e = sqrt(area_e) [m] (neXtSIM's resolution measure, per element)."""
    p = nodes[triangles]
    a = 0.5 * np.abs((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                     - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))
    return np.sqrt(a)


_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_GOLD = np.uint64(0x9E3779B97F4A7C15)


def _mix(z: np.ndarray) -> np.ndarray:
    """splitmix64 finaliser (Steele, Lea & Flood 2014), vectorised on uint64."""
    z = z ^ (z >> np.uint64(30))
    z = z * _M1
    z = z ^ (z >> np.uint64(27))
    z = z * _M2
    return z ^ (z >> np.uint64(31))


def element_uniforms(node_id: np.ndarray, triangles: np.ndarray, seed: int) -> np.ndarray:
    """U_e in [0, 1) per element: a hash of ``seed`` and the sorted persistent ids of
    the element's nodes (independent of the node order and of the element index)."""
    if node_id is None:
        raise ConfigError("the scaled strength law needs persistent node ids (state.node_id is None)")
    ids = np.sort(np.asarray(node_id, np.int64)[triangles], axis=1).astype(np.uint64)
    with np.errstate(over="ignore"):
        h = _mix(np.uint64(int(seed) & 0xFFFFFFFFFFFFFFFF) + _GOLD)
        for k in range(3):
            h = _mix(h ^ (ids[:, k] + _GOLD))
    return (h >> np.uint64(11)).astype(np.float64) * (1.0 / 9007199254740992.0)  # 53-bit mantissa


@dataclass(frozen=True)
class StrengthLaw:
    """C_e = ``lab_cohesion_pa`` · sqrt(``lab_scale_m``/Δx_e) · (1 + ``disorder`` U_e) · g_e.

    ``lab_cohesion_pa`` is in lagice's (Dansereau et al. 2016) criterion form; convert
    neXtSIM's values with :func:`from_nextsim`. g_e = 1 without a correlated field
    (``correlation_m = 0``, the default), else see :meth:`correlated_factor`."""

    lab_cohesion_pa: float = 2.0e6 / math.sqrt(1.0 - 0.49)
    lab_scale_m: float = 0.1
    disorder: float = 1.0
    seed: int = 0
    correlation_m: float = 0.0
    correlated_amplitude: float | None = None
    #: ``"new"`` (the default since 2026-11-28): only the remesh's new elements get the law's
    #: C, and kept elements keep theirs (a material property between its creation and its
    #: replacement; docs/physics.md §2, "Disorder and remeshing"); ``"all"`` (the behaviour
    #: from 2026-11-24 to 2026-11-28): after a remesh every element's C is recomputed from its
    #: current size, so kept elements jump to the strength of the size their Lagrangian
    #: deformation gave them
    after_remesh: str = "new"

    def __post_init__(self):
        check_range("rheology.strength_lab_pa", self.lab_cohesion_pa, 1e4, 1e8, unit="Pa")
        check_range("rheology.strength_lab_scale_m", self.lab_scale_m, 1e-3, 10.0, unit="m")
        check_range("rheology.strength_disorder", self.disorder, 0.0, 10.0)
        if self.after_remesh not in AFTER_REMESH:
            raise ConfigError(f"rheology.strength_after_remesh = {self.after_remesh!r}: expected one of "
                              f"{list(AFTER_REMESH)}")
        if self.correlation_m != 0.0:
            check_range("rheology.strength_correlation_m", self.correlation_m, 1.0e3, 1.0e7, unit="m")
            check_range("rheology.strength_correlated_amplitude", self.amplitude, 0.0, 0.95)
        elif self.correlated_amplitude is not None:
            raise ConfigError(f"rheology.strength_correlated_amplitude = {self.correlated_amplitude} is set but "
                              "rheology.strength_correlation_m is 0 (no correlated field); set "
                              "strength_correlation_m to a length in [1000, 1e7] m to use it")

    @property
    def amplitude(self) -> float:
        """a of g = 1 + a(2Φ(G) − 1) [-] (default 0.5: a factor 3 between the weakest and
        the strongest regions)."""
        return 0.5 if self.correlated_amplitude is None else float(self.correlated_amplitude)

    @property
    def correlated(self) -> bool:
        return self.correlation_m > 0.0

    def gaussian_field(self, x_m, y_m) -> np.ndarray:
        """G at points (x, y) [m]: a stationary Gaussian random field of unit variance and
        covariance exp(−r²/(2ℓ²)), as N_MODES random Fourier features
        sqrt(2/N) Σ cos(k_j·x + φ_j), k_j ~ N(0, I/ℓ²), φ_j ~ U[0, 2π) (drawn from the
        run seed)."""
        rng = np.random.default_rng([int(self.seed) & 0xFFFFFFFF, 0x5354524E])  # "STRN"
        k = rng.normal(0.0, 1.0 / self.correlation_m, size=(N_MODES, 2))
        phi = rng.uniform(0.0, 2.0 * np.pi, N_MODES)
        x = np.asarray(x_m, np.float64)
        y = np.asarray(y_m, np.float64)
        out = np.zeros(x.shape)
        for j in range(N_MODES):  # modes, not elements: each term is an array operation
            out += np.cos(k[j, 0] * x + k[j, 1] * y + phi[j])
        return out * math.sqrt(2.0 / N_MODES)

    def correlated_factor(self, x_m, y_m) -> np.ndarray:
        """g = 1 + a(2Φ(G) − 1) at points (x, y) [m]: uniform on [1 − a, 1 + a], mean 1."""
        if not self.correlated:
            raise ConfigError("correlated_factor needs rheology.strength_correlation_m > 0")
        from scipy.special import ndtr  # Φ, the standard normal distribution function

        return 1.0 + self.amplitude * (2.0 * ndtr(self.gaussian_field(x_m, y_m)) - 1.0)

    def scale_factor(self, size_m):
        """sqrt(L_lab/Δx) [-]."""
        return np.sqrt(self.lab_scale_m / np.asarray(size_m, np.float64))

    def disorder_factor(self, node_id, triangles) -> np.ndarray:
        """f_e = 1 + disorder · U_e [-]."""
        return 1.0 + self.disorder * element_uniforms(node_id, triangles, self.seed)

    def cohesion(self, nodes, triangles, node_id, factor=None) -> np.ndarray:
        """C_e [Pa] of every element from its size, its disorder factor and (when given)
        its correlated factor g_e."""
        c = (self.lab_cohesion_pa * self.scale_factor(element_size(nodes, triangles))
             * self.disorder_factor(node_id, triangles))
        return c if factor is None else c * factor

    def apply(self, state, event=None) -> None:
        """Set ``state.cohesion`` from the elements' current size and factors after a remesh
        (``state.strength_factor`` has been remapped with the ice): of every element
        (``after_remesh = "all"``, or without ``event``), or of the remesh ``event``'s new
        elements only (``"new"``: those stitched after its ``kept_elements``, through its
        ``element_perm`` when the mesh was renumbered; a global remesh keeps none)."""
        m = state.mesh
        if self.correlated and state.strength_factor is None:
            raise ConfigError("rheology.strength_correlation_m > 0 but the state carries no strength_factor")
        c = self.cohesion(m.nodes, m.triangles, state.node_id, state.strength_factor if self.correlated else None)
        if self.after_remesh == "all" or event is None or event.kept_elements is None:
            state.cohesion = c
            return
        new = np.arange(m.n_elements) >= len(event.kept_elements)  # stitched order
        if event.element_perm is not None:
            new = new[event.element_perm]  # new element k is stitched element perm[k]
        state.cohesion = np.where(new, c, state.cohesion)


def from_config(rheology: dict, seed: int) -> StrengthLaw | None:
    """The strength law of a scene's ``[rheology]`` table (None for ``"uniform"``:
    cohesion uniform in [cohesion_min_pa, cohesion_max_pa], the default). Raises
    ConfigError naming key, value and range; called before any mesh work."""
    law = rheology.get("strength_law", "uniform")
    if law not in LAWS:
        raise ConfigError(f"rheology.strength_law = {law!r}: expected one of {list(LAWS)}")
    if law == "uniform":
        for k in RHEOLOGY_KEYS[1:]:
            # "new" is the schema's default and what the uniform law does anyway (its C is a
            # remapped element field, never recomputed); "all" would be ignored, so it is refused
            if rheology.get(k) is not None and not (k == "strength_after_remesh" and rheology[k] == "new"):
                raise ConfigError(f"rheology.{k} is set but rheology.strength_law = 'uniform'; "
                                  "set strength_law = 'scaled' to use it")
        return None
    kw = {"seed": int(seed)}
    for key, name in (("strength_lab_pa", "lab_cohesion_pa"), ("strength_lab_scale_m", "lab_scale_m"),
                      ("strength_disorder", "disorder"), ("strength_correlation_m", "correlation_m"),
                      ("strength_correlated_amplitude", "correlated_amplitude"),
                      ("strength_after_remesh", "after_remesh")):
        if rheology.get(key) is not None:
            kw[name] = rheology[key]
    # A configuration whose strength_after_remesh is None or absent was written before the
    # default became "new" (2026-11-28): a scene validated since then always holds the value
    # (the schema's default is "new"), so None is a checkpoint of the code that recomputed
    # every element, and it resumes doing so (LEGACY_FILL of lagice.scenes.config).
    kw.setdefault("after_remesh", "all")
    return StrengthLaw(**kw)


class NextsimHealing:
    """Healing tied to the ice temperature and the concentration, as in neXtSIM
    (``finiteelement.cpp`` lines 4256–4257 and 5856–5876; ``options.cpp`` 329–331):

        H = exp(−c*(1 − A)) / T_h,   T_h = th0 · ΔT0 / ΔT,
        ΔT = (Tf − Ta)⁺ / (1 + ki hs / (ks h))   (no healing at or above freezing),

    th0 = 25 days, ΔT0 = 20 K (``dynamics.time_relaxation_damage``,
    ``dynamics.deltaT_relaxation_damage``), c* = 20 (lagice's ``concentration_c``,
    neXtSIM's ``compaction_param`` = −20). ΔT is the temperature difference across the
    ice: neXtSIM takes it from its thermodynamics (bottom minus snow–ice interface);
    lagice's zero-layer ice has a linear profile through snow and ice in series with the
    surface at the air temperature, which gives the formula above (ki, ks, Tf of
    ``thermo.zero_layer.ThermoParams``). Thin snow-free ice heals as
    th0 ΔT0/(Tf − Ta); open, low-concentration ice heals slowly (e^(−20·0.08) = 0.2 at
    A = 0.92). Returns the rate [s-1] per element for the solver's d ← d − H dt.

    ``form`` picks what heals at that rate:

    * ``"damage"`` (default; neXtSIM since January 2017): d ← d − H dt, so ice heals
      from d = 1 to 0 in T_h whatever its damage;
    * ``"compliance"`` (neXtSIM's code before commit 19db09fe, January 2017, which
      wrote it ``tmp = 1/(1 − d); tmp −= 1000 dt/T_h``): the element's compliance
      ratio χ = 1/(1 − d) = E0/E decreases linearly, χ ← χ − K H dt with
      K = ``compliance_factor`` (1000 there). Lightly damaged ice heals fast (d = 0.5
      in T_h/1000), nearly broken ice slowly (d = 0.999 to 0.99 in 0.9 T_h): cracks
      stay soft while the pack between them recovers. The returned rate is then
      negative, −K H (the sign convention of :func:`lagice.rheology.damage_step`).
    """

    FORMS = ("damage", "compliance")

    def __init__(self, air_temperature, th0_s=25.0 * 86400.0, delta_t0_k=20.0, concentration_c=20.0,
                 freezing_point_c=-1.8, conductivity_ice_w_m_k=2.0, conductivity_snow_w_m_k=0.31,
                 form="damage", compliance_factor=1000.0):
        from forcing.base import SCALAR, as_field

        self.air_temperature = as_field(air_temperature, SCALAR, "degC")
        if self.air_temperature is None:
            raise ConfigError("healing.law = 'nextsim' needs [forcing.air_temperature]")
        self.th0_s = check_range("healing.params.th0_s", th0_s, 0.0, None, low_open=True, unit="s")
        self.delta_t0_k = check_range("healing.params.delta_t0_k", delta_t0_k, 0.0, None, low_open=True, unit="K")
        self.concentration_c = check_range("healing.params.concentration_c", concentration_c, 0.0, 100.0)
        self.freezing_point_c = check_range("healing.params.freezing_point_c", freezing_point_c, -10.0, 0.0,
                                            unit="degC")
        self.ki = check_range("healing.params.conductivity_ice_w_m_k", conductivity_ice_w_m_k, 0.0, None,
                              low_open=True)
        self.ks = check_range("healing.params.conductivity_snow_w_m_k", conductivity_snow_w_m_k, 0.0, None,
                              low_open=True)
        if form not in self.FORMS:
            raise ConfigError(f"healing.params.form = {form!r}; expected one of {list(self.FORMS)}")
        self.form = form
        self.compliance_factor = check_range("healing.params.compliance_factor", compliance_factor, 1.0, 1.0e6)

    def rate(self, air_temperature_c, thickness_m, concentration, snow_m=None):
        """H [s-1] per element."""
        h = np.maximum(np.asarray(thickness_m, np.float64), 1e-6)
        hs = 0.0 if snow_m is None else np.asarray(snow_m, np.float64)
        dT = np.maximum(self.freezing_point_c - np.asarray(air_temperature_c, np.float64), 0.0)
        dT = dT / (1.0 + self.ki * hs / (self.ks * h))
        rate = np.exp(-self.concentration_c * (1.0 - np.asarray(concentration, np.float64))) * dT / (
            self.th0_s * self.delta_t0_k)
        if self.form == "compliance":
            rate *= -self.compliance_factor  # χ = 1/(1 − d) heals at K H (damage_step's sign convention)
        return rate

    def element_rate(self, state, t_s):
        """H [s-1] per element of ``state`` at time ``t_s`` [s] (air temperature at the centroids).

        The air temperature comes through the field's shared centroid memo
        (:func:`thermo.model_adapters.air_at_centroids`): the thermodynamics evaluated it at
        the end of the previous step, at the same time and on the same node positions, so
        this step's healing rate reuses that array (the same values bit for bit) unless a
        remesh or a checkpoint load came between."""
        from thermo.model_adapters import air_at_centroids

        ta = air_at_centroids(self.air_temperature).values(state.mesh, t_s)
        return self.rate(ta, state.thickness, state.concentration, state.snow)


class NextsimHealingComponent(RateComponent):
    """Component ``healing`` of :class:`lagice.model.Model` with :class:`NextsimHealing`
    (``[healing] law = "nextsim"``): :meth:`rate` gives the stepper's per-element rate
    for d ← max(0, d − H dt). It holds no state of its own."""

    name = "healing"

    def __init__(self, law: NextsimHealing):
        self.law = law

    def rate(self, state, t_s):
        return self.law.element_rate(state, t_s)



#: keyword parameters of ``[healing.params]`` for ``law = "nextsim"``
NEXTSIM_HEALING_PARAMS = ("th0_s", "delta_t0_k", "concentration_c", "freezing_point_c", "conductivity_ice_w_m_k",
                          "conductivity_snow_w_m_k", "form", "compliance_factor")


def check_nextsim_healing_params(params: dict) -> None:
    """``[healing.params]`` of the nextsim law: unknown keys and out-of-range values raise
    ConfigError naming key, value and range (before any mesh work)."""
    for k in params:
        if k not in NEXTSIM_HEALING_PARAMS:
            raise ConfigError(f"unknown key healing.params.{k} for healing.law = 'nextsim'; known keys: "
                              f"{sorted(NEXTSIM_HEALING_PARAMS)}")
    NextsimHealing(-20.0, **params)
