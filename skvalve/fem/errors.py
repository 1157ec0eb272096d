"""Errors raised by the finite-element layer: bad meshes, bad problems and solver failures.

Every solver failure derives from :class:`SolverError` and carries ``last_converged``, the
:class:`~skvalve.fem.result.Result` up to the last converged load step (``None`` when the failure
happened before the first step was attempted).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "SolverError", "ConvergenceError", "NonPositiveJacobianError", "SingularSystemError", "OutputError",
    "TangledMeshError", "LoadError",
]


def _shown(ids: np.ndarray, limit: int = 10) -> str:
    ids = np.asarray(ids).ravel()
    return ", ".join(str(int(e)) for e in ids[:limit]) + (" ..." if ids.size > limit else "")


class SolverError(RuntimeError):
    """Base of solver failures; ``last_converged`` is the result up to the last converged step."""

    last_converged = None


class ConvergenceError(SolverError):
    """Newton did not converge after the allowed step cut-backs."""


class StateRefused(SolverError):
    """A term refuses a state its energy does not guard against (:meth:`~skvalve.fem.terms.Term.check_state`: e.g. a
    self-intersection among collision primitives the barrier excludes); a solver that tries steps rejects such a
    trial as it rejects an inverted element."""


class NonPositiveJacobianError(SolverError):
    """J <= 0 (or not finite) at a quadrature point; names the elements and the load step."""

    def __init__(self, elements: np.ndarray, step: int | None, load_factor: float | None, term: str = "") -> None:
        self.elements = np.asarray(elements)
        self.step, self.load_factor = step, load_factor
        where = f" of {term}" if term else ""
        super().__init__(
            f"det F <= 0 (or not finite) in {self.elements.size} element(s){where} [{_shown(self.elements)}] "
            f"at load step {step} (load factor {load_factor})"
        )


class SingularSystemError(SolverError):
    """The tangent is singular: typically a body (or part of one) without enough supports."""

    def __init__(self, message: str, step: int | None = None, load_factor: float | None = None) -> None:
        self.step, self.load_factor = step, load_factor
        super().__init__(message)


class LoadError(SolverError):
    """A load or prescribed value that is not a finite number where it is evaluated: names the load (its callable
    or value), its term (``"nodal force"``, ``"follower pressure"``, ``"prescribed displacement"``) and the load
    factor.

    Not a ``ValueError``: the solvers do not take it for a failed step to cut back, it ends the solve at once.
    """

    def __init__(self, term: str, load, load_factor: float, detail: str, where: str = "") -> None:
        self.term, self.load, self.load_factor, self.where = term, load, load_factor, where
        on = f" ({where})" if where else ""
        super().__init__(f"{term}{on} {_load_name(load)} at load factor {load_factor:.6g}: {detail}")


def _load_name(load) -> str:
    """A callable's qualified name (``force_at`` or ``<lambda>``), else its value's repr (shortened)."""
    name = getattr(load, "__qualname__", None) or getattr(type(load), "__qualname__", "load")
    if callable(load):
        return name
    text = repr(load)
    return text if len(text) <= 60 else text[:57] + "..."


class OutputError(SolverError):
    """A step callback (output, checkpoint) failed; the converged steps so far are in ``last_converged``."""


class TangledMeshError(ValueError):
    """Elements whose reference Jacobian changes sign (scrambled node order, a node pushed outside)."""

    def __init__(self, elements: np.ndarray, detail: str = "") -> None:
        self.elements = np.asarray(elements)
        super().__init__(
            f"{self.elements.size} tangled element(s) [{_shown(self.elements)}]: the reference Jacobian det(dX/dxi) "
            f"is not of one sign over the mesh at their quadrature points or corners{detail}; check their node "
            "order and coordinates"
        )
