"""Physical parameters: one table with defaults, units and sources.

Values and sources follow ``docs/design.md`` §9 and Dansereau et al. 2016 Table 1.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

from .errors import ConfigError, check_range

#: Gravity-free physical constants shared by the forcing/thermo packages.
RHO_ICE = 900.0  # kg m-3, Dansereau et al. 2016 Table 1
RHO_AIR = 1.3  # kg m-3, Girard et al. 2011
RHO_WATER = 1025.0  # kg m-3, Girard et al. 2011
OMEGA_EARTH = 7.2921e-5  # rad s-1


#: stress-correction paths of :class:`MaxwellEBParams` (``rheology.stress_correction``)
STRESS_CORRECTIONS = ("origin", "mean_stress", "associated")
#: the stress the failure envelope judges (:attr:`MaxwellEBParams.failure_stress`)
FAILURE_STRESSES = ("nominal", "effective", "energy")
#: the power p of (1 − d) that multiplies an element's cohesion in the envelope, per
#: ``failure_stress`` (None: the cohesion is not scaled)
FAILURE_EXPONENT = {"nominal": None, "effective": 1.0, "energy": 0.5}


@dataclass(frozen=True)
class MaxwellEBParams:
    """Maxwell-Elasto-Brittle rheology parameters (Dansereau et al. 2016 Table 1).

    Attributes (units in brackets):
        poisson: ν [-], 0 <= ν < 0.5
        friction: μ internal friction coefficient [-]
        rho_ice: ice density [kg m-3]
        shear_wave_speed: cs [m s-1]; E0 = 2 cs² (1+ν) ρ unless ``young_modulus_pa`` given
        young_modulus_pa: undamaged E0 [Pa] (None: derived from cs)
        relaxation_time_s: undamaged λ0 [s]
        alpha: damage exponent α > 1 of η ∝ (1-d)^α [-]
        cohesion_min_pa, cohesion_max_pa: uniform range of cohesion C [Pa]
        healing_time_s: th of constant-rate healing [s] (None or inf: no healing)
        concentration_c: c* of exp(-c*(1-A)) [-]
        max_damage: damage cap below 1 keeping E > 0 [-]
        stress_correction: path that brings a super-critical stress back to the envelope:
            ``"origin"`` (Dansereau et al. 2016, neXtSIM: the whole tensor scaled towards 0)
            or ``"mean_stress"`` (towards θ times the mean normal stress; θ = 1: only the
            deviatoric part scaled, the mean kept; the implicit solver and the explicit
            stepper, CPU and CUDA; docs/physics.md, compression test) or ``"associated"`` (along K n, n
            the envelope's normal: the return of an associated plasticity; implicit solver
            only)
        stress_correction_mean_fraction: θ ∈ (0, 2] of ``"mean_stress"`` (None: 1) [-]; θ > 1
            returns towards a pressure above the element's own, so the inelastic strain dilates
            (sin ψ = (θ − 1)(1 − ν)/(1 + ν) in uniaxial compression; docs/physics.md §4)
        max_pressure_pa: P* of neXtSIM's compressive term [Pa] (None or 0: off). Where the mean
            normal stress is compressive, −σn > 0, the Maxwell relaxation acts only on the part
            above P_max = P* (h / 1 m)^k exp(−c*(1−A)): the relaxation factor becomes
            λ/(λ + Δt (1 − P̃)) with P̃ = min(1, P_max/(−σn)), so weakly compressed ice is
            elastic (no creep) and ice above P_max relaxes towards it (ridging). neXtSIM's
            ``dynamics.compression_factor`` = 10 kPa, ``exponent_compression_factor`` = 1.5
            (``model/finiteelement.cpp``, ``updateSigmaDamage``); explicit stepper only (CPU and CUDA)
        max_pressure_thickness_exponent: k of P_max [-] (neXtSIM: 1.5)
        relax_mean_stress: True (Dansereau et al. 2016, neXtSIM): the Maxwell relaxation σ/λ acts
            on the whole stress, so damaged ice creeps in convergence as freely as in shear.
            False (a diagnostic of lagice, 2026-11-27; docs/physics.md §4, "Where β is lost, and
            damaged ice that keeps its pressure"): it acts on the deviatoric stress σ − m I only, m = (σ1 + σ2)/2, and
            the mean normal stress of damaged ice does not creep; with ``max_pressure_pa`` set the
            mean takes the compressive term's factor above (it creeps where it is tensile or
            compressive beyond P_max). The ice then converges elastically, at damage events or
            above P_max. Explicit stepper only (CPU and CUDA)
        bulk_shear_viscosity_ratio: ζ/η [-] of the Maxwell viscous flow (None: the default, the
            whole stress relaxes with one λ, so ζ/η = K/G = (1 + ν)/(1 − ν), 1.86 at ν = 0.3, as in
            Dansereau et al. 2016). Set, the mean stress relaxes with λ_m = r λ, r = (ζ/η)(1 − ν)/(1 + ν),
            and the deviator with λ, so that the bulk viscosity K λ_m is ζ/η times the shear
            viscosity G λ: Hibler's (1979) viscous-plastic ratio is e² = 4. Large ratios approach
            the kept mean stress and its volumetric locking (docs/solvers.md). A diagnostic of
            lagice (2026-11-28, thirtieth session); explicit CPU stepper only, with the whole stress
            relaxing (relax_mean_stress true). With ``max_pressure_pa`` (since the thirty-eighth
            session) the compressive term's 1 − P̃ multiplies Δt_s in both parts' relaxation
            factors, λ/(λ + Δt_s (1 − P̃)) and λ_m/(λ_m + Δt_s (1 − P̃))
        dilatancy_angle_deg: ψ [degrees] ∈ [0, 45) of a dilatant Maxwell viscous flow (None or 0:
            off, the default; a diagnostic of lagice, 2026-11-27; docs/physics.md §4, "Broken ice
            that dilates as it shears"). The viscous (permanent) strain rate K⁻¹σ/(Eλ) of
            Dansereau et al. (2016) gets an isotropic part, so that its divergence is sin ψ
            times its shear rate, as the Reynolds dilatancy of a granular material (Tremblay
            and Mysak 1997 for sea ice; ψ = 0 is their incompressible flow). Where the ice
            cannot open, the flow builds a pressure k_ψ r, k_ψ = sin ψ (1 + ν)/(1 − ν), r the
            radius of Mohr's circle. Explicit stepper only (CPU and CUDA), with ``relax_mean_stress`` true
            and no ``max_pressure_pa``
        damage_nonlocal_radius_m: R [m] of the nonlocal damage (None or 0: off, the default, the
            local scheme of Dansereau et al. 2016; issue 12 item 4, docs/physics.md §3): the load
            ratio that drives damage is averaged over the element centroids within R with the
            bell-shaped weight of Bažant and Jirásek (2002), so a crack is at least about R wide
            whatever the mesh (:mod:`lagice.solvers.nonlocal_damage`). Explicit CPU stepper only,
            with the default stress path (origin correction, whole stress relaxing, no
            compressive term, no dilatancy); with any ``failure_stress`` (since 2026-12-02: the
            ratio averaged is then the effective stress's)
        damage_length_m: ℓ [m] of the damage time td = ℓ/cs, the same for every element (None or 0:
            off, the default: td = Δx/cs with Δx = √(2 A) the element's own size, Dansereau et al.
            2016 §3.1.1, as neXtSIM does). A rate-dependent damage law has a length of its own, the
            distance an elastic wave runs while an element damages (Needleman 1988, "Material rate
            dependence and mesh sensitivity in localization problems", Comput. Methods Appl. Mech.
            Eng. 67): td = Δx/cs makes that length the element's, so it halves with the mesh; a fixed
            ℓ keeps it in kilometres. A diagnostic of lagice (2026-11-30, forty-fourth session;
            docs/physics.md §4, "A damage time of fixed length"); ℓ has no sea-ice source. Explicit
            CPU stepper and implicit solver
        crack_band_length_m: ℓ [m] of a crack-band scaling of the Maxwell viscous flow (None or 0:
            off, the default: λ = λ0 ((1 − d) g)^(α−1) on every element, Dansereau et al. 2016).
            Set, each element's relaxation time is multiplied by Δx/ℓ, Δx = √(2 A) its size, so its
            viscosity E λ is proportional to its size. A damage band is one element wide, and the
            slip rate across it is its width times its viscous strain rate, Δx σ/(E λ): with the
            scaling, a band of any width slips at a given stress and damage as a band ℓ wide does
            without it, the idea of the crack band of Bažant and Oh (1983, "Crack band theory for
            fracture of concrete", Matériaux et Constructions 16), where the softening of an
            element is scaled with its size so that a crack dissipates the same energy per unit
            length on any mesh. Only the viscous flow is scaled, not the damaged modulus, so the
            elastic wave speed and the sub-step limit are unchanged. Intact ice (λ0 = 1e7 s)
            creeps negligibly with or without it. A diagnostic of lagice (2026-11-30,
            forty-fifth session; docs/physics.md §4, "A crack band for the viscous flow"); ℓ has
            no sea-ice source. Explicit CPU stepper only, with the local damage (no
            ``damage_nonlocal_radius_m``)
        failure_stress: the stress the Mohr-Coulomb envelope judges. ``"nominal"`` (Dansereau et
            al. 2016, neXtSIM; the default): σ itself, so damaged ice fails at the strength of
            intact ice. ``"effective"`` (a diagnostic of lagice, 2026-11-28; docs/physics.md §4,
            "Broken ice that keeps no cohesion"): the effective stress σ/(1 − d) of continuum
            damage mechanics (Kachanov 1958; Lemaitre 1985), so the cohesion and the tensile
            strength of an element are C (1 − d) and the friction μ is kept: broken ice holds by
            friction alone, as a fault does. Explicit CPU stepper (local or nonlocal damage) and
            implicit solver (local damage). ``"energy"`` (a diagnostic of
            lagice, 2026-11-30; docs/physics.md §4, "Broken ice that keeps part of its cohesion"):
            the effective stress of the hypothesis of strain-energy equivalence (Cordebois and
            Sidoroff 1982): with lagice's modulus E0 (1 − d) that effective stress is σ/√(1 − d),
            so the cohesion and tensile strength are C √(1 − d), friction kept. Explicit CPU
            stepper (local or nonlocal damage) and implicit solver (local damage)
        crack_closure: False (Dansereau et al. 2016, neXtSIM; the default): damage lowers the
            modulus for every strain. True (a diagnostic of lagice, 2026-11-28; docs/physics.md §4,
            "Broken ice whose cracks close"): quasi-unilateral damage (Ladevèze and Lemaitre 1984,
            "Damage effective stress in quasi unilateral conditions", 16th ICTAM; Mazars 1986): the
            cracks of damaged ice close under compression, so the mean normal stress of an
            element whose mean stress is compressive changes with the undamaged modulus E0
            exp(−c*(1 − A)) (the concentration factor kept, so an open lead closes freely), and
            with the damaged one where it is tensile; the deviator keeps the damaged modulus.
            Only with ``relax_mean_stress`` false (the mean stress must not creep away as it is
            built); explicit CPU stepper only
    """

    poisson: float = 0.3
    friction: float = 0.7
    rho_ice: float = RHO_ICE
    shear_wave_speed: float = 500.0
    young_modulus_pa: float | None = None
    relaxation_time_s: float = 1.0e7
    alpha: float = 4.0
    cohesion_min_pa: float = 25.0e3
    cohesion_max_pa: float = 50.0e3
    healing_time_s: float | None = 1.0e5
    concentration_c: float = 20.0
    max_damage: float = 1.0 - 1.0e-6
    stress_correction: str = "origin"
    stress_correction_mean_fraction: float | None = None
    max_pressure_pa: float | None = None
    max_pressure_thickness_exponent: float = 1.5
    relax_mean_stress: bool = True
    dilatancy_angle_deg: float | None = None
    damage_nonlocal_radius_m: float | None = None
    damage_length_m: float | None = None
    crack_band_length_m: float | None = None
    failure_stress: str = "nominal"
    crack_closure: bool = False
    bulk_shear_viscosity_ratio: float | None = None

    def __post_init__(self):
        check_range("poisson (ν)", self.poisson, 0.0, 0.5, high_open=True)
        check_range("friction (μ)", self.friction, 0.0, None)
        check_range("rho_ice", self.rho_ice, 0.0, None, low_open=True, unit="kg m-3")
        check_range("shear_wave_speed", self.shear_wave_speed, 0.0, None, low_open=True, unit="m s-1")
        if self.young_modulus_pa is not None:
            check_range("young_modulus_pa (E0)", self.young_modulus_pa, 0.0, None, low_open=True, unit="Pa")
        check_range("relaxation_time_s (λ0)", self.relaxation_time_s, 0.0, None, low_open=True, unit="s")
        check_range("alpha (α)", self.alpha, 1.0, None, low_open=True)
        check_range("cohesion_min_pa", self.cohesion_min_pa, 0.0, None, unit="Pa")
        check_range("cohesion_max_pa", self.cohesion_max_pa, self.cohesion_min_pa, None, unit="Pa")
        if self.healing_time_s is not None:
            check_range("healing_time_s (th)", self.healing_time_s, 0.0, None, low_open=True, unit="s")
        check_range("concentration_c (c*)", self.concentration_c, 0.0, None)
        check_range("max_damage", self.max_damage, 0.0, 1.0, high_open=True)
        if self.max_pressure_pa is not None:
            check_range("max_pressure_pa (P*)", self.max_pressure_pa, 0.0, 1e7, unit="Pa")
        check_range("max_pressure_thickness_exponent (k)", self.max_pressure_thickness_exponent, 0.0, 3.0)
        if not isinstance(self.relax_mean_stress, bool):
            raise ConfigError(f"rheology.relax_mean_stress = {self.relax_mean_stress!r}: expected true or false")
        if self.dilatancy_angle_deg:
            check_range("dilatancy_angle_deg (ψ)", self.dilatancy_angle_deg, 0.0, 45.0, high_open=True,
                        unit="degrees")
            if not self.relax_mean_stress or self.max_pressure_pa:
                raise ConfigError(f"rheology.dilatancy_angle_deg = {self.dilatancy_angle_deg!r} is implemented "
                                  f"with the whole stress relaxing and no compressive term only; it is set with "
                                  f"relax_mean_stress = {str(self.relax_mean_stress).lower()}, max_pressure_pa = "
                                  f"{self.max_pressure_pa!r}")
        if self.damage_nonlocal_radius_m:
            check_range("damage_nonlocal_radius_m (R)", self.damage_nonlocal_radius_m, 0.0, 1.0e6, low_open=True,
                        unit="m")
            others = {"stress_correction": self.stress_correction, "relax_mean_stress": self.relax_mean_stress,
                      "max_pressure_pa": self.max_pressure_pa, "dilatancy_angle_deg": self.dilatancy_angle_deg}
            if (self.stress_correction != "origin" or not self.relax_mean_stress or self.max_pressure_pa
                    or self.dilatancy_angle_deg):
                raise ConfigError(f"rheology.damage_nonlocal_radius_m = {self.damage_nonlocal_radius_m!r} is "
                                  f"implemented with the default stress path only (stress_correction = 'origin', "
                                  f"relax_mean_stress = true, no max_pressure_pa, no dilatancy_angle_deg); it is "
                                  f"set with {others}")
        if self.damage_length_m:
            check_range("damage_length_m (ℓ of td = ℓ/cs)", self.damage_length_m, 0.0, 1.0e6, low_open=True,
                        unit="m")
        if self.crack_band_length_m:
            check_range("crack_band_length_m (ℓ of λ Δx/ℓ)", self.crack_band_length_m, 0.0, 1.0e6, low_open=True,
                        unit="m")
            if self.damage_nonlocal_radius_m:
                raise ConfigError(f"rheology.crack_band_length_m = {self.crack_band_length_m!r} is implemented "
                                  f"with the local damage only; it is set with damage_nonlocal_radius_m = "
                                  f"{self.damage_nonlocal_radius_m!r} m")
        if self.failure_stress not in FAILURE_STRESSES:
            raise ConfigError(f"rheology.failure_stress = {self.failure_stress!r}: expected one of "
                              f"{list(FAILURE_STRESSES)}")
        if not isinstance(self.crack_closure, bool):
            raise ConfigError(f"rheology.crack_closure = {self.crack_closure!r}: expected true or false")
        if self.crack_closure and self.relax_mean_stress:
            raise ConfigError("rheology.crack_closure = true needs rheology.relax_mean_stress = false: the closed "
                              "cracks build the mean stress with the undamaged modulus, and a relaxing mean stress "
                              "would creep away as it is built")
        if self.bulk_shear_viscosity_ratio is not None:
            check_range("bulk_shear_viscosity_ratio (ζ/η)", self.bulk_shear_viscosity_ratio, 0.0, 1.0e6,
                        low_open=True)
            others = {"relax_mean_stress": self.relax_mean_stress,
                      "dilatancy_angle_deg": self.dilatancy_angle_deg,
                      "damage_nonlocal_radius_m": self.damage_nonlocal_radius_m}
            if not self.relax_mean_stress or self.dilatancy_angle_deg or self.damage_nonlocal_radius_m:
                raise ConfigError(f"rheology.bulk_shear_viscosity_ratio = {self.bulk_shear_viscosity_ratio!r} is "
                                  f"implemented with the whole stress relaxing only (relax_mean_stress = true, no "
                                  f"dilatancy_angle_deg or damage_nonlocal_radius_m; max_pressure_pa may be set); "
                                  f"it is set with {others}")
        if self.stress_correction not in STRESS_CORRECTIONS:
            raise ConfigError(f"rheology.stress_correction = {self.stress_correction!r}: expected one of "
                              f"{list(STRESS_CORRECTIONS)}")
        if self.stress_correction_mean_fraction is not None:
            if self.stress_correction != "mean_stress":
                theta = self.stress_correction_mean_fraction
                raise ConfigError(f"rheology.stress_correction_mean_fraction = {theta!r} applies to "
                                  f"stress_correction = 'mean_stress' only (it is {self.stress_correction!r})")
            check_range("stress_correction_mean_fraction (θ)", self.stress_correction_mean_fraction, 0.0, 2.0,
                        low_open=True)

    @property
    def mean_fraction(self) -> float:
        """θ of the damage stress correction: 0 for the origin path (Dansereau et al. 2016)."""
        if self.stress_correction in ("origin", "associated"):
            return 0.0
        return 1.0 if self.stress_correction_mean_fraction is None else float(self.stress_correction_mean_fraction)

    def optional_terms(self) -> dict:
        """The optional terms set away from their defaults, key → value (not every stepper
        implements each: :data:`lagice.rheology.maxwell_eb.OPTIONAL_TERMS`)."""
        out = {}
        if self.max_pressure_pa:
            out["max_pressure_pa"] = self.max_pressure_pa
        if not self.relax_mean_stress:
            out["relax_mean_stress"] = self.relax_mean_stress
        if self.dilatancy_angle_deg:
            out["dilatancy_angle_deg"] = self.dilatancy_angle_deg
        if self.damage_nonlocal_radius_m:
            out["damage_nonlocal_radius_m"] = self.damage_nonlocal_radius_m
        if self.damage_length_m:
            out["damage_length_m"] = self.damage_length_m
        if self.crack_band_length_m:
            out["crack_band_length_m"] = self.crack_band_length_m
        if self.failure_stress != "nominal":
            out["failure_stress"] = self.failure_stress
        if self.crack_closure:
            out["crack_closure"] = True
        if self.bulk_shear_viscosity_ratio is not None:
            out["bulk_shear_viscosity_ratio"] = self.bulk_shear_viscosity_ratio
        return out

    @property
    def dilatancy_factor(self) -> float | None:
        """k_ψ = sin ψ (1 + ν)/(1 − ν) of the dilatant viscous flow, or None when it is off."""
        if not self.dilatancy_angle_deg:
            return None
        return math.sin(math.radians(self.dilatancy_angle_deg)) * (1.0 + self.poisson) / (1.0 - self.poisson)

    @property
    def E0(self) -> float:
        """Undamaged Young modulus [Pa]: E0 = 2 cs² (1+ν) ρ (Dansereau et al. 2016 Table 1)."""
        if self.young_modulus_pa is not None:
            return float(self.young_modulus_pa)
        return 2.0 * self.shear_wave_speed**2 * (1.0 + self.poisson) * self.rho_ice

    @property
    def q(self) -> float:
        """Slope of the Mohr-Coulomb envelope, Dansereau et al. 2016 eq. 3."""
        return (math.sqrt(self.friction**2 + 1.0) + self.friction) ** 2

    def replace(self, **changes) -> MaxwellEBParams:
        names = {f.name for f in fields(self)}
        for k in changes:
            if k not in names:
                raise ConfigError(f"unknown rheology parameter {k!r}; known: {sorted(names)}")
        return replace(self, **changes)


@dataclass(frozen=True)
class DragParams:
    """Air/ocean drag and Coriolis parameters (Girard et al. 2011; docs/design.md §9)."""

    rho_air: float = RHO_AIR
    air_drag: float = 1.2e-3
    rho_water: float = RHO_WATER
    water_drag: float = 5.5e-3
    turning_angle_deg: float = 0.0
    coriolis_f: float = 0.0  # s-1; use coriolis_from_latitude for f(lat)
    #: floor on |Uw − u| [m s-1] in the implicit stepper's drag linearisation (0: none)
    ocean_drag_min_speed_m_s: float = 0.0


def coriolis_from_latitude(lat_deg: float) -> float:
    """Coriolis parameter f = 2 Ω sin(lat) [s-1]."""
    return 2.0 * OMEGA_EARTH * math.sin(math.radians(lat_deg))
