r"""Stress, tangent and element matrices in one compiled pass per element, for every law.

A law hands over scalar derivatives of its energy (:mod:`skvalve.materials.derivatives`); the
tensor algebra is written once here. Per quadrature point the kernel forms
:math:`P = \partial\psi/\partial F` and :math:`\mathbb{A} = \partial P/\partial F` and adds them into
the element forces and stiffness of :mod:`skvalve.fem.kernels` (same layout, node-major local dofs):
:math:`f_{ai} \mathrel{+}= w\,P_{iJ}N_{a,J}`, :math:`K_{ai,bk} \mathrel{+}= w\,N_{a,J}\mathbb{A}_{iJkL}N_{b,L}`.

The point formulas (invariant laws and principal-value laws) are derived in
:mod:`skvalve.fem.elements.fused_points`.

**Mixed u/p** (:mod:`skvalve.fem.elements.constitutive`): with the pressure :math:`p` at the points,
:math:`P \mathrel{-}= p\operatorname{cof}F`, :math:`\mathbb{A} \mathrel{-}= pJ(H_{iJ}H_{kL} - H_{iL}H_{kJ})`,
:math:`K_{up} = -\int N_{a,J}(\operatorname{cof}F)_{iJ}N^p_\beta`, and when :math:`\bar J` and the compliance
:math:`1/U''(\bar J)` are given, :math:`f_p = \int N^p_\alpha(\bar J - J)` and
:math:`K_{pp} = -\int N^p_\alpha\,U''^{-1}N^p_\beta`.

Verified against the generic path (``law.pk1_and_tangent`` + :mod:`skvalve.fem.kernels`) in
``tests/test_fem_fused.py``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from ...kinematics import determinant
from ...materials.base import Hyperelastic
from ...materials.derivatives import InvariantDerivatives, PrincipalDerivatives
from ..kernels import add_point_stiffness
from .constitutive import MaterialRegions, invert_volumetric
from .fused_points import invariant_point, inverse_transpose, principal_point

__all__ = ["FusedLaw", "FusedResponse", "MixedFields", "fused_response", "assemble_regions",
           "point_response_regions"]

_INVARIANT, _PRINCIPAL = 0, 1


@dataclass(frozen=True)
class MixedFields:
    """Pressure-field data of a mixed u/p element at the quadrature points.

    ``pressure`` (nqp, nel); ``Np`` (nel, nqp, nbp) pressure shape functions; ``Jbar`` and
    ``compliance`` (nqp, nel), :math:`\\bar J(p)` and :math:`1/U''(\\bar J)` (zero when incompressible),
    or ``None`` to leave the pressure rows of forces and stiffness to the caller.
    """

    pressure: np.ndarray
    Np: np.ndarray
    Jbar: np.ndarray | None = None
    compliance: np.ndarray | None = None


@dataclass(frozen=True)
class FusedResponse:
    """``P`` (3,3,nqp,nel) total PK1 stress; ``forces`` (nel, ndofe); ``stiffness`` (nel, ndofe, ndofe) or None."""

    P: np.ndarray
    forces: np.ndarray
    stiffness: np.ndarray | None


# ----------------------------------------------------------------------------- kernel


@njit(cache=True, inline="always")
def _point_scratch(n_derivatives):
    """Per-thread scratch of :func:`_law_point`: Fq, H, S, Pq, A, Dq, Vq, aq, G3, M3, B3, c3."""
    return (np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 3)), np.zeros((3, 3, 3, 3)),
            np.empty(n_derivatives), np.empty((3, 3)), np.zeros(3), np.empty((3, 3)), np.empty((3, 3)),
            np.empty((3, 3, 3)), np.empty(3))


@njit(cache=True, inline="always", error_model="numpy")
def _law_point(kind, F, D, aux, has_direction, q, e, Fq, H, Dq, aq, Vq, S, Pq, A, tangent, G3, M3, B3, c3):
    """Point (q, e): Fq = F[:, :, q, e], H = Fq^{-T}, S, A = dP/dF (if ``tangent``), Pq = Fq S; returns det Fq.

    The other 3x3 / 3-vector arguments are scratch arrays (see :mod:`skvalve.fem.elements.fused_points`).
    """
    for i in range(3):
        for j in range(3):
            Fq[i, j] = F[i, j, q, e]
    for r in range(D.shape[0]):
        Dq[r] = D[r, q, e]
    J = inverse_transpose(Fq, H)
    if kind == _INVARIANT:
        if has_direction:
            for i in range(3):
                aq[i] = aux[i, 0, q, e]
        invariant_point(Fq, H, J, Dq, aq, has_direction, S, A, tangent, G3, M3, B3)
    else:
        for i in range(3):
            for j in range(3):
                Vq[i, j] = aux[i, j, q, e]
        principal_point(Fq, Dq, Vq, S, A, tangent, c3, M3, G3)
    for i in range(3):
        for j in range(3):
            s = 0.0
            for K in range(3):
                s += Fq[i, K] * S[K, j]
            Pq[i, j] = s
    return J


@njit(parallel=True, cache=True, error_model="numpy")
def _point_kernel(kind, F, D, aux, has_direction, tangent, elements, P, A_all):
    """At every point (q, e) of F: P[i, J, q, t] and, if ``tangent``, A_all[t, q, i, J, k, L] = dP_iJ/dF_kL,
    t = elements[e] (a region written into the arrays of all elements)."""
    nqp, nel = F.shape[2], F.shape[3]
    for e in prange(nel):
        t = elements[e]
        Fq, H, S, Pq, A, Dq, Vq, aq, G3, M3, B3, c3 = _point_scratch(D.shape[0])
        for q in range(nqp):
            _law_point(kind, F, D, aux, has_direction, q, e, Fq, H, Dq, aq, Vq, S, Pq, A, tangent, G3, M3, B3, c3)
            for i in range(3):
                for j in range(3):
                    P[i, j, q, t] = Pq[i, j]
            if tangent:
                A_all[t, q] = A


@njit(parallel=True, cache=True, error_model="numpy")
def _fused_kernel(kind, F, D, aux, has_direction, dN, dx, tangent, pressure, Np, Jbar, compliance, ndofe):
    nel, nqp, nb, dim = dN.shape
    nbp = Np.shape[2]
    mixed = pressure.shape[0] > 0
    volumetric = Jbar.shape[0] > 0
    nu = nb * dim
    P = np.empty((3, 3, nqp, nel))
    fe = np.zeros((nel, ndofe))
    ke = np.zeros((nel if tangent else 0, ndofe, ndofe))
    for e in prange(nel):
        Fq, H, S, Pq, A, Dq, Vq, aq, G3, M3, B3, c3 = _point_scratch(D.shape[0])
        Gw = np.empty((nb, dim, dim, dim))
        for q in range(nqp):
            J = _law_point(kind, F, D, aux, has_direction, q, e, Fq, H, Dq, aq, Vq, S, Pq, A, tangent, G3, M3, B3,
                           c3)
            if mixed:
                p = pressure[q, e]
                for i in range(3):
                    for j in range(3):
                        Pq[i, j] -= p * J * H[i, j]
                if tangent:
                    pJ = p * J
                    for i in range(3):
                        for j in range(3):
                            for k in range(3):
                                for L in range(3):
                                    A[i, j, k, L] -= pJ * (H[i, j] * H[k, L] - H[i, L] * H[k, j])
            for i in range(3):
                for j in range(3):
                    P[i, j, q, e] = Pq[i, j]
            w = dx[e, q]
            for a in range(nb):
                for i in range(dim):
                    s = 0.0
                    for J_ in range(dim):
                        s += Pq[i, J_] * dN[e, q, a, J_]
                    fe[e, a * dim + i] += w * s
            if mixed:
                for al in range(nbp):
                    if volumetric:
                        fe[e, nu + al] += w * Np[e, q, al] * (Jbar[q, e] - J)
            if not tangent:
                continue
            # K[ai,bk] += w dN[a,J] A[i,J,k,L] dN[b,L] (upper triangle; mirrored after the loop)
            add_point_stiffness(ke[e], dN[e, q], A, w, Gw)
            if mixed:
                for a in range(nb):
                    for i in range(dim):
                        s = 0.0
                        for J_ in range(dim):
                            s += J * H[i, J_] * dN[e, q, a, J_]
                        for al in range(nbp):
                            ke[e, a * dim + i, nu + al] -= w * s * Np[e, q, al]
                if volumetric:
                    for al in range(nbp):
                        for be in range(al, nbp):
                            ke[e, nu + al, nu + be] -= w * compliance[q, e] * Np[e, q, al] * Np[e, q, be]
        if tangent:
            for row in range(ndofe):
                for col in range(row + 1, ndofe):
                    ke[e, col, row] = ke[e, row, col]
    return P, fe, ke


# ------------------------------------------------------------------------- interface


def _defines_before(cls: type, method: str, other: str) -> bool:
    """True when ``method`` is defined on ``cls`` at least as deep as ``other`` in its MRO."""
    mro = cls.__mro__
    owner = next((k for k in mro if method in vars(k)), None)
    other_owner = next((k for k in mro if other in vars(k)), None)
    return owner is not None and (other_owner is None or mro.index(owner) <= mro.index(other_owner))


class FusedLaw:
    """Compiled stress/tangent/element assembly for one law (see :func:`fused_response`)."""

    def __init__(self, law: Hyperelastic, kind: int) -> None:
        self.law = law
        self.kind = kind

    def _derivatives(self, F: np.ndarray):
        law = self.law
        C = np.einsum("kI...,kJ...->IJ...", F, F)
        batch = F.shape[2:]
        if self.kind == _INVARIANT:
            J = determinant(F)
            I1bar = J ** (-2.0 / 3.0) * (C[0, 0] + C[1, 1] + C[2, 2])
            d: InvariantDerivatives = law.invariant_derivatives(I1bar, J, C)
            values = (d.d_1, d.d_J, d.d_11, d.d_1J, d.d_JJ, d.d_4, d.d_14, d.d_J4, d.d_44)
            D = np.stack([np.broadcast_to(np.asarray(v, dtype=float), batch) for v in values])
            if d.direction is None:
                return D, np.zeros((3, 1, 1, 1)), False
            direction = np.broadcast_to(np.asarray(d.direction, dtype=float), (3,) + batch)
            return D, np.ascontiguousarray(direction[:, None]), True
        w, v = np.linalg.eigh(np.moveaxis(C, (0, 1), (-2, -1)))
        c = np.moveaxis(w, -1, 0)
        vectors = np.ascontiguousarray(np.moveaxis(v, (-2, -1), (0, 1)))
        d: PrincipalDerivatives = law.principal_derivatives(c)
        D = np.concatenate([np.broadcast_to(d.first, (3,) + batch),
                            np.broadcast_to(d.second, (3, 3) + batch).reshape((9,) + batch)])
        return np.ascontiguousarray(D), vectors, False

    def __call__(self, F: np.ndarray, dN: np.ndarray, dx: np.ndarray, tangent: bool = True,
                 mixed: MixedFields | None = None, ndofe: int | None = None) -> FusedResponse:
        """Element forces and stiffness for ``F`` (3,3,nqp,nel) on a displacement space ``dN``, ``dx``.

        ``dN`` (nel, nqp, nb, dim) reference shape-function gradients, ``dx`` (nel, nqp) weights
        (quadrature weight times reference Jacobian). Local dofs are node-major (``a*dim + i``),
        pressure dofs of ``mixed`` after them; ``ndofe`` defaults to ``nb*dim + nbp``.
        """
        F = np.ascontiguousarray(F, dtype=float)
        nel, nqp, nb, dim = dN.shape
        if F.shape != (3, 3, nqp, nel) or dx.shape != (nel, nqp):
            raise ValueError(f"F must have shape (3, 3, {nqp}, {nel}) and dx ({nel}, {nqp}); got {F.shape}, "
                             f"{dx.shape}")
        D, aux, has_direction = self._derivatives(F)
        empty2 = np.zeros((0, 0))
        if mixed is None:
            pressure, Np, Jbar, compliance = empty2, np.zeros((nel, nqp, 0)), empty2, empty2
        else:
            pressure, Np = np.ascontiguousarray(mixed.pressure, float), np.ascontiguousarray(mixed.Np, float)
            volumetric = mixed.Jbar is not None
            Jbar = np.ascontiguousarray(mixed.Jbar, float) if volumetric else empty2
            compliance = np.ascontiguousarray(mixed.compliance, float) if volumetric else empty2
        if ndofe is None:
            ndofe = nb * dim + Np.shape[2]
        P, fe, ke = _fused_kernel(self.kind, F, np.ascontiguousarray(D), aux, has_direction,
                                  np.ascontiguousarray(dN, float), np.ascontiguousarray(dx, float), bool(tangent),
                                  pressure, Np, Jbar, compliance, int(ndofe))
        return FusedResponse(P, fe, ke if tangent else None)

    def point_response(self, F: np.ndarray, tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """``P`` (3,3,nqp,nel) and ``A[e, q, i, J, k, L]`` :math:`= \\partial P_{iJ}/\\partial F_{kL}` (None unless
        ``tangent``) at every point of ``F`` (3,3,nqp,nel): the layout of
        :meth:`~skvalve.fem.elements.constitutive.MaterialRegions.evaluate`, one compiled loop."""
        nqp, nel = F.shape[2:] if np.ndim(F) == 4 else (0, 0)
        P = np.empty((3, 3, nqp, nel))
        A = np.empty((nel, nqp, 3, 3, 3, 3)) if tangent else None
        self.point_response_into(F, np.arange(nel), P, A)
        return P, A

    def point_response_into(self, F: np.ndarray, elements: np.ndarray, P: np.ndarray, A: np.ndarray | None) -> None:
        """:meth:`point_response` of ``F`` (3,3,nqp,n) written to ``P[:, :, :, elements]`` and ``A[elements]``
        (``A`` None: no tangent); ``P`` and ``A`` C-contiguous arrays of all elements."""
        F = np.ascontiguousarray(F, dtype=float)
        if F.ndim != 4 or F.shape[:2] != (3, 3):
            raise ValueError(f"F must have shape (3, 3, nqp, nel); got {F.shape}")
        D, aux, has_direction = self._derivatives(F)
        tangent = A is not None
        _point_kernel(self.kind, F, np.ascontiguousarray(D), aux, has_direction, tangent,
                      np.ascontiguousarray(elements, dtype=np.int64), P,
                      A if tangent else np.empty((0, F.shape[2], 3, 3, 3, 3)))


def fused_response(law) -> FusedLaw | None:
    """The compiled evaluator of ``law``, or ``None`` when the law has no fused form (use the generic path).

    A law qualifies when it supplies ``invariant_derivatives`` (laws of :math:`\\bar I_1, J, I_4`) or
    ``principal_derivatives`` (laws of the principal values of C) at least as specific as its stress
    (a subclass that overrides ``response_C`` without them falls back to the generic path).
    """
    cls = type(law)
    if not isinstance(law, Hyperelastic):
        return None
    if hasattr(law, "invariant_derivatives") and _defines_before(cls, "invariant_derivatives", "response_C") \
            and _defines_before(cls, "invariant_derivatives", "stress_C"):
        return FusedLaw(law, _INVARIANT)
    if hasattr(law, "principal_derivatives") and _defines_before(cls, "principal_derivatives", "response_C"):
        return FusedLaw(law, _PRINCIPAL)
    return None


def _fused_laws(materials: MaterialRegions) -> list[FusedLaw] | None:
    """The compiled evaluator of every region's law, or ``None`` if one has no fused form."""
    fused = [fused_response(region.law) for region in materials.regions]
    return None if any(f is None for f in fused) else fused


