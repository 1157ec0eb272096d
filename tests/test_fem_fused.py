"""The fused kernel (skvalve.fem.elements.fused) against the generic path: law.pk1_and_tangent + kernels."""

from __future__ import annotations

import numpy as np
import pytest
import skfem as fem

from skvalve.fem.elements.constitutive import MaterialRegions
from skvalve.fem.elements.fused import MixedFields, assemble_regions, fused_response
from skvalve.fem.kernels import element_forces, element_gradients, element_stiffness
from skvalve.fem.space import Space
from skvalve.kinematics import cofactor, determinant
from skvalve.materials import (
    BimodularNeoHookean,
    IncompressibleNeoHookean,
    LeeSacks,
    NeoHookean,
    Ogden,
)

TOL = 1e-12


def _space(mesh, element, intorder):
    basis = fem.CellBasis(mesh, element, intorder=intorder)
    nb = basis.Nbfun
    grads = np.stack([basis.basis[a][0].grad for a in range(nb)])  # (nb, d, nel, nqp)
    dN = np.ascontiguousarray(grads.transpose(2, 3, 0, 1))
    return basis, dN, np.ascontiguousarray(basis.dx)


def _deformation(dN, amplitude, seed):
    """F (3,3,nqp,nel) of a random smooth-enough displacement; 2D meshes get F33 = 1 (plane strain)."""
    rng = np.random.default_rng(seed)
    nel, nqp, nb, dim = dN.shape
    u_elem = amplitude * rng.standard_normal((nel, nb, dim))
    H = element_gradients(u_elem, dN)
    F = np.zeros((3, 3, nqp, nel))
    F[:dim, :dim] = H
    F += np.eye(3)[:, :, None, None]
    assert np.all(determinant(F) > 0.2)
    return F


def _generic(law, F, dN, dx, pressure=None):
    """P, element forces and stiffness through the generic einsum path and the separate kernels."""
    nel, nqp, nb, dim = dN.shape
    P, A = law.pk1_and_tangent(F)
    if pressure is not None:  # -p cof F and its derivative -p dcof/dF
        cof, J = cofactor(F), determinant(F)
        P = P - pressure * cof
        dcof = np.einsum("ijqe,klqe->ijklqe", cof, cof) - np.einsum("ilqe,kjqe->ijklqe", cof, cof)
        A = A - pressure / J * dcof
    fe = element_forces(np.ascontiguousarray(P[:dim, :dim]), dN, dx)
    ke = np.zeros((nel, nb * dim, nb * dim))
    element_stiffness(A.transpose(5, 4, 0, 1, 2, 3)[:, :, :dim, :dim, :dim, :dim], dN, dx, ke)
    return P, fe, ke


def _close(actual, expected, scale=None):
    """Agreement to TOL relative to the largest entry (or to ``scale`` where the reference vanishes)."""
    scale = np.max(np.abs(expected)) if scale is None else scale
    assert scale > 0
    assert np.max(np.abs(actual - expected)) <= TOL * scale


HEX = fem.MeshHex.init_tensor(*[np.linspace(0.0, 1.0, 3)] * 3)
DIRECTION = np.array([1.0, 1.0, 0.3])

DISPLACEMENT_LAWS = {
    "neo_hookean": NeoHookean(1.0, 3.0),
    "lee_sacks_shipped": LeeSacks(1.0, 0.5, 2.0, D=0.2),
    "lee_sacks_published": LeeSacks(1.0, 0.5, 2.0, D=0.2, published_equation=True),
    "ogden_3_term": Ogden(mu=(1.0, 0.2, 0.1), alpha=(2.5, 5.0, -2.0), D=(0.1,)),
    "ogden_2_volumetric_terms": Ogden(mu=(0.7, 0.3), alpha=(1.5, -3.0), D=(0.1, 0.4)),
    # incompressible laws evaluated in the displacement path: only their isochoric stress
    "bimodular_smoothed": BimodularNeoHookean(2.0, 1.0, DIRECTION, smoothing=0.05),
    "bimodular_sharp": BimodularNeoHookean(2.0, 1.0, DIRECTION),
}


