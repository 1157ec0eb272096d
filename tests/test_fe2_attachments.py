"""thomas2019 biaxial attachments (issue 34): tine positions, reactions against independent references.

The mechanics checks use the neo-Hookean matrix alone (Eq. 10, fast; G of the paper, nu = 0.3 so that trilinear hexes do
not lock and the Gauss-point stresses are not polluted by a pressure checkerboard), on the §2.5 block:

* uniform edges give the homogeneous plane-stress biaxial state, whose tension t P11 is a closed form;
* for any grips, the FE identity sum_a X_a f_a = integral of P dV (isoparametric elements, f the internal nodal
  forces, zero at free nodes at equilibrium) gives the tension a second way, from the Gauss-point stresses;
* a point tine is a concentrated load: Flamant's solution has sigma ~ 1/r, so the peak Gauss-point stress next to
  it doubles when the mesh size halves (uniform edges: no change).
"""

from types import SimpleNamespace

import numpy as np
import pytest
from scipy.optimize import brentq

from skvalve.fem import solve
from skvalve.kinematics import green_lagrange
from skvalve.materials import NeoHookean
from skvalve.papers.thomas2019 import data
from skvalve.papers.thomas2019.analysis import local_stretches, table1_extremes, tine_distance, tine_influence_radius
from skvalve.papers.thomas2019.attachments import DEFAULT_TINES, UNIFORM_EDGES, Tines, _snap, tine_fractions
from skvalve.papers.thomas2019.models import fe2_material
from skvalve.papers.thomas2019.protocols import biaxial_problem, edge_tensions, run_protocol
from skvalve.papers.thomas2019.sample import Sample, build_sample, sample_mesh

LAW = NeoHookean.from_shear_poisson(data.G, 0.3)
DELTA = np.array([0.35e-3, 0.21e-3])  # grip displacements (m): stretches 1.05 and 1.03 of the 7 mm edges


def _plain_sample(divisions) -> Sample:
    mesh = sample_mesh(divisions)
    zeros = np.zeros(mesh.nelements)
    return Sample(mesh, zeros, zeros, [], zeros, {})


def _solve(divisions, attachment, delta=DELTA):
    sample = _plain_sample(divisions)
    solid, schedule, grips = biaxial_problem(sample, LAW, attachment)
    schedule.add(1.0, delta)
    result = solve(solid, steps=2, progress=False, rtol=1e-10)
    return sample, solid, grips, result.u(), result.residuals[-1]


def _stresses(solid, u):
    F = solid.deformation_gradient(u)  # (3, 3, nqp, nel)
    P = LAW.pk1(F)
    sigma = LAW.cauchy(F)
    return P, sigma


def test_default_is_four_evenly_spaced_tines_and_they_snap_symmetrically():
    np.testing.assert_allclose(tine_fractions(DEFAULT_TINES), [0.125, 0.375, 0.625, 0.875])
    np.testing.assert_allclose(tine_fractions(Tines(3, span=0.5)), [0.25, 0.5, 0.75])
    assert _snap(tine_fractions(DEFAULT_TINES), 8).tolist() == [1, 3, 5, 7]
    assert _snap(tine_fractions(DEFAULT_TINES), 16).tolist() == [2, 6, 10, 14]
    index = _snap(tine_fractions(DEFAULT_TINES), 28)  # 3.5, 10.5, 17.5, 24.5: rounded away from the centre
    assert index.tolist() == [3, 10, 18, 25] and np.all(index + index[::-1] == 28)


@pytest.mark.parametrize("kwargs, match", [({"per_edge": 0}, "per_edge"), ({"per_edge": 2.0}, "per_edge"),
                                           ({"span": 1.0}, "span"), ({"span": "wide"}, "span"),
                                           ({"per_edge": 3, "span": 0.0}, "share"),
                                           ({"sliding": "yes"}, "sliding")])
def test_bad_tines_are_rejected(kwargs, match):
    with pytest.raises(ValueError, match=match):
        Tines(**kwargs)