def _single_region(materials: MaterialRegions) -> bool:
    return len(materials.regions) == 1 and isinstance(materials.regions[0].elements, slice)


def point_response_regions(materials: MaterialRegions, F: np.ndarray,
                           tangent: bool) -> tuple[np.ndarray, np.ndarray | None] | None:
    """``(P, A)`` of every region through :meth:`FusedLaw.point_response`, or ``None`` if a region has no fused form.

    The same as ``materials.evaluate(F, None, tangent)[:2]`` (P (3,3,nqp,nel), A (nel,nqp,3,3,3,3) or None):
    the stress of each region's law (its isochoric part in the mixed formulation) and its derivative.
    """
    fused = _fused_laws(materials)
    if fused is None:
        return None
    nqp, nel = F.shape[2], F.shape[3]
    P = np.empty((3, 3, nqp, nel))
    A = np.empty((nel, nqp, 3, 3, 3, 3)) if tangent else None
    for region, evaluate in zip(materials.regions, fused, strict=True):
        elements = np.arange(nel)[region.elements]
        evaluate.point_response_into(F[:, :, :, elements], elements, P, A)
    return P, A


def assemble_regions(materials: MaterialRegions, F: np.ndarray, space, tangent: bool,
                     pressure: np.ndarray | None = None) -> FusedResponse | None:
    """Every material region of ``materials`` through the fused kernel, or ``None`` if one region has no fused form.

    ``space`` provides ``dN``, ``dx``, ``nel``, ``ndofe`` and, for the mixed formulation (``pressure``
    (nqp, nel) given), ``Np``; the result holds the full element forces and stiffness of the solid
    term including the pressure rows (:math:`\bar J - J` and :math:`-1/U''` blocks).
    """
    fused = _fused_laws(materials)
    if fused is None:
        return None
    nel, nqp = space.nel, space.dx.shape[1]
    single = _single_region(materials)
    P = None if single else np.empty((3, 3, nqp, nel))
    forces = None if single else np.empty((nel, space.ndofe))
    stiffness = None if single or not tangent else np.empty((nel, space.ndofe, space.ndofe))
    for region, evaluate in zip(materials.regions, fused, strict=True):
        els = region.elements
        mixed = None
        if pressure is not None:
            p = pressure[:, els]
            if region.volumetric is not None:
                Jbar, compliance = invert_volumetric(region.volumetric, p)
            else:
                Jbar, compliance = np.ones_like(p), np.zeros_like(p)
            mixed = MixedFields(p, space.Np[els], Jbar, compliance)
        response = evaluate(F[:, :, :, els], space.dN[els], space.dx[els], tangent, mixed, space.ndofe)
        if single:
            return response
        P[:, :, :, els] = response.P
        forces[els] = response.forces
        if tangent:
            stiffness[els] = response.stiffness
    return FusedResponse(P, forces, stiffness)
