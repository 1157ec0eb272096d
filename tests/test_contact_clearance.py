"""The contact clearance limit (:mod:`skvalve.fem.contact.clearance`): it lets a surface move rigidly as far as it
likes, holds an approaching face to half the search depth, and keeps the trust region from carrying a block through
another, which it does without it."""

from functools import partial

import numpy as np
import pytest
import skfem

from skvalve.fem import HyperelasticTerm, MaterialRegions, Problem, Space
from skvalve.fem.contact import ContactSurface, SurfaceContact
from skvalve.fem.contact.blend import free_edges
from skvalve.fem.contact.clearance import clearance_fraction
from skvalve.fem.solvers.damping import lumped_volume
from skvalve.fem.solvers.ptc import PseudoTransientOptions, pseudo_transient
from skvalve.fem.solvers.trust_region import TrustRegionOptions, trust_region
from skvalve.materials import NeoHookean

GAP, PUSH, DEPTH = 0.2, 0.45, 0.1


def _blocks(penalty: float = 50.0, barrier: float | None = None):
    """Two unit cubes (2x2x2 hexes) on rollers, GAP apart; the top one's top face pushed down PUSH (more than the
    gap plus the search depth DEPTH) from the start."""
    bottom = skfem.MeshHex.init_tensor(*(np.linspace(0, 1, 3),) * 3)
    top = skfem.MeshHex.init_tensor(*(np.linspace(0, 1, 3),) * 2, np.linspace(1 + GAP, 2 + GAP, 3))
    mesh = skfem.MeshHex(np.hstack([bottom.p, top.p]), np.hstack([bottom.t, top.t + bottom.p.shape[1]]))
    space = Space(mesh)
    problem = Problem(space, [HyperelasticTerm(space, MaterialRegions(mesh, NeoHookean(1.0, 2.0)))])
    faces = mesh.facets_satisfying(lambda X: np.isclose(X[2], 1.0) | np.isclose(X[2], 1.0 + GAP), True)
    contact = problem.add_term(SurfaceContact(space, ContactSurface.from_facets(mesh, faces), penalty,
                                              smoothing=0.01, blend=0.1, max_penetration=DEPTH, barrier=barrier))
    for axis in range(3):
        problem.add_dirichlet(lambda X, a=axis: X[a] == 0.0, 0.0, components=[axis])
    problem.add_dirichlet(lambda X: np.isclose(X[2], 2.0 + GAP), -PUSH, components=[2])
    return problem, contact


def _overlap(problem, u) -> float:
    """How far the top block's lower face has passed the bottom block's upper face."""
    X = problem.space.dof_coordinates
    z = X[2] + u[2::3]
    return float(z[np.isclose(X[2], 1.0)].max() - z[np.isclose(X[2], 1.0 + GAP)].min())


def test_a_rigid_motion_is_free_and_an_approach_is_held_to_half_the_depth():
    problem, contact = _blocks()
    X = problem.space.dof_coordinates
    u = np.zeros(problem.space.n_dofs)
    assert clearance_fraction(contact, u, np.tile([3.0, -2.0, 5.0], X.shape[1])) == 1.0  # no relative motion
    step = np.zeros_like(u)
    step[2::3][X[2] > 1.0 + 0.5 * GAP] = -1.0  # the top block 1.0 down: through the bottom one
    # the faces are parallel, so the gap is GAP - f: it reaches -3 DEPTH/4 at f = GAP + 3 DEPTH/4
    assert clearance_fraction(contact, u, step) == pytest.approx(GAP + 0.75 * DEPTH, abs=1e-8)
    assert clearance_fraction(contact, u, 0.2 * step) == 1.0  # ends 0.0 apart


