"""The model clock: simulated time and iteration count, owned by the
:class:`~lagice.model.Model` (time steppers never advance time)."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass
class Clock:
    """Simulated time [s] since the run's start date and completed outer steps."""

    time_s: float = 0.0
    iteration: int = 0

    def tick(self, dt_s: float) -> None:
        """One outer step of ``dt_s`` [s] is complete."""
        self.time_s += dt_s
        self.iteration += 1

    def as_dict(self) -> dict:
        return {"time_s": self.time_s, "iteration": self.iteration}
