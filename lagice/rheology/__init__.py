"""Rheologies: what is solved (constitutive laws as functions of state; no mesh
loops, no time stepping). The time steppers that solve them are in
:mod:`lagice.solvers`.

* :class:`MaxwellEB` (:mod:`.maxwell_eb`): the Maxwell-Elasto-Brittle law of
  Dansereau et al. (2016), solved by the ``implicit`` and ``explicit`` steppers.
* :class:`ViscousPlastic` (:mod:`.viscous_plastic`): Hibler's (1979)
  viscous-plastic law, solved by the ``evp`` (mEVP) stepper; the comparison
  rheology of the validation report.
"""
from .maxwell_eb import (
    DAMAGE_UPDATE,
    MaxwellEB,
    _dcrit,
    damage_step,
    damage_update_kernel,
    dcrit,
    draw_cohesion,
    envelope,
    plane_stress_matrix,
    principal_stresses,
    relaxation_time,
    young_modulus,
)
from .viscous_plastic import ViscousPlastic, ViscousPlasticParams, ice_strength, vp_stress, vp_stress_of

#: rheology laws by the name used in scene files (``[rheology] law``)
RHEOLOGIES = {"maxwell_eb": MaxwellEB, "viscous_plastic": ViscousPlastic}

__all__ = ["MaxwellEB", "ViscousPlastic", "ViscousPlasticParams", "RHEOLOGIES", "DAMAGE_UPDATE", "_dcrit",
           "damage_step", "damage_update_kernel", "dcrit", "draw_cohesion", "envelope", "plane_stress_matrix",
           "principal_stresses", "relaxation_time", "young_modulus", "ice_strength", "vp_stress", "vp_stress_of"]
