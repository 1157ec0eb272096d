"""Finite-strain solid mechanics on scikit-fem: total-Lagrangian, displacement or mixed u/p.

Typical use::

    solid = Solid(mesh, NeoHookean(1.0, 10.0))                # Q1 hexes, displacement
    solid.add_dirichlet("left", 0.0, components=[0])
    solid.add_dirichlet("right", 0.5, components=[0])          # ramped with the load factor
    result = solid.solve(steps=5)
    result.reaction("right"), result.evaluate("cauchy")

See ``docs/fem.md``. Derivations are in the module docstrings: :mod:`.solid` (weak form),
:mod:`.constitutive` (mixed u/p), :mod:`.loads` (follower pressure), :mod:`.newton`.
"""

from .linsolve import available_solvers, solver_name
from .newton import solve
from .result import Result
from .solid import ConvergenceError, NonPositiveJacobianError, Solid, SolverError
from .space import Space

__all__ = [
    "Solid", "Result", "Space", "solve", "SolverError", "ConvergenceError", "NonPositiveJacobianError",
    "solver_name", "available_solvers",
]
