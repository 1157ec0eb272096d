"""FE² with the RVEs on a 2-worker Dask LocalCluster against the in-process RVEMaterial (issue 9, item 7).

The reference is the in-process material solving the same problem (same networks, same load path, incl. a
forced failed step and its rewind): displacements, committed RVE states and stresses must agree to 1e-12.
"""

import numpy as np
import pytest

from skvalve.fem import ConvergenceError, Solid, solve
from skvalve.fem.meshes import box
from skvalve.materials.exponential_fiber import ExponentialFiber
from skvalve.materials.neo_hookean import NeoHookean
from skvalve.multiscale.distributed import DistributedRVEMaterial
from skvalve.multiscale.material import RVEFailure, RVEMaterial
from skvalve.networks.generate import generate

distributed = pytest.importorskip("distributed", reason="dask[distributed] is not installed (extra 'distributed')")

G, NU, E_F, BETA, LAMBDA_C, DIAMETER, PSI = 2.1e3, 0.49, 10.5e3, 50.5, 1.12, 450e-9, 0.43
STATE = ("positions", "F", "sensitivity", "fiber_stretch")


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0")
    with cluster, distributed.Client(cluster) as connected:
        yield connected


@pytest.fixture(scope="module")
def laws():
    return NeoHookean.from_shear_poisson(G, NU), ExponentialFiber.from_diameter(E_F, DIAMETER, BETA, LAMBDA_C)


@pytest.fixture(scope="module")
def nets():
    return [generate(a, m, n_fibers=60, seed=s) for s, (a, m) in enumerate([(30.0, 0.0), (45.0, 60.0), (20.0, -30.0),
                                                                              (40.0, 90.0)])]


def stretched_block(material, stretch=1.2):
    mesh = box((2, 2, 1), lengths=(2.0, 2.0, 1.0))
    solid = Solid(mesh, material)
    for axis in range(3):
        solid.add_dirichlet(lambda X, a=axis: np.isclose(X[a], 0.0), 0.0, components=[axis])
    solid.add_dirichlet(lambda X: np.isclose(X[0], 2.0), stretch - 1.0, components=[0])
    return solid


def load_path(material):
    """Step to 0.5, a failed step to 1.0 (one Newton iteration, no cut-back), then 0.75 and 1.0."""
    solid = stretched_block(material)
    first = solve(solid, steps=[0.5], progress=False)
    with pytest.raises(ConvergenceError):
        solve(solid, steps=[1.0], u0=first.u(), t0=0.5, max_iter=1, max_cutbacks=0, progress=False)
    final = solve(solid, steps=[0.75, 1.0], u0=first.u(), t0=0.5, progress=False)
    return solid, final


def close(a, b, tol=1e-12):
    return np.abs(np.asarray(a) - np.asarray(b)).max() <= tol * max(np.abs(np.asarray(b)).max(), 1e-300)


def test_two_workers_match_in_process_over_steps_with_a_rewind(client, laws, nets):
    matrix, fiber = laws
    local = RVEMaterial(nets, matrix, fiber, psi=PSI, fiber_diameter=DIAMETER)
    remote = DistributedRVEMaterial.from_material(RVEMaterial(nets, matrix, fiber, psi=PSI, fiber_diameter=DIAMETER),
                                                  client, chunks=3, numba_threads=1)  # uneven: worker 0 owns two
    assert set(remote.owners) == set(client.nthreads())
    solid_local, final_local = load_path(local)
    solid_remote, final_remote = load_path(remote)
    u = final_local.u()
    assert np.abs(u).max() > 0.19  # the block did stretch (20 %)
    assert close(final_remote.u(), u)
    assert final_remote.iterations == final_local.iterations
    for name in STATE:
        assert close(getattr(remote.state(), name), getattr(local.state(), name)), name
    F = solid_local.deformation_gradient(u)
    P_local, A_local = local.pk1_and_tangent(F)
    P_remote, A_remote = remote.pk1_and_tangent(F)
    assert close(P_remote, P_local) and close(A_remote, A_local)
    assert close(remote.cauchy(F), local.cauchy(F))
    assert close(remote.committed_nodes(3, 5), local.committed_nodes(3, 5))
    assert close(remote.committed_fiber_stretch(1, 2), local.committed_fiber_stretch(1, 2))
    assert remote.solves > 0 and remote.solve_seconds >= remote.worker_seconds > 0


def test_rewind_keeps_worker_states_bit_for_bit(client, laws, nets):
    matrix, fiber = laws
    remote = DistributedRVEMaterial(nets, matrix, fiber, client, n_points=8, psi=PSI, fiber_diameter=DIAMETER)
    reference = RVEMaterial(nets, matrix, fiber, psi=PSI, fiber_diameter=DIAMETER).state()
    committed = remote.state()
    for name in STATE:  # the reference state solved on the workers is the in-process one
        assert close(getattr(committed, name), getattr(reference, name)), name
    F = np.broadcast_to(np.diag([1.1, 1.05, 0.9])[:, :, None, None], (3, 3, 8, 4)).copy()
    remote.pk1_and_tangent(F)
    remote.rewind()
    after = remote.state()
    for name in STATE:
        assert np.array_equal(getattr(after, name), getattr(committed, name)), name
    remote.pk1(F)
    remote.commit()
    assert np.array_equal(remote.state().F[0], F[:, :, 0, 0])
    remote.set_state(committed)  # a checkpoint restored onto the workers
    for name in STATE:
        assert np.array_equal(getattr(remote.state(), name), getattr(committed, name)), name


def test_bad_input_is_named(client, laws, nets):
    matrix, fiber = laws
    remote = DistributedRVEMaterial(nets[:2], matrix, fiber, client, n_points=1, psi=PSI, fiber_diameter=DIAMETER)
    F = np.broadcast_to(np.eye(3)[:, :, None, None], (3, 3, 1, 2)).copy()
    F[2, 2, 0, 1] = -1.0
    with pytest.raises(RVEFailure, match="element 1, point 0"):
        remote.pk1(F)
    with pytest.raises(ValueError, match="chunks"):
        DistributedRVEMaterial(nets[:2], matrix, fiber, client, n_points=1, psi=PSI, fiber_diameter=DIAMETER, chunks=3)
    with pytest.raises(ValueError, match="sensitivity has shape"):
        state = remote.state()
        state.sensitivity = state.sensitivity[1:]
        remote.set_state(state)
    with pytest.raises(AttributeError, match="set_state"):
        remote.batch  # noqa: B018
