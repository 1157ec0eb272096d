r"""A problem: one displacement (and pressure) field, Dirichlet constraints and a sum of terms.

The Newton driver (:mod:`skvalve.fem.solvers.newton`) sees only this class's small protocol:
:meth:`Problem.assemble` (residual and a :class:`Tangent`), :meth:`Problem.constrained`,
:meth:`Problem.commit` and :meth:`Problem.rewind`. Reactions are the residual at the constrained
dofs, :math:`r = f_\text{int} - f_\text{ext}`: the force the supports exert on the body.

Assembly: the blocks of every term are added into one CSR matrix of the free dofs whose pattern
and entry positions are built once per set of constraints (terms' connectivities stacked, padded
with -1).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .errors import SingularSystemError
from .kernels import csr_positions, csr_structure, scatter_add
from .loads import Dirichlet
from .space import Space
from .sparse_layout import GrowingPattern
from .terms import Contribution, Term

__all__ = ["Problem", "Tangent", "Pattern"]


@dataclass
class Pattern:
    """Free/fixed dof split and the CSR layout of the free-dof tangent."""

    fixed: np.ndarray
    free: np.ndarray
    reduced: np.ndarray  # global dof -> free index, -1 if fixed
    indptr: np.ndarray
    indices: np.ndarray
    positions: list[list[np.ndarray]]  # per term, per block: (n, m, m) CSR positions
    layout: GrowingPattern  # the tangent's pattern: this one, the diagonal and the terms' extra entries seen so far


@dataclass
class Tangent:
    """The terms' contributions at one state: enough to form K_ff or apply K to a vector."""

    contributions: list[Contribution]


