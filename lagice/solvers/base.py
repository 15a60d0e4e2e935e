"""The time-stepper protocol and what every stepper reports.

A *time stepper* is how a rheology is solved over one outer step: it advances
the node velocity and the element stress and damage of an
:class:`~lagice.state.IceState` from ``t_s`` to ``t_s + dt_s``. It does **not**
advance time (the :class:`~lagice.model.Model` owns the clock), move the mesh
(the mesh-motion component does, with :attr:`TimeStepper.transport_velocity`)
or change thickness/concentration (mesh motion and thermodynamics do).

The transport velocity (docs/design.md, "Which velocity moves the mesh") is the
time mean, over the step, of the velocity the stepper integrated: the mean of the
elastic sub-step velocities for the explicit stepper, the end-of-step velocity
u^{n+1} for the backward-Euler implicit and mEVP steppers, the prescribed velocity
for the kinematic stepper. Nodes, drifters and the displacement behind every
Lagrangian deformation rate move with it, and ``last_strain_rate`` is its strain
rate.

A stepper that keeps fields on a device between steps (the GPU explicit stepper,
docs/gpu.md) also has ``to_host(state, fields)``, which brings them up to date in
``state`` (the model calls it through :meth:`lagice.model.Model.needs_host_state`
before anything reads them), and ``device_check(max_speed_m_s)`` for the NaN
checker. Both are optional: CPU steppers have neither.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np

from ..boundary import DirichletSet, VelocityBC

__all__ = ["TimeStepper", "StepInfo", "Timer", "VelocityBC", "DirichletSet"]


@runtime_checkable
class TimeStepper(Protocol):
    """What :class:`~lagice.model.Model` needs of a time stepper."""

    name: str

    def step(self, state, t_s: float, dt_s: float) -> StepInfo:
        """Advance velocity, stress and damage of ``state`` over [t_s, t_s + dt_s]."""

    def reset_topology(self, mesh) -> None:
        """The mesh connectivity changed (remesh): rebuild every cache."""

    def update_geometry(self) -> None:
        """The node positions changed (mesh motion): refresh geometry caches."""

    @property
    def transport_velocity(self) -> np.ndarray | None:
        """(n, 2) [m s-1] velocity that moves the nodes over the last step (None before one)."""

    @property
    def last_strain_rate(self) -> np.ndarray | None:
        """(m, 3) [s-1] strain rate of the transport velocity over the last step."""


@dataclass
class StepInfo:
    """What one time step did: iterations, residual, timings [s], damage events."""

    iterations: int = 0
    residual: float = 0.0
    linear_iterations: int = 0
    n_damaged: int = 0
    n_capped: int = 0
    timings: dict = field(default_factory=lambda: {"assembly": 0.0, "solve": 0.0, "damage": 0.0})
    kernel_timings: dict = field(default_factory=dict)


class Timer:
    def __init__(self, timings: dict, key: str):
        self.t, self.k = timings, key

    def __enter__(self):
        self.t0 = time.perf_counter()

    def __exit__(self, *exc):
        self.t[self.k] = self.t.get(self.k, 0.0) + time.perf_counter() - self.t0
