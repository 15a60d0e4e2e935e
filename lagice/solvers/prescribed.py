"""Kinematic time stepper: the ice velocity is prescribed, nothing is solved.

For scenes that exercise mesh motion, remeshing, remapping, thermodynamics or
drifters without the cost (and the feedback) of a rheology: the velocity of every
node over a step is ``velocity(t_s, x, y)`` evaluated at the start of the step at
the node positions (forward Euler), with the prescribed boundary values
(:class:`~lagice.boundary.VelocityBC`, coast no-slip) imposed on top. Stress and
damage are left as they are (carried, moved and remapped with the ice).

The transport velocity is that velocity, and :attr:`last_strain_rate` its
strain rate.
"""
from __future__ import annotations

import numpy as np

from ..boundary import DirichletSet
from ..errors import ConfigError, SolverError
from ..fem import SHAPE_GRADIENTS, STRAIN_RATE
from ..forces import evaluate_vector
from .base import StepInfo


class PrescribedStepper:
    """Kinematic stepper.

    Args:
        rheology: not used (accepted because :class:`~lagice.model.Model` passes one); a
            Maxwell-EB rheology that asks for a non-origin stress correction or an optional
            term is refused (:meth:`~lagice.rheology.MaxwellEB.require_stepper`).
        mesh: the mesh.
        velocity: callable ``f(t_s, x_m, y_m) -> (u, v)`` [m s-1] (or a ``(2, n)``
            array), or a constant pair.
        bcs: list of :class:`~lagice.boundary.VelocityBC` imposed on top; coast
            nodes have zero velocity.
        forces, heal_rate: must be empty / None: nothing is solved, so external
            forces and healing would be ignored; that is refused rather than done
            silently.
    """

    name = "prescribed"

    def __init__(self, rheology=None, mesh=None, velocity=None, bcs=(), forces=(), heal_rate=None):
        if mesh is None:
            raise ConfigError("PrescribedStepper needs a mesh")
        if velocity is None:
            raise ConfigError("solver 'prescribed' needs a velocity field (solver.velocity = "
                              "'module:function' or an expression pair)")
        if list(forces):
            raise ConfigError("solver 'prescribed' solves no momentum equation: external forces (wind, "
                              "ocean, Coriolis) would be ignored; remove [forcing.wind]/[forcing.ocean]/"
                              "[forcing.coriolis] or use another solver")
        if heal_rate is not None:
            raise ConfigError("solver 'prescribed' updates no damage: a healing law would be ignored "
                              "(set healing.law = 'none')")
        if hasattr(rheology, "require_stepper"):  # Maxwell-EB: no correction path or term it would ignore
            rheology.require_stepper("prescribed")
        self.rheology = rheology
        self.velocity = velocity
        self.bcs = list(bcs)
        self._transport = None
        self._strain_rate = None
        self.reset_topology(mesh)

    @property
    def transport_velocity(self):
        return self._transport

    @property
    def last_strain_rate(self):
        return self._strain_rate

    def reset_topology(self, mesh) -> None:
        self.mesh = mesh
        self.dirichlet = DirichletSet(mesh, self.bcs)
        self._transport = None
        self._strain_rate = None
        self.update_geometry()

    def update_geometry(self) -> None:
        m = self.mesh
        self.b, self.c, self.area = SHAPE_GRADIENTS[0](m.nodes, m.triangles)
        if np.any(self.area <= 0):
            raise SolverError(f"{int(np.sum(self.area <= 0))} inverted elements in the mesh")

    def step(self, state, t_s: float, dt: float) -> StepInfo:
        if not dt > 0:
            raise ConfigError(f"dt = {dt!r} s must be > 0")
        vel = evaluate_vector(self.velocity, t_s, self.mesh.nodes, "solver.velocity")
        d = self.dirichlet
        if len(d.dofs):
            vel.reshape(-1)[d.dofs] = d.values(t_s)
        state.velocity = vel
        self._transport = vel
        self._strain_rate = STRAIN_RATE[0](self.mesh.triangles, self.b, self.c, vel)
        return StepInfo(iterations=0)
