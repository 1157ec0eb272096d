"""Network cache (issue 12 item 5): concurrent writers, damaged files, exact round trip, bounds."""

import multiprocessing
import re
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

from skvalve.networks import library
from skvalve.networks.generate import MAX_ATTEMPTS, MAX_FIBERS, generate
from skvalve.networks.library import CacheWarning, NetworkLibrary, cached_network, network_file
from skvalve.networks.network import Network

ALPHA, MU, N_FIBERS, SEED = 30.0, 10.0, 60, 5


@pytest.fixture(scope="module")
def reference() -> Network:
    return generate(ALPHA, MU, n_fibers=N_FIBERS, seed=SEED)


def assert_same_network(a: Network, b: Network) -> None:
    for name in ("nodes", "fibers", "boundary", "face"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
        assert getattr(a, name).dtype == getattr(b, name).dtype
    assert {k: (type(v), v) for k, v in a.meta.items()} == {k: (type(v), v) for k, v in b.meta.items()}


def test_cache_hit_returns_exactly_what_generate_returns(tmp_path, reference):
    first = cached_network(ALPHA, MU, N_FIBERS, SEED, directory=tmp_path)  # generated and written
    assert_same_network(first, reference)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        hit = cached_network(ALPHA, MU, N_FIBERS, SEED, directory=tmp_path)
    assert_same_network(hit, reference)
    assert type(hit.meta["seed"]) is int and type(hit.meta["attempt"]) is int
    assert type(hit.meta["alpha"]) is float


def _writer(directory: str, seeds: list[int], network: Network, barrier, errors) -> None:
    """One of the concurrent processes: every process writes the same files at the same moment."""
    library.generate = lambda alpha, mu, n_fibers, seed: Network(
        network.nodes, network.fibers, network.boundary, network.face, dict(network.meta, seed=seed)
    )
    try:
        for seed in seeds:
            barrier.wait(timeout=60)
            cached_network(ALPHA, MU, N_FIBERS, seed, directory=directory)
    except Exception as err:  # reported to the parent
        errors.put(f"{type(err).__name__}: {err}")


def test_concurrent_writers_publish_whole_files(tmp_path, reference):
    # the old shared temporary name made 4 parallel writers crash with FileNotFoundError
    context = multiprocessing.get_context("fork")
    barrier, errors = context.Barrier(4), context.Queue()
    seeds = list(range(100, 110))
    workers = [
        context.Process(target=_writer, args=(str(tmp_path), seeds, reference, barrier, errors)) for _ in range(4)
    ]
    for worker in workers:
        worker.start()
    for worker in workers:
        worker.join(timeout=120)
    messages = [errors.get() for _ in range(errors.qsize())] if not errors.empty() else []
    assert messages == [] and all(w.exitcode == 0 for w in workers)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(network_file(ALPHA, MU, N_FIBERS, s) for s in seeds)
    for seed in seeds:  # every published file is complete
        loaded = Network.load(tmp_path / network_file(ALPHA, MU, N_FIBERS, seed))
        np.testing.assert_array_equal(loaded.nodes, reference.nodes)
        assert loaded.meta["seed"] == seed


def _damage(kind: str, path: Path, reference: Network) -> None:
    if kind == "empty":
        path.write_bytes(b"")
    elif kind == "truncated":
        reference.save(path)
        data = path.read_bytes()
        path.write_bytes(data[: len(data) // 2])
    elif kind == "foreign arrays":
        np.savez(path, something=np.arange(3))
    elif kind == "pickled object":
        with open(path, "wb") as stream:
            np.save(stream, np.array([{"a": 1}], dtype=object), allow_pickle=True)
    elif kind == "text":
        path.write_text("not a network\n")
    elif kind == "wrong shapes":
        np.savez(
            path,
            nodes=np.zeros((3, 2)),
            fibers=np.zeros((1, 2)),
            boundary=np.zeros(3),
            face=np.zeros(3),
            meta_keys=np.array([], dtype=str),
            meta_values=np.array([], dtype=str),
        )


@pytest.mark.parametrize("kind", ["empty", "truncated", "foreign arrays", "pickled object", "text", "wrong shapes"])
def test_damaged_cache_file_is_regenerated_with_a_warning(tmp_path, reference, kind):
    path = tmp_path / network_file(ALPHA, MU, N_FIBERS, SEED)
    _damage(kind, path, reference)
    with pytest.warns(CacheWarning, match=re.escape(str(path))) as caught:
        network = cached_network(ALPHA, MU, N_FIBERS, SEED, directory=tmp_path)
    message = str(caught[0].message)
    assert not any(word in message for word in ("BadZipFile", "EOFError", "pickle", "allow_pickle")), message
    assert_same_network(network, reference)
    assert_same_network(Network.load(path), reference)  # the damaged file was replaced


def test_huge_requests_fail_fast_naming_the_parameter(tmp_path):
    start = time.perf_counter()
    with pytest.raises(ValueError, match="n_fibers"):
        generate(ALPHA, MU, n_fibers=10**9)
    with pytest.raises(ValueError, match="n_fibers"):
        generate(ALPHA, MU, n_fibers=MAX_FIBERS + 1)
    with pytest.raises(ValueError, match="max_attempts"):
        generate(ALPHA, MU, n_fibers=N_FIBERS, max_attempts=MAX_ATTEMPTS + 1)
    with pytest.raises(ValueError, match="n_fibers"):
        cached_network(ALPHA, MU, 10**12, directory=tmp_path)
    with pytest.raises(ValueError, match="n_fibers"):
        cached_network(ALPHA, MU, 450.0, directory=tmp_path)  # a float would also make a bad file name
    with pytest.raises(ValueError, match="seed"):
        NetworkLibrary([ALPHA], [MU], n_fibers=N_FIBERS, seed=-1, directory=tmp_path)
    assert time.perf_counter() - start < 1.0
    assert list(tmp_path.iterdir()) == []
