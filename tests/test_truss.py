"""Trusses and uniaxial laws: Ogden in uniaxial stress against the 3D law, bar tangents against finite
differences, a single chord against its closed form, a chord tied to a block."""

import numpy as np
import pytest
import skfem
from _truss_checks import two_blocks_with_chord

from skvalve.fem import NodalForce, Problem, Space, solve
from skvalve.fem.elements.truss import LawAssignment, Truss, bar_response
from skvalve.fem.solvers.trust_steps import project_psd
from skvalve.materials import Ogden
from skvalve.materials.uniaxial import LinearUniaxial, OgdenUniaxial, TensionOnly

# chordae-like parameters (three terms, one of them with a tiny exponent), MPa
CHORD = OgdenUniaxial(mu=(4.2, 7.6, 1e-4), alpha=(50.4, 15.4, 1e-4))


@pytest.mark.parametrize("stretch", [0.8, 1.0, 1.03, 1.2])
def test_ogden_uniaxial_matches_the_3d_incompressible_law(stretch):
    """P = (sigma_11 - sigma_22)/lambda of the 3D law at F = diag(l, l^-1/2, l^-1/2) (lateral stress free)."""
    mu, alpha = (0.6, 0.3), (3.0, -2.0)
    law3d = Ogden(mu=mu, alpha=alpha)
    F = np.diag([stretch, stretch**-0.5, stretch**-0.5])
    sigma = law3d.cauchy(F)
    expected = (sigma[0, 0] - sigma[1, 1]) / stretch
    P, _ = OgdenUniaxial(mu, alpha).nominal_stress(np.array([stretch]))
    assert P[0] == pytest.approx(expected, rel=1e-10, abs=1e-12)


def test_ogden_uniaxial_slope_and_small_exponent():
    lam = np.linspace(0.7, 1.3, 13)
    P, dP = CHORD.nominal_stress(lam)
    h = 1e-6
    fd = (CHORD.nominal_stress(lam + h)[0] - CHORD.nominal_stress(lam - h)[0]) / (2 * h)
    assert np.allclose(dP, fd, rtol=1e-7)
    assert dP[6] == pytest.approx(CHORD.young_modulus, rel=1e-12)
    # one term with alpha -> 0: P -> 2 mu (3/2 L + 3/8 alpha L^2) / lambda, L = ln(lambda) (Taylor series)
    tiny = OgdenUniaxial(mu=(43.0,), alpha=(1e-4,))
    L = np.log(lam)
    series = 2 * 43.0 * (1.5 * L + 0.375 * 1e-4 * L**2 + 0.1875 * 1e-8 * L**3) / lam
    assert np.allclose(tiny.nominal_stress(lam)[0], series, rtol=1e-10, atol=1e-14)


def test_tension_only_is_slack_below_unit_stretch():
    cable = TensionOnly(CHORD, slack_fraction=1e-4)
    k = cable.slack_stiffness
    lam = np.array([0.5, 0.999, 1.0, 1.1])
    P, dP = cable.nominal_stress(lam)
    assert k == pytest.approx(1e-4 * CHORD.young_modulus)
    assert np.allclose(P[:2], k * (lam[:2] - 1.0)) and np.allclose(dP[:2], k)
    assert np.allclose(P[2:], CHORD.nominal_stress(lam[2:])[0] + k * (lam[2:] - 1.0))
    # a slack stretch makes a curved chain force-free in its reference state, continuous at stretch 1
    Ps, _ = cable.nominal_stress(np.array([0.6, 1.0 - 1e-12, 1.0]), slack_stretch=0.6)
    assert Ps[0] == 0.0 and Ps[1] == pytest.approx(Ps[2]) and Ps[2] == pytest.approx(0.4 * k)
    with pytest.raises(ValueError, match="slack_fraction"):
        TensionOnly(CHORD, slack_fraction=0.0)
    with pytest.raises(ValueError, match="stretch"):
        cable.nominal_stress(np.array([-1.0]))


def test_tension_only_transition_is_smooth_and_consistent():
    cable = TensionOnly(CHORD, slack_fraction=1e-4, transition=0.01)
    lam = np.array([0.99, 1.0, 1.002, 1.005, 1.0099, 1.01, 1.02])
    P, dP = cable.nominal_stress(lam, slack_stretch=0.9)
    h = 1e-8
    fd = (cable.nominal_stress(lam + h, 0.9)[0] - cable.nominal_stress(lam - h, 0.9)[0]) / (2 * h)
    assert np.allclose(dP, fd, rtol=1e-5, atol=1e-6 * CHORD.young_modulus)
    # beyond the transition: the law plus the slack spring
    assert P[-1] == pytest.approx(CHORD.nominal_stress(np.array([1.02]))[0][0] + cable.slack_stiffness * 0.12)


