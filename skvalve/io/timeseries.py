"""ParaView time series: one VTU file per converged step plus a ``.pvd`` collection (meshio).

Point data at mesh vertices: ``displacement`` (3 components; zero out of plane in 2D) and,
for the mixed formulation, ``pressure``. Cell data at element centres: ``cauchy`` and
``green_strain`` (9 components, row-major), their principal values (ascending) and ``J``.
Higher-order meshes are written with their vertex connectivity.
"""

from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np

__all__ = ["TimeSeriesWriter", "step_fields"]

_CELL_TYPES = {"hex": "hexahedron", "tet": "tetra", "quad": "quad", "tri": "triangle"}


def step_fields(solid, u: np.ndarray, centres) -> tuple[dict, dict]:
    """(point_data, cell_data) of one state ``u`` for meshio."""
    space = solid.space
    nv = solid.mesh.nvertices
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
    """Write ``<stem>_<k>.vtu`` after each step and keep ``<stem>.pvd`` up to date."""

    def __init__(self, path, solid) -> None:
        from ..fem.fields import element_centres

        self.path = Path(path).with_suffix(".pvd")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.solid = solid
        self.centres = element_centres(solid)
        mesh = solid.mesh
        self.points = mesh.p.T
        self.cells = [(_CELL_TYPES[solid.space.family], mesh.t.T)]
        self.entries: list[tuple[float, str]] = []

    def write(self, t: float, u: np.ndarray) -> Path:
        point_data, cell_data = step_fields(self.solid, u, self.centres)
        name = f"{self.path.stem}_{len(self.entries):04d}.vtu"
        meshio.write(self.path.parent / name, meshio.Mesh(self.points, self.cells, point_data, cell_data))
        self.entries.append((float(t), name))
        self._write_collection()
        return self.path.parent / name

    def _write_collection(self) -> None:
        lines = ['<?xml version="1.0"?>', '<VTKFile type="Collection" version="0.1">', "  <Collection>"]
        lines += [f'    <DataSet timestep="{t!r}" part="0" file="{name}"/>' for t, name in self.entries]
        lines += ["  </Collection>", "</VTKFile>", ""]
        self.path.write_text("\n".join(lines))

    def close(self) -> None:
        """Nothing is held open; kept for symmetry with context use."""
