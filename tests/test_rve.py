"""RVE force balance, Eq. 8 stress and the consistent tangent (Thomas 2019 section 2.4)."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from skvalve.materials.exponential_fiber import ExponentialFiber
from skvalve.networks.dense_cholesky import (
    cholesky_in_place,
    cholesky_solve,
    cholesky_solve_vector,
    dense_envelope,
    factor_with_shift,
    interior_numbering,
    node_cholesky_in_place,
    node_cholesky_solve,
)
from skvalve.networks.generate import generate
from skvalve.networks.network import Network
from skvalve.networks.rve import RVEState, boundary_stress, solve_rve, solve_rve_batch
from skvalve.papers.thomas2019.data import FIBER, NETWORK

E_F, BETA, LAMBDA_C, DIAMETER = FIBER.E_f, FIBER.beta, FIBER.lambda_c, FIBER.diameter
PSI = NETWORK.volume_fraction
AREA = math.pi * DIAMETER**2 / 4
RVE = dict(psi=PSI, fiber_diameter=DIAMETER)  # thomas2019 §2.5


def eq9(lam):
    """Eq. 9 written out independently of ExponentialFiber (scalar)."""
    if lam < LAMBDA_C:
        return E_F * AREA / BETA * (math.exp(BETA * 0.5 * (lam**2 - 1)) - 1)
    ec = 0.5 * (LAMBDA_C**2 - 1)
    return E_F * AREA / BETA * (math.exp(BETA * ec) - 1) + E_F * AREA * LAMBDA_C * math.exp(BETA * ec) * (
        lam - LAMBDA_C
    )


def interior_imbalance(network, result, fiber):
    """(‖Σ fiber forces on interior nodes‖, ‖f‖), recomputed from the deformed nodes with Eq. 9."""
    x = result.deformed_nodes
    d = network.fiber_vectors(x)
    ell = np.linalg.norm(d, axis=1)
    f = fiber.force(ell / network.fiber_lengths())
    net_force = np.zeros_like(x)
    np.add.at(net_force, network.fibers[:, 0], f[:, None] * d / ell[:, None])
    np.add.at(net_force, network.fibers[:, 1], -f[:, None] * d / ell[:, None])
    return np.linalg.norm(net_force[~network.boundary]), np.linalg.norm(f)


@pytest.fixture(scope="module")
def fiber():
    return ExponentialFiber.from_diameter(E_F, DIAMETER, BETA, LAMBDA_C)


@pytest.fixture(scope="module")
def network():
    return generate(35.0, 20.0, n_fibers=200, seed=4)


F_BIAXIAL = np.array([[1.12, 0.03, 0.0], [0.01, 1.08, 0.02], [0.0, 0.0, 0.80]])


def test_affine_network_matches_eq8_by_hand(fiber):
    # every node on a face: no unknowns, the network deforms affinely
    nodes = np.array(
        [[-0.5, -0.2, 0.1], [0.5, 0.3, -0.1], [0.2, -0.5, 0.0], [-0.1, 0.5, 0.4], [0.3, 0.1, -0.5], [0.0, 0.2, 0.5]]
    )
    face = np.array([0, 1, 2, 3, 4, 5])
    net = Network(nodes, [[0, 1], [2, 3], [4, 5], [0, 3]], np.ones(6, bool), face)
    result = solve_rve(net, F_BIAXIAL, fiber, **RVE)
    J = np.linalg.det(F_BIAXIAL)
    total = sum(np.linalg.norm(nodes[b] - nodes[a]) for a, b in net.fibers)
    expected = np.zeros((3, 3))
    for a, b in net.fibers:
        d = F_BIAXIAL @ (nodes[b] - nodes[a])
        ell = np.linalg.norm(d)
        lam = ell / np.linalg.norm(nodes[b] - nodes[a])
        expected += eq9(lam) * np.outer(d, d) / ell
    expected *= PSI / (total * AREA * J)
    np.testing.assert_allclose(result.cauchy, expected, rtol=1e-12, atol=1e-12 * abs(expected).max())


def test_single_fiber_uniaxial_exact_force(fiber):
    net = Network([[-0.5, 0, 0], [0.5, 0, 0]], [[0, 1]], [True, True], [0, 1])
    for lam in (0.9, 1.05, 1.2):
        result = solve_rve(net, np.diag([lam, 1.0, 1.0]), fiber, **RVE)
        assert result.fiber_stretch[0] == pytest.approx(lam, rel=1e-15)
        # σ_xx = ψ/(L A_f V) · x·f with L = 1, V = λ, x·f = λ f
        assert result.cauchy[0, 0] == pytest.approx(PSI / AREA * eq9(lam), rel=1e-12)
        assert np.count_nonzero(result.cauchy) == 1


def test_interior_node_of_a_chain_finds_equal_stretch(fiber):
    # −½ → 0.2 → ½ along x; equal forces need equal stretches: node at 0.2 λ
    net = Network([[-0.5, 0, 0], [0.2, 0, 0], [0.5, 0, 0]], [[0, 1], [1, 2]], [True, False, True], [0, -1, 1])
    F = np.diag([1.1, 1.0, 1.0])
    start = np.array([[-0.55, 0, 0], [0.05, 0.02, -0.01], [0.55, 0, 0]])  # off equilibrium
    result = solve_rve(net, F, fiber, state=RVEState(start, F, np.zeros((3, 9))), tol=1e-13, **RVE)
    np.testing.assert_allclose(result.deformed_nodes[1], [0.22, 0, 0], atol=1e-12)
    np.testing.assert_allclose(result.fiber_stretch, 1.1, rtol=1e-12)
    assert result.iterations > 1


def test_force_balance_residual(network, fiber):
    result = solve_rve(network, F_BIAXIAL, fiber, **RVE)
    x = result.deformed_nodes
    imbalance, force_norm = interior_imbalance(network, result, fiber)
    assert imbalance < 1e-10 * force_norm
    interior = ~network.boundary
    # the motion is genuinely non-affine
    assert np.abs(x[interior] - network.nodes[interior] @ F_BIAXIAL.T).max() > 1e-3
    # Eq. 8 summed over boundary cross-links equals the fiber virial
    np.testing.assert_allclose(
        boundary_stress(network, result, fiber, **RVE), result.cauchy, rtol=1e-8, atol=1e-8 * abs(result.cauchy).max()
    )


def test_objectivity(network, fiber):
    result = solve_rve(network, F_BIAXIAL, fiber, **RVE)
    R = Rotation.from_rotvec([0.3, -1.1, 0.7]).as_matrix()
    rotated = solve_rve(network, R @ F_BIAXIAL, fiber, **RVE)
    np.testing.assert_allclose(rotated.fiber_stretch, result.fiber_stretch, rtol=1e-10)
    np.testing.assert_allclose(rotated.cauchy, R @ result.cauchy @ R.T, rtol=1e-8, atol=1e-9 * abs(result.cauchy).max())
    # pure rotation: no stretch, no stress
    spin = solve_rve(network, R, fiber, **RVE)
    np.testing.assert_allclose(spin.fiber_stretch, 1.0, atol=1e-12)
    assert abs(spin.cauchy).max() < 1e-9 * abs(result.cauchy).max()


def fd_tangent(network, F, fiber, state=None, h=1e-6):
    """Central differences of the equilibrated σ with respect to every F_pq."""
    fd = np.zeros((3, 3, 3, 3))
    for p in range(3):
        for q in range(3):
            dF = np.zeros((3, 3))
            dF[p, q] = h
            plus = solve_rve(network, F + dF, fiber, state=state, tol=1e-12, **RVE)
            minus = solve_rve(network, F - dF, fiber, state=state, tol=1e-12, **RVE)
            fd[:, :, p, q] = (plus.cauchy - minus.cauchy) / (2 * h)
    return fd


def test_tangent_matches_finite_differences(network, fiber):
    # h = 1e-6: truncation ~h² relative; force balance to 1e-12 leaves ~1e-12/h = 1e-6 relative
    # noise at worst; a missing or wrong term is O(1e-2) or more (see the affine check below)
    result = solve_rve(network, F_BIAXIAL, fiber, **RVE)
    fd = fd_tangent(network, F_BIAXIAL, fiber, state=result.state)
    assert abs(result.tangent - fd).max() / abs(fd).max() < 1e-6
    # the implicit (relaxation) term matters: the same network held affine (every node on the
    # boundary) has a tangent that differs by far more than the tolerance above
    affine_net = Network(network.nodes, network.fibers, np.ones(network.n_nodes, bool), network.face)
    affine = solve_rve(affine_net, F_BIAXIAL, fiber, **RVE)
    assert abs(affine.tangent - fd).max() / abs(fd).max() > 1e-2
    affine_fd = fd_tangent(affine_net, F_BIAXIAL, fiber)
    assert abs(affine.tangent - affine_fd).max() < 1e-6 * abs(affine_fd).max()


@pytest.mark.parametrize("compression", ["paper", "buckle"])
def test_tangent_matches_finite_differences_in_compression(network, compression):
    """Biaxial compression (many fibres below λ = 1, convexified Newton path) in both modes."""
    fiber = ExponentialFiber.from_diameter(E_F, DIAMETER, BETA, LAMBDA_C, compression=compression)
    F = np.array([[0.95, 0.02, 0.0], [0.0, 0.93, 0.01], [0.0, 0.0, 1.02]])
    result = solve_rve(network, F, fiber, max_iter=100, **RVE)
    assert result.status == 0
    fd = fd_tangent(network, F, fiber, state=result.state)
    assert abs(result.tangent - fd).max() / abs(fd).max() < 1e-5


def test_warm_start_and_batch_agree(network, fiber):
    cold = solve_rve(network, F_BIAXIAL, fiber, **RVE)
    F2 = F_BIAXIAL + 2e-3 * np.eye(3)
    warm = solve_rve(network, F2, fiber, state=cold.state, **RVE)
    reference = solve_rve(network, F2, fiber, **RVE)
    assert warm.iterations < reference.iterations
    np.testing.assert_allclose(warm.cauchy, reference.cauchy, rtol=1e-9)
    other = generate(27.0, 90.0, n_fibers=150, seed=2)
    batch = solve_rve_batch([network, other], np.stack([F2, F_BIAXIAL]), fiber, states=[cold.state, None], **RVE)
    np.testing.assert_allclose(batch[0].cauchy, warm.cauchy, rtol=1e-12)
    np.testing.assert_allclose(batch[0].tangent, warm.tangent, rtol=1e-10, atol=1e-12 * abs(warm.tangent).max())
    single = solve_rve(other, F_BIAXIAL, fiber, **RVE)
    np.testing.assert_allclose(batch[1].cauchy, single.cauchy, rtol=1e-12)
    np.testing.assert_allclose(batch[1].tangent, single.tangent, rtol=1e-10, atol=1e-12 * abs(single.tangent).max())
    np.testing.assert_array_equal(batch[1].fiber_stretch, single.fiber_stretch)
    assert batch[1].deformed_nodes.shape == (other.n_nodes, 3)


def test_large_cold_step_converges_and_diameter_cancels(network):
    F = np.diag([1.3, 1.3, 1 / 1.69])
    thin = ExponentialFiber.from_diameter(E_F, 100e-9, BETA, LAMBDA_C)
    thick = ExponentialFiber.from_diameter(E_F, 900e-9, BETA, LAMBDA_C)
    a = solve_rve(network, F, thin, fiber_diameter=100e-9, psi=PSI)
    b = solve_rve(network, F, thick, fiber_diameter=900e-9, psi=PSI)
    assert a.status == 0 and a.residual < 1e-10
    np.testing.assert_allclose(a.cauchy, b.cauchy, rtol=1e-9)
    assert b.rve_edge_length == pytest.approx(9 * a.rve_edge_length, rel=1e-12)  # γ ∝ d


def test_bad_input(network, fiber):
    with pytest.raises(ValueError, match="det F"):
        solve_rve(network, np.diag([1.0, 1.0, -1.0]), fiber, **RVE)
    with pytest.raises(ValueError, match="psi"):
        solve_rve(network, np.eye(3), fiber, psi=1.5, fiber_diameter=DIAMETER)
    with pytest.raises(ValueError, match="shape"):
        solve_rve(network, np.eye(2), fiber, **RVE)
    with pytest.raises(ValueError, match="state"):
        solve_rve(network, np.eye(3), fiber, state=RVEState(np.zeros((2, 3)), np.eye(3), np.zeros((1, 9))), **RVE)
    with pytest.raises(ValueError, match="finite"):
        solve_rve(network, np.full((3, 3), np.nan), fiber, **RVE)
    with pytest.raises(ValueError, match=r"shape \(3, 3\)"):
        solve_rve(network, np.eye(3)[:, :, None], fiber, **RVE)
    for diameter in (-450e-9, 0.0, np.nan):  # a negative diameter used to pass (π d²/4 > 0)
        with pytest.raises(ValueError, match="fiber_diameter"):
            solve_rve(network, np.eye(3), fiber, fiber_diameter=diameter, psi=PSI)
    with pytest.raises(ValueError, match="tol"):
        solve_rve(network, np.eye(3), fiber, tol=-1.0, **RVE)
    with pytest.raises(TypeError, match="ExponentialFiber"):
        solve_rve(network, np.eye(3), "fiber", **RVE)
    with pytest.raises(ValueError, match="3 states for 2 networks"):
        solve_rve_batch([network, network], np.stack([np.eye(3)] * 2), fiber, states=[None] * 3, **RVE)
    with pytest.raises(ValueError, match=r"shape \(2, 3, 3\)"):
        solve_rve_batch([network, network], np.eye(3), fiber, **RVE)


@pytest.mark.parametrize("compression", ["paper", "buckle"])
def test_compressed_network_converges(network, compression):
    # biaxial compression: most fibers shorten, K loses definiteness along the path
    fiber = ExponentialFiber.from_diameter(E_F, DIAMETER, BETA, LAMBDA_C, compression=compression)
    result = solve_rve(network, np.diag([0.9, 0.9, 1.0]), fiber, max_iter=100, **RVE)
    assert result.status == 0
    imbalance, force_norm = interior_imbalance(network, result, fiber)
    # balanced to 1e-8 of the (small, compressive) fiber forces
    assert imbalance < 1e-8 * force_norm
    assert result.cauchy[0, 0] < 0 and result.cauchy[1, 1] < 0


def test_envelope_cholesky_against_numpy():
    rng = np.random.default_rng(1)
    a = rng.normal(size=(40, 40))
    spd = a @ a.T + 40 * np.eye(40)
    rhs = rng.normal(size=(40, 9))
    dense = dense_envelope(40)
    work = spd.copy()
    assert cholesky_in_place(work, 40, dense)
    y = rhs.copy()
    cholesky_solve(work, 40, dense, y)
    np.testing.assert_allclose(y, np.linalg.solve(spd, rhs), rtol=1e-10, atol=1e-12)
    indefinite = spd - (np.linalg.eigvalsh(spd)[0] + 1.0) * np.eye(40)  # one negative eigenvalue
    assert not cholesky_in_place(indefinite.copy(), 40, dense)
    assert not factor_with_shift(indefinite, np.empty((40, 40)), 40, dense)  # shifted, flagged
    # a variable band: row i starts at first[i]; only the lower envelope is read (NaN elsewhere)
    first = np.maximum(np.arange(40) - rng.integers(0, 6, size=40), 0).astype(np.int64)
    banded = np.zeros((40, 40))
    for i in range(40):
        banded[i, first[i] : i] = rng.normal(size=i - first[i])
    banded = banded + banded.T + 10 * np.eye(40)
    stored = np.where(np.arange(40)[None, :] >= first[:, None], banded, np.nan)
    stored[np.triu_indices(40, 1)] = np.nan
    work = np.full((40, 40), np.nan)
    assert factor_with_shift(stored, work, 40, first)
    y = rhs.copy()
    cholesky_solve(work, 40, first, y)
    np.testing.assert_allclose(y, np.linalg.solve(banded, rhs), rtol=1e-10, atol=1e-12)
    y = rhs[:, 0].copy()
    cholesky_solve_vector(work, 40, first, y)
    np.testing.assert_allclose(y, np.linalg.solve(banded, rhs[:, 0]), rtol=1e-10, atol=1e-12)


def test_node_blocked_cholesky_matches_numpy():
    """3 unknowns per node sharing the envelope start: the node-blocked factor is the scalar one."""
    rng = np.random.default_rng(3)
    first = np.repeat(3 * np.maximum(np.arange(12) - rng.integers(0, 5, size=12), 0), 3).astype(np.int64)
    matrix = np.zeros((36, 36))
    for i in range(36):
        matrix[i, first[i] : i] = rng.normal(size=i - first[i])
    matrix = matrix + matrix.T + 12 * np.eye(36)
    work = np.full((36, 36), np.nan)
    assert factor_with_shift(np.tril(matrix), work, 36, first, True)
    rhs = rng.normal(size=(36, 9))
    for solve in (cholesky_solve, node_cholesky_solve):
        y = rhs.copy()
        solve(work, 36, first, y)
        np.testing.assert_allclose(y, np.linalg.solve(matrix, rhs), rtol=1e-10, atol=1e-12)
    indefinite = matrix - (np.linalg.eigvalsh(matrix)[0] + 1.0) * np.eye(36)
    assert not node_cholesky_in_place(np.tril(indefinite), 36, first)


def test_interior_numbering_envelope_holds_every_coupling(network):
    dof, first = interior_numbering(network)
    interior = ~network.boundary
    assert sorted(dof[interior]) == list(range(interior.sum())) and np.all(dof[~interior] == -1)
    ends = dof[network.fibers]
    coupled = ends[(ends >= 0).all(axis=1)]
    high, low = coupled.max(axis=1), coupled.min(axis=1)
    assert np.all(first[3 * high] <= 3 * low)  # every off-diagonal block lies inside the envelope
    # and the envelope is smaller than the dense lower triangle
    n = 3 * interior.sum()
    assert np.sum(np.arange(n) - first + 1) < 0.7 * n * (n + 1) / 2
