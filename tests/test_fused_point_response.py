"""Pointwise P and A = dP/dF of the compiled laws (skvalve.fem.elements.fused.point_response_regions, used by F-bar)
against the generic numpy path MaterialRegions.evaluate (law.pk1_and_tangent), per law and per region."""

from __future__ import annotations

import numpy as np
import pytest
import skfem as fem

from skvalve.fem.elements.constitutive import MaterialRegions
from skvalve.fem.elements.fused import fused_response, point_response_regions
from skvalve.kinematics import determinant
from skvalve.materials import BimodularNeoHookean, LeeSacks, NeoHookean, Ogden

TOL = 1e-12
MESH = fem.MeshHex.init_tensor(*[np.linspace(0.0, 1.0, 4)] * 3)  # 27 elements
NQP = 8


def _deformation(kind: str, nel: int, seed: int) -> np.ndarray:
    """F (3, 3, NQP, nel): random near the identity, or a large stretch (1.6, 0.9, 0.75) of a random one."""
    rng = np.random.default_rng(seed)
    F = np.eye(3)[:, :, None, None] + (0.02 if kind == "near_identity" else 0.1) * rng.standard_normal((3, 3, NQP, nel))
    if kind == "large_stretch":
        F = np.einsum("ij,jkqe->ikqe", np.diag([1.6, 0.9, 0.75]), F)
    assert np.all(determinant(F) > 0.5)
    return F


def _directions(n: int, seed: int) -> np.ndarray:
    """One random unit direction per element, shape (3, n)."""
    a = np.random.default_rng(seed).standard_normal((3, n))
    return a / np.linalg.norm(a, axis=0)


def _assert_close(actual, expected):
    scale = np.abs(expected).max()
    assert scale > 0
    assert np.abs(actual - expected).max() <= TOL * scale


def _compare(materials: MaterialRegions, F: np.ndarray):
    got = point_response_regions(materials, F, tangent=True)
    assert got is not None
    P, A, _ = materials.evaluate(F, None, True)
    _assert_close(got[0], P)
    _assert_close(got[1], A)
    P_only, A_none = point_response_regions(materials, F, tangent=False)
    assert A_none is None
    assert np.array_equal(P_only, got[0])


NEL = MESH.nelements
COMPRESSIBLE = {
    "neo_hookean": NeoHookean(1.0, 3.0),
    "lee_sacks_shipped": LeeSacks(1.0, 0.5, 2.0, D=0.2),
    "lee_sacks_published": LeeSacks(1.0, 0.5, 2.0, D=0.2, published_equation=True),
    "lee_sacks_trivalve_leaflet": LeeSacks(1.0e-3, 1.188659e-4, 15.260081, 20.0669),
    "ogden_3_term": Ogden(mu=(1.0, 0.2, 0.1), alpha=(2.5, 5.0, -2.0), D=(0.1,)),
    "ogden_2_volumetric_terms": Ogden(mu=(0.7, 0.3), alpha=(1.5, -3.0), D=(0.1, 0.4)),
}
# incompressible laws (isochoric stress, as the mixed formulation's MaterialRegions evaluates them), with one
# fibre direction per element
DIRECTIONAL = {
    "bimodular_smoothed": BimodularNeoHookean(2.0, 1.0, _directions(NEL, 5), smoothing=0.05),
    "bimodular_sharp": BimodularNeoHookean(2.0, 1.0, _directions(NEL, 6)),
}


@pytest.mark.parametrize("kind", ["near_identity", "large_stretch"])
@pytest.mark.parametrize("name", sorted(COMPRESSIBLE) + sorted(DIRECTIONAL))
def test_point_response_matches_the_generic_path(name, kind):
    law = COMPRESSIBLE.get(name) or DIRECTIONAL[name]
    assert fused_response(law) is not None
    _compare(MaterialRegions(MESH, law, mixed=name in DIRECTIONAL), _deformation(kind, NEL, seed=1))


@pytest.mark.parametrize("kind", ["near_identity", "large_stretch"])
def test_point_response_per_region(kind):
    """Three laws on interleaved element sets; in the mixed layout a per-element direction on its own region."""
    regions = np.arange(NEL) % 3
    laws = [COMPRESSIBLE["lee_sacks_trivalve_leaflet"], COMPRESSIBLE["ogden_3_term"], COMPRESSIBLE["neo_hookean"]]
    F = _deformation(kind, NEL, seed=2)
    _compare(MaterialRegions(MESH, laws, regions), F)
    directional = BimodularNeoHookean(2.0, 1.0, _directions(int((regions == 0).sum()), 7), smoothing=0.05)
    _compare(MaterialRegions(MESH, [directional, laws[0], laws[1]], regions, mixed=True), F)


def test_a_region_without_a_fused_form_gives_none():
    class Custom(NeoHookean):  # overrides the stress without stating its invariant derivatives
        def response_C(self, C):
            return super().response_C(C)

    materials = MaterialRegions(MESH, [NeoHookean(1.0, 3.0), Custom(1.0, 3.0)], np.arange(NEL) % 2)
    assert point_response_regions(materials, _deformation("near_identity", NEL, seed=3), True) is None


def test_bad_shape_is_named():
    with pytest.raises(ValueError, match="F must have shape"):
        fused_response(NeoHookean(1.0, 1.0)).point_response(np.zeros((3, 2, 2)))
