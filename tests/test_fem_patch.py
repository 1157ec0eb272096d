"""Homogeneous patch tests on distorted meshes against skvalve.analytic.homogeneous, for every law,
and the nearly incompressible block (J -> 1, pressure equal to its closed form).

A homogeneous deformation is linear in X, hence exactly representable by every element used
here even on distorted meshes; the FE solution must then equal the closed form up to the
Newton tolerance (rtol 1e-10 -> agreement to ~1e-9 relative; asserted at 1e-7).
"""

import numpy as np
import pytest

from skvalve.analytic import homogeneous
from skvalve.fem import Solid
from skvalve.fem.meshes import box, distort
from skvalve.materials import BimodularNeoHookean, IncompressibleNeoHookean, LeeSacks, NeoHookean, Ogden

COMPRESSIBLE = {
    "NeoHookean": NeoHookean.from_shear_poisson(1.0, 0.3),
    "Ogden": Ogden(mu=(0.7, 0.3), alpha=(4.0, -2.0), D=(0.8,)),
    "LeeSacks": LeeSacks(c0=1.0, c1=0.5, c2=2.0, D=0.5),
}
INCOMPRESSIBLE = {
    "IncompressibleNeoHookean": IncompressibleNeoHookean(1.0),
    "Ogden": Ogden(mu=(0.7, 0.3), alpha=(4.0, -2.0)),
    "LeeSacks": LeeSacks(c0=1.0, c1=0.5, c2=2.0),
    "BimodularNeoHookean": BimodularNeoHookean(mu_tension=2.0, mu_compression=0.5, direction=[0.0, 0.0, 1.0]),
}
STRETCH = 1.3


def _patch(material, mode: str, formulation: str, kind: str = "hex"):
    n = 2 if formulation == "up" else 3
    mesh = distort(box(n, kind=kind), amount=0.25, seed=5)
    solid = Solid(mesh, material, formulation=formulation)
    solid.add_dirichlet("left", 0.0, components=[0]).add_dirichlet("bottom", 0.0, components=[1])
    solid.add_dirichlet("front", 0.0, components=[2]).add_dirichlet("right", STRETCH - 1.0, components=[0])
    if mode == "equibiaxial":
        solid.add_dirichlet("top", STRETCH - 1.0, components=[1])
    result = solid.solve(steps=3, rtol=1e-10, progress=False)
    corner = result.evaluate("displacement", np.array([[1.0], [1.0], [1.0]]))[:, 0] + 1.0
    return result, corner


def _closed_form(material, mode, incompressible):
    if mode == "uniaxial":
        return homogeneous.uniaxial(material, STRETCH, incompressible=incompressible)
    return homogeneous.equibiaxial(material, STRETCH, incompressible=incompressible)


@pytest.mark.parametrize("mode", ["uniaxial", "equibiaxial"])
@pytest.mark.parametrize("name", list(COMPRESSIBLE))
def test_compressible_patch_equals_closed_form(name, mode):
    material = COMPRESSIBLE[name]
    result, corner = _patch(material, mode, "u")
    exact = _closed_form(material, mode, incompressible=False)
    # the unit faces carry the nominal (first Piola-Kirchhoff) stress as total force
    assert result.reaction("right")[0] == pytest.approx(exact.nominal[0], rel=1e-7)
    if mode == "equibiaxial":
        assert result.reaction("top")[1] == pytest.approx(exact.nominal[1], rel=1e-7)
    assert corner == pytest.approx(exact.stretches, rel=1e-8)
    sigma = result.evaluate("cauchy")
    assert np.allclose(sigma[0, 0], exact.cauchy[0], rtol=1e-7)
    assert np.allclose(sigma[2, 2], 0.0, atol=1e-7 * abs(exact.cauchy[0]))


@pytest.mark.parametrize("mode", ["uniaxial", "equibiaxial"])
@pytest.mark.parametrize("name", list(INCOMPRESSIBLE))
def test_incompressible_patch_equals_closed_form_mixed_hex(name, mode):
    material = INCOMPRESSIBLE[name]
    result, corner = _patch(material, mode, "up")
    exact = _closed_form(material, mode, incompressible=True)
    assert result.reaction("right")[0] == pytest.approx(exact.nominal[0], rel=1e-7)
    assert corner == pytest.approx(exact.stretches, rel=1e-8)
    # the pressure field is uniform and cancels the law's lateral (e3) stress: p = sigma_law,33
    law_sigma = material.cauchy(np.diag(exact.stretches)[:, :, None])[..., 0]
    assert np.allclose(result.pressure(), law_sigma[2, 2], rtol=1e-7, atol=1e-9)