def test_tines_that_do_not_fit_the_mesh_are_rejected():
    with pytest.raises(ValueError, match="distinct interior node columns"):
        biaxial_problem(_plain_sample((4, 4, 1)), LAW, DEFAULT_TINES)
    with pytest.raises(TypeError, match="UniformEdges or Tines"):
        biaxial_problem(_plain_sample((4, 4, 1)), LAW, "hooks")


def test_uniform_edges_give_the_closed_form_plane_stress_biaxial_tension():
    """Bonet-Wood neo-Hookean, F = diag(l1, l2, l3): P_ii = G(l_i - 1/l_i) + Lambda ln J / l_i, P33 = 0."""
    sample, solid, grips, u, residual = _solve((4, 4, 1), UNIFORM_EDGES)
    law = LAW
    width, height, thickness = sample.size
    l1, l2 = 1 + DELTA[0] / width, 1 + DELTA[1] / height

    def p(li, J):
        return law.mu * (li - 1 / li) + law.lmbda * np.log(J) / li

    l3 = brentq(lambda l3: p(l3, l1 * l2 * l3), 0.5, 1.0)
    exact = thickness * np.array([p(l1, l1 * l2 * l3), p(l2, l1 * l2 * l3)])
    np.testing.assert_allclose(edge_tensions(solid, residual, sample, grips), exact, rtol=1e-8)


@pytest.mark.parametrize("attachment", [UNIFORM_EDGES, DEFAULT_TINES], ids=["uniform", "tines"])
def test_grip_tension_equals_the_volume_integral_of_the_stress(attachment):
    """T1 W H = sum_a X_a R_a,x = integral of P11 dV (sliding grips: only the right ones have X R_x != 0)."""
    sample, solid, grips, u, residual = _solve((16, 16, 1), attachment)
    width, height, _ = sample.size
    P, _ = _stresses(solid, u)
    dV = solid.space.dx.T  # (nqp, nel)
    volume_integral = np.array([(P[0, 0] * dV).sum() / width, (P[1, 1] * dV).sum() / height])
    tensions = edge_tensions(solid, residual, sample, grips)
    np.testing.assert_allclose(tensions * np.array([height, width]), volume_integral, rtol=1e-7)
    left = residual[solid.space.displacement_dofs(grips.nodes["left"], [0])].sum()
    assert left == pytest.approx(-tensions[0] * height, rel=1e-8)  # the two grips balance


def test_tines_leave_the_corners_unloaded_and_pinned_tines_hold_tangentially():
    sample, solid, grips, u, residual = _solve((16, 16, 1), DEFAULT_TINES)
    _, sigma = _stresses(solid, u)
    centres = sample.mesh.p[:, sample.mesh.t].mean(axis=1)
    corner = int(np.argmin(np.linalg.norm(centres[:2], axis=0)))
    centre = int(np.argmin(np.linalg.norm(centres[:2] - 3.5e-3, axis=0)))
    assert np.abs(sigma[:2, :2, :, corner]).max() < 0.1 * sigma[0, 0, :, centre].mean()  # under a tenth
    _, solid_u, _, u_u, _ = _solve((16, 16, 1), UNIFORM_EDGES)
    _, sigma_u = _stresses(solid_u, u_u)
    assert sigma_u[0, 0, :, corner].mean() > 0.9 * sigma_u[0, 0, :, centre].mean()  # uniform edges load corners
    tangential = residual[solid.space.displacement_dofs(grips.nodes["left"], [1])]
    assert np.abs(tangential).max() < 1e-9 * np.abs(residual).max()  # sliding: free along the edge
    _, solid_p, grips_p, _, residual_p = _solve((16, 16, 1), Tines(sliding=False))
    held = residual_p[solid_p.space.displacement_dofs(grips_p.nodes["left"], [1])]
    normal = residual_p[solid_p.space.displacement_dofs(grips_p.nodes["left"], [0])]
    assert np.abs(held).max() > 0.05 * np.abs(normal).max()  # pinned tines carry tangential forces


