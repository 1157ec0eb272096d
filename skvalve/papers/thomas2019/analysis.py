r"""Post-processing of the protocol runs: Table 1 extremes, Fig. 6 networks before/after, Fig. 7 strains.

* :func:`table1_extremes` — [min, max] of E11, E22 (Green strain) and S11, S22 (Cauchy stress, kPa) over
  all Gauss points of the final state (the paper does not say where it sampled; Gauss points include the
  extremes next to the clamped corners).
* :func:`network_change` — α and μ of a network before and after, from the committed (deformed)
  cross-link positions of the RVEs of an element (projected on the sample plane, Eqs. 1–3), and its
  fiber engineering strains λ − 1.
* :func:`element_max_principal_strain` — E1 per element (Fig. 7) and one RVE's fiber strains per element.
* :func:`tine_distance`, :func:`tine_influence_radius` — where a tine's point load sets the stress: Flamant's
  half-plane solution gives a radial stress :math:`2P/(\pi r t)` on the line of a point force P
  (thickness t); with the force per tine :math:`P = T s` (tension T, tine spacing s) it equals the mean membrane
  stress :math:`T/t` at :math:`r^* = 2s/\pi` (1.1 mm for four tines on 7 mm). Closer to a tine the peak is that
  of a concentrated load, which grows as the mesh is refined (:math:`\propto 1/h`), farther the body's.
* :func:`local_stretches` — in-plane stretches of an element (what sets a network's α after loading, Fig. 6).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...multiscale.fields import gauss_fields
from ...networks.orientation import network_alpha_mu
from .protocols import ProtocolRun

__all__ = ["NetworkChange", "table1_extremes", "network_change", "element_max_principal_strain", "tine_distance",
           "tine_influence_radius", "local_stretches"]


def table1_extremes(run: ProtocolRun, elements: np.ndarray | None = None) -> dict[str, tuple[float, float]]:
    """{"E11": (min, max), "E22": ..., "S11" (kPa): ..., "S22" (kPa): ...} at the final state, over the Gauss
    points of ``elements`` (an index or boolean array; None: all)."""
    fields = gauss_fields(run.solid, run.material, run.u)
    E, S = fields.green_strain, fields.cauchy / 1e3
    chosen = slice(None) if elements is None else elements
    values = {"E11": E[0, 0], "E22": E[1, 1], "S11": S[0, 0], "S22": S[1, 1]}
    return {name: (float(v[:, chosen].min()), float(v[:, chosen].max())) for name, v in values.items()}


def tine_distance(run: ProtocolRun) -> np.ndarray:
    """(n_elements,) in-plane distance (m) of each element centre to the nearest tine (inf for uniform edges)."""
    mesh = run.solid.mesh
    width, height = (float(np.ptp(mesh.p[a])) for a in range(2))
    tines = run.grips.points(width, height)
    if tines.shape[1] == 0:
        return np.full(mesh.nelements, np.inf)
    centres = mesh.p[:2, mesh.t].mean(axis=1)
    return np.hypot(centres[0][:, None] - tines[0][None, :], centres[1][:, None] - tines[1][None, :]).min(axis=1)


def tine_influence_radius(run: ProtocolRun) -> float:
    """r* = 2 s/π (module docstring), s the largest spacing of neighbouring tines along an edge (m)."""
    spacing = max(float(np.diff(np.sort(p)).max()) for p in run.grips.positions.values() if p.size > 1)
    return 2.0 * spacing / np.pi


def local_stretches(run: ProtocolRun, element: int) -> tuple[float, float]:
    """(λ1, λ2): in-plane stretches √C11, √C22 of the element's mean deformation gradient."""
    F = run.solid.deformation_gradient(run.u)[:, :, :, element].mean(axis=2)
    C = F.T @ F
    return float(np.sqrt(C[0, 0])), float(np.sqrt(C[1, 1]))


@dataclass
class NetworkChange:
    """A network's orientation before and after loading (mean over the element's RVEs) and fiber strains."""

    element: int
    alpha_before: float
    alpha_after: float
    mu_before: float
    mu_after: float
    fiber_strain: np.ndarray  # λ − 1 of every fiber of the element's RVEs
    deformed_nodes: np.ndarray  # of the element's first RVE, for plotting


def network_change(run: ProtocolRun, element: int) -> NetworkChange:
    """α/μ before and after (Fig. 6) of ``element``'s network, averaged over its Gauss-point RVEs."""
    material = run.material
    network = material.networks[element]
    alpha0, mu0 = network_alpha_mu(network)
    after = [network_alpha_mu(network, positions=material.committed_nodes(element, q))
             for q in range(material.n_points)]
    strains = np.concatenate([material.committed_fiber_stretch(element, q) - 1.0 for q in range(material.n_points)])
    return NetworkChange(element, alpha0, float(np.mean([a for a, _ in after])), mu0,
                         float(np.mean([m for _, m in after])), strains, material.committed_nodes(element, 0))


def element_max_principal_strain(run: ProtocolRun) -> tuple[np.ndarray, np.ndarray]:
    """(E1 of each element's mean Green strain, fiber engineering strains of one RVE per element)."""
    fields = gauss_fields(run.solid, run.material, run.u)
    E1 = np.linalg.eigvalsh(fields.element_average("green_strain"))[:, -1]
    material = run.material
    fibers = np.concatenate([material.committed_fiber_stretch(e, 0) - 1.0 for e in range(material.n_elements)])
    return E1, fibers
