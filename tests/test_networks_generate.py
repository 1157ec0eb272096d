"""Delaunay RVE generation (Thomas 2019 section 2.3), clipping, cleaning and the cached library."""

import numpy as np
import pytest

from skvalve.networks import library
from skvalve.networks.generate import clip_to_unit_cube, delaunay_fibers, generate, prune
from skvalve.networks.network import Network
from skvalve.networks.orientation import network_alpha_mu
from skvalve.papers.thomas2019.data import NETWORK

N_FIBERS = NETWORK.fibers_per_rve  # thomas2019 §2.5: ~450 fibers per RVE


@pytest.fixture(scope="module")
def networks():
    return {(a, m): generate(a, m, n_fibers=N_FIBERS, seed=1) for a, m in [(27.0, 0.0), (41.0, 60.0), (28.0, -45.0)]}


def test_targets_are_met(networks):
    for (alpha, mu), net in networks.items():
        a, m = network_alpha_mu(net)  # measured independently of the generator's meta
        assert abs(a - alpha) <= 3.0
        assert abs((m - mu + 90) % 180 - 90) <= 5.0
        assert 405 <= net.n_fibers <= 495  # "~450 fibers": the generator keeps the count within ±10 %


def test_geometry_and_tags(networks):
    for net in networks.values():
        x, b = net.nodes, net.boundary
        assert np.all(np.abs(x) <= 0.5 + 1e-15)
        assert np.all(np.abs(x[~b]) < 0.5)  # interior strictly inside
        assert np.all(net.face[~b] == -1)
        axis, side = net.face[b] // 2, net.face[b] % 2
        on_face = x[b][np.arange(b.sum()), axis]
        np.testing.assert_array_equal(on_face, np.where(side == 1, 0.5, -0.5))
        assert np.all(net.fiber_lengths() > 1e-9)
        pairs = np.sort(net.fibers, axis=1)
        assert len(np.unique(pairs, axis=0)) == net.n_fibers  # no duplicates
        degree = np.bincount(net.fibers.ravel(), minlength=net.n_nodes)
        assert np.all(degree[~b] >= 3)  # no dangling fibers or hinges
        assert np.all(degree[b] == 1)  # each cut makes its own boundary node


def test_seeded_and_deterministic():
    a, b = generate(30.0, 10.0, n_fibers=200, seed=5), generate(30.0, 10.0, n_fibers=200, seed=5)
    np.testing.assert_array_equal(a.nodes, b.nodes)
    np.testing.assert_array_equal(a.fibers, b.fibers)
    c = generate(30.0, 10.0, n_fibers=200, seed=6)
    assert c.n_nodes != a.n_nodes or not np.array_equal(c.nodes, a.nodes)


def test_random_target_and_bad_input():
    net = generate(0.0, 0.0, n_fibers=N_FIBERS, seed=2)  # α ≈ 0 is below the sampling noise: sub-seeds are retried
    assert network_alpha_mu(net)[0] <= 3.0
    with pytest.raises(ValueError, match="alpha"):
        generate(120.0, 0.0, n_fibers=N_FIBERS)
    with pytest.raises(ValueError, match="n_fibers"):
        generate(30.0, 0.0, n_fibers=5)
    with pytest.raises(ValueError, match="n_fibers"):
        generate(30.0, 0.0, n_fibers=200.5)
    for seed in (None, -1, 1.5):
        with pytest.raises(ValueError, match="seed"):
            generate(30.0, 0.0, n_fibers=N_FIBERS, seed=seed)
    # a negative tolerance used to run all 200 sub-seeds before a RuntimeError
    with pytest.raises(ValueError, match="alpha_tol"):
        generate(30.0, 0.0, n_fibers=N_FIBERS, alpha_tol=-1.0)
    with pytest.raises(ValueError, match="mu_tol"):
        generate(30.0, 0.0, n_fibers=N_FIBERS, mu_tol=0.0)
    with pytest.raises(ValueError, match="mu"):
        generate(30.0, np.nan, n_fibers=N_FIBERS)


