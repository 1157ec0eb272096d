"""Delaunay fiber-network RVEs with a target SALS alignment (Thomas et al. 2019, section 2.3).

Recipe (after Sander et al. / Dhume et al., as summarised in the paper):

1. random points in [−1, 1]³;
2. Delaunay tetrahedralisation (scipy.spatial); the unique edges of its triangles are fibers;
3. stretch the whole network by s ≥ 1 along x and rotate it by μ about z — the affine map
   lengthens and turns the fibers towards μ, so the projected anisotropy grows with s;
4. clip to the central unit cube [−½, ½]³: a fiber crossing a face is cut there and the cut
   point becomes a boundary cross-link tagged with that face;
5. clean up: pieces shorter than 1e-6 of the RVE edge (picometres) are dropped, duplicate fibers cannot occur (edges are
   made unique before clipping, and every cut makes its own node); interior cross-links with
   fewer than three fibers — dangling ends and two-fiber hinges — cannot be held in 3D by
   central forces in the unstressed state, carry no load at equilibrium, and are pruned
   (repeatedly, since pruning can create new ones); finally clusters not connected to any
   boundary node (free rigid bodies) are removed.  The pruned fibers are counted in
   ``meta["pruned_fibers"]`` (none for generic Delaunay networks: an interior point keeps all
   of its ≥ 4 spanning Delaunay edges).

Stretch search.  For a fixed seed the candidate point sets are nested: N_max points with
uniform marks u_k are drawn once and, for stretch s, those with u_k < s/s_max are kept.  The
point density in the final cube is then independent of s (so the fiber count stays near
``n_fibers``) and α(s) changes gradually, which lets a bisection on s hit the target α; the
rotation is then corrected by the measured μ error, and the point density by the fiber-count
error (kept within ±10 % of ``n_fibers`` when the search succeeds).  If a seed cannot meet the tolerance
(sampling noise at small α), the next sub-seed is tried — deterministic for a given ``seed``.
The projected α of a *random* 450-fiber network scatters by ~5 % (long cut fibers weigh a lot),
so targets below ~5 % typically need several sub-seeds (cheap: s = 1 needs no bisection).
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import Delaunay

from skvalve.materials.base import check_scalar
from skvalve.networks.network import INTERIOR, Network
from skvalve.networks.orientation import network_alpha_mu

HALF = 0.5  # the RVE is [−½, ½]³
MAX_STRETCH = 8.0
# fibers in the clipped RVE per point of the final cube (about 7 Delaunay edges per point plus
# the cut edges crossing the faces); calibrated once on random (s = 1) networks.
FIBERS_PER_POINT = 11.5
DENSITY_HEADROOM = 1.5  # extra points drawn so that the density can be corrected upwards
# bounds on a request, so that a huge one fails at once instead of after minutes of Delaunay
# work or gigabytes of points: ~8.4 n_fibers points are drawn per attempt
MAX_FIBERS = 20_000
MAX_ATTEMPTS = 10_000


def _is_integer(value) -> bool:
    return isinstance(value, (int, np.integer)) and not isinstance(value, bool)


def check_request(n_fibers: int, seed: int, max_attempts: int = 1) -> None:
    """Raise ValueError naming the parameter if a generation request is malformed or too big."""
    if not _is_integer(n_fibers) or not 20 <= n_fibers <= MAX_FIBERS:
        raise ValueError(f"generate: n_fibers must be an integer in [20, {MAX_FIBERS}], got {n_fibers!r}")
    if not _is_integer(seed) or seed < 0:
        raise ValueError(f"generate: seed must be a non-negative integer, got {seed!r}")
    if not _is_integer(max_attempts) or not 1 <= max_attempts <= MAX_ATTEMPTS:
        raise ValueError(f"generate: max_attempts must be an integer in [1, {MAX_ATTEMPTS}], got {max_attempts!r}")


def random_points(n_points: int, rng: np.random.Generator) -> np.ndarray:
    """Uniform random points in [−1, 1]³ (Fig. 3a)."""
    return rng.uniform(-1.0, 1.0, size=(n_points, 3))


def delaunay_fibers(points: np.ndarray) -> np.ndarray:
    """Unique edges of the Delaunay tetrahedra, as (m, 2) sorted node pairs (Fig. 3b)."""
    simplices = Delaunay(points).simplices
    pairs = np.concatenate([simplices[:, [i, j]] for i in range(4) for j in range(i + 1, 4)])
    return np.unique(np.sort(pairs, axis=1), axis=0)


def stretch_rotate(points: np.ndarray, stretch: float, mu_deg: float) -> np.ndarray:
    """x ↦ R_z(μ) diag(s, 1, 1) x."""
    c, s = np.cos(np.radians(mu_deg)), np.sin(np.radians(mu_deg))
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return points @ (rotation @ np.diag([stretch, 1.0, 1.0])).T


def clip_to_unit_cube(points: np.ndarray, edges: np.ndarray, min_length: float = 1e-6) -> Network:
    """Cut the fibers at the faces of [−½, ½]³ (Liang–Barsky) and tag the cut points (Fig. 3c)."""
    p0, p1 = points[edges[:, 0]], points[edges[:, 1]]
    d = p1 - p0
    t_in, t_out = np.zeros(len(edges)), np.ones(len(edges))
    face_in = np.full(len(edges), INTERIOR)
    face_out = np.full(len(edges), INTERIOR)
    with np.errstate(divide="ignore", invalid="ignore"):
        for axis in range(3):
            lo = (-HALF - p0[:, axis]) / d[:, axis]
            hi = (HALF - p0[:, axis]) / d[:, axis]
            positive = d[:, axis] > 0
            enter, leave = np.where(positive, lo, hi), np.where(positive, hi, lo)
            parallel = d[:, axis] == 0
            outside = parallel & (np.abs(p0[:, axis]) > HALF)
            enter = np.where(parallel, np.where(outside, np.inf, -np.inf), enter)
            leave = np.where(parallel, np.where(outside, -np.inf, np.inf), leave)
            face_enter = np.where(positive, 2 * axis, 2 * axis + 1)
            face_leave = np.where(positive, 2 * axis + 1, 2 * axis)
            face_in = np.where(enter > t_in, face_enter, face_in)
            t_in = np.maximum(t_in, enter)
            face_out = np.where(leave < t_out, face_leave, face_out)
            t_out = np.minimum(t_out, leave)
    keep = (t_out - t_in) * np.linalg.norm(d, axis=1) > min_length
    p0, d, t_in, t_out = p0[keep], d[keep], t_in[keep], t_out[keep]
    face_in, face_out, kept_edges = face_in[keep], face_out[keep], edges[keep]

    inside_ids = np.unique(np.concatenate([kept_edges[:, 0][face_in < 0], kept_edges[:, 1][face_out < 0]]))
    new_id = np.full(len(points), -1)
    new_id[inside_ids] = np.arange(len(inside_ids))
    nodes = [points[inside_ids]]
    faces = [np.full(len(inside_ids), INTERIOR)]
    start = np.where(face_in < 0, new_id[kept_edges[:, 0]], -1)
    end = np.where(face_out < 0, new_id[kept_edges[:, 1]], -1)
    count = len(inside_ids)
    for t, face, ends in ((t_in, face_in, start), (t_out, face_out, end)):
        cut = face >= 0
        cut_points = p0[cut] + t[cut, None] * d[cut]
        axis = face[cut] // 2
        cut_points[np.arange(cut.sum()), axis] = np.where(face[cut] % 2 == 1, HALF, -HALF)
        ends[cut] = count + np.arange(cut.sum())
        count += cut.sum()
        nodes.append(cut_points)
        faces.append(face[cut])
    face_all = np.concatenate(faces)
    return Network(np.concatenate(nodes), np.column_stack([start, end]), face_all >= 0, face_all)


def prune(network: Network) -> tuple[Network, int]:
    """Remove under-connected interior nodes and floating clusters (see module docstring)."""
    nodes, fibers, face = network.nodes, network.fibers, network.face
    n_start = len(fibers)
    while True:
        degree = np.bincount(fibers.ravel(), minlength=len(nodes))
        weak = (face < 0) & (degree < 3) & (degree > 0)
        if not weak.any():
            break
        fibers = fibers[~(weak[fibers[:, 0]] | weak[fibers[:, 1]])]
    n = len(nodes)
    graph = coo_matrix((np.ones(len(fibers)), (fibers[:, 0], fibers[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    anchored = np.zeros(label.max() + 1, dtype=bool)
    anchored[label[face >= 0]] = True
    fibers = fibers[anchored[label[fibers[:, 0]]]]
    used = np.zeros(n, dtype=bool)
    used[fibers.ravel()] = True
    renumber = np.cumsum(used) - 1
    pruned = Network(nodes[used], renumber[fibers], face[used] >= 0, face[used], dict(network.meta))
    return pruned, n_start - len(fibers)


def _candidate(points, marks, stretch, mu_deg, density_factor=1.0) -> Network:
    chosen = points[marks < density_factor * stretch / (DENSITY_HEADROOM * MAX_STRETCH)]
    edges = delaunay_fibers(chosen)
    network, n_pruned = prune(clip_to_unit_cube(stretch_rotate(chosen, stretch, mu_deg), edges))
    network.meta["pruned_fibers"] = n_pruned
    return network


def generate(
    alpha: float,
    mu: float,
    n_fibers: int,
    seed: int = 0,
    alpha_tol: float = 3.0,
    mu_tol: float = 5.0,
    max_attempts: int = 200,
) -> Network:
    """Delaunay network whose projected (xy-plane) α and μ match the targets.

    alpha : target anisotropy index in percent (Eq. 2), 0 ≤ alpha < 95.
    mu : target mean fiber direction in degrees (Eq. 3), measured from x towards y.
    n_fibers : approximate number of fibers in the RVE, 20 ≤ n_fibers ≤ ``MAX_FIBERS``
    (thomas2019 uses ~450: ``skvalve.papers.thomas2019.data.NETWORK.fibers_per_rve``).
    seed : non-negative integer; the result is a deterministic function of all arguments.
    max_attempts : sub-seeds tried, 1 ≤ max_attempts ≤ ``MAX_ATTEMPTS``.
    ``meta`` holds the targets and the achieved α, μ (float), stretch, rotation (float), seed,
    attempt and pruned_fibers (int).
    The result satisfies ``abs(α − alpha) ≤ alpha_tol`` and, for alpha ≥ 10, ``abs(μ − mu) ≤ mu_tol``
    (axially, modulo 180°); RuntimeError if ``max_attempts`` sub-seeds all fail.
    """
    for name, value in (("alpha", alpha), ("mu", mu), ("alpha_tol", alpha_tol), ("mu_tol", mu_tol)):
        try:
            check_scalar(name, value)
        except TypeError as err:
            raise TypeError(f"generate: {err}") from None
    if not (0.0 <= alpha < 95.0):
        raise ValueError(f"generate: alpha must be in [0, 95) percent, got {alpha}")
    if not np.isfinite(mu):
        raise ValueError(f"generate: mu must be finite, got {mu}")
    check_request(n_fibers, seed, max_attempts)
    for name, value in (("alpha_tol", alpha_tol), ("mu_tol", mu_tol)):
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"generate: {name} must be positive and finite, got {value!r}")
    density = n_fibers / FIBERS_PER_POINT  # interior points per unit volume in the final cube
    n_max = int(round(8.0 * density * MAX_STRETCH * DENSITY_HEADROOM))
    check_mu = alpha >= 10.0
    for attempt in range(max_attempts):
        rng = np.random.default_rng([seed, attempt])
        points, marks = random_points(n_max, rng), rng.uniform(size=n_max)
        lo, hi, stretch = 1.0, MAX_STRETCH, 1.0
        rotation, density_factor = mu, 1.0
        for _ in range(40):
            network = _candidate(points, marks, stretch, rotation, density_factor)
            a, m = network_alpha_mu(network)
            mu_error = (m - mu + 90.0) % 180.0 - 90.0
            count_error = network.n_fibers / n_fibers - 1.0
            if abs(count_error) > 0.1:  # keep "about n_fibers" fibers (affects α only weakly)
                density_factor = min(density_factor / (1.0 + count_error), DENSITY_HEADROOM)
                continue
            if abs(a - alpha) <= 0.5 * alpha_tol and (not check_mu or abs(mu_error) <= mu_tol / 2):
                break
            if check_mu and abs(mu_error) > mu_tol / 2:
                rotation -= mu_error
                continue
            lo, hi = (stretch, hi) if a < alpha else (lo, stretch)
            if a > alpha and stretch == 1.0:
                break  # already too aligned at s = 1: try another sub-seed
            stretch = 0.5 * (lo + hi)
        mu_error = (m - mu + 90.0) % 180.0 - 90.0
        count_ok = abs(network.n_fibers / n_fibers - 1.0) <= 0.1  # the loop may end on a count correction
        if count_ok and abs(a - alpha) <= alpha_tol and (not check_mu or abs(mu_error) <= mu_tol):
            network.meta.update(
                alpha_target=float(alpha),
                mu_target=float(mu),
                alpha=float(a),
                mu=float(m),
                stretch=float(stretch),
                rotation=float(rotation),
                seed=int(seed),
                attempt=int(attempt),
                pruned_fibers=int(network.meta["pruned_fibers"]),
            )
            return network
    raise RuntimeError(
        f"generate: no network with alpha={alpha}±{alpha_tol}, mu={mu}±{mu_tol} "
        f"in {max_attempts} attempts (seed {seed}); widen the tolerances or raise n_fibers"
    )
