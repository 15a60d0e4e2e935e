"""External forcing for lagice: wind, ocean current, air temperature (docs/design.md §6).

See ``docs/forcing_thermo.md`` for the expected use.
"""
from .base import CallableField, ConstantField, Field, Forcing, ForcingValues, ScalarField, VectorField, as_field
from .gridded import GriddedRecords, open_air_temperature, open_gridded, open_ocean_current, open_wind
from .records import InMemoryRecords, LonLatGrid, RecordField, RegularGrid
from .synthetic import (
                   Cyclone,
                   cyclone_wind,
                   eddy_current,
                   gyre_current,
                   ocean_at_rest,
                   random_cyclones,
                   random_wind,
                   record_times,
                   uniform_current,
                   uniform_wind,
)

__all__ = [
    "Field", "ScalarField", "VectorField", "ConstantField", "CallableField", "as_field",
    "Forcing", "ForcingValues",
    "RegularGrid", "LonLatGrid", "InMemoryRecords", "RecordField",
    "GriddedRecords", "open_gridded", "open_wind", "open_air_temperature", "open_ocean_current",
    "record_times", "uniform_wind", "random_wind", "Cyclone", "random_cyclones", "cyclone_wind",
    "ocean_at_rest", "uniform_current", "gyre_current", "eddy_current",
]
