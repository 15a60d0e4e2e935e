"""The component protocol: optional processes a :class:`~lagice.model.Model`
advances after its time stepper in every outer step.

Built-in components (each is built only when a scene asks for it, and costs
nothing otherwise):

============== ======================================== ==========================
name           class                                    what it does per step
============== ======================================== ==========================
drifters       :class:`lagice.drifters.Drifters`        move buoys with the ice
mesh_motion    :class:`lagice.lagrangian.MeshMotion`    move the nodes, keep mass
thermodynamics :class:`thermo.model_adapters.ThermoComponent` growth, melt, new ice
remeshing      :class:`lagice.remesh.Remesher`          remesh distorted patches
healing        :class:`thermo.model_adapters.HealingComponent` healing rate for the stepper
============== ======================================== ==========================

``advance`` is called with the model at the start of the step (``model.clock``
not yet advanced) after the stepper has updated velocity, stress and damage;
components read the transport velocity from ``model.transport_velocity``.
"""
from __future__ import annotations

from typing import Protocol, runtime_checkable

#: the order in which a model advances its components (drifters first: they are
#: located in the mesh before it moves, so they keep their barycentric position)
ORDER = ("drifters", "mesh_motion", "thermodynamics", "remeshing")


@runtime_checkable
class Component(Protocol):
    """A process advanced once per outer step, with state carried in checkpoints."""

    name: str

    def advance(self, model, dt_s: float):
        """Advance over [t, t + dt_s] (t = ``model.clock.time_s``); returns a report."""

    def checkpoint_state(self) -> tuple[dict, dict]:
        """``(arrays, meta)``: numpy arrays and a JSON-able dict that restore this component."""

    def restore(self, arrays: dict, meta: dict) -> None:
        """Restore what :meth:`checkpoint_state` returned."""


class RateComponent:
    """Base of components that only provide a rate the stepper applies (healing laws):
    nothing to advance, no state of their own. Subclasses define ``name`` and
    ``rate(state, t_s)``; calling the component is calling :meth:`rate`."""

    def rate(self, state, t_s):  # pragma: no cover - defined by subclasses
        raise NotImplementedError

    def __call__(self, state, t_s):
        return self.rate(state, t_s)

    def advance(self, model, dt_s):
        """Nothing to advance: the stepper applies :meth:`rate` in its damage update."""
        return None

    def checkpoint_state(self):
        return {}, {}

    def restore(self, arrays, meta):
        pass
