"""Finite-strain solid mechanics on scikit-fem: a displacement field and a sum of terms.

Typical use::

    solid = Solid(mesh, NeoHookean(1.0, 10.0))                # Q1 hexes, displacement
    solid.add_dirichlet("left", 0.0, components=[0])
    solid.add_dirichlet("right", 0.5, components=[0])          # ramped with the load factor
    result = solid.solve(steps=5)
    result.reaction("right"), result.evaluate("cauchy")

:class:`Solid` is a :class:`Problem` with a :class:`HyperelasticTerm`; any other term (trusses,
contact, constraints) joins with :meth:`Problem.add_term`, and :func:`solve` is the Newton driver.
See ``docs/fem.md``. Derivations are in the module docstrings: :mod:`.elements.hyperelastic` (weak
form), :mod:`.elements.constitutive` (mixed u/p), :mod:`.loads` (follower pressure), :mod:`.solvers.newton`. The
element terms are in :mod:`.elements`, the solvers in :mod:`.solvers`, contact in :mod:`.contact`.
"""

from .elements.constitutive import MaterialRegions
from .elements.hyperelastic import HyperelasticTerm
from .errors import (
    ConvergenceError,
    NonPositiveJacobianError,
    OutputError,
    SingularSystemError,
    SolverError,
    TangledMeshError,
)
from .loads import FollowerPressure, NodalForce
from .problem import Problem
from .result import Result
from .solid import Solid
from .solvers.linsolve import SolverUnavailableError, available_solvers, solver_name
from .solvers.newton import StepEvent, solve
from .solvers.soft_modes import SoftModes, soft_modes
from .space import Space
from .taylor import TermTaylor, taylor_test
from .terms import Blocks, Contribution, Term

__all__ = [
    "Solid", "Problem", "Term", "Blocks", "Contribution", "HyperelasticTerm", "MaterialRegions", "FollowerPressure",
    "NodalForce", "Result", "Space", "solve", "StepEvent", "SolverError", "ConvergenceError",
    "NonPositiveJacobianError", "SingularSystemError", "OutputError", "TangledMeshError", "SolverUnavailableError",
    "solver_name", "available_solvers", "SoftModes", "soft_modes", "TermTaylor", "taylor_test",
]
