"""Newton solver behaviour, error reporting, layered materials, prescribed rotations and output."""

import meshio
import numpy as np
import pytest
from _truss_checks import two_blocks_with_chord
from scipy.optimize import brentq

from skvalve.analytic import homogeneous
from skvalve.fem import ConvergenceError, NonPositiveJacobianError, Solid
from skvalve.fem.meshes import box, rectangle
from skvalve.fem.problem import Problem
from skvalve.fem.solvers import newton
from skvalve.io.timeseries import TimeSeriesWriter
from skvalve.materials import BimodularNeoHookean, IncompressibleNeoHookean, NeoHookean
from skvalve.materials.uniaxial import LinearUniaxial, TensionOnly

MATERIAL = NeoHookean.from_shear_poisson(1.0, 0.3)


def _uniaxial_block(stretch: float, n: int = 3, material=MATERIAL) -> Solid:
    solid = Solid(box(n), material)
    solid.add_dirichlet("left", 0.0, components=[0]).add_dirichlet("bottom", 0.0, components=[1])
    solid.add_dirichlet("front", 0.0, components=[2]).add_dirichlet("right", stretch - 1.0, components=[0])
    return solid


def test_newton_converges_quadratically():
    result = _uniaxial_block(1.5).solve(steps=1, rtol=1e-14, progress=False)
    r = np.array([rec["relative_residual"] for rec in result.log])
    r = r[r > 1e-13]  # above round-off
    assert r.size >= 3
    rates = np.log(r[2:] / r[1:-1]) / np.log(r[1:-1] / r[:-2])
    assert rates[-1] > 1.8  # quadratic: 2


def test_cutback_reaches_target_and_matches_closed_form():
    result = _uniaxial_block(3.0, n=2).solve(steps=1, max_iter=4, progress=False)
    assert result.load_factors[-1] == 1.0
    assert len(result.load_factors) > 2  # sub-steps were inserted
    exact = homogeneous.uniaxial(MATERIAL, 3.0, incompressible=False)
    assert result.reaction("right")[0] == pytest.approx(exact.nominal[0], rel=1e-7)


def test_inverted_element_raises_with_elements_and_step():
    solid = Solid(box(2), MATERIAL)
    solid.add_dirichlet("left", 0.0).add_dirichlet("right", -1.5, components=[0])
    with pytest.raises(NonPositiveJacobianError, match="load step 1") as info:
        solid.solve(steps=2, max_cutbacks=0, progress=False)
    err = info.value
    right_elements = np.unique(solid.mesh.f2t[0, solid.mesh.boundaries["right"]])
    assert err.elements.size > 0 and set(err.elements) <= set(right_elements)
    assert err.last_converged.load_factors == [0.0]


def test_nonconvergence_carries_last_converged_state_on_disk(tmp_path):
    solid = _uniaxial_block(2.5, n=2)
    with pytest.raises(ConvergenceError, match="cut-backs") as info:
        solid.solve(steps=[0.02, 1.0], max_iter=3, max_cutbacks=0, progress=False,
                    callbacks=[TimeSeriesWriter(tmp_path / "run.pvd", solid)])
    last = info.value.last_converged
    assert last.load_factors == [0.0, 0.02]
    written = sorted(tmp_path.glob("run_*.vtu"))
    assert len(written) == 2
    mesh = meshio.read(written[-1])
    expected = last.displacement()[:, : solid.mesh.nvertices].T
    assert np.allclose(mesh.point_data["displacement"], expected)
    assert "timestep=\"0.02\"" in (tmp_path / "run.pvd").read_text()


def test_layered_block_in_confined_compression_matches_closed_form():
    """Two layers in series along x, lateral faces on rollers: F = diag(lambda_i, 1, 1) per layer,
    equal nominal stress P(l) = mu (l - 1/l) + lambda ln(l)/l, lengths adding up."""
    soft, stiff = NeoHookean(1.0, 2.0), NeoHookean(4.0, 3.0)
    mesh = box((4, 1, 1))
    centres = mesh.p[:, mesh.t].mean(axis=1)
    regions = (centres[0] > 0.5).astype(int)
    total = 0.8

    def nominal(law, lam):
        return law.mu * (lam - 1 / lam) + law.lmbda * np.log(lam) / lam

    lam_soft = brentq(lambda l: nominal(soft, l) - nominal(stiff, 2 * total - l), 0.3, 1.0)
    for materials, kwargs in (([soft, stiff], {"regions": regions}),):
        solid = Solid(mesh, materials, **kwargs)
        for name, comp in (("bottom", 1), ("top", 1), ("front", 2), ("back", 2), ("left", 0)):
            solid.add_dirichlet(name, 0.0, components=[comp])
        solid.add_dirichlet("right", total - 1.0, components=[0])
        result = solid.solve(steps=2, progress=False)
        assert result.reaction("right")[0] == pytest.approx(nominal(soft, lam_soft), rel=1e-8)
        mid = result.evaluate("displacement", np.array([[0.5], [0.5], [0.5]]))[0, 0]
        assert mid == pytest.approx(0.5 * (lam_soft - 1.0), rel=1e-8)
    # the same with named subdomains
    named = mesh.with_subdomains({"soft": np.flatnonzero(regions == 0), "stiff": np.flatnonzero(regions == 1)})
    solid = Solid(named, {"soft": soft, "stiff": stiff})
    for name, comp in (("bottom", 1), ("top", 1), ("front", 2), ("back", 2), ("left", 0)):
        solid.add_dirichlet(name, 0.0, components=[comp])
    solid.add_dirichlet("right", total - 1.0, components=[0])
    assert solid.solve(steps=2, progress=False).reaction("right")[0] == pytest.approx(nominal(soft, lam_soft), rel=1e-8)


