"""Type and range checks of free-form scene tables (``[forcing.*]`` generator
keywords, ``remesh.params``, ``thermo.params``, ``healing.params``,
``[forcing.drag]``), before any work.

The expected type of a keyword comes from an explicit spec (:data:`SPECS`), else
from the annotation or the default value of the function or dataclass that takes
it (a float default: a number; a pair default: ``[a, b]``; a bool default: a
boolean; a string default: a string). Ranges the functions check themselves
(``check_range``) are found by a dry run on a tiny grid (:mod:`.components`).
Every failure is a :class:`~lagice.errors.ConfigError` naming the key, the value
and what is expected.
"""
from __future__ import annotations

import dataclasses
import inspect
import math

from ..errors import ConfigError

NUMBER, INTEGER, BOOLEAN, STRING, PAIR, RANGE, DURATION = ("number", "integer", "boolean", "string", "pair",
                                                             "range", "duration")


@dataclasses.dataclass(frozen=True)
class Spec:
    """What a keyword accepts: ``kind`` (number, integer, boolean, string, pair:
    ``[a, b]`` of numbers, range: ``[low, high]`` with low <= high, duration),
    bounds ``low``/``high`` (inclusive unless ``low_open``/``high_open``), ``choices``
    (strings), ``unit`` (for messages)."""

    kind: str
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    choices: tuple = ()
    unit: str = ""


#: explicit specs by keyword name (they win over annotations and defaults)
SPECS = {
    "n": Spec(INTEGER, 0, None),
    "seed": Spec(INTEGER),
    "path": Spec(STRING),
    "u": Spec(STRING), "v": Spec(STRING), "name": Spec(STRING),
    "u_m_s": Spec(NUMBER, -20.0, 20.0, unit="m s-1"), "v_m_s": Spec(NUMBER, -20.0, 20.0, unit="m s-1"),
    "speed_m_s": Spec(NUMBER, 0.0, 150.0, unit="m s-1"),
    "mean_speed_m_s": Spec(NUMBER, 0.0, 150.0, unit="m s-1"),
    "speed_std_m_s": Spec(NUMBER, 0.0, 150.0, unit="m s-1"),
    "max_speed_m_s": Spec(NUMBER, 0.0, 150.0, unit="m s-1"),
    "translation_speed_max_m_s": Spec(NUMBER, 0.0, 150.0, unit="m s-1"),
    "radius_range_m": Spec(RANGE, 0.0, None, low_open=True, unit="m"),
    "max_speed_range_m_s": Spec(RANGE, 0.0, 150.0, unit="m s-1"),
    "lifetime_range_s": Spec(RANGE, 0.0, None, low_open=True, unit="s"),
    "inflow_angle_deg": Spec(NUMBER, -90.0, 90.0, unit="deg"),
    "anticyclone_fraction": Spec(NUMBER, 0.0, 1.0),
    "background_m_s": Spec(PAIR, -150.0, 150.0, unit="m s-1"),
    "gradient_k_per_1000km": Spec(PAIR, -100.0, 100.0, unit="K per 1000 km"),
    "interval_s": Spec(NUMBER, 0.0, None, low_open=True, unit="s"),
    "ramp_s": Spec(NUMBER, 0.0, None, unit="s"),
    "turn_duration_s": Spec(NUMBER, 0.0, None, unit="s"),
    "mean_c": Spec(NUMBER, -100.0, 60.0, unit="degC"),
    "value_c": Spec(NUMBER, -100.0, 60.0, unit="degC"),
    "start_day_of_year": Spec(NUMBER, 0.0, 366.0, unit="day"),
    "coldest_day_of_year": Spec(NUMBER, 0.0, 366.0, unit="day"),
    "horizon": Spec(DURATION),
    "time_extrapolation": Spec(STRING, choices=("error", "hold")),
    "space_extrapolation": Spec(STRING, choices=("error", "clamp")),
    "coords": Spec(STRING, choices=("auto", "lonlat", "xy")),
    "vector_frame": Spec(STRING, choices=("auto", "east_north", "xy")),
    "rebuild_tolerance_m": Spec(NUMBER, 0.0, None, unit="m"),
    "clockwise": Spec(BOOLEAN),
    # remesh.params options (lagice.remesh.remesh_if_needed)
    "rings": Spec(INTEGER, 0, None), "max_retries": Spec(INTEGER, 0, None),
    "max_patch_fraction": Spec(NUMBER, 0.0, 1.0, low_open=True),
    "algorithm": Spec(INTEGER, choices=(1, 2, 3, 5, 6, 7, 8, 9, 11)),
    "remap_method": Spec(STRING, choices=("auto", "clip", "celltree")),
    "damage_remap": Spec(STRING, choices=("area", "compliance")),
    "density_control": Spec(BOOLEAN), "density_tolerance": Spec(NUMBER, 0.0, 1.0),
}

_ANNOTATIONS = {"float": NUMBER, "int": INTEGER, "bool": BOOLEAN, "str": STRING}


def _fmt(v):
    return f"{v:g}" if isinstance(v, float) else str(v)


