"""Time steppers of the Maxwell-EB rheology; a scene picks one by name."""
from .base import DirichletSet, StepInfo, VelocityBC
from .implicit import ImplicitSolver

SOLVERS = {"implicit": ImplicitSolver}

__all__ = ["DirichletSet", "StepInfo", "VelocityBC", "ImplicitSolver", "SOLVERS"]
