"""The contact clearance limit (:mod:`skvalve.fem.contact_clearance`): it lets a surface move rigidly as far as it
likes, holds an approaching face to half the search depth, and keeps the trust region from carrying a block through
another, which it does without it."""

from functools import partial

import numpy as np
import pytest
import skfem

from skvalve.fem import HyperelasticTerm, MaterialRegions, Problem, Space
from skvalve.fem.contact import ContactSurface, SurfaceContact
from skvalve.fem.contact_clearance import clearance_fraction
from skvalve.fem.trust_region import TrustRegionOptions, trust_region
from skvalve.materials import NeoHookean

GAP, PUSH, DEPTH = 0.2, 0.45, 0.1


def _blocks():
    """Two unit cubes (2x2x2 hexes) on rollers, GAP apart; the top one's top face pushed down PUSH (more than the
    gap plus the search depth DEPTH) from the start."""
    bottom = skfem.MeshHex.init_tensor(*(np.linspace(0, 1, 3),) * 3)
    top = skfem.MeshHex.init_tensor(*(np.linspace(0, 1, 3),) * 2, np.linspace(1 + GAP, 2 + GAP, 3))
    mesh = skfem.MeshHex(np.hstack([bottom.p, top.p]), np.hstack([bottom.t, top.t + bottom.p.shape[1]]))
    space = Space(mesh)
    problem = Problem(space, [HyperelasticTerm(space, MaterialRegions(mesh, NeoHookean(1.0, 2.0)))])
    faces = mesh.facets_satisfying(lambda X: np.isclose(X[2], 1.0) | np.isclose(X[2], 1.0 + GAP), True)
    contact = problem.add_term(SurfaceContact(space, ContactSurface.from_facets(mesh, faces), 50.0, smoothing=0.01,
                                              blend=0.1, max_penetration=DEPTH))
    for axis in range(3):
        problem.add_dirichlet(lambda X, a=axis: X[a] == 0.0, 0.0, components=[axis])
    problem.add_dirichlet(lambda X: np.isclose(X[2], 2.0 + GAP), -PUSH, components=[2])
    return problem, contact


def _overlap(problem, u) -> float:
    """How far the top block's lower face has passed the bottom block's upper face."""
    X = problem.space.dof_coordinates
    z = X[2] + u[2::3]
    return float(z[np.isclose(X[2], 1.0)].max() - z[np.isclose(X[2], 1.0 + GAP)].min())


def test_a_rigid_motion_is_free_and_an_approach_is_held_to_the_depth():
    problem, contact = _blocks()
    X = problem.space.dof_coordinates
    u = np.zeros(problem.space.n_dofs)
    assert clearance_fraction(contact, u, np.tile([3.0, -2.0, 5.0], X.shape[1])) == 1.0  # no relative motion
    step = np.zeros_like(u)
    step[2::3][X[2] > 1.0 + 0.5 * GAP] = -1.0  # the top block 1.0 down: through the bottom one
    fraction = clearance_fraction(contact, u, step)
    # a triangle's centroid-corner reach (0.37) exceeds the gap, so the distance bound is 0 and half the depth is left
    assert fraction == pytest.approx(0.5 * DEPTH)
    assert fraction * 1.0 <= GAP + 0.5 * DEPTH  # the moved face ends at most half the depth through the other
    assert clearance_fraction(contact, u, 0.02 * step) == 1.0  # under a quarter of the depth: no pair can pass half


def test_the_limit_keeps_a_long_step_from_carrying_a_block_through_another():
    """A radius of 1 lets the first steps carry the top block 0.45 down: without the limit it ends 0.2 through the
    bottom block (past the search depth, where the penalty no longer sees it); with it, at the state that steps of
    at most half the depth reach, in fewer steps."""
    options = TrustRegionOptions(rtol=1e-10, radius=1.0, max_radius=2.0, solver="scipy")
    problem, _ = _blocks()
    loose = trust_region(problem, 1.0, np.zeros(problem.space.n_dofs), options, progress=False)
    assert _overlap(problem, loose.u) > 2.0 * DEPTH  # tunnelled
    problem, contact = _blocks()
    limited = trust_region(problem, 1.0, np.zeros(problem.space.n_dofs), options, progress=False,
                           limit=partial(clearance_fraction, contact))
    problem, _ = _blocks()
    capped = trust_region(problem, 1.0, np.zeros(problem.space.n_dofs),
                          TrustRegionOptions(rtol=1e-10, radius=0.04, max_radius=0.5 * DEPTH, solver="scipy",
                                             max_steps=2000), progress=False)
    assert limited.converged and capped.converged
    assert 0.0 < _overlap(problem, limited.u) < 0.1 * DEPTH
    np.testing.assert_allclose(limited.u, capped.u, atol=1e-9)
    assert len(limited.residuals) < len(capped.residuals)


def test_a_limit_outside_zero_to_one_is_refused():
    problem, _ = _blocks()
    with pytest.raises(ValueError, match="step limit"):
        trust_region(problem, 1.0, np.zeros(problem.space.n_dofs), TrustRegionOptions(solver="scipy"),
                     progress=False, limit=lambda u, p: 0.0)
