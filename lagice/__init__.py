"""lagice: Lagrangian Maxwell-Elasto-Brittle sea-ice model."""
__version__ = "0.2.0"  # the one version source (pyproject.toml reads it)

import os as _os

# OpenMP workers (numba's "omp" threading layer, GNU libgomp) spin briefly after a parallel
# region, then sleep, unless the user chose a policy: read once when the OpenMP runtime loads,
# i.e. at the first parallel kernel, after this import. GOMP_SPINCOUNT sets the spin (libgomp:
# about 100 000 spins per ms, so ~0.1 ms; its default is 300 000, ~3 ms) and overrides the
# wait policy's spin; OMP_WAIT_POLICY=PASSIVE makes an oversubscribed pool (more threads than
# free CPUs) sleep at once. Measured on the 2-vCPU VM (docs/benchmarks.md): quiet, parallel
# sub-step loop at 50k elements 54-61 M element-sub-steps/s passive, 74-80 M/s with this
# spin; winter_basin 10 km, 2 days, 55 -> 77 M/s in the sub-step loop. Loaded (shared
# cores, load 4.5, default 3 ms spin): 3.6 M/s spinning against 17.8 M/s passive, which is
# why the spin is short; `solver.parallel = "auto"` picks the serial build there anyway.
if "GOMP_SPINCOUNT" not in _os.environ and "OMP_WAIT_POLICY" not in _os.environ:
    _os.environ["GOMP_SPINCOUNT"] = "10000"
_os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

# numba's disk cache keyed on all of the model's source (lagice/_numba_cache.py): numba keys a
# kernel on its own file only, so an edit to a function another module's kernel inlines would
# otherwise load a stale kernel. Before any kernel module is imported.
from . import _numba_cache  # noqa: E402

_numba_cache.configure()

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