def _range_text(spec: Spec) -> str:
    if spec.low is None and spec.high is None:
        return ""
    lo = "-inf" if spec.low is None else _fmt(spec.low)
    hi = "inf" if spec.high is None else _fmt(spec.high)
    u = f" {spec.unit}" if spec.unit else ""
    return ("(" if spec.low_open else "[") + f"{lo}, {hi}" + (")" if spec.high_open else "]") + u


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _in_range(v, spec: Spec) -> bool:
    if spec.low is not None and (v <= spec.low if spec.low_open else v < spec.low):
        return False
    return not (spec.high is not None and (v >= spec.high if spec.high_open else v > spec.high))


def check_value(key: str, value, spec: Spec) -> None:
    """ConfigError naming ``key``, ``value`` and what ``spec`` expects, unless it fits."""
    rng = _range_text(spec)
    if spec.kind in (NUMBER, INTEGER):
        want = "a number" if spec.kind == NUMBER else "an integer"
        ok = _is_number(value) if spec.kind == NUMBER else (isinstance(value, int) and not isinstance(value, bool))
        if not ok:
            raise ConfigError(f"{key} = {value!r}: expected {want}{' in ' + rng if rng else ''}")
        if not _in_range(value, spec):
            raise ConfigError(f"{key} = {value!r}{' ' + spec.unit if spec.unit else ''} is out of range; "
                              f"expected {want} in {rng}")
    elif spec.kind == BOOLEAN:
        if not isinstance(value, bool):
            raise ConfigError(f"{key} = {value!r}: expected a boolean (true or false)")
    elif spec.kind == STRING:
        if not isinstance(value, str):
            raise ConfigError(f"{key} = {value!r}: expected a string")
    elif spec.kind in (PAIR, RANGE):
        what = "[x, y] pair of numbers" if spec.kind == PAIR else "[low, high] pair of numbers with low <= high"
        if not (isinstance(value, (list, tuple)) and len(value) == 2 and all(_is_number(v) for v in value)):
            raise ConfigError(f"{key} = {value!r}: expected a {what}{', each in ' + rng if rng else ''}")
        if not all(_in_range(v, spec) for v in value):
            raise ConfigError(f"{key} = {value!r}: expected a {what}, each in {rng}")
        if spec.kind == RANGE and value[0] > value[1]:
            raise ConfigError(f"{key} = {value!r}: expected [low, high] with low <= high (got low > high)")
    elif spec.kind == DURATION:
        from ..schedule import parse_duration

        parse_duration(value, key)
    else:  # pragma: no cover - a spec typo
        raise AssertionError(spec.kind)
    if spec.choices and value not in spec.choices:
        raise ConfigError(f"{key} = {value!r}: expected one of {list(spec.choices)}")


def spec_from(annotation, default) -> Spec | None:
    """The spec an annotation (``"float"``, ``"int | None"``...) or a default value implies, or None."""
    if isinstance(annotation, str):
        parts = [p.strip() for p in annotation.split("|") if p.strip() != "None"]
        if len(parts) == 1 and parts[0] in _ANNOTATIONS:
            return Spec(_ANNOTATIONS[parts[0]])
    elif annotation in (float, int, bool, str):
        return Spec(_ANNOTATIONS[annotation.__name__])
    if default is inspect.Parameter.empty or default is None:
        return None
    if isinstance(default, bool):
        return Spec(BOOLEAN)
    if isinstance(default, (int, float)):
        return Spec(NUMBER)
    if isinstance(default, str):
        return Spec(STRING)
    if isinstance(default, tuple) and len(default) == 2 and all(_is_number(v) for v in default):
        return Spec(PAIR)
    return None


def check_keywords(prefix: str, kw: dict, funcs, extra: dict | None = None) -> None:
    """Check each keyword of ``kw`` against :data:`SPECS`, ``extra`` specs, or the
    annotation/default of the parameter of that name in ``funcs``."""
    params = {}
    for f in funcs:
        for name, p in inspect.signature(f).parameters.items():
            params.setdefault(name, p)
    for k, v in kw.items():
        spec = (extra or {}).get(k) or SPECS.get(k)
        if spec is None and k in params:
            spec = spec_from(params[k].annotation, params[k].default)
        if spec is not None:
            check_value(f"{prefix}.{k}", v, spec)


def check_dataclass_params(prefix: str, cls, params: dict) -> None:
    """Unknown keys, then types from the dataclass field annotations, then the
    class's own range checks (``__post_init__``); errors name ``prefix.key``."""
    if not isinstance(params, dict):
        raise ConfigError(f"{prefix} = {params!r}: expected a table of parameters")
    fields = {f.name: f for f in dataclasses.fields(cls)}
    for k, v in params.items():
        if k not in fields:
            raise ConfigError(f"unknown key {prefix}.{k}; known keys: {sorted(fields)}")
        spec = SPECS.get(k) or spec_from(fields[k].type, fields[k].default)
        if spec is not None:
            check_value(f"{prefix}.{k}", v, spec)
    call_checked(prefix, cls, **params)


def call_checked(prefix: str, fn, *args, **kwargs):
    """``fn(*args, **kwargs)``; its ConfigError, TypeError or ValueError becomes a
    ConfigError prefixed with ``prefix`` (the table the values came from)."""
    try:
        return fn(*args, **kwargs)
    except ConfigError as exc:
        msg = str(exc)
        head = msg.split(" ", 1)[0]
        if head in kwargs:
            raise ConfigError(f"{prefix}.{msg}") from None
        raise ConfigError(f"{prefix}: {msg}") from None
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"{prefix}: {exc}") from None