def test_direction_per_element_equals_uniform_direction():
    """A direction array of shape (3, n_elements) gives the same solution and stresses as the
    uniform direction (element order matters: a permuted array with mixed directions differs)."""
    mesh = box(2)
    uniform = BimodularNeoHookean(2.0, 0.5, direction=[1.0, 0.0, 0.0])
    per_element = BimodularNeoHookean(2.0, 0.5, direction=np.tile([[1.0], [0.0], [0.0]], (1, mesh.nelements)))
    mixed = np.tile([[1.0], [0.0], [0.0]], (1, mesh.nelements))
    mixed[:, ::2] = [[0.0], [0.0], [1.0]]
    results = []
    for law in (uniform, per_element, BimodularNeoHookean(2.0, 0.5, direction=mixed)):
        solid = Solid(mesh, law, formulation="up")
        solid.add_dirichlet("left", 0.0, components=[0]).add_dirichlet("bottom", 0.0, components=[1])
        solid.add_dirichlet("front", 0.0, components=[2]).add_dirichlet("right", 0.2, components=[0])
        results.append(solid.solve(steps=1, progress=False))
    forces = [r.reaction("right")[0] for r in results]
    assert forces[1] == pytest.approx(forces[0], rel=1e-12)
    assert forces[0] == pytest.approx(homogeneous.uniaxial(uniform, 1.2).nominal[0], rel=1e-7)
    assert np.allclose(results[1].evaluate("cauchy"), results[0].evaluate("cauchy"), rtol=1e-10, atol=1e-12)
    assert forces[2] < 0.9 * forces[0]  # half the elements see the compression modulus


def test_prescribed_end_rotation_reaction_moment():
    """Plane-strain strip clamped at x = 0, end x = L rotated rigidly by theta about its centre:
    forces and moments of the two ends balance, and the end moment matches the fixed-fixed beam
    value 4 E' I theta / L (E' = 4 mu for nu -> 1/2) within the shear/finite-strain correction."""
    L, H, theta = 10.0, 1.0, 0.02
    centre = np.array([[L], [H / 2]])

    def rotate(X, t):
        c, s = np.cos(theta * t), np.sin(theta * t)
        d = X - centre
        return np.vstack([c * d[0] - s * d[1], s * d[0] + c * d[1]]) - d

    law = NeoHookean.from_shear_poisson(1.0, 0.4999)
    solid = Solid(rectangle((20, 2), (L, H)), law, formulation="up")
    solid.add_dirichlet("left", 0.0).add_dirichlet("right", rotate)
    result = solid.solve(steps=2, progress=False)
    f_left, f_right = result.reaction("left"), result.reaction("right")
    assert np.allclose(f_left + f_right, 0.0, atol=1e-9 * np.abs(f_right).max())
    point = [L / 2, H / 2]
    m_left, m_right = result.reaction_moment("left", point), result.reaction_moment("right", point)
    assert m_left + m_right == pytest.approx(0.0, abs=1e-8 * abs(m_right))
    beam = 4 * (4 * law.mu) * (H**3 / 12) * theta / L
    assert result.reaction_moment("right", centre[:, 0]) == pytest.approx(beam, rel=0.06)


def test_fields_at_points_and_stretch_tensor():
    result = _uniaxial_block(1.4, n=2).solve(steps=2, progress=False)
    exact = homogeneous.uniaxial(MATERIAL, 1.4, incompressible=False)
    U = result.evaluate("stretch_tensor", np.array([[0.3, 0.9], [0.2, 0.7], [0.5, 0.1]]))
    assert np.allclose(U, np.diag(exact.stretches)[:, :, None], rtol=1e-8, atol=1e-9)
    E = result.evaluate("green_strain")
    assert np.allclose(E[0, 0], 0.5 * (1.4**2 - 1.0), rtol=1e-8)
    with pytest.raises(ValueError, match="outside"):
        result.evaluate("displacement", np.array([[2.0], [0.5], [0.5]]))
    with pytest.raises(ValueError, match="unknown quantity"):
        result.evaluate("vorticity")


