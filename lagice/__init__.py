"""lagice: Lagrangian Maxwell-Elasto-Brittle sea-ice model."""
__version__ = "0.2.0"  # the one version source (pyproject.toml reads it)

import os as _os

# OpenMP workers (numba's "omp" threading layer) sleep instead of spinning between parallel
# regions unless the user chose otherwise: read once when the OpenMP runtime loads, i.e. at
# the first parallel kernel, after this import. Measured on the shared 2-core VM (load 4.5,
# winter_basin 10 km, parallel kernels on 2 threads): 3.6 M element-sub-steps/s with the
# default (spinning) policy, 17.8 M/s passive; thermodynamics 0.63 s -> 0.30 s per 6 h
# (spinning workers took CPU from the serial components). docs/benchmarks.md.
_os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

from .errors import (  # noqa: E402
    ConfigError,
    ForcingError,
    LagiceError,
    MeshError,
    OutputError,
    RestartError,
    SolverError,
)

__all__ = ["__version__", "LagiceError", "ConfigError", "MeshError", "ForcingError", "RestartError",
           "SolverError", "OutputError", "Model", "Simulation", "open_run", "Ensemble"]


def __getattr__(name):  # lazy: keep `import lagice` light
    if name == "Model":
        from .model import Model
        return Model
    if name == "Simulation":
        from .simulation import Simulation
        return Simulation
    if name == "open_run":
        from .io.run import open_run
        return open_run
    if name == "Ensemble":  # ensembles (lagice.ensemble, dask): imported on first use
        from .ensemble import Ensemble
        return Ensemble
    raise AttributeError(name)
