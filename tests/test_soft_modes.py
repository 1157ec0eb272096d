"""Softest modes of a tangent against the closed-form spectrum of a spring chain."""

import numpy as np
import pytest
import skfem

from skvalve.fem import NodalForce, Problem, Space, soft_modes
from skvalve.fem.elements.truss import Truss
from skvalve.materials.uniaxial import LinearUniaxial

N_BARS, MODULUS, AREA = 6, 3.0, 0.5  # unit rest lengths: spring constant k = E A / L = 1.5


def _chain(transverse_fixed: bool) -> tuple[Problem, np.ndarray]:
    """Bars joining the nodes x = 0, 1, ..., N_BARS of a hex mesh's edge y = z = 0; the chain's ends and every other
    node fixed; the chain's inner nodes free along x (and across it unless ``transverse_fixed``)."""
    mesh = skfem.MeshHex.init_tensor(np.arange(N_BARS + 1.0), np.array([0.0, 1.0]), np.array([0.0, 1.0]))
    space = Space(mesh)
    X = space.dof_coordinates
    on_edge = np.isclose(X[1], 0.0) & np.isclose(X[2], 0.0)
    chain = np.flatnonzero(on_edge)[np.argsort(X[0, on_edge])]
    bars = np.column_stack([chain[:-1], chain[1:]])
    problem = Problem(space, [Truss(space, bars, AREA, LinearUniaxial(MODULUS))])
    inner = chain[1:-1]
    problem.add_dirichlet(nodes=np.setdiff1d(np.arange(space.n_scalar), inner), value=0.0)
    if transverse_fixed:
        problem.add_dirichlet(nodes=inner, value=0.0, components=[1, 2])
    return problem, inner


def test_chain_spectrum_and_newton_reach_match_the_closed_form():
    """Fixed-fixed chain of n springs k: K = k tridiag(-1, 2, -1) on the n - 1 inner x dofs, eigenvalues
    4 k sin^2(j pi / 2n) with modes sin(j pi i / n); a force F on inner node i has R . v_j = -F v_j(i) and Newton
    moves along mode j by F v_j(i) / lambda_j (here exact: the chain is linear)."""
    problem, inner = _chain(transverse_fixed=True)
    k_spring = MODULUS * AREA
    force = 0.2
    problem.add_term(NodalForce(problem.space, np.array([inner[1]]), [force, 0.0, 0.0], ramp=False))
    modes = soft_modes(problem, np.zeros(problem.space.n_dofs), 1.0, k=4)
    j = np.arange(1, 5)
    exact = 4.0 * k_spring * np.sin(j * np.pi / (2 * N_BARS)) ** 2
    np.testing.assert_allclose(modes.values, exact, rtol=1e-10)
    i = np.arange(1, N_BARS)
    for m in range(4):
        shape = np.sin((m + 1) * np.pi * i / N_BARS)
        shape /= np.linalg.norm(shape)
        x_part = modes.vectors[3 * inner, m]
        np.testing.assert_allclose(abs(x_part @ shape), 1.0, rtol=1e-10)
        np.testing.assert_allclose(modes.vectors[3 * inner[1], m] * force / exact[m], modes.newton_reach[m],
                                   rtol=1e-10)


def test_unstressed_chain_has_exact_zero_modes_that_still_factorise():
    """Free transverse dofs of an unstressed chain: 2 (n - 1) zero eigenvalues (a bar with N = 0 has no transverse
    stiffness); the shift below zero factorises them and reports them within 1e-8 k, below the axial spectrum (to
    1e-6 only: beside eigenvalues 1e9 times the shift's inverse, Lanczos resolves the others to ~1e-8)."""
    problem, inner = _chain(transverse_fixed=False)
    modes = soft_modes(problem, np.zeros(problem.space.n_dofs), 1.0, k=2 * (N_BARS - 1) + 1)
    zero = 2 * (N_BARS - 1)
    assert np.all(np.abs(modes.values[:zero]) < 1e-8 * MODULUS * AREA)
    assert modes.values[zero] == pytest.approx(4.0 * MODULUS * AREA * np.sin(np.pi / (2 * N_BARS)) ** 2, rel=1e-6)
    assert np.all(np.isinf(modes.newton_reach[:zero]) | (np.abs(modes.residual_along[:zero]) < 1e-14))
    moving = modes.moving_nodes(zero, 3, problem.space.n_scalar, count=N_BARS - 1)
    assert set(moving.tolist()) == set(inner.tolist())


def test_bad_arguments_name_what_is_wrong():
    problem, _ = _chain(transverse_fixed=True)
    with pytest.raises(ValueError, match="finite"):
        soft_modes(problem, np.full(problem.space.n_dofs, np.nan), 1.0)
    with pytest.raises(ValueError, match="k must be between"):
        soft_modes(problem, np.zeros(problem.space.n_dofs), 1.0, k=N_BARS - 1)
    modes = soft_modes(problem, np.zeros(problem.space.n_dofs), 1.0, k=2)
    with pytest.raises(IndexError, match="2 modes"):
        modes.moving_nodes(5, 3, problem.space.n_scalar)


def test_a_compressed_chain_reports_its_negative_transverse_modes():
    """Every bar shortened to stretch 0.9: axial force N = A E (0.9 - 1) < 0 and transverse stiffness N/l per bar, so
    across the chain K = (N/l) tridiag(-1, 2, -1) in y and in z, with the negative eigenvalues 4 (N/l) sin^2(j pi/2n)
    (each twice); the softest two are the j = 1 pair, reported (not raised) as an unstable state."""
    problem, _ = _chain(transverse_fixed=False)
    X = problem.space.dof_coordinates
    u = np.zeros(problem.space.n_dofs)
    u[0::3] = -0.1 * X[0]  # uniform compression along x: every bar of the chain at stretch 0.9
    axial = AREA * MODULUS * (0.9 - 1.0)
    modes = soft_modes(problem, u, 1.0, k=2)
    exact = 4.0 * axial / 0.9 * np.sin(np.pi / (2 * N_BARS)) ** 2
    np.testing.assert_allclose(modes.values, [exact, exact], rtol=1e-8)
