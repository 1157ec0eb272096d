"""Converged load steps of a solve and the quantities derived from them."""

from __future__ import annotations

import numpy as np

from .fields import PointData, element_centres, locate

__all__ = ["Result"]


class Result:
    """Per converged step: load factor, solution vector, residual (reactions), Newton log.

    Step 0 is the reference state (load factor 0). ``step=-1`` is the last converged step.
    """

    def __init__(self, problem, solver: str) -> None:
        self.solid, self.solver = problem, solver
        self.problem = problem
        self.load_factors: list[float] = []
        self.solutions: list[np.ndarray] = []
        self.residuals: list[np.ndarray] = []
        self.histories: list[list[dict]] = []
        self._centres: PointData | None = None
        #: wall time (s) of the pattern set-up, the assembly and the sparse solves of the solve
        self.timings: dict[str, float] = {}

    def append(self, t: float, u: np.ndarray, residual: np.ndarray, history: list[dict]) -> None:
        self.load_factors.append(float(t))
        self.solutions.append(u.copy())
        self.residuals.append(residual.copy())
        self.histories.append(history)

    def __len__(self) -> int:
        return len(self.load_factors)

    @property
    def iterations(self) -> int:
        """Total Newton iterations (linear solves) over all steps."""
        return sum(len(h) for h in self.histories)

    @property
    def log(self) -> list[dict]:
        """Every Newton iteration: step, load factor, residual norms, increment norm, alpha."""
        return [record for history in self.histories for record in history]

    # ----------------------------------------------------------- raw fields
    def u(self, step: int = -1) -> np.ndarray:
        """Full solution vector (displacements, then pressures)."""
        return self.solutions[step]

    def displacement(self, step: int = -1) -> np.ndarray:
        """Displacement at the scalar dofs (for Lagrange elements: vertices first), shape (dim, n)."""
        space = self.solid.space
        return self.solutions[step][: space.n_u].reshape(-1, space.dim).T

    def pressure(self, step: int = -1) -> np.ndarray | None:
        """Pressure dofs of the mixed formulation (positive in compression), or None."""
        space = self.solid.space
        return None if space.n_p == 0 else self.solutions[step][space.n_u:]

    # --------------------------------------------------------- reactions
    def reaction(self, where, step: int = -1) -> np.ndarray:
        """Reaction force (dim,) on the dofs of a boundary (per unit width in 2D)."""
        space = self.solid.space
        dofs = space.displacement_dofs(space.scalar_dofs_on(where))
        return self.residuals[step][dofs].sum(axis=1)

    def reaction_moment(self, where, point, step: int = -1, deformed: bool = True):
        """Moment of the reactions about ``point``: (3,) in 3D, scalar per unit width in 2D."""
        space = self.solid.space
        scalar = space.scalar_dofs_on(where)
        dofs = space.displacement_dofs(scalar)
        u = self.solutions[step]
        x = space.dof_coordinates[:, scalar] + (u[dofs] if deformed else 0.0)
        arm = x - np.asarray(point, dtype=float).reshape(-1, 1)
        f = self.residuals[step][dofs]
        if space.dim == 2:
            return float(np.sum(arm[0] * f[1] - arm[1] * f[0]))
        return np.cross(arm.T, f.T).sum(axis=0)

    # ------------------------------------------------------- derived fields
    def at(self, points=None) -> PointData:
        """Basis data at reference points (dim, n), or at element centres when ``points`` is None."""
        if points is not None:
            return locate(self.solid, points)
        if self._centres is None:
            self._centres = element_centres(self.solid)
        return self._centres

    def evaluate(self, quantity: str, points=None, step: int = -1) -> np.ndarray:
        """``quantity`` in displacement, deformation_gradient, stretch_tensor, green_strain, cauchy,
        pressure; at reference ``points`` (dim, n) or at element centres (``points=None``)."""
        data = self.at(points)
        names = ("displacement", "deformation_gradient", "stretch_tensor", "green_strain", "cauchy", "pressure")
        if quantity not in names:
            raise ValueError(f"unknown quantity {quantity!r}; choose one of {names}")
        return getattr(data, quantity)(self.solutions[step])
