"""Shared helpers for the material tests: random deformations and central finite differences."""

from __future__ import annotations

import numpy as np

from skvalve.materials import (
    BimodularNeoHookean,
    IncompressibleNeoHookean,
    LeeSacks,
    NeoHookean,
    Ogden,
)

FD_STEP = 1e-6


def random_deformations(n: int, seed: int, spread: float = 0.25, min_det: float = 0.3) -> np.ndarray:
    """``n`` deformation gradients ``I + spread * N(0, 1)`` with det F > min_det, shape (3, 3, n)."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        F = np.eye(3) + spread * rng.standard_normal((3, 3))
        if np.linalg.det(F) > min_det:
            out.append(F)
    return np.stack(out, axis=-1)


def random_rotations(n: int, seed: int) -> np.ndarray:
    """Proper rotations (3, 3, n) from QR of Gaussian matrices."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        Q, R = np.linalg.qr(rng.standard_normal((3, 3)))
        Q = Q @ np.diag(np.sign(np.diag(R)))
        if np.linalg.det(Q) < 0:
            Q[:, 0] *= -1
        out.append(Q)
    return np.stack(out, axis=-1)


def central_differences(fun, F: np.ndarray, h: float = FD_STEP) -> np.ndarray:
    """d fun(F) / dF_kL by central differences: fun's tensor axes, then (k, L), then the batch axes."""
    batch_ndim = F.ndim - 2
    columns = []
    for k in range(3):
        for L in range(3):
            Fp, Fm = F.copy(), F.copy()
            Fp[k, L] += h
            Fm[k, L] -= h
            columns.append((fun(Fp) - fun(Fm)) / (2 * h))
    value_ndim = columns[0].ndim - batch_ndim
    stacked = np.stack(columns, axis=value_ndim)
    return stacked.reshape(stacked.shape[:value_ndim] + (3, 3) + stacked.shape[value_ndim + 1 :])


def fd_pk1(law, F: np.ndarray, h: float = FD_STEP) -> np.ndarray:
    """Central differences of psi with respect to every F_kL, shape (3, 3, *batch)."""
    return central_differences(law.psi, F, h)


def fd_tangent(law, F: np.ndarray, h: float = FD_STEP) -> np.ndarray:
    """Central differences of pk1 with respect to every F_kL, shape (3, 3, 3, 3, *batch)."""
    return central_differences(law.pk1, F, h)


def relative_error(a: np.ndarray, b: np.ndarray) -> float:
    """max |a - b| / max |b| (max |b| floored at 1e-300)."""
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))


#: chordae parameters of Texas TriValve 1.0 (anterior, MPa; Mathur et al. 2022, CC BY-NC-SA 4.0)
#: with alpha scaled down so that the random deformations stay within float range.
LAWS = {
    "neo_hookean": NeoHookean(mu=1.3, lmbda=4.0),
    "neo_hookean_auxetic": NeoHookean.from_shear_poisson(1.0, -0.3),
    "incompressible_neo_hookean": IncompressibleNeoHookean(mu=0.7),
    "ogden_1term_incompressible": Ogden(mu=(1.0,), alpha=(5.0,)),
    "ogden_3term_one_D": Ogden(mu=(0.6, 0.01, 0.3), alpha=(9.0, -4.0, 2.5), D=(0.5,)),
    "ogden_2term_two_D": Ogden(mu=(1.0, 0.2), alpha=(2.0, -1.5), D=(0.8, 2.0)),
    "lee_sacks_shipped": LeeSacks(c0=1.0, c1=0.12, c2=1.5, D=0.5),
    "lee_sacks_published": LeeSacks(c0=1.0, c1=0.12, c2=1.5, D=0.5, published_equation=True),
    "lee_sacks_incompressible": LeeSacks(c0=1.0, c1=0.12, c2=1.5),
    "bimodular": BimodularNeoHookean(mu_tension=4.7, mu_compression=1.0, direction=[1.0, 2.0, -0.5]),
}