def test_clipping_by_hand():
    points = np.array(
        [[-1.0, 0.0, 0.0], [0.2, 0.1, 0.0], [1.0, 1.0, 0.0], [0.0, -2.0, 0.3], [2.0, 2.0, 2.0], [3.0, 2.0, 2.0]]
    )
    edges = np.array([[0, 1], [1, 2], [0, 2], [1, 3], [4, 5]])
    net = clip_to_unit_cube(points, edges)
    assert net.n_fibers == 4  # the edge 4–5 lies outside
    lookup = {tuple(np.round(p, 12)): i for i, p in enumerate(net.nodes)}
    # 0→1 enters through x = −½ at y = 0.1·(0.5/1.2)
    enter = lookup[(-0.5, round(0.1 * 0.5 / 1.2, 12), 0.0)]
    assert net.face[enter] == 0 and net.boundary[enter]
    # 1→2 reaches x = +½ (t = 0.375) before y = +½ (t = 0.444): leaves through +x
    leave = lookup[(0.5, round(0.1 + 0.9 * 0.375, 12), 0.0)]
    assert net.face[leave] == 1
    # 1→3 leaves through y = −½ at t = 0.6/2.1
    t = 0.6 / 2.1
    assert net.face[lookup[(round(0.2 - 0.2 * t, 12), -0.5, round(0.3 * t, 12))]] == 2
    inner = lookup[(0.2, 0.1, 0.0)]
    assert not net.boundary[inner] and net.face[inner] == -1
    # 0→2 crosses the cube: two boundary nodes (faces −x and +y)
    crossing = [f for f in net.fibers if net.boundary[f].all()]
    assert len(crossing) == 1 and sorted(net.face[crossing[0]]) == [0, 3]


def test_prune_removes_dangling_and_floating():
    # interior node 1 hangs on a single fiber from boundary node 0; 2–3 float free
    nodes = np.array([[-0.5, 0, 0], [0, 0, 0], [0.1, 0.1, 0.1], [0.2, 0.1, 0.1]])
    net = Network(nodes, [[0, 1], [2, 3]], [True, False, False, False], [0, -1, -1, -1])
    pruned, removed = prune(net)
    assert pruned.n_fibers == 0 and removed == 2


def test_delaunay_fibers_unique_edges():
    rng = np.random.default_rng(0)
    edges = delaunay_fibers(rng.uniform(-1, 1, (60, 3)))
    assert np.all(edges[:, 0] < edges[:, 1])
    assert len(np.unique(edges, axis=0)) == len(edges)


def test_library_cache_roundtrip(tmp_path, monkeypatch):
    monkeypatch.setenv("SKVALVE_CACHE", str(tmp_path))
    assert library.cache_dir() == tmp_path / "networks"
    lib = library.NetworkLibrary([25.0, 40.0], [0.0, 90.0], n_fibers=150, seed=3)
    assert lib.build() == 4
    files = sorted((tmp_path / "networks").glob("*.npz"))
    assert len(files) == 4
    calls = []
    monkeypatch.setattr(library, "generate", lambda *a, **k: calls.append(a))
    reloaded = library.NetworkLibrary([25.0, 40.0], [0.0, 90.0], n_fibers=150, seed=3)
    net = reloaded.nearest(38.0, -85.0)  # μ is axial: −85° is next to 90°
    assert calls == []  # served from the cache
    original = lib.get(1, 1)
    np.testing.assert_array_equal(net.nodes, original.nodes)
    np.testing.assert_array_equal(net.face, original.face)
    assert net.meta["alpha_target"] == 40.0


def test_library_cache_does_not_confuse_targets_that_round_alike(tmp_path, monkeypatch):
    """File names hold α, μ to 0.01: α = 25.001 and α = 25.0 share a name but are different networks."""
    calls = []

    def fake_generate(alpha, mu, n_fibers, seed):
        calls.append(alpha)
        net = Network([[-0.5, 0, 0], [0.5, 0, 0]], [[0, 1]], [True, True], [0, 1])
        net.meta.update(alpha_target=float(alpha), mu_target=float(mu))
        return net

    monkeypatch.setattr(library, "generate", fake_generate)
    library.cached_network(25.001, 0.0, 150, 3, directory=tmp_path)
    assert library.cached_network(25.0, 0.0, 150, 3, directory=tmp_path).meta["alpha_target"] == 25.0
    assert library.cached_network(25.0, 0.0, 150, 3, directory=tmp_path).meta["alpha_target"] == 25.0
    assert calls == [25.001, 25.0]  # the second 25.0 is a cache hit


def test_network_rejects_non_finite_nodes():
    with pytest.raises(ValueError, match="finite"):
        Network([[np.nan, 0, 0], [0.5, 0, 0]], [[0, 1]], [True, True], [0, 1])
