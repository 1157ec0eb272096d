r"""Homogeneous biaxial membrane test of a set of RVEs: the RVE-level fast model.

Every RVE of an :class:`~skvalve.multiscale.RVEMaterial` (one point per network) is given the same
deformation :math:`F = \operatorname{diag}(\lambda_1, \lambda_2, \lambda_3)`; the stresses are averaged
over the RVEs (a uniform-strain, Voigt average over the sample's networks). With a sample of reference
thickness :math:`h` the membrane tensions (force per unit *reference* edge length, the biaxial-test
convention) are :math:`T_i = h\,\bar P_{ii}`, and the free faces give :math:`\bar P_{33} = 0`. For target
tensions :math:`(T_1^*, T_2^*)` Newton solves

.. math::

    h\bar P_{11}(\lambda) = T_1^*,\quad h\bar P_{22}(\lambda) = T_2^*,\quad \bar P_{33}(\lambda) = 0,
    \qquad \frac{\partial \bar P_{ii}}{\partial\lambda_j} = \bar{\mathbb{A}}_{iijj},

along a ramp of the targets, committing the RVE states after each converged increment. It gives the
initial edge displacements of the FE protocols and the fast path of the parameter fit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .material import RVEMaterial

__all__ = ["HomogeneousBiaxial", "BiaxialState"]


@dataclass
class BiaxialState:
    """Converged homogeneous state: stretches (λ1, λ2, λ3), tensions (N/m), mean Cauchy stress (Pa)."""

    stretches: np.ndarray
    tensions: np.ndarray
    cauchy: np.ndarray


class HomogeneousBiaxial:
    """Uniform biaxial stretch of every RVE of ``material`` (built with ``n_points=1``).

    Parameters
    ----------
    material : the RVE material; all its RVEs get the same F.
    thickness : reference thickness h (m) converting the mean first Piola–Kirchhoff stress to tension.
    """

    def __init__(self, material: RVEMaterial, thickness: float) -> None:
        if material.n_points != 1:
            raise ValueError("HomogeneousBiaxial: build the RVEMaterial with n_points=1 (one RVE per network)")
        if not thickness > 0:
            raise ValueError(f"HomogeneousBiaxial: thickness must be positive, got {thickness!r}")
        self.material, self.thickness = material, float(thickness)
        self.stretches = np.ones(3)

    def _F(self, stretches: np.ndarray) -> np.ndarray:
        F = np.zeros((3, 3, 1, self.material.n_elements))
        for i in range(3):
            F[i, i] = stretches[i]
        return F

    def evaluate(self, stretches: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(mean P (3,3), mean dP/dF (3,3,3,3)) at F = diag(stretches)."""
        P, A = self.material.pk1_and_tangent(self._F(np.asarray(stretches, dtype=float)))
        return P.mean(axis=(2, 3)), A.mean(axis=(4, 5))

    def tensions_at(self, stretch_1: float, stretch_2: float, tol: float = 1e-12, max_iter: int = 30) -> np.ndarray:
        """(T1, T2) in N/m at in-plane stretches (λ1, λ2), λ3 solved from P̄33 = 0; commits the state.

        Call along a loading path (increasing stretches): each point warm-starts from the previous one.
        """
        lam = np.array([stretch_1, stretch_2, self.stretches[2]], dtype=float)
        for _ in range(max_iter):
            P, A = self.evaluate(lam)
            if abs(P[2, 2]) <= tol * max(abs(P[0, 0]), abs(P[1, 1]), self.material.matrix.mu):
                break
            lam[2] -= P[2, 2] / A[2, 2, 2, 2]
        else:
            raise RuntimeError(f"HomogeneousBiaxial: P33 = 0 not reached at stretches ({stretch_1}, {stretch_2})")
        self.material.commit()
        self.stretches = lam
        return self.thickness * np.array([P[0, 0], P[1, 1]])

    def solve(self, tensions, increments: int = 8, tol: float = 1e-10, max_iter: int = 30) -> list[BiaxialState]:
        """Ramp the tensions (N/m) to ``tensions`` = (T1, T2) in ``increments``; the converged states."""
        target = np.asarray(tensions, dtype=float)
        if target.shape != (2,) or not np.all(np.isfinite(target)):
            raise ValueError(f"HomogeneousBiaxial.solve: tensions must be two finite numbers, got {tensions!r}")
        start = self.stretches.copy()
        start_P = self.evaluate(start)[0]
        start_T = self.thickness * np.array([start_P[0, 0], start_P[1, 1]])
        states = []
        lam = start.copy()
        for k in range(1, increments + 1):
            goal = start_T + (target - start_T) * k / increments
            for _ in range(max_iter):
                P, A = self.evaluate(lam)
                residual = np.array([self.thickness * P[0, 0] - goal[0], self.thickness * P[1, 1] - goal[1], P[2, 2]])
                scale = np.array([self.thickness, self.thickness, 1.0])
                jacobian = np.array([[A[i, i, j, j] for j in range(3)] for i in range(3)]) * scale[:, None]
                reference = max(np.abs(goal).max(), self.thickness * abs(P[0, 0]), 1e-12)
                if np.abs(residual).max() <= tol * reference:
                    break
                step = np.linalg.solve(jacobian, -residual)
                lam = lam + step * min(1.0, 0.05 / max(np.abs(step).max(), 1e-300))  # at most 5 % per iterate
            else:
                raise RuntimeError(f"HomogeneousBiaxial: no convergence at tensions {goal} (residual {residual})")
            self.material.commit()
            self.stretches = lam.copy()
            sigma = self.material.cauchy(self._F(lam)).mean(axis=(2, 3))
            states.append(BiaxialState(lam.copy(), np.array([self.thickness * P[0, 0], self.thickness * P[1, 1]]),
                                       sigma))
        return states
