"""lagice: Lagrangian Maxwell-Elasto-Brittle sea-ice model."""
__version__ = "0.2.0"  # the one version source (pyproject.toml reads it)

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
