r"""Total-Lagrangian hyperelastic solid on a scikit-fem mesh: a :class:`Problem` with a solid term.

Weak form (reference configuration :math:`\Omega_0`, first Piola–Kirchhoff stress
:math:`P = \partial\psi/\partial F`): find :math:`u` with prescribed values on the
Dirichlet boundary such that for all admissible :math:`\delta u`

.. math::

    R(u;\delta u) = \int_{\Omega_0} P(F) : \nabla_0 \delta u \, dV
                  + \int_{\Gamma_p} p\,(\operatorname{cof}F\,N)\cdot\delta u\,dA
                  - \sum_n f_n\cdot\delta u(X_n) = 0,\qquad F = I + \nabla_0 u .

Each of the three integrals is a term (:class:`~skvalve.fem.elements.hyperelastic.HyperelasticTerm`,
:class:`~skvalve.fem.loads.FollowerPressure`, :class:`~skvalve.fem.loads.NodalForce`); more terms
(trusses, contact, constraints) are added with :meth:`Problem.add_term`. The mixed u/p terms are in
:mod:`skvalve.fem.elements.constitutive`, the follower-pressure load stiffness in :mod:`skvalve.fem.loads`.
Plane strain (2D meshes) gives quantities per unit width.
"""

from __future__ import annotations

import numpy as np
import skfem as fem

from ..materials.base import Hyperelastic
from .elements.constitutive import MaterialRegions
from .elements.hyperelastic import HyperelasticTerm
from .loads import FollowerPressure, NodalForce
from .problem import Problem
from .solvers.newton import solve
from .space import Space

__all__ = ["Solid"]


class Solid(Problem):
    """Hyperelastic solid: mesh, formulation, materials, constraints and loads.

    Parameters
    ----------
    mesh : scikit-fem mesh (hex, tet; quad or triangle for plane strain).
    materials : a :class:`~skvalve.materials.base.Hyperelastic` law (or quadrature-point material),
        a mapping ``{subdomain name: law}`` (``mesh.subdomains``) or a sequence of laws with ``regions``.
    formulation : ``"u"`` (displacement, order 1 or 2) or ``"up"`` (mixed Q2/Q1, P2/P1).
    order : displacement polynomial order (default 1 for ``"u"``, 2 for ``"up"``).
    regions : element -> material index array, with a sequence of ``materials``.
    intorder : quadrature order override.

    Examples
    --------
    >>> import skfem
    >>> from skvalve.materials import NeoHookean
    >>> solid = Solid(skfem.MeshHex().refined(1), NeoHookean(1.0, 10.0))
    >>> for axis in range(3):                    # rollers on the three planes through the origin
    ...     _ = solid.add_dirichlet(lambda X, a=axis: X[a] == 0.0, 0.0, components=[axis])
    >>> _ = solid.add_dirichlet(lambda X: X[0] == 1.0, 0.1, components=[0])
    >>> result = solid.solve(steps=2, progress=False)
    >>> float(result.evaluate("deformation_gradient")[0, 0].round(12).max())   # homogeneous stretch
    1.1
    """

    def __init__(self, mesh: fem.Mesh, materials: Hyperelastic | dict | list, formulation: str = "u",
                 order: int | None = None, regions: np.ndarray | None = None, intorder: int | None = None) -> None:
        space = Space(mesh, formulation, order, intorder)
        super().__init__(space)
        self.solid = self.add_term(HyperelasticTerm(space, MaterialRegions(mesh, materials, regions,
                                                                           mixed=formulation == "up")))
        self.pressures: list[FollowerPressure] = []
        self.nodal_forces: list[NodalForce] = []

    @property
    def materials(self) -> MaterialRegions:
        return self.solid.materials

    def add_pressure(self, facets, pressure, ramp: bool = True) -> Solid:
        """Follower pressure (positive = compressive, pushes against the outward normal) on boundary facets.

        ``facets``: boundary name, facet indices or a predicate on facet midpoints.
        ``pressure``: number (times ``t`` when ``ramp``) or callable ``p(t)``.
        """
        load = FollowerPressure(self.space, self.space.facets_of(facets), pressure, ramp)
        self.pressures.append(self.add_term(load))
        return self

    def add_nodal_force(self, where=None, force=0.0, *, nodes=None, ramp: bool = True) -> Solid:
        """Force vector (dim,) at each selected node; number/array times ``t`` or callable ``f(t)``."""
        if (where is None) == (nodes is None):
            raise ValueError("give exactly one of where= or nodes=")
        scalar = self.space.scalar_dofs_on(where) if nodes is None else np.asarray(nodes, dtype=int).ravel()
        self.nodal_forces.append(self.add_term(NodalForce(self.space, scalar, force, ramp)))
        return self

    def deformation_gradient(self, u: np.ndarray) -> np.ndarray:
        """F at the quadrature points, shape (3, 3, nqp, nel) (F33 = 1 in plane strain)."""
        return self.solid.deformation_gradient(u)

    def solve(self, steps=10, **options):
        """Load-controlled Newton–Raphson; see :func:`skvalve.fem.solvers.newton.solve` for options."""
        return solve(self, steps, **options)
