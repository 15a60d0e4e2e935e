"""lagice: Lagrangian Maxwell-Elasto-Brittle sea-ice model."""
__version__ = "0.2.0"  # the one version source (pyproject.toml reads it)

from .errors import ConfigError, ForcingError, LagiceError, MeshError, RestartError, SolverError  # noqa: E402

__all__ = ["__version__", "LagiceError", "ConfigError", "MeshError", "ForcingError", "RestartError",
           "SolverError", "Model", "Simulation"]


def __getattr__(name):  # lazy: keep `import lagice` light
    if name == "Model":
        from .model import Model
        return Model
    if name == "Simulation":
        from .simulation import Simulation
        return Simulation
    raise AttributeError(name)
