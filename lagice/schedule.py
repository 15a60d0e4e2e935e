"""Durations and schedules.

Durations: ``"6h"``, ``"1d"``, ``"30min"``, ``"90s"`` or a number of seconds.

A *schedule* decides, after each outer step, whether an activity of a
:class:`~lagice.simulation.Simulation` is due (Oceananigans-style: the schedule is
called with the model):

* :class:`TimeInterval` — every time simulated time crosses a multiple of an
  interval (``"6h"``, ``3600``);
* :class:`IterationInterval` — every N outer steps (``"10 steps"``);
* :class:`WallTimeInterval` — every so much wall-clock time (``"wall 55min"``),
  for batch queues;
* :class:`AnyOf` — due when any of several schedules is (``checkpoint.every`` and
  ``checkpoint.every_wall`` together); :class:`Never` — never due (an activity that
  only runs at the end of a run or when it is stopped).

:func:`parse_schedule` turns those strings into schedules.
"""
from __future__ import annotations

import re
import time

from .errors import ConfigError

_UNITS = {"s": 1.0, "sec": 1.0, "min": 60.0, "m": 60.0, "h": 3600.0, "hr": 3600.0, "d": 86400.0,
          "day": 86400.0, "days": 86400.0, "w": 604800.0}
_RE = re.compile(r"^\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*([a-z]*)\s*$")
_STEPS = re.compile(r"^\s*([0-9]+)\s*(steps?|iterations?|it)\s*$")
_WALL = re.compile(r"^\s*wall\s+(.+)$|^\s*(.+?)\s+wall\s*$")


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


class Schedule:
    """Base class: ``initialize(model)`` once before a run (or after a resume), then
    ``schedule(model)`` after every step returns True when the activity is due."""

    def initialize(self, model) -> None:
        pass

    def __call__(self, model) -> bool:
        raise NotImplementedError


class TimeInterval(Schedule):
    """Due whenever simulated time crosses a multiple of ``interval`` seconds."""

    def __init__(self, every, name="every"):
        self.interval = parse_duration(every, name)
        self._last = None

    def _k(self, t: float) -> int:
        return int((t + 1e-9 * self.interval) // self.interval)

    def initialize(self, model) -> None:
        self._last = self._k(model.clock.time_s)

    def due(self, t_prev: float, t_now: float) -> bool:
        """True when (t_prev, t_now] contains a multiple of the interval."""
        return self._k(t_now) > self._k(t_prev)

    def __call__(self, model) -> bool:
        k = self._k(model.clock.time_s)
        if self._last is None:
            self._last = k
            return False
        if k > self._last:
            self._last = k
            return True
        return False

    def __repr__(self):
        return f"TimeInterval({self.interval:g} s)"


class IterationInterval(Schedule):
    """Due every ``n`` outer steps (when the iteration count is a multiple of n)."""

    def __init__(self, n: int, name="every"):
        if isinstance(n, bool) or int(n) != n or int(n) < 1:
            raise ConfigError(f"{name} = {n!r} steps: expected an integer >= 1")
        self.n = int(n)

    def __call__(self, model) -> bool:
        return model.clock.iteration % self.n == 0

    def __repr__(self):
        return f"IterationInterval({self.n})"


class WallTimeInterval(Schedule):
    """Due once ``interval`` seconds of wall-clock time have passed since the last
    time it was due (or since the run, or its resumption, started)."""

    def __init__(self, every, name="every"):
        self.interval = parse_duration(every, name)
        self._last = None

    def initialize(self, model) -> None:
        self._last = time.perf_counter()

    def __call__(self, model) -> bool:
        now = time.perf_counter()
        if self._last is None:
            self._last = now
            return False
        if now - self._last >= self.interval:
            self._last = now
            return True
        return False

    def __repr__(self):
        return f"WallTimeInterval({self.interval:g} s)"


class Never(Schedule):
    """Never due (the activity runs only at the start, the end or a requested stop)."""

    def __call__(self, model) -> bool:
        return False

    def __repr__(self):
        return "Never()"


class AnyOf(Schedule):
    """Due when any of ``schedules`` is due (each is called every step, so each
    keeps its own state)."""

    def __init__(self, *schedules):
        self.schedules = [s for s in schedules if s is not None]

    def initialize(self, model) -> None:
        for s in self.schedules:
            s.initialize(model)

    def __call__(self, model) -> bool:
        due = [s(model) for s in self.schedules]
        return any(due)

    def __repr__(self):
        return f"AnyOf({', '.join(map(repr, self.schedules))})"


def parse_schedule(value, name: str = "every") -> Schedule:
    """A schedule from a :class:`Schedule`, a duration (``"6h"``, seconds: simulated
    time), ``"N steps"`` (iterations) or ``"wall 55min"`` / ``"55min wall"`` (wall time)."""
    if isinstance(value, Schedule):
        return value
    if value is None:
        return Never()
    if isinstance(value, str):
        m = _STEPS.match(value)
        if m:
            return IterationInterval(int(m.group(1)), name)
        m = _WALL.match(value)
        if m:
            return WallTimeInterval((m.group(1) or m.group(2)).strip(), name)
    return TimeInterval(value, name)