@pytest.mark.parametrize("name", sorted(DISPLACEMENT_LAWS))
def test_fused_matches_generic_on_hexahedra(name):
    law = DISPLACEMENT_LAWS[name]
    _, dN, dx = _space(HEX, fem.ElementHex1(), 3)
    F = _deformation(dN, 0.15, seed=1)
    fused = fused_response(law)
    assert fused is not None
    got = fused(F, dN, dx, tangent=True)
    P, fe, ke = _generic(law, F, dN, dx)
    _close(got.P, P)
    _close(got.forces, fe)
    _close(got.stiffness, ke)
    assert np.array_equal(fused(F, dN, dx, tangent=False).forces, got.forces)


def test_fused_plane_strain_quadrilaterals():
    law = LeeSacks(1.0, 0.5, 2.0, D=0.2)
    mesh = fem.MeshQuad.init_tensor(*[np.linspace(0.0, 1.0, 4)] * 2)
    _, dN, dx = _space(mesh, fem.ElementQuad2(), 5)
    F = _deformation(dN, 0.01, seed=2)
    got = fused_response(law)(F, dN, dx)
    P, fe, ke = _generic(law, F, dN, dx)
    _close(got.P, P)
    _close(got.forces, fe)
    _close(got.stiffness, ke)


@pytest.mark.parametrize("stretches", [(1.0, 1.0, 1.0), (1.2, 1.2, 0.9), (0.8, 1.1, 1.1)])
def test_ogden_at_repeated_principal_stretches(stretches):
    """Coincident eigenvalues of C take the limit of the divided difference; generic path is exact there."""
    law = Ogden(mu=(1.0, 0.2), alpha=(2.5, -2.0), D=(0.1,))
    _, dN, dx = _space(fem.MeshHex.init_tensor(*[np.linspace(0.0, 1.0, 2)] * 3), fem.ElementHex1(), 3)
    rotation = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    F = np.broadcast_to((rotation @ np.diag(stretches))[:, :, None, None], (3, 3) + dx.T.shape).copy()
    got = fused_response(law)(F, dN, dx)
    P, fe, ke = _generic(law, F, dN, dx)
    _close(got.P, P, scale=law.shear_modulus)
    _close(got.stiffness, ke)


MIXED_LAWS = {
    "incompressible_neo_hookean": (IncompressibleNeoHookean(1.5), None),
    "bimodular_smoothed": (BimodularNeoHookean(2.0, 1.0, DIRECTION, smoothing=0.05), None),
    "lee_sacks_split": LeeSacks(1.0, 0.5, 2.0, D=0.2).split(),
    "neo_hookean_split": NeoHookean(1.0, 3.0).split(),
}


