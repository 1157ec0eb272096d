"""2D fiber orientation tensor, anisotropy index and mean direction (Thomas et al. 2019, Eqs. 1–3).

SALS measures, in the plane of the tissue, the distribution R(θ) of fiber directions.  With
r(θ) = (cos θ, sin θ) the second-order orientation tensor is (Eq. 1)

    H = ∮ r ⊗ r R(θ) dθ,      ∮ R dθ = 1,

a symmetric 2×2 tensor with trace 1.  For a discrete sample (angles θ_k with weights w_k,
e.g. projected fiber lengths — the light a fiber scatters grows with its length in the beam)
the integral becomes the weighted mean H = Σ w_k r_k ⊗ r_k / Σ w_k.

With eigenvalues λ1 ≤ λ2 and eigenvector V2 of λ2,

    α = 100 (1 − λ1/λ2)            (Eq. 2: 0 for a random, 100 for a perfectly aligned network),
    μ = atan2(V2·j, V2·i)          (Eq. 3, reported in degrees in (−90°, 90°]).

Fibers are axial objects (θ and θ + 180° are the same fiber): r ⊗ r is invariant under
r → −r, so H, α and μ are too.  For the axial von Mises density R ∝ exp(κ cos 2(θ − μ)) one
finds H = ½ I + ½ ρ (cos 2μ, sin 2μ; sin 2μ, −cos 2μ) with ρ = I1(κ)/I0(κ), hence
α = 200 ρ/(1 + ρ) — the independent reference used by the tests.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from skvalve.networks.network import Network


def orientation_tensor(angles: ArrayLike, weights: ArrayLike | None = None) -> np.ndarray:
    """H = Σ w r⊗r / Σ w for fiber angles in radians (Eq. 1 as a quadrature or sample mean)."""
    theta = np.asarray(angles, dtype=float).ravel()
    if theta.size == 0:
        raise ValueError("orientation_tensor: angles is empty")
    if not np.all(np.isfinite(theta)):
        raise ValueError("orientation_tensor: angles contain non-finite values")
    if weights is None:
        w = np.ones_like(theta)
    else:
        w = np.asarray(weights, dtype=float).ravel()
        if w.shape != theta.shape:
            raise ValueError(f"orientation_tensor: weights shape {w.shape} != angles shape {theta.shape}")
        if not np.all(np.isfinite(w)) or np.any(w < 0):
            raise ValueError("orientation_tensor: weights must be finite and non-negative")
    total = w.sum()
    if total <= 0:
        raise ValueError("orientation_tensor: weights sum to zero")
    c, s = np.cos(theta), np.sin(theta)
    h11, h22, h12 = (w * c * c).sum(), (w * s * s).sum(), (w * c * s).sum()
    return np.array([[h11, h12], [h12, h22]]) / total


def _check_tensor(H: ArrayLike) -> np.ndarray:
    """H as a symmetric positive semi-definite 2×2 array, or ``ValueError`` saying what is wrong."""
    H = np.asarray(H, dtype=float)
    if H.shape != (2, 2) or not np.all(np.isfinite(H)):
        raise ValueError(f"orientation tensor must be a finite 2x2 array, got shape {H.shape}")
    scale = np.max(np.abs(H))
    if abs(H[0, 1] - H[1, 0]) > 1e-12 * scale:
        raise ValueError(
            f"orientation tensor must be symmetric (Eq. 1), got H12 = {float(H[0, 1])!r} != H21 = {float(H[1, 0])!r}"
        )
    if np.linalg.eigvalsh(H)[0] < -1e-12 * scale:
        raise ValueError("orientation tensor must be positive semi-definite (Eq. 1: a mean of r ⊗ r)")
    return 0.5 * (H + H.T)


def anisotropy_index(H: ArrayLike) -> float:
    """α = 100 (1 − λ1/λ2) in percent, Eq. 2."""
    eigenvalues = np.linalg.eigvalsh(_check_tensor(H))
    if eigenvalues[1] <= 0:
        raise ValueError("anisotropy_index: orientation tensor has no positive eigenvalue")
    return float(100.0 * (1.0 - eigenvalues[0] / eigenvalues[1]))


def mean_direction(H: ArrayLike) -> float:
    """μ in degrees in (−90, 90]: direction of the major eigenvector, Eq. 3.

    For an isotropic H (α = 0) every direction is a major one and μ is meaningless; the
    value returned then is that of the eigen-solver's choice (90° for H = I/2).
    """
    _, vectors = np.linalg.eigh(_check_tensor(H))
    major = vectors[:, 1]
    mu = np.degrees(np.arctan2(major[1], major[0]))
    mu = (mu + 90.0) % 180.0 - 90.0  # axial: fold into [−90, 90)
    return float(90.0 if mu == -90.0 else mu)


def project(
    network: Network, normal: ArrayLike = (0.0, 0.0, 1.0), positions: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Project fibers on the plane with the given normal, as SALS sees them.

    Returns (angles in radians, projected lengths) to pass to :func:`orientation_tensor`.
    The in-plane axes are e1 = normalised projection of x (or of y if the normal is along x)
    and e2 = n × e1, so that for the default normal angles are measured from x towards y.
    ``positions`` (deformed nodes) replaces the reference nodes if given.
    """
    n = np.asarray(normal, dtype=float)
    norm = np.linalg.norm(n)
    if n.shape != (3,) or not np.isfinite(norm) or norm == 0:
        raise ValueError(f"project: normal must be a non-zero 3-vector, got {normal}")
    n = n / norm
    reference = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = reference - (reference @ n) * n
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    d = network.fiber_vectors(positions)
    a, b = d @ e1, d @ e2
    return np.arctan2(b, a), np.hypot(a, b)


def network_alpha_mu(
    network: Network, normal: ArrayLike = (0.0, 0.0, 1.0), positions: np.ndarray | None = None
) -> tuple[float, float]:
    """(α %, μ °) of the length-weighted projected fibers."""
    H = orientation_tensor(*project(network, normal, positions))
    return anisotropy_index(H), mean_direction(H)
