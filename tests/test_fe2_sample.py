"""thomas2019 §2.5 sample and protocols: the α/μ map, user maps, the homogeneous model, edge tensions."""

import numpy as np
import pytest
from _fe2_networks import affine_network

from skvalve.multiscale.affine import AffineFiberModel
from skvalve.multiscale.homogeneous import HomogeneousBiaxial
from skvalve.multiscale.material import RVEMaterial
from skvalve.papers.thomas2019 import data
from skvalve.papers.thomas2019.models import fe2_material, fiber_law, matrix_law
from skvalve.papers.thomas2019.protocols import run_protocol, targets
from skvalve.papers.thomas2019.sample import build_sample, default_alpha_mu, sample_mesh


def test_default_map_has_the_papers_alpha_at_n1_n2_n3():
    width, height = (s * 1e-3 for s in data.SAMPLE_SIZE_MM[:2])
    for name, expected in (("N1", 41.0), ("N2", 27.0), ("N3", 28.0)):  # Fig. 6d-f
        fx, fy = data.NETWORK_LOCATIONS[name]
        alpha, mu = default_alpha_mu(np.array([fx * width]), np.array([fy * height]))
        assert alpha[0] == pytest.approx(expected, abs=1e-12) and mu[0] == 0.0


def test_paper_mesh_has_2352_hexes_of_the_sample_size():
    mesh = sample_mesh()
    assert mesh.nelements == 2352  # §2.5
    np.testing.assert_allclose(mesh.p.max(axis=1) - mesh.p.min(axis=1), [7e-3, 7e-3, 0.406e-3])


def test_user_maps_pick_matching_networks(tmp_path):
    sample = build_sample((2, 2, 1), lambda x, y: (np.where(x < 3.5e-3, 20.0, 40.0), 30.0), n_fibers=60,
                          library_directory=tmp_path)
    left = sample.mesh.p[0, sample.mesh.t].mean(axis=0) < 3.5e-3
    np.testing.assert_allclose(sample.alpha, np.where(left, 20.0, 40.0))
    assert np.all(np.abs(sample.network_alpha - sample.alpha) <= 3.0)  # generator tolerance
    values = np.column_stack([np.full(4, 35.0), np.full(4, -10.0)])
    assert np.all(build_sample((2, 2, 1), values, n_fibers=60, library_directory=tmp_path).mu == -10.0)
    with pytest.raises(ValueError, match=r"shape \(4, 2\)"):
        build_sample((2, 2, 1), np.zeros((3, 2)), n_fibers=60, library_directory=tmp_path)
    bad = values.copy()
    bad[2, 0] = 120.0
    with pytest.raises(ValueError, match="element 2"):
        build_sample((2, 2, 1), bad, n_fibers=60, library_directory=tmp_path)


def test_homogeneous_biaxial_reaches_tensions_with_free_faces():
    """Affine networks: check the solved stretches with the independent affine model."""
    nets = [affine_network(seed) for seed in range(3)]
    matrix, fiber = matrix_law(), fiber_law()
    thickness = 0.4e-3
    model = HomogeneousBiaxial(RVEMaterial(nets, matrix, fiber, n_points=1), thickness)
    state = model.solve([20.0, 10.0], increments=4)[-1]
    F = np.zeros((3, 3, 1, 3))
    for i in range(3):
        F[i, i] = state.stretches[i]
    P = (matrix.pk1(F) + AffineFiberModel(nets, fiber, n_points=1).pk1(F)).mean(axis=(2, 3))
    np.testing.assert_allclose(thickness * np.diag(P)[:2], [20.0, 10.0], rtol=1e-8)
    assert abs(P[2, 2]) <= 1e-8 * abs(P[0, 0])
    assert state.stretches[0] > 1 and state.stretches[2] < 1


def test_protocol_reaches_the_edge_tensions(tmp_path):
    sample = build_sample((2, 2, 1), n_fibers=60, library_directory=tmp_path)
    run = run_protocol(sample, fe2_material(sample), (1.0, 0.5), max_tension=10.0, steps=3, tolerance=0.005)
    np.testing.assert_allclose(run.targets, targets((1.0, 0.5), 10.0))
    assert np.abs(run.path_tension[-1] - [10.0, 5.0]).max() <= 0.05
    assert run.delta[0] > 0 and run.delta[1] > 0
    assert np.all(np.diff(run.path_tension[: 4, 0]) > 0)  # the ramp loads monotonically