def test_a_point_tine_is_a_concentrated_load_whose_peak_grows_as_one_over_h():
    """Flamant: sigma ~ P/(pi r t); the Gauss point nearest a tine sits at r ~ h, so the peak doubles as h halves."""
    delta = DELTA * 0.1  # small strains: the linear-elastic solution is the reference
    peaks = {}
    for attachment in (UNIFORM_EDGES, Tines(per_edge=2)):
        for n in (8, 16, 32):
            _, solid, _, u, _ = _solve((n, n, 1), attachment, delta)
            peaks[attachment, n] = np.abs(_stresses(solid, u)[1][0, 0]).max()
    ratios = [peaks[Tines(per_edge=2), 2 * n] / peaks[Tines(per_edge=2), n] for n in (8, 16)]
    assert all(1.6 < r < 2.4 for r in ratios), ratios
    assert abs(peaks[UNIFORM_EDGES, 32] / peaks[UNIFORM_EDGES, 8] - 1) < 0.01


def test_fe2_protocol_with_tines_reaches_the_tensions(tmp_path):
    sample = build_sample((4, 4, 1), n_fibers=60, library_directory=tmp_path)
    for attachment in (Tines(per_edge=2), Tines(per_edge=2, sliding=False)):
        run = run_protocol(sample, fe2_material(sample), (1.0, 0.5), max_tension=10.0, steps=3, tolerance=0.005,
                           attachment=attachment, max_corrections=10)
        assert np.abs(run.path_tension[-1] - [10.0, 5.0]).max() <= 0.05
        assert run.grips.attachment is attachment and run.grips.nodes["right"].size == 2 * 2  # 2 tines x 2 layers


def _run(divisions, attachment, delta=DELTA):
    """A run-like record of the neo-Hookean solve, for the post-processing of analysis.py."""
    sample, solid, grips, u, _ = _solve(divisions, attachment, delta)
    return sample, SimpleNamespace(solid=solid, material=LAW, u=u, grips=grips)


def test_tine_points_distances_and_influence_radius():
    sample, run = _run((16, 16, 1), DEFAULT_TINES)
    width, height, _ = sample.size
    points = run.grips.points(width, height)
    along = np.array([0.125, 0.375, 0.625, 0.875]) * 7e-3  # 16 divisions: the tines sit exactly on node columns
    expected = np.concatenate([np.stack([np.zeros(4), along]), np.stack([np.full(4, 7e-3), along]),
                               np.stack([along, np.zeros(4)]), np.stack([along, np.full(4, 7e-3)])], axis=1)
    np.testing.assert_allclose(points, expected, atol=1e-15)
    assert tine_influence_radius(run) == pytest.approx(2 * 1.75e-3 / np.pi, rel=1e-12)  # 2 s / pi, s = 7 mm / 4
    distance = tine_distance(run)
    centres = sample.mesh.p[:2, sample.mesh.t].mean(axis=1)
    corner = int(np.argmin(np.linalg.norm(centres, axis=0)))  # element centre (0.219, 0.219) mm, tines at 0.875 mm
    assert distance[corner] == pytest.approx(np.hypot(0.21875e-3, 0.875e-3 - 0.21875e-3), rel=1e-12)
    _, uniform = _run((4, 4, 1), UNIFORM_EDGES)
    assert uniform.grips.points(width, height).shape == (2, 0) and np.all(np.isinf(tine_distance(uniform)))


def test_local_stretches_and_extremes_of_chosen_elements():
    """Uniform edges give the homogeneous state: every element's stretches are the grips' 1 + delta / L."""
    sample, run = _run((4, 4, 1), UNIFORM_EDGES)
    for element in (0, 7, 15):
        np.testing.assert_allclose(local_stretches(run, element), 1 + DELTA / 7e-3, rtol=1e-9)
    every = table1_extremes(run)
    assert table1_extremes(run, np.ones(sample.n_elements, dtype=bool)) == every
    one = table1_extremes(run, np.array([5]))
    E = green_lagrange(run.solid.deformation_gradient(run.u))[:, :, :, 5]
    assert one["E11"] == (E[0, 0].min(), E[0, 0].max())
