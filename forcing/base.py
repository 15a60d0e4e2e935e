"""The field interface shared by every external forcing (docs/design.md §6).

A *field* is something that can be evaluated at a model time ``t`` (seconds
since the run's reference time) and at the **current** positions ``x, y`` of
the points that need it (metres in the model's projected plane, arrays of
shape ``(n,)``; usually mesh nodes for wind and ocean current, element
centroids for air temperature).

Conventions
-----------
* A **scalar** field returns a float64 array of shape ``(n,)``.
* A **vector** field returns a float64 array of shape ``(2, n)``: row 0 is
  the x component, row 1 the y component, both in the model's projected
  frame (m s-1 for wind and ocean current).
* Any Python callable ``f(t, x, y)`` is a valid field.  :func:`as_field`
  adapts it: a scalar callable may return a scalar or an ``(n,)`` array; a
  vector callable may return a tuple ``(u, v)`` (scalars or arrays) or an
  array of shape ``(2, n)``.  Plain numbers (scalar) and pairs of numbers
  (vector) become constant fields.
* :meth:`Field.prepare` is called once before a run with the run's time span
  and the initial positions.  It raises :class:`lagice.errors.ForcingError`
  if the field cannot deliver finite values over that span (records
  missing, mesh outside the grid, NaN in the data, ...).

``forcing`` knows nothing about solvers (STYLE.md); a model calls
:meth:`Forcing.evaluate` once per outer step.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lagice.errors import ConfigError, ForcingError

SCALAR = "scalar"
VECTOR = "vector"


class Field:
    """Base class of all forcing fields.

    Subclasses set :attr:`kind` (``"scalar"`` or ``"vector"``) and
    implement :meth:`evaluate`; :meth:`prepare` is optional.
    """

    kind: str = SCALAR
    #: Physical units of the values the field returns (documentation only).
    units: str = ""
    #: Human-readable name used in error messages (file path, callable name).
    name: str = "<field>"

    def evaluate(self, t, x, y, *, mesh_version=None, out=None):
        """Field values at time ``t`` [s] and positions ``x, y`` [m].

        Parameters
        ----------
        t : float
            Seconds since the run's reference time.
        x, y : ndarray, shape (n,)
            Current positions in the projected plane [m].
        mesh_version : hashable, optional
            Token that the caller changes whenever the positions change
            (see :class:`forcing.records.RecordField` for what it saves).
        out : ndarray, optional
            Output array of the right shape, filled in place and returned.

        Returns
        -------
        ndarray
            ``(n,)`` for scalar fields, ``(2, n)`` for vector fields.
        """
        raise NotImplementedError

    def prepare(self, t_start, t_end, x, y):
        """Check, before a run starts, that the field covers ``[t_start, t_end]``
        at positions ``x, y``; raise :class:`ForcingError` otherwise."""
        return None

    def __call__(self, t, x, y):
        return self.evaluate(t, x, y)


class ScalarField(Field):
    """A field returning an ``(n,)`` array (e.g. air temperature in °C)."""

    kind = SCALAR


class VectorField(Field):
    """A field returning a ``(2, n)`` array of x/y components (e.g. wind, m s-1)."""

    kind = VECTOR


def _shape_out(kind, n):
    return (n,) if kind == SCALAR else (2, n)


class ConstantField(Field):
    """A field constant in time and space.

    Parameters
    ----------
    value : float or (float, float)
        Scalar value, or ``(u, v)`` for a vector field.
    units : str
        Units of the value (documentation only).
    """

    def __init__(self, value, units=""):
        arr = np.asarray(value, dtype=np.float64)
        if arr.ndim == 0:
            self.kind = SCALAR
        elif arr.shape == (2,):
            self.kind = VECTOR
        else:
            raise ConfigError(f"constant field value {value!r} must be a number or a pair (u, v)")
        if not np.all(np.isfinite(arr)):
            raise ConfigError(f"constant field value {value!r} is not finite")
        self.value = arr
        self.units = units
        self.name = f"<constant {value!r}>"

    def evaluate(self, t, x, y, *, mesh_version=None, out=None):
        n = np.shape(x)[0]
        if out is None:
            out = np.empty(_shape_out(self.kind, n))
        if self.kind == SCALAR:
            out[:] = self.value
        else:
            out[0, :] = self.value[0]
            out[1, :] = self.value[1]
        return out


class CallableField(Field):
    """Adapter making any callable ``f(t, x, y)`` a field (see module docstring).

    Parameters
    ----------
    func : callable
        ``f(t, x, y)`` with ``t`` in seconds and ``x, y`` in metres.
    kind : {"scalar", "vector"}
    units : str
        Units of what ``func`` returns (documentation only).
    """

    def __init__(self, func, kind, units=""):
        if not callable(func):
            raise ConfigError(f"forcing {func!r} is not callable")
        if kind not in (SCALAR, VECTOR):
            raise ConfigError(f"field kind {kind!r} must be 'scalar' or 'vector'")
        self.func = func
        self.kind = kind
        self.units = units
        self.name = f"<callable {getattr(func, '__qualname__', repr(func))}>"

    def evaluate(self, t, x, y, *, mesh_version=None, out=None):
        n = np.shape(x)[0]
        res = self.func(t, x, y)
        shape = _shape_out(self.kind, n)
        try:
            if self.kind == VECTOR and isinstance(res, (tuple, list)):
                if len(res) != 2:
                    raise ValueError("expected a pair (u, v)")
                val = np.empty(shape)
                val[0] = np.broadcast_to(np.asarray(res[0], dtype=np.float64), (n,))
                val[1] = np.broadcast_to(np.asarray(res[1], dtype=np.float64), (n,))
            else:
                val = np.broadcast_to(np.asarray(res, dtype=np.float64), shape)
        except ValueError as exc:
            raise ForcingError(
                f"{self.name}: returned a value of shape {np.shape(res)} at t = {t} s; "
                f"expected a {self.kind} field of shape {shape} ({exc})") from None
        if out is None:
            out = np.empty(shape)
        out[...] = val
        return out

    def prepare(self, t_start, t_end, x, y):
        for t in (t_start, 0.5 * (t_start + t_end), t_end):
            val = self.evaluate(t, x, y)
            if not np.all(np.isfinite(val)):
                raise ForcingError(f"{self.name}: non-finite values at t = {t} s "
                                   f"(problem: NaN or inf in the forcing)")


def as_field(obj, kind, units=""):
    """Turn ``obj`` into a :class:`Field` of the given ``kind``.

    ``None`` stays ``None`` (component switched off); a :class:`Field` is
    checked for its kind; a number or pair becomes a :class:`ConstantField`;
    a callable becomes a :class:`CallableField`.
    """
    if obj is None:
        return None
    if isinstance(obj, Field):
        if obj.kind != kind:
            raise ConfigError(f"forcing {obj.name} is a {obj.kind} field; expected a {kind} field")
        return obj
    if callable(obj):
        return CallableField(obj, kind, units)
    field = ConstantField(obj, units)
    if field.kind != kind:
        raise ConfigError(f"forcing value {obj!r} is a {field.kind}; expected a {kind} field")
    return field


@dataclass
class ForcingValues:
    """Forcing at one time: ``wind`` and ``ocean`` ``(2, n_nodes)`` [m s-1],
    ``air_temperature`` ``(n_points,)`` [°C]; ``None`` for absent components."""

    wind: np.ndarray | None = None
    ocean: np.ndarray | None = None
    air_temperature: np.ndarray | None = None


class Forcing:
    """The external forcing of a model: wind, ocean current, air temperature.

    Each component is anything :func:`as_field` accepts, or ``None`` (absent:
    no work is done for it).

    Parameters
    ----------
    wind : vector field, m s-1 (10 m wind, projected x/y frame)
    ocean : vector field, m s-1 (surface current, projected x/y frame)
    air_temperature : scalar field, °C (2 m air temperature)
    """

    def __init__(self, wind=None, ocean=None, air_temperature=None):
        self.wind = as_field(wind, VECTOR, "m s-1")
        self.ocean = as_field(ocean, VECTOR, "m s-1")
        self.air_temperature = as_field(air_temperature, SCALAR, "degC")

    def components(self):
        """``{name: field}`` of the components that are present."""
        return {k: v for k, v in (("wind", self.wind), ("ocean", self.ocean),
                                  ("air_temperature", self.air_temperature)) if v is not None}

    def prepare(self, t_start, t_end, x, y, xc=None, yc=None):
        """Validate all components for a run over ``[t_start, t_end]`` [s].

        ``x, y``: node positions [m]; ``xc, yc``: element centroids [m] where
        the air temperature is needed (defaults to the nodes).
        """
        if not t_end >= t_start:
            raise ConfigError(f"run end time {t_end} s is before its start {t_start} s")
        for name, f in self.components().items():
            if name == "air_temperature" and xc is not None:
                f.prepare(t_start, t_end, xc, yc)
            else:
                f.prepare(t_start, t_end, x, y)

    def evaluate(self, t, x, y, xc=None, yc=None, *, mesh_version=None):
        """All present components at time ``t`` [s]; wind and ocean at the
        nodes ``x, y``, air temperature at ``xc, yc`` (default the nodes)."""
        vals = ForcingValues()
        if self.wind is not None:
            vals.wind = self.wind.evaluate(t, x, y, mesh_version=mesh_version)
        if self.ocean is not None:
            vals.ocean = self.ocean.evaluate(t, x, y, mesh_version=mesh_version)
        if self.air_temperature is not None:
            if xc is None:
                xc, yc = x, y
            vals.air_temperature = self.air_temperature.evaluate(t, xc, yc, mesh_version=mesh_version)
        return vals
