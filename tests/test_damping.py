"""Pseudo-transient viscous damping (skvalve.fem.solvers.damping): the damped solve ends at the undamped equilibrium
of a statically determinate block, lags it by an amount that vanishes with the coefficient, and its
residual and tangent are consistent."""

import numpy as np
import pytest
import skfem
from scipy.optimize import brentq

from skvalve.analytic.homogeneous import uniaxial
from skvalve.fem import Solid
from skvalve.fem.solvers.damping import DampingSchedule, ViscousDamping, lumped_volume, undamped_residual
from skvalve.materials import NeoHookean

LAW = NeoHookean(1.0, 2.0)


def pulled_block() -> Solid:
    """A unit cube on rollers pulled by a total force 0.3 on its x = 1 face: statically determinate (P11 = 0.3)."""
    solid = Solid(skfem.MeshHex().refined(1), LAW)
    for axis in range(3):
        solid.add_dirichlet(lambda X, a=axis: X[a] == 0.0, 0.0, components=[axis])
    nodes = solid.space.scalar_dofs_on(lambda X: X[0] == 1.0)
    mid = np.isclose(solid.space.dof_coordinates[1:, nodes], 0.5)
    weights = np.where(mid[0], 2.0, 1.0) * np.where(mid[1], 2.0, 1.0)
    share = np.zeros((3, nodes.size))
    share[0] = 0.3 * weights / weights.sum()  # consistent nodal forces of a uniform traction on a 2x2 face
    solid.add_nodal_force(nodes=nodes, force=share)
    return solid


def test_lumped_volume_sums_to_the_body_volume():
    solid = pulled_block()
    weights = lumped_volume(solid.space)
    assert weights[0::3].sum() == pytest.approx(1.0)
    assert np.all(weights > 0)


def test_damped_solve_ends_at_the_undamped_solution_and_lags_less_as_c_falls():
    reference = pulled_block().solve(steps=4, progress=False, solver="scipy")
    u_ref = reference.u()
    # the undamped result is the closed form: homogeneous uniaxial nominal stress 0.3
    stretch = brentq(lambda lam: uniaxial(LAW, lam, incompressible=False).nominal[0] - 0.3, 1.0, 2.0)
    F = reference.evaluate("deformation_gradient")
    np.testing.assert_allclose(F[0, 0], stretch, rtol=1e-8)
    lags = []
    for c0 in (1.0, 0.1):
        solid = pulled_block()
        damping = solid.add_term(ViscousDamping(solid.space, DampingSchedule(c0, t_off=0.75)))
        result = solid.solve(steps=4, progress=False, solver="scipy", rtol=1e-10)
        np.testing.assert_allclose(result.u(), u_ref, rtol=1e-7, atol=1e-10)  # damping is off at t >= 0.75
        norm, relative = undamped_residual(solid, result.u(), 1.0)
        assert relative < 1e-9
        lags.append(np.abs(result.u(2) - reference.u(2)).max())  # at t = 0.5 the damping holds the block back
        assert damping.committed_t == 1.0
        assert undamped_residual(solid, result.u(2), 0.5)[1] > 1e-6
    assert lags[1] < 0.2 * lags[0]
    assert lags[1] > 0


def test_damping_residual_tangent_and_commit():
    solid = pulled_block()
    damping = ViscousDamping(solid.space, DampingSchedule(2.0, t_off=1.0, power=1.0), weighting="identity")
    rng = np.random.default_rng(0)
    u = rng.normal(size=solid.space.n_dofs)
    contribution = damping.assemble(u, 0.25, True, 1)
    eta = 2.0 * (1 - 0.25) / 0.25
    np.testing.assert_allclose(contribution.internal, eta * u)
    np.testing.assert_allclose(contribution.blocks[0].matrices[:, 0, 0], eta)
    damping.commit()
    np.testing.assert_allclose(damping.assemble(u, 0.5, False, 2).internal, 0.0)
    damping.rewind()
    assert damping.committed_t == 0.25
    with pytest.raises(ValueError, match="weighting"):
        ViscousDamping(solid.space, DampingSchedule(1.0, 1.0), weighting="mass")
    with pytest.raises(ValueError, match="t_off"):
        DampingSchedule(1.0, 0.0)