@pytest.mark.parametrize("mode", ["uniaxial", "equibiaxial"])
def test_tetrahedra_patch(mode):
    """P1 (displacement) and P2/P1 (mixed) tetrahedra, neo-Hookean laws."""
    material = COMPRESSIBLE["NeoHookean"]
    result, _ = _patch(material, mode, "u", kind="tet")
    assert result.reaction("right")[0] == pytest.approx(_closed_form(material, mode, False).nominal[0], rel=1e-7)
    material = INCOMPRESSIBLE["IncompressibleNeoHookean"]
    result, _ = _patch(material, mode, "up", kind="tet")
    assert result.reaction("right")[0] == pytest.approx(_closed_form(material, mode, True).nominal[0], rel=1e-7)


def test_incompressible_neo_hookean_pressure_closed_form():
    """Uniaxial incompressible neo-Hookean: sigma_22 = mu (1/lam - (lam^2 + 2/lam)/3) - p = 0."""
    mu, lam = 1.0, STRETCH
    result, _ = _patch(IncompressibleNeoHookean(mu), "uniaxial", "up")
    assert np.allclose(result.pressure(), mu * (1.0 / lam - lam**2) / 3.0, rtol=1e-8)
    assert result.reaction("right")[0] == pytest.approx(mu * (lam - lam**-2), rel=1e-8)


def test_nearly_incompressible_block_J_and_pressure():
    """nu = 0.4999 neo-Hookean, mixed Q2/Q1: J -> 1 and p = -U'(J) = -lambda ln J / J."""
    material = NeoHookean.from_shear_poisson(1.0, 0.4999)
    result, corner = _patch(material, "uniaxial", "up")
    exact = homogeneous.uniaxial(material, STRETCH, incompressible=False)
    J = float(exact.J[0]) if np.ndim(exact.J) else float(exact.J)
    assert abs(J - 1.0) < 1e-3  # nearly incompressible
    F = result.evaluate("deformation_gradient")
    J_fe = np.linalg.det(F.transpose(2, 0, 1))
    assert np.allclose(J_fe, J, rtol=1e-9)
    assert np.allclose(result.pressure(), -material.lmbda * np.log(J) / J, rtol=1e-6)
    # and the incompressible limit: nominal stress of the incompressible law within 3 |J - 1|
    limit = homogeneous.uniaxial(IncompressibleNeoHookean(1.0), STRETCH).nominal[0]
    assert result.reaction("right")[0] == pytest.approx(limit, rel=3 * abs(J - 1.0) + 1e-6)


@pytest.mark.parametrize("kind", ["quad", "tri"])
def test_plane_strain_patch_mixed(kind):
    """Incompressible neo-Hookean in plane strain, F = diag(l, 1/l, 1), sigma_22 = 0:
    p = mu / l^2 and P_11 = mu (l - l^-3) per unit width (Q2/Q1 quads, P2/P1 triangles)."""
    from skvalve.fem.meshes import rectangle

    mu, lam = 1.5, 1.4
    mesh = rectangle(2, kind=kind)
    mesh = distort(mesh, amount=0.2, seed=3) if kind == "quad" else mesh
    solid = Solid(mesh, IncompressibleNeoHookean(mu), formulation="up")
    solid.add_dirichlet("left", 0.0, components=[0]).add_dirichlet("bottom", 0.0, components=[1])
    solid.add_dirichlet("right", lam - 1.0, components=[0])
    result = solid.solve(steps=2, rtol=1e-10, progress=False)
    assert result.reaction("right")[0] == pytest.approx(mu * (lam - lam**-3), rel=1e-8)
    law_p = mu * (1.0 / lam**2 - (lam**2 + lam**-2 + 1.0) / 3.0)  # sigma_law,22 of mu dev(B)
    assert np.allclose(result.pressure(), law_p, rtol=1e-8)
    top = result.evaluate("displacement", np.array([[0.5], [1.0]]))[1, 0]
    assert top == pytest.approx(1.0 / lam - 1.0, rel=1e-8)