def test_bad_input_raises():
    with pytest.raises(ValueError, match="incompressible"):
        Solid(box(1), IncompressibleNeoHookean(1.0))
    with pytest.raises(ValueError, match="order"):
        Solid(box(1), IncompressibleNeoHookean(1.0), formulation="up", order=1)
    solid = Solid(box(1), MATERIAL)
    with pytest.raises(ValueError, match="unknown boundary"):
        solid.add_dirichlet("nowhere", 0.0)
    with pytest.raises(ValueError, match="components"):
        solid.add_dirichlet("left", 0.0, components=[3])
    with pytest.raises(ValueError, match="steps"):
        solid.solve(steps=0)
    with pytest.raises(ValueError, match="regions"):
        Solid(box(1), [MATERIAL, MATERIAL], regions=np.zeros(5, dtype=int))
    with pytest.raises(ValueError, match="finite"):
        solid.add_dirichlet("left", np.nan)


def test_nodal_forces_are_balanced_by_reactions():
    solid = Solid(box(2), MATERIAL)
    solid.add_dirichlet("left", 0.0)
    solid.add_nodal_force("right", [0.01, 0.0, -0.005])
    result = solid.solve(steps=2, progress=False)
    n_nodes = solid.space.scalar_dofs_on("right").size
    assert np.allclose(result.reaction("left"), -n_nodes * np.array([0.01, 0.0, -0.005]), rtol=1e-8)
    assert result.displacement()[0].max() > 0


def test_energy_criterion_adds_iterations_and_progress_bar_runs():
    loose = _uniaxial_block(1.3, n=2).solve(steps=1, rtol=1e-2, progress=True)
    strict = _uniaxial_block(1.3, n=2).solve(steps=1, rtol=1e-2, energy_tol=1e-20, progress=False)
    assert strict.iterations > loose.iterations
    assert strict.log[-1]["relative_energy"] <= 1e-20


def test_reaction_moment_3d_balances():
    """3D block clamped at x = 0, end x = L twisted rigidly about the x axis: end forces and end
    moments (about a common point, deformed positions) balance; the twist moment is about e_x."""
    L, angle = 3.0, 0.1
    axis_point = np.array([[L], [0.5], [0.5]])

    def twist(X, t):
        c, s = np.cos(angle * t), np.sin(angle * t)
        d = X - axis_point
        return np.vstack([0 * d[0], c * d[1] - s * d[2] - d[1], s * d[1] + c * d[2] - d[2]])

    solid = Solid(box((3, 2, 2), (L, 1.0, 1.0)), MATERIAL)
    solid.add_dirichlet("left", 0.0).add_dirichlet("right", twist)
    result = solid.solve(steps=2, progress=False)
    point = [L / 2, 0.5, 0.5]
    m_left, m_right = result.reaction_moment("left", point), result.reaction_moment("right", point)
    assert np.allclose(m_left + m_right, 0.0, atol=1e-8 * np.abs(m_right).max())
    assert np.allclose(result.reaction("left") + result.reaction("right"), 0.0, atol=1e-9)
    assert m_right[0] > 0 and abs(m_right[0]) > 10 * np.abs(m_right[1:]).max()


def _slack_chord_pulled_taut():
    """Two unit blocks 2 apart, tied face centre to face centre by a tension-only chord of rest length 2.1; the
    second block is moved 0.4 away in two load steps, so the chord turns taut within the first."""
    law = TensionOnly(LinearUniaxial(10.0), slack_fraction=1e-4)
    solid, chord, _, _ = two_blocks_with_chord(law, 0.2, 2.1)
    X = solid.space.dof_coordinates
    solid.add_dirichlet(lambda X: X[0] < 1e-9, 0.0)
    moved = np.flatnonzero(X[0] > 2.5)
    solid.add_dirichlet(nodes=moved, value=0.4, components=[0]).add_dirichlet(nodes=moved, value=0.0, components=[1, 2])
    return solid, chord


def test_the_true_residual_is_assembled_only_where_the_first_full_step_fails(monkeypatch):
    """The line search's limit after a prescribed move is the true residual with the new prescribed values; it is
    assembled only where the full first step does not beat the linearised one (the step where the chord turns taut),
    and the last assembled state is always the accepted one (terms with state commit it)."""
    solid, chord = _slack_chord_pulled_taut()
    true_calls, last = [], {}
    original_true, original_assemble = newton._true_residual, Problem.assemble

    def true_residual(*args, **kwargs):
        true_calls.append(args[1].copy())
        return original_true(*args, **kwargs)

    def assemble(self, u, *args, **kwargs):
        last["u"] = np.array(u, copy=True)
        return original_assemble(self, u, *args, **kwargs)

    monkeypatch.setattr(newton, "_true_residual", true_residual)
    monkeypatch.setattr(Problem, "assemble", assemble)
    mismatches = []
    result = solid.solve(steps=2, progress=False, rtol=1e-11,
                         callbacks=[lambda event: mismatches.append(np.max(np.abs(last["u"] - event.u)))])
    assert len(true_calls) == 1  # step 1 only: the taut chord's force is not in the linearised residual
    assert [record["alpha"] for record in result.log if record["iteration"] == 1] == [1.0, 1.0]
    assert max(mismatches[1:]) == 0.0  # steps 1 and 2 end on their accepted, last assembled state
    u = result.u()
    tension = chord.response(u).axial_force[0]
    assert tension > 0.0
    assert result.reaction(lambda X: X[0] < 1e-9)[0] == pytest.approx(-tension, rel=1e-8)  # block 1 in balance