@pytest.mark.parametrize("law", [CHORD, TensionOnly(CHORD), TensionOnly(CHORD, 1e-3, 0.05), LinearUniaxial(3.0)])
def test_bar_tangent_matches_central_differences(law):
    rng = np.random.default_rng(3)
    n = 6
    x_a, x_b = rng.standard_normal((n, 3)), rng.standard_normal((n, 3))
    length = np.linalg.norm(x_b - x_a, axis=1)
    rest = length * rng.uniform(0.85, 1.1, n)  # some slack, some taut
    area = rng.uniform(0.2, 0.5, n)
    laws = LawAssignment(law, None, n)
    state = bar_response(x_a, x_b, rest, area, laws)
    x = np.hstack([x_a, x_b])
    h = 1e-7
    for m in range(6):
        plus, minus = x.copy(), x.copy()
        plus[:, m] += h
        minus[:, m] -= h
        fp = bar_response(plus[:, :3], plus[:, 3:], rest, area, laws, tangent=False).forces
        fm = bar_response(minus[:, :3], minus[:, 3:], rest, area, laws, tangent=False).forces
        fd = (fp - fm) / (2 * h)
        scale = np.abs(state.matrices).max()
        assert np.abs(state.matrices[:, :, m] - fd).max() < 1e-6 * scale
    assert np.allclose(state.matrices, state.matrices.transpose(0, 2, 1))
    # geometric stiffness: transverse stiffness N / l
    n_hat = (x_b - x_a) / length[:, None]
    t_hat = np.cross(n_hat, [0.0, 0.0, 1.0])
    t_hat /= np.linalg.norm(t_hat, axis=1, keepdims=True)
    transverse = np.einsum("ei,eij,ej->e", t_hat, state.matrices[:, 3:, 3:], t_hat)
    assert np.allclose(transverse, state.axial_force / length)


def _single_chord_space(L: float) -> Space:
    """A one-element hex mesh used only for its nodes 0 = (0,0,0) and 1 = (L,0,0)."""
    mesh = skfem.MeshHex().scaled([L, L, L])
    return Space(mesh)


def test_single_chord_against_closed_form():
    """Chord along x, one end fixed, the other pulled by a force F: A P(lambda) = F, lateral stress free."""
    L, area, force = 2.0, 0.33, 1.5
    space = _single_chord_space(L)
    X = space.dof_coordinates
    a = int(np.flatnonzero(np.all(np.isclose(X, 0.0), axis=0))[0])
    b = int(np.flatnonzero(np.isclose(X[0], L) & np.isclose(X[1], 0) & np.isclose(X[2], 0))[0])
    problem = Problem(space, [Truss(space, [[a, b]], area, CHORD)])
    others = np.setdiff1d(np.arange(space.n_scalar), [b])
    problem.add_dirichlet(nodes=others, value=0.0)
    problem.add_term(NodalForce(space, np.array([b]), [force, 0.0, 0.0], ramp=True))
    result = solve(problem, steps=4, progress=False, rtol=1e-11)
    stretch = 1.0 + result.u()[3 * b] / L
    # closed form A P(lambda) = F, inverted by bisection on the 3-term formula written out
    lo, hi = 1.0, 1.5
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        terms = zip(CHORD.mu, CHORD.alpha, strict=True)
        value = sum(2 * m / al * (mid ** (al - 1) - mid ** (-al / 2 - 1)) for m, al in terms)
        lo, hi = (mid, hi) if area * value < force else (lo, mid)
    assert stretch == pytest.approx(lo, rel=1e-9)
    assert np.allclose(result.u()[3 * b + 1: 3 * b + 3], 0.0, atol=1e-12)



