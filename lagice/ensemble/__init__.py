"""Ensembles and parameter sweeps on dask.distributed (``lagice ensemble``, docs/ensembles.md).

- :class:`Ensemble` — ``Ensemble.from_file(spec).run(client=None)`` returns the summary Dataset;
- :func:`load_spec` — parse and validate a spec (every member's config) without running;
- :func:`open_summary`, :func:`open_grids` (lazy, ``member`` dimension), :func:`spread`.

Names are imported on first use, so ``lagice.ensemble.command`` (the CLI
parser) stays light.
"""
import importlib

_WHERE = {
    "Ensemble": "core", "EnsembleSpec": "spec", "Member": "spec", "load_spec": "spec",
    "member_diagnostics": "member", "run_member": "member",
    "open_grids": "summary", "open_summary": "summary", "plot_spread": "summary", "spread": "summary",
}
__all__ = list(_WHERE)


def __getattr__(name):
    if name in _WHERE:
        return getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)
    raise AttributeError(f"module 'lagice.ensemble' has no attribute {name!r}")
