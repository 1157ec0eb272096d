"""Resumable FE² runs (issue 9 item 8): stop after step k, resume from the checkpoint, same result."""

import meshio
import numpy as np
import pytest

from skvalve.fem import OutputError, Solid, solve
from skvalve.fem.meshes import box
from skvalve.materials.exponential_fiber import ExponentialFiber
from skvalve.materials.neo_hookean import NeoHookean
from skvalve.multiscale.checkpoint import Checkpoint, load_checkpoint, resume
from skvalve.multiscale.fields import GaussPointWriter, gauss_fields
from skvalve.multiscale.material import RVEMaterial
from skvalve.multiscale.progress import FE2Progress
from skvalve.networks.generate import generate

STEPS = [0.25, 0.5, 0.75, 1.0]


def build():
    nets = [generate(a, m, n_fibers=60, seed=s) for s, (a, m) in enumerate([(30.0, 0.0), (45.0, 60.0)])]
    fiber = ExponentialFiber.from_diameter(10.5e3, 450e-9, 50.5, 1.12)
    material = RVEMaterial(nets, NeoHookean.from_shear_poisson(2.1e3, 0.49), fiber)
    mesh = box((2, 1, 1), lengths=(2.0, 1.0, 1.0))
    solid = Solid(mesh, material)
    for axis in range(3):
        solid.add_dirichlet(lambda X, a=axis: np.isclose(X[a], 0.0), 0.0, components=[axis])
    solid.add_dirichlet("right", [0.25, 0.05, 0.0])
    return solid, material


class StopAfter:
    def __init__(self, step):
        self.step = step

    def __call__(self, event):
        if event.step == self.step:
            raise RuntimeError("simulated interruption")


def test_interrupted_run_resumes_to_the_same_result(tmp_path):
    solid, material = build()
    straight = solve(solid, steps=STEPS, progress=False)
    path = tmp_path / "run.npz"
    solid2, material2 = build()
    with pytest.raises(OutputError):
        solve(solid2, steps=STEPS, progress=False, callbacks=[Checkpoint(path, material2), StopAfter(2)])
    saved = load_checkpoint(path)
    assert saved.step == 2 and saved.load_factor == 0.5
    solid3, material3 = build()  # a new process: nothing but the checkpoint survives
    u0, t0, _ = resume(material3, path)
    progress = FE2Progress(material3, total=2, disable=True)
    resumed = solve(solid3, steps=STEPS, u0=u0, t0=t0, progress=False, callbacks=[progress])
    assert progress.steps == 2 and progress.iterations == resumed.iterations > 0
    assert np.abs(resumed.u() - straight.u()).max() <= 1e-12 * np.abs(straight.u()).max()
    assert np.abs(material3.state().positions - material.state().positions).max() <= 1e-12


def test_checkpoint_rejects_other_files(tmp_path):
    np.savez(tmp_path / "other.npz", a=1)
    with pytest.raises(ValueError, match="not an FE"):
        load_checkpoint(tmp_path / "other.npz")
    with pytest.raises(FileNotFoundError):
        load_checkpoint(tmp_path / "missing.npz")


def test_gauss_point_writer_round_trip(tmp_path):
    solid, material = build()
    writer = GaussPointWriter(tmp_path / "out" / "run.pvd", solid, material, {"alpha": np.array([30.0, 45.0])})
    result = solve(solid, steps=[0.5, 1.0], progress=False, callbacks=[writer])
    assert (tmp_path / "out" / "run.pvd").read_text().count("<DataSet") == 3
    last = meshio.read(tmp_path / "out" / "run_0002.vtu")
    np.testing.assert_allclose(last.point_data["displacement"], result.displacement()[:, : solid.mesh.nvertices].T)
    sigma = gauss_fields(solid, material, result.u()).cauchy.mean(axis=2)  # (3, 3, nel)
    np.testing.assert_allclose(last.cell_data["cauchy"][0].reshape(-1, 3, 3), sigma.transpose(2, 0, 1))
    np.testing.assert_array_equal(last.cell_data["alpha"][0], [30.0, 45.0])


def test_generic_problem_checkpoint_carries_the_rve_states(tmp_path):
    """skvalve.io.checkpoint (any Problem) stores the RVE states through the solid term and resumes to the
    same result as the uninterrupted run."""
    from skvalve.io.checkpoint import Checkpoint as ProblemCheckpoint
    from skvalve.io.checkpoint import resume as resume_problem

    solid, material = build()
    straight = solve(solid, steps=STEPS, progress=False)
    solid2, _ = build()
    with pytest.raises(OutputError):
        solve(solid2, steps=STEPS, progress=False, callbacks=[ProblemCheckpoint(tmp_path), StopAfter(2)])
    solid3, material3 = build()
    t0, u0 = resume_problem(solid3, tmp_path)
    assert t0 == 0.5
    resumed = solve(solid3, steps=STEPS, u0=u0, t0=t0, progress=False)
    assert np.abs(resumed.u() - straight.u()).max() <= 1e-12 * np.abs(straight.u()).max()
    assert np.abs(material3.state().positions - material.state().positions).max() <= 1e-12
