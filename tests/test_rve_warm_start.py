"""RVEBatch warm starts from an earlier evaluation and copies RVEs whose F did not change (issue 34 item 4).

References: cold solves of each RVE (``solve_rve`` from the affine guess, a different start and path), the
force balance itself, and the plain stored-state start for the bit-for-bit copy.
"""

import numpy as np
import pytest

from skvalve.multiscale.material import RVEMaterial
from skvalve.networks.generate import generate
from skvalve.networks.rve import RVEBatch, solve_rve

PSI, DIAMETER, TOL = 0.43, 450e-9, 1e-12


@pytest.fixture(scope="module")
def networks():
    return [generate(35.0, 0.0, n_fibers=120, seed=s) for s in range(4)]


def biaxial(count, l1, l2, shear=0.0):
    F = np.diag([l1, l2, 1.0 / (l1 * l2)])
    F[0, 1] = shear
    return np.tile(F, (count, 1, 1))


def test_start_from_a_nearer_evaluation_gives_the_cold_solution_in_fewer_iterations(networks, fiber):
    batch = RVEBatch(networks, fiber, PSI, DIAMETER, tol=TOL)
    batch.solve(biaxial(4, 1.04, 1.05))  # the stored (committed) state
    far = biaxial(4, 1.12, 1.15, 0.02)
    near = far + 1e-4 * np.eye(3)
    latest = batch.solve(far, update_state=False)
    from_stored = batch.solve(near, update_state=False)
    from_latest = batch.solve(near, update_state=False, alternate=latest)
    assert from_latest["iterations"].sum() < from_stored["iterations"].sum()
    for r, net in enumerate(networks):
        cold = solve_rve(net, near[r], fiber, PSI, DIAMETER, tol=TOL)
        scale = np.abs(cold.cauchy).max()
        assert np.abs(from_latest["cauchy"][r] - cold.cauchy).max() < 1e-9 * scale
        assert np.abs(from_latest["tangent"][r] - cold.tangent).max() < 1e-7 * np.abs(cold.tangent).max()
    # a farther alternate is not used: the result is the stored-state start's, bit for bit
    ignored = batch.solve(near, update_state=False, alternate=batch.solve(biaxial(4, 1.3, 1.3), update_state=False))
    for name in ("x", "cauchy", "tangent", "sensitivity"):
        assert np.array_equal(ignored[name], from_stored[name]), name


def test_unchanged_rves_are_copied_and_equal_a_solve_from_the_same_state(networks, fiber):
    batch = RVEBatch(networks, fiber, PSI, DIAMETER, tol=TOL)
    F0 = biaxial(4, 1.06, 1.08)
    batch.solve(F0)  # stored state with its results (accepted)
    F1 = F0.copy()
    F1[[1, 3]] = biaxial(2, 1.07, 1.08)  # two RVEs move, two do not
    out = batch.solve(F1, update_state=False)
    assert out["solved"] == 2 and out["iterations"][[0, 2]].tolist() == [0, 0]
    plain = RVEBatch(networks, fiber, PSI, DIAMETER, tol=TOL)  # same state, no stored results: solves all four
    plain.solve(F0)
    plain.accepted = None
    again = plain.solve(F1, update_state=False)
    assert again["solved"] == 4 and again["iterations"][[0, 2]].tolist() == [0, 0]  # converged at the start
    for name in ("x", "cauchy", "tangent", "stretch", "sensitivity"):
        assert np.array_equal(out[name], again[name]), name


def test_material_counts_solved_and_copied_rves_and_rewind_restarts_from_the_commit(networks, fiber, matrix):
    material = RVEMaterial(networks[:2], matrix, fiber, n_points=2, psi=PSI, fiber_diameter=DIAMETER, tol=TOL)
    F = np.broadcast_to(np.diag([1.08, 1.05, 0.9])[:, :, None, None], (3, 3, 2, 2)).copy()
    material.pk1_and_tangent(F)
    material.commit()
    G = F.copy()
    G[0, 0, 1, 1] += 0.01  # one RVE (element 1, point 1) moves
    solves = material.solves
    P_first, A_first = material.pk1_and_tangent(G)
    assert material.solves - solves == 1 and material.reused >= 3
    material.pk1_and_tangent(G + 0.02 * np.eye(3)[:, :, None, None])  # a trial that is given up
    material.rewind()
    P_again, A_again = material.pk1_and_tangent(G)
    assert np.array_equal(P_again, P_first) and np.array_equal(A_again, A_first)



def test_recycled_arrays_give_the_same_numbers_as_fresh_ones(networks, fiber, matrix):
    """The material reuses the packed arrays of an evaluation it no longer needs (neither committed nor the latest);
    the sequence evaluate, evaluate, commit, evaluate, rewind, evaluate gives bit for bit what fresh arrays give."""
    def sequence(material):
        base = np.broadcast_to(np.diag([1.06, 1.04, 0.92])[:, :, None, None], (3, 3, 2, 2)).copy()
        results, arrays = [], []
        for k, action in enumerate(("eval", "eval", "eval", "commit", "eval", "eval", "rewind", "eval")):
            if action == "commit":
                material.commit()
            elif action == "rewind":
                material.rewind()
            else:
                results.append(material.pk1_and_tangent(base + 0.004 * k * np.eye(3)[:, :, None, None]))
                arrays.append(material._latest["x"])
        return results, arrays

    recycled = RVEMaterial(networks[:2], matrix, fiber, n_points=2, psi=PSI, fiber_diameter=DIAMETER, tol=TOL)
    fresh = RVEMaterial(networks[:2], matrix, fiber, n_points=2, psi=PSI, fiber_diameter=DIAMETER, tol=TOL)
    fresh._recycle = lambda out: None  # never reuse: every evaluation allocates
    (got, arrays), (expected, fresh_arrays) = sequence(recycled), sequence(fresh)
    for (P, A), (P0, A0) in zip(got, expected, strict=True):
        assert np.array_equal(P, P0) and np.array_equal(A, A0)
    assert arrays[2] is arrays[0]  # the third evaluation wrote into the first one's arrays
    assert len({id(x) for x in fresh_arrays}) == len(fresh_arrays)
