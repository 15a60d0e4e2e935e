"""Argument validation shared by the diagnostics (plain-array data model).

Every failure raises :class:`lagice.errors.ConfigError` naming the argument,
the offending value or shape, and what was expected.
"""

import numpy as np

from lagice.errors import ConfigError, check_range


def as_points(name, value, n_nodes=None):
    """Return ``value`` as a finite float64 array of shape ``(n, 2)`` (metres or m s-1)."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ConfigError(f"{name} must be a numeric array of shape (n_nodes, 2); got {value!r:.80}") from None
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ConfigError(f"{name} must have shape (n_nodes, 2); got shape {arr.shape}")
    if n_nodes is not None and arr.shape[0] != n_nodes:
        raise ConfigError(f"{name} has {arr.shape[0]} nodes; expected {n_nodes} (same as nodes_xy0)")
    if not np.all(np.isfinite(arr)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(arr), axis=1))[0])
        raise ConfigError(f"{name} contains non-finite values (first at node {bad}: {arr[bad].tolist()})")
    return arr


def as_triangles(value, n_nodes):
    """Return ``value`` as an int64 array of shape ``(m, 3)`` with indices in ``[0, n_nodes)``."""
    arr = np.asarray(value)
    if arr.ndim != 2 or arr.shape[1] != 3 or arr.shape[0] == 0:
        raise ConfigError(f"triangles must have shape (n_elements, 3) with n_elements >= 1; got shape {arr.shape}")
    if not np.issubdtype(arr.dtype, np.integer):
        raise ConfigError(f"triangles must hold integer node indices; got dtype {arr.dtype}")
    arr = arr.astype(np.int64, copy=False)
    lo, hi = int(arr.min()), int(arr.max())
    if lo < 0 or hi >= n_nodes:
        raise ConfigError(f"triangles index nodes in [{lo}, {hi}]; expected indices in [0, {n_nodes - 1}]")
    return arr


def positive(name, value, unit=""):
    """Return ``value`` as a float, requiring ``0 < value < inf``."""
    v = check_range(name, value, 0.0, None, low_open=True, unit=unit)
    if not np.isfinite(v):
        raise ConfigError(f"{name} = {value!r} {unit} must be finite".rstrip())
    return v


def choice(name, value, allowed):
    """Return ``value`` if it is one of ``allowed``."""
    if value not in allowed:
        raise ConfigError(f"{name} = {value!r}; expected one of {sorted(allowed)}")
    return value


def values_1d(name, value, size=None):
    """Return ``value`` as a finite 1-D float64 array (optionally of given size)."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ConfigError(f"{name} must be a 1-D numeric array") from None
    if arr.ndim != 1:
        raise ConfigError(f"{name} must be 1-D; got shape {arr.shape}")
    if size is not None and arr.shape[0] != size:
        raise ConfigError(f"{name} has {arr.shape[0]} values; expected {size}")
    if not np.all(np.isfinite(arr)):
        raise ConfigError(f"{name} contains non-finite values")
    return arr
