r"""Stress and tangent at the quadrature points: materials per region, mixed u/p terms.

Materials are called with the batch layout ``(n_quadrature_points, n_elements_of_region)``
so that a direction given per element as an array of shape ``(3, n_elements_of_region)``
broadcasts over the quadrature points.

**Mixed u/p (perturbed Lagrangian).** A law is split as :math:`\psi = \hat\psi(F) + U(J)`
(:meth:`~skvalve.materials.base.Hyperelastic.split`; an incompressible law has no
:math:`U`). With the pressure :math:`p` (positive in compression, as in
:mod:`skvalve.materials.base`) interpolated independently, the two-field potential is

.. math::

    \Pi(u, p) = \int_{\Omega_0} \Big[\hat\psi(F) - p\,\big(J - \bar J(p)\big) + U(\bar J(p))\Big]\,dV,
    \qquad U'(\bar J(p)) = -p,

where :math:`\bar J(p)` inverts the volumetric stress pointwise (:math:`\bar J \equiv 1`
when incompressible). Because :math:`\partial_p[p\bar J + U(\bar J)] = \bar J`, the
stationarity conditions are

.. math::

    \int (\hat P - p\,\operatorname{cof}F) : \nabla_0\delta u\,dV = W_\text{ext}, \qquad
    \int \delta p\,(\bar J(p) - J)\,dV = 0,

i.e. :math:`J = \bar J` weakly, and eliminating :math:`p` pointwise returns the
displacement formulation. The Hessian of :math:`\Pi` is the (symmetric, indefinite) tangent

.. math::

    \mathbb{A} = \hat{\mathbb{A}} - p\,\frac{\partial \operatorname{cof}F}{\partial F},\quad
    \frac{\partial (\operatorname{cof}F)_{iJ}}{\partial F_{kL}}
        = \frac{(\operatorname{cof}F)_{iJ}(\operatorname{cof}F)_{kL}
                - (\operatorname{cof}F)_{iL}(\operatorname{cof}F)_{kJ}}{J},

    K_{up} = -\int \nabla_0\delta u : \operatorname{cof}F\;\Delta p\,dV,\qquad
    K_{pp} = \int \delta p\,\frac{d\bar J}{dp}\,\Delta p\,dV = -\int \frac{\delta p\,\Delta p}{U''(\bar J)}\,dV .

**Fast path.** For the compressible :class:`~skvalve.materials.NeoHookean`
(:math:`\psi = \tfrac\mu2(I_1-3) - \mu\ln J + \tfrac\lambda2(\ln J)^2`) stress and tangent
are evaluated in one compiled loop from

.. math::

    P = \mu F + (\lambda\ln J - \mu) F^{-T},\qquad
    \mathbb{A}_{iJkL} = \mu\,\delta_{ik}\delta_{JL} + (\mu - \lambda\ln J)\,F^{-1}_{Jk}F^{-1}_{Li}
                        + \lambda\,F^{-1}_{Ji}F^{-1}_{Lk},

using :math:`\partial F^{-1}_{Ji}/\partial F_{kL} = -F^{-1}_{Jk}F^{-1}_{Li}` (tested against
the generic law).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from numba import njit, prange

from ...kinematics import cofactor, determinant
from ...materials.base import Hyperelastic, VolumetricEnergy
from ...materials.neo_hookean import NeoHookean

__all__ = ["Region", "MaterialRegions", "neo_hookean_response"]


@njit(parallel=True, cache=True)
def neo_hookean_response(F: np.ndarray, mu: float, lmbda: float, tangent: bool):
    """P[i, J, q, e] and A[e, q, i, J, k, L] of the compressible neo-Hookean law."""
    nqp, nel = F.shape[2], F.shape[3]
    P = np.empty((3, 3, nqp, nel))
    A = np.empty((nel if tangent else 0, nqp, 3, 3, 3, 3))
    for e in prange(nel):
        Fi = np.empty((3, 3))
        for q in range(nqp):
            a, b, c = F[0, 0, q, e], F[0, 1, q, e], F[0, 2, q, e]
            d, f, g = F[1, 0, q, e], F[1, 1, q, e], F[1, 2, q, e]
            h, k, m = F[2, 0, q, e], F[2, 1, q, e], F[2, 2, q, e]
            J = a * (f * m - g * k) - b * (d * m - g * h) + c * (d * k - f * h)
            Fi[0, 0], Fi[0, 1], Fi[0, 2] = (f * m - g * k) / J, (c * k - b * m) / J, (b * g - c * f) / J
            Fi[1, 0], Fi[1, 1], Fi[1, 2] = (g * h - d * m) / J, (a * m - c * h) / J, (c * d - a * g) / J
            Fi[2, 0], Fi[2, 1], Fi[2, 2] = (d * k - f * h) / J, (b * h - a * k) / J, (a * f - b * d) / J
            lnJ = np.log(J)
            c1 = lmbda * lnJ - mu
            for i in range(3):
                for j in range(3):
                    P[i, j, q, e] = mu * F[i, j, q, e] + c1 * Fi[j, i]
            if tangent:
                c2 = mu - lmbda * lnJ
                for i in range(3):
                    for j in range(3):
                        for kk in range(3):
                            for L in range(3):
                                val = c2 * Fi[j, kk] * Fi[L, i] + lmbda * Fi[j, i] * Fi[L, kk]
                                if i == kk and j == L:
                                    val += mu
                                A[e, q, i, j, kk, L] = val
    return P, A


def invert_volumetric(U: VolumetricEnergy, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r"""Solve :math:`U'(\bar J) = -p` pointwise; return :math:`\bar J` and :math:`1/U''(\bar J)`."""
    Jbar = np.maximum(1.0 - p / U.second_derivative(np.ones(1))[0], 0.05)
    for _ in range(50):
        g = U.first_derivative(Jbar) + p
        h = U.second_derivative(Jbar)
        step = g / h
        Jbar = np.maximum(Jbar - step, 0.5 * Jbar)
        if np.all(np.abs(step) <= 1e-14 * np.abs(Jbar)):
            break
    h = U.second_derivative(Jbar)
    mismatch = np.abs(U.first_derivative(Jbar) + p) > 1e-8 * (1 + np.abs(p))
    if not np.all(np.isfinite(Jbar)) or np.any(h <= 0.0) or np.any(mismatch):
        raise ValueError("pressure outside the range of the volumetric energy U'(J) (no J with U'(J) = -p)")
    return Jbar, 1.0 / h


def _is_quadrature_material(material) -> bool:
    """Duck-typed material evaluated in batch at the quadrature points (e.g. an FE² RVE material)."""
    return all(hasattr(material, name) for name in ("pk1", "pk1_and_tangent", "cauchy", "incompressible"))


class Region:
    """One material on a set of elements (``elements`` is ``slice(None)`` for all)."""

    def __init__(self, material: Hyperelastic, elements, mixed: bool) -> None:
        if not isinstance(material, Hyperelastic) and not _is_quadrature_material(material):
            raise TypeError(
                "material must be a skvalve.materials.Hyperelastic or a quadrature-point material with "
                f"pk1, pk1_and_tangent, cauchy and incompressible; got {type(material).__name__}"
            )
        self.material = material
        self.elements = elements
        self.volumetric: VolumetricEnergy | None = None
        self.law = material
        if mixed:
            if not material.incompressible:
                if not hasattr(material, "split"):
                    raise ValueError(f"{type(material).__name__} has no split(): use the displacement formulation")
                rest, U = material.split()
                if U is None:
                    raise ValueError(
                        f"{type(material).__name__} has no volumetric split; the mixed 'up' formulation needs an "
                        "incompressible law or a law whose split() returns a volumetric energy"
                    )
                self.law, self.volumetric = rest, U
        elif material.incompressible:
            raise ValueError(
                f"{type(material).__name__} is incompressible: use the mixed formulation (formulation='up')"
            )
        law = self.law
        self.fast = type(law) is NeoHookean

    def response(self, F: np.ndarray, tangent: bool):
        """P (3,3,nqp,nel_r) and A (nel_r,nqp,3,3,3,3) view, or None."""
        if self.fast:
            P, A = neo_hookean_response(F, float(self.law.mu), float(self.law.lmbda), tangent)
            return P, (A if tangent else None)
        if tangent:
            P, A = self.law.pk1_and_tangent(F)
            return P, A.transpose(5, 4, 0, 1, 2, 3)
        return self.law.pk1(F), None


class MaterialRegions:
    """Materials assigned to elements: one law, ``{subdomain: law}`` or laws + element index array."""

    def __init__(self, mesh, materials, regions=None, mixed: bool = False) -> None:
        nel = mesh.nelements
        self.nel = nel
        if isinstance(materials, Hyperelastic) or _is_quadrature_material(materials):
            if regions is not None:
                raise ValueError("regions is only used with a sequence of materials")
            self.regions = [Region(materials, slice(None), mixed)]
        elif isinstance(materials, Mapping):
            subdomains = mesh.subdomains or {}
            owner = np.full(nel, -1)
            self.regions = []
            for n, (name, law) in enumerate(materials.items()):
                if name not in subdomains:
                    raise ValueError(f"unknown subdomain {name!r}; mesh has {sorted(subdomains)}")
                elements = np.asarray(subdomains[name], dtype=int)
                if np.any(owner[elements] >= 0):
                    raise ValueError(f"subdomain {name!r} overlaps another material region")
                owner[elements] = n
                self.regions.append(Region(law, elements, mixed))
            self._check_covered(owner)
        elif isinstance(materials, Sequence):
            if regions is None:
                raise ValueError("a sequence of materials needs regions: one material index per element")
            regions = np.asarray(regions)
            if regions.shape != (nel,) or not np.issubdtype(regions.dtype, np.integer):
                raise ValueError(f"regions must be an integer array of shape ({nel},); got {regions.shape}")
            if regions.min() < 0 or regions.max() >= len(materials):
                raise ValueError(f"regions must index the {len(materials)} materials")
            self.regions = [Region(law, np.flatnonzero(regions == n), mixed) for n, law in enumerate(materials)]
            self.regions = [r for r in self.regions if r.elements.size]
        else:
            raise TypeError("materials must be a Hyperelastic law, a {subdomain: law} mapping or a sequence of laws")

    def energy_density(self, F: np.ndarray) -> np.ndarray | None:
        r"""Strain energy per reference volume :math:`\psi(C)` at the quadrature points (nqp, nel), or ``None`` when
        a region's law has no ``energy_C`` (quadrature-point materials) or is incompressible (mixed formulation)."""
        C = np.einsum("kiqe,kjqe->ijqe", F, F)
        W = np.zeros(F.shape[2:])
        for region in self.regions:
            law = region.material
            if region.volumetric is not None or law.incompressible or not isinstance(law, Hyperelastic):
                return None
            W[:, region.elements] = law.energy_C(C[:, :, :, region.elements])
        return W

    def _check_covered(self, owner: np.ndarray) -> None:
        missing = np.flatnonzero(owner < 0)
        if missing.size:
            raise ValueError(f"elements without a material, e.g. {missing[:5].tolist()}")

    def evaluate(self, F: np.ndarray, p: np.ndarray | None, tangent: bool):
        """Total P (3,3,nqp,nel), A (nel,nqp,3,3,3,3) or None, and for mixed (Jbar, dJbar/dp, J, cof)."""
        single = len(self.regions) == 1 and isinstance(self.regions[0].elements, slice)
        nqp, nel = F.shape[2], F.shape[3]
        if single:
            P, A = self.regions[0].response(F, tangent)
        else:
            P = np.empty((3, 3, nqp, nel))
            A = np.empty((nel, nqp, 3, 3, 3, 3)) if tangent else None
            for region in self.regions:
                Pr, Ar = region.response(F[:, :, :, region.elements], tangent)
                P[:, :, :, region.elements] = Pr
                if tangent:
                    A[region.elements] = Ar
        if p is None:
            return P, A, None
        # mixed terms: -p cof F in P, -p dcof/dF in A
        J = determinant(F)
        cof = cofactor(F)
        P = P - p * cof
        if tangent:
            cofe = cof.transpose(3, 2, 0, 1)  # (nel, nqp, 3, 3)
            dcof = (np.einsum("eqij,eqkl->eqijkl", cofe, cofe) - np.einsum("eqil,eqkj->eqijkl", cofe, cofe))
            A = A - (p / J).T[:, :, None, None, None, None] * dcof
        Jbar = np.ones_like(p)
        compliance = np.zeros_like(p)
        for region in self.regions:
            if region.volumetric is not None:
                pr = p[:, region.elements]
                Jbar[:, region.elements], compliance[:, region.elements] = invert_volumetric(region.volumetric, pr)
        return P, A, (Jbar, compliance, J, cof)
