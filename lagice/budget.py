"""The ice-volume ledger: one book that every process changing the ice volume
writes into, so the budget closes exactly (docs/design.md, "Conservation").

    V(t) − V(0) = Σ booked changes + residual

Mesh motion books the volume that leaves through open boundaries
(``"outflow"``, negative), thermodynamics its growth, melt, new ice in leads
and the thickness floor (``"thermo"``, signed). Remapping and mesh motion
inside the domain book nothing: they conserve the volume, so the residual
measures their round-off.
"""
from __future__ import annotations

#: prefixes of the booked terms: thermodynamic sources and open-boundary outflow
THERMO = "thermo"
OUTFLOW = "outflow"


class VolumeLedger:
    """Signed changes of the ice volume [m³] by process, from an initial volume."""

    def __init__(self, initial_m3: float | None = None):
        self.initial_m3 = None if initial_m3 is None else float(initial_m3)
        self.terms: dict[str, float] = {}

    def start(self, volume_m3: float) -> None:
        """Set V(0) once (a resumed run keeps its original V(0))."""
        if self.initial_m3 is None:
            self.initial_m3 = float(volume_m3)

    def book(self, term: str, change_m3: float) -> None:
        """Add a signed change of the ice volume [m³] (outflow < 0, growth > 0)."""
        self.terms[term] = self.terms.get(term, 0.0) + float(change_m3)

    def total(self, prefix: str = "") -> float:
        return float(sum(v for k, v in self.terms.items() if k.startswith(prefix)))

    def budget(self, current_m3: float) -> dict:
        """``initial_m3, current_m3, thermodynamic_m3`` (net growth), ``outflow_m3``
        (> 0 when ice left), ``residual_m3`` and ``relative_residual``."""
        v0 = self.initial_m3 if self.initial_m3 is not None else float(current_m3)
        thermo = self.total(THERMO)
        outflow = 0.0 - self.total(OUTFLOW)
        res = float(current_m3) - v0 - self.total()
        return {"initial_m3": v0, "current_m3": float(current_m3), "thermodynamic_m3": thermo,
                "outflow_m3": outflow, "residual_m3": res, "relative_residual": res / v0 if v0 else 0.0,
                "terms": dict(self.terms)}

    def as_dict(self) -> dict:
        return {"initial_m3": self.initial_m3, "terms": dict(self.terms)}

    @classmethod
    def from_dict(cls, d: dict) -> VolumeLedger:
        led = cls(d.get("initial_m3"))
        led.terms = {k: float(v) for k, v in d.get("terms", {}).items()}
        return led
