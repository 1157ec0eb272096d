"""The prescribed increment carried into the free nodes (:mod:`skvalve.fem.solvers.extension`) and the load step that
starts from it (:func:`skvalve.fem.solvers.incremental.minimise_step`, ``carry=``).

Checked against closed forms of the discrete Laplace problem (a constant is harmonic; a node of no element stays; the
components are independent) and against the same step started from the prescribed dofs moved alone (one minimiser).
"""

import numpy as np
import pytest
from test_ipc_contact import _block_over_obstacle  # the block and obstacle of the IPC tests

from skvalve.fem import Solid
from skvalve.fem.meshes import box
from skvalve.fem.solvers import linsolve
from skvalve.fem.solvers.extension import MotionExtension
from skvalve.fem.solvers.incremental import IncrementalOptions, StepFailed, minimise_step
from skvalve.fem.terms import Contribution, Term
from skvalve.materials import NeoHookean

MATERIAL = NeoHookean.from_shear_poisson(1.0, 0.3)


def _slab(shift):
    """A 4 x 4 x 1 slab whose x = 0 edge face is moved by ``shift`` and whose x = 1 face is ``held`` (or free)."""
    solid = Solid(box((4, 4, 1), (1.0, 1.0, 0.1)), MATERIAL)
    solid.add_dirichlet(lambda X: X[0] < 1e-9, np.asarray(shift, dtype=float))
    return solid


def test_a_translated_boundary_translates_every_connected_node():
    """The only other condition is the free faces' (natural): the harmonic extension of a uniform increment is that
    constant everywhere (to the regularisation's 1e-9), each component on its own."""
    solid = _slab([0.3, -0.2, 0.05])
    extension = MotionExtension(solid, solid.terms)
    u_old = np.zeros(solid.space.n_dofs)
    u = u_old.copy()
    u[solid.pattern.fixed] = solid.constrained(1.0)[1]
    carried = extension(u_old, u).reshape(-1, 3)
    np.testing.assert_allclose(carried, np.tile([0.3, -0.2, 0.05], (carried.shape[0], 1)), atol=1e-7)
    assert np.array_equal(extension(u_old, u_old), u_old)  # no increment: nothing moves


def test_two_held_faces_interpolate_and_bad_terms_are_named():
    """Between a face moved by d and a held face the extension is monotone in x, from d to 0, and the same in
    every row of nodes (the slab's symmetry); a term whose element dofs are not whole nodes is refused."""
    solid = _slab([0.0, 0.4, 0.0])
    solid.add_dirichlet(lambda X: X[0] > 1.0 - 1e-9, 0.0)
    extension = MotionExtension(solid, solid.terms)
    u = np.zeros(solid.space.n_dofs)
    u[solid.pattern.fixed] = solid.constrained(1.0)[1]
    carried = extension(np.zeros_like(u), u).reshape(-1, 3)
    x = solid.mesh.p[0]
    np.testing.assert_allclose(carried[:, [0, 2]], 0.0, atol=1e-12)  # the y increment moves only y
    columns = [carried[np.isclose(x, value), 1] for value in np.unique(x)]
    means = [float(np.mean(column)) for column in columns]
    assert means[0] == pytest.approx(0.4) and means[-1] == pytest.approx(0.0, abs=1e-15)
    assert all(a > b for a, b in zip(means[:-1], means[1:], strict=True))
    assert max(float(np.ptp(column)) for column in columns) < 1e-12

    class Odd:
        def connectivity(self):
            return [np.array([[0, 1, 2, 3]])]

    with pytest.raises(ValueError, match="whole nodes"):
        MotionExtension(solid, [Odd()])


@pytest.mark.skipif("pardiso" not in linsolve.available_solvers(), reason="the shifted direction needs PARDISO")
def test_a_step_started_from_the_carried_state_reaches_the_same_minimiser_sooner():
    """The x = 0 face sheared by 0.3 in one step with x = 1 held: started from the extension, the step converges in
    fewer iterations to the minimiser that the start with the prescribed face moved alone reaches."""

    def step(carry: bool):
        solid = _slab([0.0, 0.3, 0.0])
        solid.add_dirichlet(lambda X: X[0] > 1.0 - 1e-9, 0.0)
        u_old = np.zeros(solid.space.n_dofs)
        extension = MotionExtension(solid, solid.terms) if carry else None
        options = IncrementalOptions(rtol=1e-10, atol=1e-12, predictor=False)
        u, _, history = minimise_step(solid, u_old, 0.0, 1.0, u_old, np.zeros_like(u_old), 1, options, "pardiso",
                                      carry=extension)
        return u, len(history)

    carried, fewer = step(True)
    alone, more = step(False)
    np.testing.assert_allclose(carried, alone, atol=1e-8 * np.abs(alone).max())
    assert fewer < more, (fewer, more)


