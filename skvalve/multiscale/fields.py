"""Gauss-point fields of an FE² solve and a ParaView writer for them (a solver callback).

The RVE material lives at the quadrature points, so stresses are evaluated there (not at element
centres): Green strain E = ½(FᵀF − I) and Cauchy stress σ = σ^m + σ^c (Eqs. 8, 10) at every Gauss point,
element averages for the VTU cell data. Files are written under a temporary name and renamed
(atomic), one ``.vtu`` per converged step plus a ``.pvd`` collection.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import meshio
import numpy as np

from ..io.files import replace_atomically
from ..kinematics import green_lagrange

__all__ = ["GaussFields", "gauss_fields", "GaussPointWriter"]


@dataclass
class GaussFields:
    """Fields at the Gauss points, shape (3, 3, n_points, n_elements)."""

    F: np.ndarray
    green_strain: np.ndarray
    cauchy: np.ndarray

    def element_average(self, name: str) -> np.ndarray:
        """(n_elements, 3, 3) mean over the element's Gauss points."""
        return getattr(self, name).mean(axis=2).transpose(2, 0, 1)


def gauss_fields(solid, material, u: np.ndarray) -> GaussFields:
    """F, Green strain and Cauchy stress of ``material`` (the solid's quadrature material) at ``u``."""
    F = solid.deformation_gradient(u)
    return GaussFields(F, green_lagrange(F), material.cauchy(F))


class GaussPointWriter:
    """Solver callback writing displacement (points) and element-averaged σ, E (cells) per converged step.

    Parameters
    ----------
    path : the ``.pvd`` collection; step files are ``<stem>_<step>.vtu`` beside it.
    solid, material : the problem (None: the problem of the solver's event) and its RVE material.
    cell_data : extra constant cell fields (e.g. α of each element's network).
    """

    def __init__(self, path, solid, material, cell_data: dict | None = None) -> None:
        self.path = Path(path)
        if self.path.suffix != ".pvd":
            raise ValueError(f"GaussPointWriter: path must end in .pvd, got {self.path}")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.solid, self.material = solid, material
        self.extra = {k: np.asarray(v, dtype=float) for k, v in (cell_data or {}).items()}
        self.entries: list[tuple[float, str]] = []

    def __call__(self, event) -> None:
        if self.solid is None:
            self.solid = event.problem
        self.write(event.load_factor, event.u)

    def write(self, t: float, u: np.ndarray) -> Path:
        mesh = self.solid.mesh
        fields = gauss_fields(self.solid, self.material, u)
        disp = u[: self.solid.space.n_u].reshape(-1, 3)[: mesh.nvertices]
        cells = {
            "cauchy": [fields.element_average("cauchy").reshape(-1, 9)],
            "green_strain": [fields.element_average("green_strain").reshape(-1, 9)],
        }
        cells.update({name: [value] for name, value in self.extra.items()})
        data = meshio.Mesh(mesh.p.T, [("hexahedron", mesh.t.T)], point_data={"displacement": disp}, cell_data=cells)
        name = f"{self.path.stem}_{len(self.entries):04d}.vtu"
        target = self.path.with_name(name)
        replace_atomically(target, lambda tmp: meshio.write(tmp, data, file_format="vtu"))
        self.entries.append((float(t), name))
        lines = ['<?xml version="1.0"?>', '<VTKFile type="Collection" version="0.1">', "  <Collection>"]
        lines += [f'    <DataSet timestep="{time:.10g}" file="{file}"/>' for time, file in self.entries]
        lines += ["  </Collection>", "</VTKFile>", ""]
        replace_atomically(self.path, lambda tmp: Path(tmp).write_text("\n".join(lines)))
        return target


