"""Exception hierarchy of lagice.

Every error raised on bad input is a :class:`LagiceError` subclass whose
message names the offending parameter/file/field, its value and what was
expected, so that a user can fix the input without reading the code.
"""


class LagiceError(Exception):
    """Base class of all lagice errors."""


class ConfigError(LagiceError, ValueError):
    """A parameter or scene setting is invalid (name, value, valid range)."""


class MeshError(LagiceError):
    """A mesh or domain geometry is invalid, or mesh generation failed."""


class ForcingError(LagiceError):
    """A forcing field or file is invalid (file, variable, problem)."""


class RestartError(LagiceError):
    """A checkpoint is unreadable, truncated, corrupted or incompatible."""


class OutputError(LagiceError):
    """An output or checkpoint file could not be written (disk full, read-only folder)."""


class RunFolderLocked(LagiceError):
    """Another process holds the lock of a run folder (or the folder cannot be locked)."""


class SolverError(LagiceError):
    """A time step could not be completed (divergence, NaN, inverted element)."""


def check_range(name, value, low=None, high=None, *, low_open=False, high_open=False,
                unit="", error=ConfigError):
    """Raise ``error`` unless ``low (<|<=) value (<|<=) high``.

    The message names the parameter, its value and the valid range.
    Returns the value as float for convenience.
    """
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise error(f"{name} = {value!r} is not a number") from None
    bad = v != v  # NaN
    if low is not None:
        bad |= (v <= low) if low_open else (v < low)
    if high is not None:
        bad |= (v >= high) if high_open else (v > high)
    if bad:
        lo = "-inf" if low is None else f"{low:g}"
        hi = "inf" if high is None else f"{high:g}"
        rng = ("(" if low_open else "[") + f"{lo}, {hi}" + (")" if high_open else "]")
        u = f" {unit}" if unit else ""
        raise error(f"{name} = {value!r}{u} is out of range; expected a value in {rng}{u}")
    return v