def test_a_prescribed_move_that_crosses_the_body_alone_is_carried():
    """A block's top face moved down by 0.8 (its height is 0.5) in one step, nothing else held: moved alone it would
    pass through the bottom face (not collision-free: the step is refused); carried, the whole block translates
    with it, which the barrier allows, and the step ends in that translation (the only equilibrium)."""
    solid, contact, _ = _block_over_obstacle(drop=0.8, gap=2.0, dhat=0.02)
    u_old = np.zeros(solid.space.n_dofs)
    options = IncrementalOptions(rtol=1e-10, atol=1e-12)
    solver = linsolve.solver_name(None)
    with pytest.raises(StepFailed, match="collision-free"):
        minimise_step(solid, u_old, 0.0, 1.0, u_old, np.zeros_like(u_old), 1, options, solver)
    contact.rewind()
    extension = MotionExtension(solid, [solid.terms[0]])
    u, _, _ = minimise_step(solid, u_old, 0.0, 1.0, u_old, np.zeros_like(u_old), 1, options, solver, carry=extension)
    np.testing.assert_allclose(u.reshape(-1, 3), np.tile([0.0, 0.0, -0.8], (u.size // 3, 1)), atol=1e-9)
    assert not contact.intersects(u, 1.0)


def test_a_pushed_node_moves_the_elements_around_it_as_a_whole():
    """A node in the slab's middle pushed by (0, 0, 0.2) with nothing prescribed moving: every node of the hexes
    around it moves by exactly that (the elements ride whole: none is crushed), the others by less, and the held
    x = 0 face not at all."""
    solid = _slab([0.0, 0.0, 0.0])
    extension = MotionExtension(solid, solid.terms)
    X = solid.mesh.p
    node = int(np.argmin(np.linalg.norm(X.T - [0.5, 0.5, 0.1], axis=1)))
    u0 = np.zeros(solid.space.n_dofs)
    carried = extension(u0, u0, (np.array([3 * node + 2]), np.array([0.2]))).reshape(-1, 3)
    around = np.unique(solid.mesh.t[:, np.any(solid.mesh.t == node, axis=0)])
    np.testing.assert_allclose(carried[around], np.tile([0.0, 0.0, 0.2], (around.size, 1)), atol=1e-15)
    others = np.setdiff1d(np.arange(X.shape[1]), around)
    assert np.all(carried[others, 2] < 0.2) and np.all(carried[X[0] < 1e-9, 2] == 0.0)
    np.testing.assert_allclose(carried[:, :2], 0.0, atol=0.0)


def test_a_carried_start_that_a_term_limits_is_refused_naming_the_term():
    """A term that allows half of any move (a stand-in for the corner barrier): the carried start of a prescribed
    shear is refused, and the step's failure names that term and its share."""

    class Halving(Term):
        name = "halving stand-in"

        def assemble(self, u, t, tangent, step):
            return Contribution(internal=np.zeros(u.size))

        def step_fraction(self, u0, t0, u1, t1):
            return 0.5 if np.any(u1 != u0) else 1.0

    solid = _slab([0.0, 0.3, 0.0])
    solid.add_term(Halving())
    u_old = np.zeros(solid.space.n_dofs)
    options = IncrementalOptions(rtol=1e-10, atol=1e-12, predictor=False)
    with pytest.raises(StepFailed, match="the carried start is limited by halving stand-in 0.5"):
        minimise_step(solid, u_old, 0.0, 1.0, u_old, np.zeros_like(u_old), 1, options, linsolve.solver_name(None),
                      carry=MotionExtension(solid, solid.terms[:1]))
    assert solid.step_limits(u_old, 0.0, u_old, 1.0) == ""
