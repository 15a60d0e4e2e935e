"""Time steppers: how a rheology is solved over one outer step (what is solved
lives in :mod:`lagice.rheology`). A scene picks one by name (``[solver] name``);
every stepper follows :class:`~lagice.solvers.base.TimeStepper`.

========== ======================== =============================================
name       rheology                 method
========== ======================== =============================================
implicit   Maxwell-EB               backward Euler, sparse linear solve per step
explicit   Maxwell-EB               lumped mass, N elastic sub-steps per step
evp        viscous-plastic          mEVP iterations (adaptive α, β)
prescribed (none)                   kinematic: the velocity is given
========== ======================== =============================================

The explicit stepper also runs on an NVIDIA GPU (``[solver] device = "cuda"``):
:class:`lagice.solvers.cuda_explicit.CudaExplicitSolver`, imported only when
asked for (docs/gpu.md).
"""
from ..boundary import DirichletSet, VelocityBC
from .base import StepInfo, TimeStepper
from .evp import EVPSolver
from .explicit import ExplicitSolver
from .implicit import ImplicitSolver
from .prescribed import PrescribedStepper

SOLVERS = {"implicit": ImplicitSolver, "explicit": ExplicitSolver, "evp": EVPSolver,
           "prescribed": PrescribedStepper}

#: the rheology law each stepper solves (None: any / none)
SOLVER_RHEOLOGY = {"implicit": "maxwell_eb", "explicit": "maxwell_eb", "evp": "viscous_plastic",
                   "prescribed": None}

__all__ = ["DirichletSet", "StepInfo", "TimeStepper", "VelocityBC", "ImplicitSolver", "ExplicitSolver",
           "EVPSolver", "PrescribedStepper", "SOLVERS", "SOLVER_RHEOLOGY"]
