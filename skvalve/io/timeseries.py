"""ParaView time series as a solver callback: one VTU file per converged step plus a ``.pvd`` collection.

Point data at mesh vertices: ``displacement`` (3 components; zero out of plane in 2D) and,
for the mixed formulation, ``pressure``. Cell data at element centres: ``cauchy`` and
``green_strain`` (9 components, row-major), their principal values (ascending) and ``J``.
Higher-order meshes are written with their vertex connectivity. Every file is written under a
temporary name and renamed, so an interrupted run never leaves a partial file under its final name.

Use::

    writer = TimeSeriesWriter("out/run.pvd", solid)
    solid.solve(steps=10, callbacks=[writer])
"""

from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np

from ..fem.fields import element_centres
from ..fem.solvers.newton import StepEvent
from .files import replace_atomically

__all__ = ["TimeSeriesWriter", "step_fields"]

_CELL_TYPES = {"hex": "hexahedron", "tet": "tetra", "quad": "quad", "tri": "triangle"}


def step_fields(problem, u: np.ndarray, centres) -> tuple[dict, dict]:
    """(point_data, cell_data) of one state ``u`` for meshio."""
    space = problem.space
    nv = problem.mesh.nvertices
    disp = np.zeros((nv, 3))
    disp[:, : space.dim] = u[: space.n_u].reshape(-1, space.dim)[:nv]
    point_data = {"displacement": disp}
    if space.n_p:
        point_data["pressure"] = u[space.n_u:][:nv]
    F = centres.deformation_gradient(u)
    sigma = centres.cauchy(u)
    E = centres.green_strain(u)
    cell_data = {
        "cauchy": [sigma.transpose(2, 0, 1).reshape(-1, 9)],
        "green_strain": [E.transpose(2, 0, 1).reshape(-1, 9)],
        "principal_cauchy": [np.linalg.eigvalsh(sigma.transpose(2, 0, 1))],
        "principal_green_strain": [np.linalg.eigvalsh(E.transpose(2, 0, 1))],
        "J": [np.linalg.det(F.transpose(2, 0, 1))],
    }
    return point_data, cell_data


class TimeSeriesWriter:
    """Solver callback writing ``<stem>_<k>.vtu`` after each step and keeping ``<stem>.pvd`` up to date.

    Parameters
    ----------
    path : the ``.pvd`` file (the suffix is forced); its folder is created.
    problem : the solved problem (its single solid term gives the stresses).
    """

    def __init__(self, path, problem) -> None:
        path = Path(path)
        if str(path) in ("", "."):
            raise ValueError("TimeSeriesWriter needs a file name, e.g. 'out/run.pvd'")
        if path.is_dir():
            raise ValueError(f"TimeSeriesWriter: {path} is a folder; give a file name such as {path / 'run.pvd'}")
        self.path = path.with_suffix(".pvd")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.problem = problem
        self.centres = element_centres(problem)
        mesh = problem.mesh
        self.points = mesh.p.T
        self.cells = [(_CELL_TYPES[problem.space.family], mesh.t.T)]
        self.entries: list[tuple[float, str]] = []

    def __call__(self, event: StepEvent) -> None:
        self.write(event.load_factor, event.u)

    def write(self, t: float, u: np.ndarray) -> Path:
        point_data, cell_data = step_fields(self.problem, u, self.centres)
        name = f"{self.path.stem}_{len(self.entries):04d}.vtu"
        target = self.path.parent / name
        mesh = meshio.Mesh(self.points, self.cells, point_data, cell_data)
        replace_atomically(target, lambda p: meshio.write(p, mesh, file_format="vtu"))
        self.entries.append((float(t), name))
        self._write_collection()
        return target

    def _write_collection(self) -> None:
        lines = ['<?xml version="1.0"?>', '<VTKFile type="Collection" version="0.1">', "  <Collection>"]
        lines += [f'    <DataSet timestep="{t!r}" part="0" file="{name}"/>' for t, name in self.entries]
        lines += ["  </Collection>", "</VTKFile>", ""]
        replace_atomically(self.path, lambda p: p.write_text("\n".join(lines)))

    def close(self) -> None:
        """Nothing is held open; called by the solver at the end."""
