"""Durations and schedules: ``"6h"``, ``"1d"``, ``"30min"``, ``"90s"`` or seconds."""
from __future__ import annotations

import re

from .errors import ConfigError

_UNITS = {"s": 1.0, "sec": 1.0, "min": 60.0, "m": 60.0, "h": 3600.0, "hr": 3600.0, "d": 86400.0,
          "day": 86400.0, "days": 86400.0, "w": 604800.0}
_RE = re.compile(r"^\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*([a-z]*)\s*$")


def parse_duration(value, name: str = "duration") -> float:
    """Seconds from a number (seconds) or a string like ``"6h"``, ``"2.5d"``, ``"30min"``."""
    if isinstance(value, bool):
        raise ConfigError(f"{name} = {value!r}: expected a duration like '6h' or a number of seconds")
    if isinstance(value, (int, float)):
        sec = float(value)
    elif isinstance(value, str):
        m = _RE.match(value)
        if not m or (m.group(2) and m.group(2) not in _UNITS):
            raise ConfigError(f"{name} = {value!r}: expected a duration like '90s', '30min', '6h', '2d'")
        sec = float(m.group(1)) * _UNITS.get(m.group(2) or "s")
    else:
        raise ConfigError(f"{name} = {value!r}: expected a duration like '6h' or a number of seconds")
    if not sec > 0 or sec != sec or sec == float("inf"):
        raise ConfigError(f"{name} = {value!r}: must be a positive finite duration")
    return sec


class TimeInterval:
    """Fires when simulated time crosses a multiple of ``interval`` seconds."""

    def __init__(self, every, name="every"):
        self.interval = parse_duration(every, name)

    def due(self, t_prev: float, t_now: float) -> bool:
        """True when (t_prev, t_now] contains a multiple of the interval."""
        k_prev = int((t_prev + 1e-9 * self.interval) // self.interval)
        k_now = int((t_now + 1e-9 * self.interval) // self.interval)
        return k_now > k_prev
