"""Time steppers of the Maxwell-EB rheology; a scene picks one by name."""
from .base import DirichletSet, StepInfo, VelocityBC
from .explicit import ExplicitSolver
from .evp import EVPSolver
from .implicit import ImplicitSolver

SOLVERS = {"implicit": ImplicitSolver, "explicit": ExplicitSolver, "evp": EVPSolver}

__all__ = ["DirichletSet", "StepInfo", "VelocityBC", "ImplicitSolver", "ExplicitSolver", "EVPSolver", "SOLVERS"]
