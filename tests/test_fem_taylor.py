"""The Taylor test of a problem's terms (skvalve.fem.taylor): second order for exact tangents (a solid and a
follower pressure), first order for a tangent that is wrong by a few per cent, which it must catch."""

from dataclasses import replace

import numpy as np
import pytest

from skvalve.fem import Solid, Term, taylor_test
from skvalve.fem.meshes import box, distort
from skvalve.materials import NeoHookean

LENGTHS = (1e-4, 1e-3, 1e-2)


def _loaded_block() -> tuple[Solid, np.ndarray, np.ndarray]:
    """A distorted cube, clamped on the left, a follower pressure on the right, at a random deformed state, with a
    random direction that is zero on the clamped dofs."""
    solid = Solid(distort(box(2)), NeoHookean(1.0, 3.0))
    solid.add_dirichlet("left", 0.0).add_pressure("right", 0.5)
    rng = np.random.default_rng(7)
    free = solid.pattern.free
    u, p = np.zeros(solid.space.n_dofs), np.zeros(solid.space.n_dofs)
    u[free] = 0.03 * rng.standard_normal(free.size)
    p[free] = rng.standard_normal(free.size)
    return solid, u, p


class _WrongTangent(Term):
    """A term whose tangent is its wrapped term's scaled by ``factor`` (forces unchanged)."""

    def __init__(self, term: Term, factor: float) -> None:
        self.term, self.factor, self.name = term, factor, "wrong " + term.name

    def connectivity(self):
        return self.term.connectivity()

    def assemble(self, u, t, tangent, step):
        contribution = self.term.assemble(u, t, tangent, step)
        if tangent:
            blocks = [replace(block, matrices=self.factor * block.matrices) for block in contribution.blocks]
            contribution = replace(contribution, blocks=blocks)
        return contribution


def test_exact_tangents_leave_a_second_order_remainder():
    solid, u, p = _loaded_block()
    results = taylor_test(solid, u, 1.0, p, LENGTHS)
    assert [r.name for r in results] == [term.name for term in solid.terms]
    for result in results:
        assert result.errors[0] > 0.0
        np.testing.assert_allclose(result.orders, 2.0, atol=0.05)
        assert result.worst_nodes.shape == (3, 4)
    # the lengths are the largest nodal motions of the scaled step
    np.testing.assert_array_equal(results[0].lengths, LENGTHS)


def test_a_tangent_wrong_by_five_percent_shows_first_order():
    solid, u, p = _loaded_block()
    solid.terms[0] = _WrongTangent(solid.terms[0], 0.95)
    wrong, pressure = taylor_test(solid, u, 1.0, p, LENGTHS)
    np.testing.assert_allclose(wrong.orders, 1.0, atol=0.05)
    np.testing.assert_allclose(pressure.orders, 2.0, atol=0.05)


def test_taylor_test_refuses_a_direction_that_moves_nothing_and_bad_lengths():
    solid, u, p = _loaded_block()
    with pytest.raises(ValueError, match="moves no node"):
        taylor_test(solid, u, 1.0, np.zeros_like(p))
    with pytest.raises(ValueError, match="lengths"):
        taylor_test(solid, u, 1.0, p, (1e-3,))
    with pytest.raises(ValueError, match="entries"):
        taylor_test(solid, u[:-1], 1.0, p)