def test_a_single_truss_with_the_plain_law_carries_compression_beside_a_slack_chain():
    """Laws mixed in one term (``ValveModel.problem(compression=True)``): bar 0, a tension-only chain with slack
    stretch 0.8, and bar 1, a single truss with the plain Ogden law (slack stretch 1), both shortened to 0.9 of their
    rest length. The chain carries only its slack spring k_s (0.9 - 0.8); the truss carries A P(0.9) < 0 written out
    from the Ogden formula. A plain law with a slack stretch below 1 is refused."""
    space = _single_chord_space(2.0)
    X = space.dof_coordinates
    a = int(np.flatnonzero(np.all(np.isclose(X, 0.0), axis=0))[0])
    b = int(np.flatnonzero(np.isclose(X[0], 2.0) & np.isclose(X[1], 0) & np.isclose(X[2], 0))[0])
    cable = TensionOnly(CHORD, slack_fraction=1e-4)
    truss = Truss(space, [[a, b], [a, b]], 0.3, [cable, CHORD], np.array([0, 1]), rest_length=[2.0, 2.0],
                  slack_stretch=[0.8, 1.0])
    u = np.zeros(space.n_dofs)
    u[3 * b] = -0.2  # both bars at stretch 0.9
    response = truss.response(u)
    by_hand = sum(2 * m / al * (0.9 ** (al - 1) - 0.9 ** (-al / 2 - 1)) for m, al in zip(CHORD.mu, CHORD.alpha,
                                                                                          strict=True))
    assert by_hand < 0.0
    assert response.axial_force[1] == pytest.approx(0.3 * by_hand, rel=1e-12)
    assert response.axial_force[0] == pytest.approx(0.3 * cable.slack_stiffness * 0.1, rel=1e-12)
    with pytest.raises(TypeError, match="slack stretch below 1 needs a tension-only law"):
        Truss(space, [[a, b], [a, b]], 0.3, [cable, CHORD], np.array([0, 1]), slack_stretch=[1.0, 0.9])


def test_chord_tied_to_a_block():
    """A chord pulls the free face of a block: chord force = block reaction, and the chord force equals
    A P(lambda) at the stretch the solve reached (two laws meeting at shared nodes)."""
    area, rest = 0.2, 1.9  # pre-stretched: rest length below the 2.0 gap
    solid, chord, face, anchor = two_blocks_with_chord(LinearUniaxial(10.0), area, rest)
    X = solid.space.dof_coordinates
    solid.add_dirichlet(lambda X: X[0] < 1e-9, 0.0)
    second = np.flatnonzero(X[0] > 2.5)
    solid.add_dirichlet(nodes=second, value=0.0)
    result = solid.solve(steps=1, progress=False, rtol=1e-11)
    u = result.u()
    state = chord.response(u)
    # chord force from the law at the reached stretch
    gap = np.linalg.norm(X[:, anchor] - (X[:, face] + u[3 * face: 3 * face + 3]))
    assert state.axial_force[0] == pytest.approx(area * 10.0 * (gap / rest - 1.0), rel=1e-10)
    # the fixed face x = 0 of the block carries the chord force (equilibrium of the first block)
    reaction = result.reaction(lambda X: X[0] < 1e-9)
    assert reaction[0] == pytest.approx(-state.axial_force[0], rel=1e-8)
    assert 0 < u[3 * face] < 0.1


@pytest.mark.parametrize("law", [CHORD, LinearUniaxial(3.0), TensionOnly(CHORD), TensionOnly(CHORD, 1e-3, 0.05)],
                         ids=["ogden", "linear", "tension_only", "tension_only_ramp"])
def test_uniaxial_energy_is_the_integral_of_the_nominal_stress(law):
    """dW/dlambda = P by central differences (slack and taut stretches, across the ramp), W(1) = 0 for the plain
    laws; the Ogden bracket's series branch (|alpha ln lambda| < 1e-3) joins the closed form to rounding."""
    lam = np.array([0.8, 0.97, 0.9995, 1.00002, 1.004, 1.02, 1.049, 1.07])  # not at the tension-only kink 1
    slack = 0.9
    extra = (slack,) if isinstance(law, TensionOnly) else ()
    h = 1e-6
    fd = (law.energy(lam + h, *extra) - law.energy(lam - h, *extra)) / (2 * h)
    P = law.nominal_stress(lam, *extra)[0]
    assert np.allclose(fd, P, rtol=1e-6, atol=1e-9 * np.abs(P).max())
    if not isinstance(law, TensionOnly):
        assert law.energy(np.array([1.0]))[0] == 0.0
    tiny = OgdenUniaxial(mu=(2.0,), alpha=(3.0,))
    edge = np.exp(np.array([0.999e-3, 1.001e-3]) / 3.0)  # either side of the series' switch
    closed = 2.0 * 2.0 / 9.0 * (edge**3 + 2.0 * edge**-1.5 - 3.0)
    assert np.allclose(tiny.energy(edge), closed, rtol=1e-9)