class Problem:
    """A field ``space`` with Dirichlet constraints and a list of terms.

    Parameters
    ----------
    space : the :class:`~skvalve.fem.space.Space` (displacement, and pressure for mixed u/p).
    terms : initial terms (more with :meth:`add_term`).

    Examples
    --------
    >>> import skfem
    >>> from skvalve.fem import Problem, Space, HyperelasticTerm, MaterialRegions, solve
    >>> from skvalve.materials import NeoHookean
    >>> mesh = skfem.MeshHex().refined(1)
    >>> space = Space(mesh)
    >>> problem = Problem(space, [HyperelasticTerm(space, MaterialRegions(mesh, NeoHookean(1.0, 10.0)))])
    >>> _ = problem.add_dirichlet(lambda X: X[0] == 0.0, 0.0)
    >>> _ = problem.add_dirichlet(lambda X: X[0] == 1.0, 0.1, components=[0])
    >>> round(float(solve(problem, steps=2, progress=False).reaction(lambda X: X[0] == 1.0)[0]), 4)
    0.3466
    """

    def __init__(self, space: Space, terms=()) -> None:
        self.space = space
        self.mesh = space.mesh
        self.dim = space.dim
        self.dirichlet: list[Dirichlet] = []
        self.terms: list[Term] = []
        self._pattern: Pattern | None = None
        for term in terms:
            self.add_term(term)

    # ------------------------------------------------------------ definitions
    def add_term(self, term: Term) -> Term:
        """Add a term (anything following :class:`~skvalve.fem.terms.Term`); returns it."""
        if not hasattr(term, "assemble") or not hasattr(term, "connectivity"):
            raise TypeError(f"a term needs assemble() and connectivity(); got {type(term).__name__}")
        self.terms.append(term)
        self._pattern = None
        return term

    def add_dirichlet(self, where=None, value=0.0, components=None, *, nodes=None, ramp: bool = True):
        """Prescribe displacement components on a boundary.

        ``where``: boundary name, facet indices or ``X -> bool`` on dof locations (shape (dim, n));
        or ``nodes=`` scalar dof indices. ``value``: number or per-component array (times the
        load factor ``t`` when ``ramp``) or a callable ``value(X, t) -> (dim, n)`` array,
        e.g. a rigid rotation ``(R(theta t) - I)(X - X0)``. ``components``: indices (default all).
        """
        if (where is None) == (nodes is None):
            raise ValueError("give exactly one of where= (facets/boundary/predicate) or nodes=")
        scalar = self.space.scalar_dofs_on(where) if nodes is None else np.unique(np.asarray(nodes, dtype=int))
        if scalar.size == 0:
            raise ValueError(f"add_dirichlet: the selection {where!r} contains no dofs")
        if scalar.min() < 0 or scalar.max() >= self.space.n_scalar:
            raise ValueError(f"nodes must lie in 0..{self.space.n_scalar - 1}")
        self.dirichlet.append(Dirichlet(self.space, scalar, components, value, ramp))
        self._pattern = None
        return self

    # ---------------------------------------------------------- constraints
    def constrained(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Constrained dofs (sorted, unique) and their values at load factor ``t`` (later wins)."""
        if not self.dirichlet:
            return np.zeros(0, dtype=np.int64), np.zeros(0)
        dofs = np.concatenate([bc.dofs.ravel() for bc in self.dirichlet]).astype(np.int64)
        vals = np.concatenate([np.asarray(bc.values(t), dtype=float).ravel() for bc in self.dirichlet])
        # the last definition of a dof wins: unique over the reversed order
        unique, first = np.unique(dofs[::-1], return_index=True)
        return unique, vals[::-1][first]

    @property
    def pattern(self) -> Pattern:
        """Free-dof CSR pattern and the CSR position of every block entry (built once)."""
        if self._pattern is None:
            self._pattern = self._build_pattern()
        return self._pattern

    def _build_pattern(self) -> Pattern:
        n = self.space.n_dofs
        fixed, _ = self.constrained(0.0)
        reduced = np.full(n, -1, dtype=np.int64)
        free = np.setdiff1d(np.arange(n), fixed)
        reduced[free] = np.arange(free.size)
        connectivities = [[np.asarray(c, dtype=np.int64) for c in term.connectivity()] for term in self.terms]
        flat = [c for group in connectivities for c in group if c.size]
        width = max((c.shape[1] for c in flat), default=1)
        stacked = np.full((sum(c.shape[0] for c in flat), width), -1, dtype=np.int64)
        row = 0
        for c in flat:
            stacked[row: row + c.shape[0], : c.shape[1]] = reduced[c]
            row += c.shape[0]
        indptr, indices = csr_structure(stacked, free.size)
        # each block group's positions at its own width: padding every block to the widest (a chord's insertion
        # patches) took 3.6 GB on the 1.1 healthy valve (129 k dofs)
        per_term = []
        for group in connectivities:
            blocks = []
            for c in group:
                if c.size == 0:
                    blocks.append(np.zeros((0, 0, 0), dtype=np.int64))
                    continue
                blocks.append(csr_positions(reduced[c], indptr, indices))
            per_term.append(blocks)
        return Pattern(fixed, free, reduced, indptr.astype(np.int32), indices.astype(np.int32), per_term,
                       GrowingPattern(indptr, indices, free.size))

    def check_supports(self) -> None:
        """Raise :class:`SingularSystemError` if the constraints leave a rigid-body motion free.

        The rigid motions of the displacement dofs (translations, and rotations about the
        centroid) restricted to the constrained dofs must have full rank. Terms that support the
        body elastically (springs, contact with an obstacle) set ``supports = True`` to skip this.
        """
        if any(getattr(term, "supports", False) for term in self.terms):
            return
        fixed = self.pattern.fixed
        space = self.space
        X = space.dof_coordinates
        X = X - X.mean(axis=1, keepdims=True)
        d = space.dim
        modes, names = [], []
        for i in range(d):
            mode = np.zeros((d, X.shape[1]))
            mode[i] = 1.0
            modes.append(mode)
            names.append(f"translation along {'xyz'[i]}")
        axes = [(1, 2, "x"), (2, 0, "y"), (0, 1, "z")] if d == 3 else [(0, 1, "z")]
        for a, b, axis in axes:
            mode = np.zeros((d, X.shape[1]))
            mode[a], mode[b] = -X[b], X[a]
            modes.append(mode)
            names.append(f"rotation about {axis}")
        R = np.zeros((space.n_dofs, len(modes)))
        for k, mode in enumerate(modes):
            R[: space.n_u, k] = mode.T.ravel()
        restricted = R[fixed]
        if restricted.size and np.linalg.matrix_rank(restricted, tol=1e-10 * np.abs(restricted).max()) == len(modes):
            return
        # name the free motions: the null space of the restricted modes
        if restricted.size:
            _, sv, vt = np.linalg.svd(restricted)
            rank = int((sv > 1e-10 * sv.max()).sum()) if sv.size else 0
            null = vt[rank:]
        else:
            null = np.eye(len(modes))
        free = [names[int(np.argmax(np.abs(v)))] for v in null]
        raise SingularSystemError(
            f"the Dirichlet conditions leave {len(null)} rigid-body motion(s) free ({', '.join(free)}): the tangent "
            "is singular. Add supports that remove them (or mark a supporting term with supports = True)."
        )

    # ---------------------------------------------------------------- assembly
    @property
    def symmetric(self) -> bool:
        """True when every term's tangent is symmetric."""
        return all(getattr(term, "symmetric", True) for term in self.terms)

    def assemble(self, u: np.ndarray, t: float, tangent: bool = True, step: int | None = None,
                 reuse: Tangent | None = None, fresh=()) -> tuple[np.ndarray, Tangent]:
        """Residual (all dofs) and the terms' contributions at ``u`` and load factor ``t``.

        ``reuse``: contributions of an earlier call at the same ``u``, or at a ``u`` that differs only in dofs that
        no term but those in ``fresh`` touches (e.g. after a block relaxation of them); only load-dependent terms and
        the terms in ``fresh`` are re-evaluated. ``self.internal_forces`` / ``self.external_forces`` hold the two
        parts.
        """
        n = self.space.n_dofs
        internal, external = np.zeros(n), np.zeros(n)
        contributions = []
        for k, term in enumerate(self.terms):
            if (reuse is not None and not getattr(term, "load_dependent", False)
                    and not any(term is other for other in fresh)):
                contribution = reuse.contributions[k]
            else:
                contribution = term.assemble(u, t, tangent, step)
            if contribution.internal is not None:
                internal += contribution.internal
            if contribution.external is not None:
                external += contribution.external
            contributions.append(contribution)
        self.internal_forces, self.external_forces = internal, external
        return internal - external, Tangent(contributions)

    def tangent_matrix(self, tangent: Tangent, blocks=None, matrix=None, projected: bool = False,
                       diagonal: np.ndarray | None = None) -> sp.csr_matrix:
        """Free-dof tangent K_ff (plus ``diagonal``) from the contributions of :meth:`assemble`, on the problem's
        growing pattern (:class:`~skvalve.fem.sparse_layout.GrowingPattern`: the same pattern while the terms' extra
        entries stay within it, so a direct solver keeps its analysis).

        ``blocks(term, matrices) -> matrices`` and ``matrix(term, sparse) -> sparse``, when given, replace each term's
        element blocks and extra matrix before they are added (e.g. their symmetric parts, or blocks projected onto
        positive semidefinite ones: :func:`skvalve.fem.solvers.trust_region.step_matrix`). ``projected``: a term's
        blocks and extra matrix are replaced by its own PSD projections where it gives them (``Blocks.projected``,
        ``Contribution.projected_matrix``).
        """
        pat = self.pattern
        data = np.zeros(pat.indices.size)
        extra = []
        for term, positions, contribution in zip(self.terms, pat.positions, tangent.contributions, strict=True):
            for pos, block in zip(positions, contribution.blocks, strict=True):
                if block.matrices is None:
                    raise ValueError("tangent_matrix needs contributions assembled with tangent=True")
                if pos.size:
                    if projected and block.projected is not None:
                        matrices = block.projected
                    else:
                        matrices = block.matrices if blocks is None else blocks(term, block.matrices)
                    scatter_add(np.ascontiguousarray(matrices), pos, data)
            if contribution.matrix is not None:
                own = contribution.matrix
                if projected and contribution.projected_matrix is not None:
                    own = contribution.projected_matrix
                whole = own if matrix is None else matrix(term, own)
                extra.append(sp.csr_matrix(whole)[pat.free][:, pat.free].tocoo())
        if not extra:
            return pat.layout.matrix(data, diagonal=diagonal)
        rows, cols, values = (np.concatenate([getattr(part, key) for part in extra]) for key in ("row", "col", "data"))
        return pat.layout.matrix(data, rows, cols, values, diagonal)

    def add_diagonal(self, matrix: sp.spmatrix, diagonal: np.ndarray) -> sp.csr_matrix:
        """``matrix + diag(diagonal)`` (free dofs) on the tangent's pattern where ``matrix`` is on it."""
        return self.pattern.layout.add_diagonal(matrix, diagonal)

    def symmetric_part(self, matrix: sp.spmatrix, diagonal: np.ndarray | None = None) -> sp.csr_matrix:
        """``(K + K^T) / 2`` (plus ``diagonal``) on the tangent's pattern where ``K`` is on it."""
        return self.pattern.layout.symmetric_part(matrix, diagonal)

    def apply(self, tangent: Tangent, vector: np.ndarray) -> np.ndarray:
        """Full tangent (all dofs) times ``vector``."""
        out = np.zeros(self.space.n_dofs)
        for contribution in tangent.contributions:
            for block in contribution.blocks:
                if block.matrices is None or block.dofs.size == 0:
                    continue
                local = np.einsum("emn,en->em", block.matrices, vector[block.dofs])
                out += np.bincount(block.dofs.ravel(), local.ravel(), minlength=out.size)
            if contribution.matrix is not None:
                out += contribution.matrix @ vector
        return out

    # ------------------------------------------------------- steps and energy
    def step_fraction(self, u0: np.ndarray, t0: float, u1: np.ndarray, t1: float) -> float:
        """The smallest of the terms' :meth:`~skvalve.fem.terms.Term.step_fraction` for the straight move from
        ``(u0, t0)`` to ``(u1, t1)``: the share of it that every term allows (1 when none limits steps)."""
        return min((share for _, share in self._step_shares(u0, t0, u1, t1)), default=1.0)

    def step_limits(self, u0: np.ndarray, t0: float, u1: np.ndarray, t1: float) -> str:
        """The terms that allow less than the whole straight move from ``(u0, t0)`` to ``(u1, t1)``, with their shares
        (``"corner barrier 0.464, ipc contact 0.26"``; empty when none limits it): what a refused step names."""
        return ", ".join(f"{name} {share:.3g}" for name, share in self._step_shares(u0, t0, u1, t1) if share < 1.0)

    def _step_shares(self, u0: np.ndarray, t0: float, u1: np.ndarray, t1: float) -> list[tuple[str, float]]:
        """Each term's name and :meth:`~skvalve.fem.terms.Term.step_fraction` of the move (checked to lie in (0, 1])."""
        shares = []
        for term in self.terms:
            limit = getattr(term, "step_fraction", None)
            if limit is not None:
                value = float(limit(u0, t0, u1, t1))
                if not 0.0 < value <= 1.0:
                    raise ValueError(f"term {term.name!r}: step_fraction must lie in (0, 1]; got {value!r}")
                shares.append((getattr(term, "name", type(term).__name__), value))
        return shares

    def pushed(self, u: np.ndarray, t0: float, t1: float) -> tuple[np.ndarray, np.ndarray] | None:
        """The free dofs the terms' prescribed motion pushes from ``t0`` to ``t1`` at ``u``, with their nonzero
        increments (:meth:`~skvalve.fem.terms.Term.pushed`; a dof two terms push takes the first one's); ``None`` when
        none moves."""
        return self._free_increments("pushed", (u, t0, t1))

    def crossed(self, u0: np.ndarray, t0: float, u1: np.ndarray, t1: float) -> tuple[np.ndarray, np.ndarray] | None:
        """The free dofs the straight move from ``(u0, t0)`` to ``(u1, t1)`` crosses, with increments from ``u0`` that
        let them ride with what crosses them (:meth:`~skvalve.fem.terms.Term.crossed`); ``None`` when none."""
        return self._free_increments("crossed", (u0, t0, u1, t1))

    def _free_increments(self, method: str, arguments: tuple) -> tuple[np.ndarray, np.ndarray] | None:
        dofs, increments = [], []
        for term in self.terms:
            ask = getattr(term, method, None)
            found = None if ask is None else ask(*arguments)
            if found is not None and len(found[0]):
                dofs.append(np.asarray(found[0], dtype=np.int64))
                increments.append(np.asarray(found[1], dtype=float))
        if not dofs:
            return None
        dofs, increments = np.concatenate(dofs), np.concatenate(increments)
        dofs, first = np.unique(dofs, return_index=True)
        increments = increments[first]
        keep = np.isin(dofs, self.pattern.free) & (increments != 0.0)
        return (dofs[keep], increments[keep]) if np.any(keep) else None

    def check_state(self, u: np.ndarray, t: float) -> None:
        """Let every term vet an accepted state (:meth:`~skvalve.fem.terms.Term.check_state`)."""
        for term in self.terms:
            check = getattr(term, "check_state", None)
            if check is not None:
                check(u, t)

    def energy(self, u: np.ndarray, t: float) -> float | None:
        r"""The total potential :math:`\Pi(u, t) = \sum_k \Pi_k`, or ``None`` when a term has none (a follower
        pressure on an open surface, a term without :meth:`~skvalve.fem.terms.Term.energy`)."""
        total = 0.0
        for term in self.terms:
            getter = getattr(term, "energy", None)
            value = None if getter is None else getter(u, t)
            if value is None:
                return None
            total += float(value)
        return total

    def work_terms(self, u: np.ndarray, t: float) -> list[int]:
        """Indices of the terms with no potential at ``(u, t)`` (``energy`` missing or ``None``: a follower pressure
        on an open surface); a solver integrates their work along a step and takes the others' energy change."""
        return [k for k, term in enumerate(self.terms)
                if getattr(term, "energy", None) is None or term.energy(u, t) is None]

    def potential_energy(self, u: np.ndarray, t: float, skip: Sequence[int] = ()) -> float:
        r""":math:`\sum_k \Pi_k(u, t)` over the terms not in ``skip`` (those must all have a potential)."""
        return float(sum(float(term.energy(u, t)) for k, term in enumerate(self.terms) if k not in skip))

    # ------------------------------------------------------------------ state
    def commit(self) -> None:
        """Accept the converged state of every stateful term."""
        for term in self.terms:
            term.commit()

    def rewind(self) -> None:
        """Return every stateful term to its last committed state."""
        for term in self.terms:
            term.rewind()

    def term_labels(self) -> list[str]:
        """Each term's label in :meth:`state`: its ``name`` (else its class name), with ``#2``, ``#3``, ... on the
        second, third, ... term of the same name."""
        labels, seen = [], {}
        for term in self.terms:
            name = str(getattr(term, "name", type(term).__name__))
            seen[name] = seen.get(name, 0) + 1
            labels.append(name if seen[name] == 1 else f"{name}#{seen[name]}")
        return labels

    def state(self) -> dict[str, np.ndarray]:
        """Committed state of every term that has one (``term.state()``), keyed ``"<label>/<name>"`` by the term's
        label (:meth:`term_labels`): adding a term of another name does not move another term's keys."""
        out = {}
        for label, term in zip(self.term_labels(), self.terms, strict=True):
            getter = getattr(term, "state", None)
            if getter is not None:
                for name, array in getter().items():
                    out[f"{label}/{name}"] = np.asarray(array)
        return out

    def restore(self, state: dict[str, np.ndarray]) -> None:
        """Give each term back what :meth:`state` took from it (``term.restore(arrays)``).

        Keys ``"<k>/<name>"`` with a number ``k`` (states written before the terms were labelled by name) go to the
        ``k``-th term. A key that names no term of the problem, or state for a term without ``restore``, is an error.
        """
        labels = self.term_labels()
        grouped: dict[int, dict[str, np.ndarray]] = {}
        for key, value in state.items():
            label, _, name = key.partition("/")
            if label.isdigit() and int(label) < len(self.terms):
                k = int(label)
            elif label in labels:
                k = labels.index(label)
            else:
                raise ValueError(f"saved term state {key!r}: the problem has no term {label!r} (its terms: "
                                 f"{', '.join(labels)})")
            grouped.setdefault(k, {})[name] = value
        for k, term in enumerate(self.terms):
            restore = getattr(term, "restore", None)
            mine = grouped.get(k, {})
            if restore is not None:
                restore(mine)
            elif mine:
                raise ValueError(f"term {labels[k]!r} ({type(term).__name__}) has saved state but no restore()")

    @property
    def materials(self):
        """The material regions of the (single) solid term, for stress output."""
        solids = [term for term in self.terms if hasattr(term, "materials")]
        if len(solids) != 1:
            raise AttributeError(f"the problem has {len(solids)} solid terms; stress output needs exactly one")
        return solids[0].materials