@pytest.mark.parametrize("name", sorted(MIXED_LAWS))
def test_fused_mixed_up_blocks(name):
    """Q2/Q1 u/p: -p cof F in P and A, the coupling K_up and the pressure rows (Jbar - J, -1/U'')."""
    law, volumetric = MIXED_LAWS[name]
    mesh = fem.MeshHex.init_tensor(*[np.linspace(0.0, 1.0, 3)] * 3)
    basis_u, dN, dx = _space(mesh, fem.ElementHex2(), 4)
    basis_p = fem.CellBasis(mesh, fem.ElementHex1(), quadrature=basis_u.quadrature)
    Np = np.ascontiguousarray(np.stack([np.asarray(basis_p.basis[a][0]) for a in range(basis_p.Nbfun)])
                              .transpose(1, 2, 0))
    nel, nqp, nb, _ = dN.shape
    F = _deformation(dN, 0.03, seed=3)
    rng = np.random.default_rng(4)
    p = np.einsum("eqa,ea->qe", Np, 0.3 * rng.standard_normal((nel, Np.shape[2])))
    Jbar = 1.0 + 0.01 * rng.standard_normal(p.shape)
    compliance = np.zeros_like(p) if volumetric is None else 1.0 / volumetric.second_derivative(Jbar)
    got = fused_response(law)(F, dN, dx, mixed=MixedFields(p, Np, Jbar, compliance))
    P, fe, ke = _generic(law, F, dN, dx, pressure=p)
    nu = nb * 3
    _close(got.P, P)
    _close(got.forces[:, :nu], fe)
    _close(got.stiffness[:, :nu, :nu], ke)
    wN = Np * dx[:, :, None]
    J = determinant(F)
    _close(got.forces[:, nu:], np.einsum("eqa,qe->ea", wN, Jbar - J))
    coupling = -np.einsum("ijqe,eqaj,eqb->eaib", cofactor(F), dN, wN).reshape(nel, nu, -1)
    _close(got.stiffness[:, :nu, nu:], coupling)
    _close(got.stiffness[:, nu:, :nu], coupling.transpose(0, 2, 1))
    if volumetric is not None:
        _close(got.stiffness[:, nu:, nu:], -np.einsum("eqa,qe,eqb->eab", wN, compliance, Np))
    else:
        assert np.all(got.stiffness[:, nu:, nu:] == 0.0)


def test_laws_without_a_fused_form_use_the_generic_path():
    class Custom(NeoHookean):  # overrides the stress without stating its invariant derivatives
        def response_C(self, C):
            return super().response_C(C)

    assert fused_response(Custom(1.0, 1.0)) is None
    assert fused_response(object()) is None
    assert fused_response(NeoHookean(1.0, 1.0)) is not None


def test_bad_shapes_are_named():
    _, dN, dx = _space(HEX, fem.ElementHex1(), 3)
    with pytest.raises(ValueError, match="F must have shape"):
        fused_response(NeoHookean(1.0, 1.0))(np.zeros((3, 3, 2, 2)), dN, dx)


@pytest.mark.parametrize("formulation", ["u", "up"])
def test_assemble_regions_matches_material_regions(formulation):
    """Two laws on two element sets, through MaterialRegions.evaluate + kernels vs assemble_regions."""
    mesh = fem.MeshHex.init_tensor(*[np.linspace(0.0, 1.0, 3)] * 3)
    space = Space(mesh, formulation)
    laws = ([NeoHookean(1.0, 3.0), LeeSacks(1.0, 0.5, 2.0, D=0.2)] if formulation == "u"
            else [IncompressibleNeoHookean(1.5), LeeSacks(1.0, 0.5, 2.0, D=0.2)])
    materials = MaterialRegions(mesh, laws, regions=np.arange(mesh.nelements) % 2, mixed=formulation == "up")
    F = _deformation(space.dN, 0.02, seed=6)
    rng = np.random.default_rng(7)
    p = None if formulation == "u" else np.einsum("eqa,ea->qe", space.Np, 0.05 * rng.standard_normal(
        (space.nel, space.nb_p)))
    got = assemble_regions(materials, F, space, True, p)
    P, A, mixed = materials.evaluate(F, p, True)
    nu = space.nb_u * 3
    fe = element_forces(np.ascontiguousarray(P), space.dN, space.dx)
    ke = np.zeros((space.nel, nu, nu))
    element_stiffness(A, space.dN, space.dx, ke)
    _close(got.P, P)
    _close(got.forces[:, :nu], fe)
    _close(got.stiffness[:, :nu, :nu], ke)
    if mixed is not None:
        Jbar, compliance, J, _ = mixed
        wN = space.Np * space.dx[:, :, None]
        _close(got.forces[:, nu:], np.einsum("eqa,qe->ea", wN, Jbar - J), scale=np.abs(got.forces).max())
        _close(got.stiffness[:, nu:, nu:], -np.einsum("eqa,qe,eqb->eab", wN, compliance, space.Np))