def test_a_close_node_slides_freely_and_goes_no_deeper_than_three_quarters_of_the_depth():
    """The top block already 0.04 through the bottom one may slide 1.0 sideways in one step (a bound on the relative
    motion alone would allow 0.05) and go 3/4 of the depth - 0.04 deeper; one coming in from the side, past the
    other's free edges, may come in at 0.6 of the depth but not sink to 0.9 as it does; a node already 0.78 of the
    depth through (in the fade-out) is left free."""
    problem, contact = _blocks()
    X = problem.space.dof_coordinates
    top = X[2] > 1.0 + 0.5 * GAP
    u = np.zeros(problem.space.n_dofs)
    u[2::3][top] = -(GAP + 0.04)
    slide = np.zeros_like(u)
    slide[0::3][top] = 1.0
    assert clearance_fraction(contact, u, slide) == 1.0
    down = np.zeros_like(u)
    down[2::3][top] = -1.0
    assert clearance_fraction(contact, u, down) == pytest.approx(0.75 * DEPTH - 0.04, abs=1e-8)
    u[0::3][top], u[2::3][top] = 1.5, -(GAP + 0.6 * DEPTH)  # beside the bottom block, out of its triangles' bands
    back = np.zeros_like(u)
    back[0::3][top] = -1.5
    assert clearance_fraction(contact, u, back) == 1.0
    assert clearance_fraction(contact, u, back + 0.3 * DEPTH * down) < 1.0
    u[0::3][top], u[2::3][top] = 0.0, -(GAP + 0.78 * DEPTH)
    assert clearance_fraction(contact, u, -down) == 1.0  # out
    assert clearance_fraction(contact, u, 0.01 * down) == 1.0  # in the fade-out: the energy lets it go


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


def test_the_limit_keeps_a_pseudo_transient_step_from_carrying_a_block_through_another():
    """One lightly damped pseudo-step of the whole push (0.45, ramped with the load factor) carries the top block
    through the bottom one; with the limit the rejected steps are cut until no node ends deeper than half the depth,
    and Ψtc ends at the same contact state as the trust region with steps of at most half the depth."""
    options = PseudoTransientOptions(damping=1e-3, first_step=1.0, max_load_step=1.0, rtol=1e-10, atol=1e-12,
                                     max_increment=None, max_strain_increment=None)
    problem, _ = _blocks()
    loose = pseudo_transient(problem, lumped_volume(problem.space), 1.0, options, progress=False)
    assert _overlap(problem, loose.u) > 2.0 * DEPTH  # tunnelled
    problem, contact = _blocks()
    seen = []

    def watched(u, p):
        fraction = clearance_fraction(contact, u, p)
        seen.append(fraction)
        return fraction

    limited = pseudo_transient(problem, lumped_volume(problem.space), 1.0, options, progress=False, limit=watched)
    problem, _ = _blocks()
    capped = trust_region(problem, 1.0, np.zeros(problem.space.n_dofs),
                          TrustRegionOptions(rtol=1e-10, radius=0.04, max_radius=0.5 * DEPTH, solver="scipy",
                                             max_steps=2000), progress=False)
    assert limited.converged and limited.rejected >= 1 and min(seen) < 1.0
    assert 0.0 < _overlap(problem, limited.u) < 0.1 * DEPTH
    np.testing.assert_allclose(limited.u, capped.u, atol=1e-8)
    problem, _ = _blocks()
    with pytest.raises(ValueError, match="fraction in"):
        pseudo_transient(problem, lumped_volume(problem.space), 1.0, options, progress=False, limit=lambda u, p: 2.0)


def test_the_limit_counts_the_pairs_the_energy_counts():
    """The facing factor and band the limit uses are the contact energy's own: for the pairs of a blended search they
    reproduce the factors it lists, and the band is -2 beta past a free edge, -beta past a shared one."""
    problem, contact = _blocks()
    X = problem.space.dof_coordinates
    u = np.zeros(problem.space.n_dofs)
    u[2::3][X[2] > 1.0 + 0.5 * GAP] = -(GAP + 0.02)
    pairs = contact.active_pairs(u)
    assert pairs.size > 0
    x = contact.X + u[: problem.space.n_u].reshape(-1, 3)
    np.testing.assert_allclose(contact.facing(pairs.node, pairs.triangle, x), pairs.facing, rtol=0, atol=1e-14)
    lower = contact.band_lower(np.arange(contact.surface.triangles.shape[0]))
    assert set(np.unique(lower)) == {-0.2, -0.1} and np.all((lower == -0.2) == free_edges(contact.surface.triangles))


def test_a_limit_outside_zero_to_one_is_refused():
    problem, _ = _blocks()
    with pytest.raises(ValueError, match="step limit"):
        trust_region(problem, 1.0, np.zeros(problem.space.n_dofs), TrustRegionOptions(solver="scipy"),
                     progress=False, limit=lambda u, p: 0.0)
