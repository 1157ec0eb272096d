"""The closure's VTU/PVD series (:class:`skvalve.valve.outputs.ClosureWriter`) as a solver callback: two blocks brought
into IPC contact, one file per step event with displacement, nodal contact pressure and stress, hexes in VTK order."""

from types import SimpleNamespace

import meshio
import numpy as np
import skfem

from skvalve.fem import Solid
from skvalve.fem.contact import IPCContact
from skvalve.fem.meshes import box
from skvalve.fem.solvers.newton import StepEvent
from skvalve.materials import NeoHookean
from skvalve.valve.outputs import ClosureWriter, max_principal_cauchy
from skvalve.valve.setup import ValveSetup

MATERIAL = NeoHookean.from_shear_poisson(G=10.0, nu=0.3)
GAP, DHAT = 0.05, 0.02


def _blocks() -> ValveSetup:
    """A block and a smaller one ``GAP`` above it in IPC contact: the setup of a valve closure with stand-ins for the
    input's model (one 'cable' between two vertices)."""
    lower = box((2, 2, 1), (1.0, 1.0, 0.5))
    upper = skfem.MeshHex.init_tensor(np.linspace(0.1, 0.9, 3), np.linspace(0.1, 0.9, 3),
                                      np.linspace(0.5 + GAP, 1.0 + GAP, 2))
    mesh = skfem.MeshHex(np.hstack([lower.p, upper.p]), np.hstack([lower.t, upper.t + lower.p.shape[1]]))
    solid = Solid(mesh, MATERIAL)
    contact = solid.add_term(IPCContact(solid.space, dhat=DHAT, stiffness=20.0))
    model = SimpleNamespace(mesh=mesh, chordae=SimpleNamespace(ends=np.array([[0, mesh.p.shape[1] - 1]])),
                            regions=np.zeros(mesh.nelements, dtype=int))
    n = mesh.p.shape[1]
    return ValveSetup(None, model, solid, contact, np.zeros(n, dtype=np.int64), np.ones(3 * n), "blocks", 1.0)


def test_closure_writer_writes_contact_pressure_and_stress_per_step(tmp_path):
    """Step events of the open blocks, the upper one lowered to within the barrier's range, then squashed onto the
    lower one (no solve: the CCD of a solve costs seconds per step here; the writer reads only the event's state)."""
    setup = _blocks()
    space = setup.problem.space
    X = setup.model.mesh.p.T
    upper = X[:, 2] > 0.5 + 0.5 * GAP
    states = [np.zeros(space.n_dofs) for _ in range(3)]
    states[1][: space.n_u].reshape(-1, 3)[upper, 2] = -(GAP - 0.5 * DHAT)  # rigidly down, 0.01 apart
    states[2][: space.n_u].reshape(-1, 3)[upper, 2] = -(GAP - 0.5 * DHAT) - 0.1 * (X[upper, 2] - 0.5 - GAP)
    writer = ClosureWriter(tmp_path / "closure.pvd", setup)
    for k, (t, u) in enumerate(zip((0.0, 0.5, 1.0), states, strict=True)):
        writer(StepEvent(setup.problem, k, t, u, None))
    files = sorted(tmp_path.glob("closure_*.vtu"))
    assert len(files) == 3
    assert (tmp_path / "closure.pvd").read_text().count("<DataSet") == 3
    assert 'timestep="0.5"' in (tmp_path / "closure.pvd").read_text()
    u = states[-1]
    last = meshio.read(files[-1])
    np.testing.assert_allclose(last.point_data["displacement"].ravel(), u[: space.n_u])
    pressure = last.point_data["contact_pressure"]
    np.testing.assert_allclose(pressure, setup.contact.nodal_pressure(u, 1.0))
    facing = np.isclose(X[:, 2], 0.5) | np.isclose(X[:, 2], 0.5 + GAP)  # (a face pair's force is on all its vertices)
    assert np.all(pressure[facing] > 0) and np.all(pressure[~facing] == 0)  # the faces that meet, and only they
    assert np.all(meshio.read(files[0]).point_data["contact_pressure"] == 0.0)  # open: no pair within dhat
    # hexes are written in VTK order: every cell has a positive volume in the reference configuration
    hexes = last.cells_dict["hexahedron"]
    P = last.points[hexes]
    jac = np.einsum("ij,ij->i", np.cross(P[:, 1] - P[:, 0], P[:, 3] - P[:, 0]), P[:, 4] - P[:, 0])
    assert np.all(jac > 0)
    stress = last.cell_data_dict["max_principal_cauchy"]["hexahedron"]
    np.testing.assert_allclose(stress, max_principal_cauchy(setup, u))
    assert stress.shape == (setup.model.mesh.nelements,) and stress.min() < 0.0  # the squashed block, confined
    assert last.cells_dict["line"].tolist() == setup.model.chordae.ends.tolist()
