"""Thermodynamics and healing for lagice (docs/design.md §3).

A scene that does not need them builds none: :func:`build` returns ``None``
for a component that is switched off, and the model skips it (no work).
See ``docs/forcing_thermo.md``.
"""
from .air_temperature import synthetic_air_temperature
from .healing import ConstantHealing, FreezingDegreeDayHealing, Healing, ThermodynamicHealing, make_healing
from .model_adapters import HealingComponent, ThermoComponent
from .zero_layer import ThermoParams, ThermoTendencies, VolumeBudget, ZeroLayerThermo


def build(thermodynamics=False, healing=None, *, thermo_params=None, healing_params=None):
    """Build the thermodynamic components a scene asks for.

    Parameters
    ----------
    thermodynamics : bool
        True: a :class:`ZeroLayerThermo` with ``thermo_params`` (default
        :class:`ThermoParams`); False: ``None``.
    healing : {None, "constant", "thermodynamic", "fdd"}
        Healing law (see :mod:`thermo.healing`), ``None`` for no healing.
    thermo_params : ThermoParams, optional
    healing_params : dict, optional
        Keyword arguments of the healing class.

    Returns
    -------
    (ZeroLayerThermo or None, Healing or None)
    """
    zl = ZeroLayerThermo(thermo_params) if thermodynamics else None
    heal = make_healing(healing, **(healing_params or {}))
    return zl, heal


__all__ = [
    "synthetic_air_temperature", "Healing", "ConstantHealing", "ThermodynamicHealing",
    "FreezingDegreeDayHealing", "make_healing", "ThermoParams", "ThermoTendencies",
    "VolumeBudget", "ZeroLayerThermo", "build", "ThermoComponent", "HealingComponent",
]
