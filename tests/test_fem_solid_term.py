"""The solid term's compiled path (skvalve.fem.elements.fused) equals its generic path, for every law, u and u/p, 3D and
plane strain — so the finite-difference tangent checks of test_fem_tangent.py cover both."""

import numpy as np
import pytest

from skvalve.fem import Solid
from skvalve.fem.elements.fused import fused_response
from skvalve.fem.meshes import box, distort, rectangle
from skvalve.materials import BimodularNeoHookean, IncompressibleNeoHookean, LeeSacks, NeoHookean, Ogden

CASES = {
    "neo-Hookean hex u": lambda: Solid(distort(box(2)), NeoHookean(1.0, 2.0)),
    "Lee-Sacks hex u": lambda: Solid(distort(box(2)), LeeSacks(c0=1.0, c1=0.5, c2=2.0, D=0.5)),
    "Ogden tet P2 u": lambda: Solid(box(1, kind="tet"), Ogden(mu=(0.6, 0.4), alpha=(3.0, -2.0), D=(0.5,)), order=2),
    "incompressible neo-Hookean Q2/Q1": lambda: Solid(box(1), IncompressibleNeoHookean(1.0), formulation="up"),
    "Lee-Sacks Q2/Q1 split": lambda: Solid(distort(box(1)), LeeSacks(c0=1.0, c1=0.5, c2=2.0, D=0.05),
                                           formulation="up"),
    "bimodular smoothed quad Q2/Q1": lambda: Solid(
        distort(rectangle(2)), BimodularNeoHookean(2.0, 0.5, direction=[1.0, 0.0, 0.0], smoothing=1e-2),
        formulation="up"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_fused_and_generic_solid_terms_agree(name):
    solid = CASES[name]()
    rng = np.random.default_rng(3)
    u = 0.03 * rng.standard_normal(solid.space.n_dofs)
    term = solid.solid
    assert all(fused_response(region.law) is not None for region in term.materials.regions)  # not a fallback
    fused = term.assemble(u, 1.0, True, 1)
    term.fused = False
    generic = term.assemble(u, 1.0, True, 1)
    scale_f = np.abs(generic.internal).max()
    scale_k = np.abs(generic.blocks[0].matrices).max()
    assert np.abs(fused.internal - generic.internal).max() <= 1e-12 * scale_f
    assert np.abs(fused.blocks[0].matrices - generic.blocks[0].matrices).max() <= 1e-12 * scale_k