def test_truss_energy_gradient_is_its_internal_force():
    """A chord network of three laws (Ogden, tension-only with a slack stretch, linear) between hex nodes: the
    directional derivative of Truss.energy by central differences equals the assembled internal force."""
    space = Space(skfem.MeshHex.init_tensor(*(np.linspace(0.0, 2.0, 3),) * 3))
    rng = np.random.default_rng(5)
    pairs = np.array([[0, 26], [1, 13], [4, 22], [8, 18]])
    laws = [CHORD, TensionOnly(CHORD, 1e-3, 0.05), LinearUniaxial(3.0)]
    truss = Truss(space, pairs, 0.3, laws, law_index=np.array([0, 1, 1, 2]),
                  slack_stretch=np.array([1.0, 0.95, 1.0, 1.0]))
    u = 0.05 * rng.standard_normal(space.n_dofs)
    v = rng.standard_normal(space.n_dofs)
    h = 1e-7
    fd = (truss.energy(u + h * v, 1.0) - truss.energy(u - h * v, 1.0)) / (2 * h)
    internal = truss.assemble(u, 1.0, False, 0).internal
    assert fd == pytest.approx(internal @ v, rel=1e-6)


class _Softening:
    """A falling branch: P = -0.5 (lambda - 1) (negative axial stiffness)."""

    def nominal_stress(self, stretch):
        return -0.5 * (stretch - 1.0), np.full_like(stretch, -0.5)


def test_closed_form_projection_is_the_nearest_psd_bar_tangent():
    """Bars in compression (negative geometric stiffness) and on a falling law branch (negative axial stiffness):
    the closed-form projection equals the eigendecomposition's nearest PSD matrix; taut bars keep their tangent."""
    rng = np.random.default_rng(8)
    n = 8
    x_a, x_b = rng.standard_normal((n, 3)), rng.standard_normal((n, 3))
    length = np.linalg.norm(x_b - x_a, axis=1)
    rest = length * np.where(np.arange(n) % 2, 1.2, 0.9)  # odd bars compressed, even ones stretched
    laws = LawAssignment([LinearUniaxial(3.0), _Softening()], np.arange(n) % 4 // 2, n)
    state = bar_response(x_a, x_b, rest, rng.uniform(0.2, 0.5, n), laws)
    assert np.any(state.axial_force < 0.0)
    assert np.allclose(state.projected, project_psd(state.matrices), atol=1e-12 * np.abs(state.matrices).max())
    taut = (state.axial_force > 0.0) & (np.arange(n) % 4 // 2 == 0)
    assert np.array_equal(state.projected[taut], state.matrices[taut])


def test_each_block_groups_positions_keep_their_own_width_and_assemble_the_dense_sum():
    """The CSR positions of the hexes (24 dofs) and of the chord (6) are built at each block's own width (no
    padding to the widest block: 3.6 GB of padding on the 1.1 healthy valve), and the assembled free-dof tangent is
    the dense sum of every element block (np.add.at, no CSR positions)."""
    solid, chord, face, anchor = two_blocks_with_chord(OgdenUniaxial((2.0,), (3.0,)), 0.1, 1.5)
    solid.add_dirichlet(lambda X: X[0] == 0.0, 0.0)
    pattern = solid.pattern
    for term, positions in zip(solid.terms, pattern.positions, strict=True):
        for dofs, block in zip(term.connectivity(), positions, strict=True):
            assert block.shape == (dofs.shape[0], dofs.shape[1], dofs.shape[1])
            assert getattr(block.base, "nbytes", block.nbytes) <= block.nbytes  # no view into a padded array
    rng = np.random.default_rng(3)
    u = np.zeros(solid.space.n_dofs)
    u[pattern.free] = 0.05 * rng.standard_normal(pattern.free.size)
    _, tangent = solid.assemble(u, 1.0)
    dense = np.zeros((solid.space.n_dofs, solid.space.n_dofs))
    for contribution in tangent.contributions:
        for block in contribution.blocks:
            if block.dofs.size:
                np.add.at(dense, (block.dofs[:, :, None], block.dofs[:, None, :]), block.matrices)
    K = solid.tangent_matrix(tangent).toarray()
    expected = dense[np.ix_(pattern.free, pattern.free)]
    assert np.abs(K - expected).max() <= 1e-12 * np.abs(expected).max()
