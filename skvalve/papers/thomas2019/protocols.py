r"""The five biaxial protocols (§2.5): grip displacements found so that the edge tensions hit the targets.

The paper drove each edge with the actuator displacement recorded at each tension (not published). Here
the intent is reproduced: the grips of each edge (:mod:`.attachments`: the whole edge face, or the tines)
move along the edge normal, symmetrically (:math:`u_x = \mp\delta_x/2` on left/right,
:math:`u_y = \mp\delta_y/2` on bottom/top; free tangentially unless the tines are pinned, free through
the thickness, one node pinned in z), and the final sizes :math:`(\delta_x, \delta_y)` are found so that
the membrane tensions — the summed grip reactions per unit *reference* edge length (N/m),
:math:`T_1 = R_x^\text{right}/H`, :math:`T_2 = R_y^\text{top}/W` — reach the protocol's targets
(circumferential : radial = a : b, the larger one 40 N/m):

1. initial guess from the homogeneous RVE model (:class:`~skvalve.multiscale.HomogeneousBiaxial`, all
   networks of the sample under one uniform biaxial F, plane stress);
2. an FE² ramp to that guess in ``steps`` load steps (the tension–stretch path of Fig. 5b);
3. Broyden corrections :math:`\delta \leftarrow \delta + J^{-1}(T^* - T)`, each one more load step from
   the converged state, started from the homogeneous model's condensed stiffness
   :math:`J = \partial T/\partial\delta`, until :math:`\max|T - T^*| \le` ``tolerance`` × 40 N/m.

With uniform edges the corners are the stiffest places (both edges pull there); with tines the corners
are free and unloaded, and the stress concentrates at the tines.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ...fem import Solid, solve
from ...multiscale.homogeneous import HomogeneousBiaxial
from ...multiscale.material import RVEMaterial
from . import data
from .attachments import UNIFORM_EDGES, Attachment, Grips, grips_of
from .sample import Sample

__all__ = ["EdgeSchedule", "ProtocolRun", "biaxial_problem", "edge_tensions", "run_protocol", "targets"]


def targets(ratio: tuple[float, float], max_tension: float = data.MAX_TENSION_N_PER_M) -> np.ndarray:
    """Target (T1, T2) in N/m of a circumferential : radial protocol, the larger one ``max_tension``."""
    a, b = (float(r) for r in ratio)
    if not (a > 0 and b > 0):
        raise ValueError(f"protocol ratio must be two positive numbers, got {ratio!r}")
    return max_tension * np.array([a, b]) / max(a, b)


class EdgeSchedule:
    """Piecewise-linear edge displacements δ(t) = (δx, δy) over the load factor (breakpoints added as it goes)."""

    def __init__(self) -> None:
        self.t = [0.0]
        self.delta = [np.zeros(2)]

    def add(self, t: float, delta) -> None:
        if t <= self.t[-1]:
            raise ValueError(f"EdgeSchedule: breakpoints must increase, got {t} after {self.t[-1]}")
        self.t.append(float(t))
        self.delta.append(np.asarray(delta, dtype=float).copy())

    def __call__(self, t: float) -> np.ndarray:
        d = np.array(self.delta)
        return np.array([np.interp(t, self.t, d[:, 0]), np.interp(t, self.t, d[:, 1])])

    def edge_value(self, axis: int, sign: float) -> Callable:
        """Dirichlet value ``(X, t) -> (3, 1)``: sign δ_axis(t)/2 in component ``axis``."""

        def value(X, t, axis=axis, sign=sign):
            out = np.zeros((3, 1))
            out[axis, 0] = 0.5 * sign * self(t)[axis]
            return out

        return value


def biaxial_problem(sample: Sample, material: RVEMaterial,
                    attachment: Attachment = UNIFORM_EDGES) -> tuple[Solid, EdgeSchedule, Grips]:
    """The sample held by ``attachment``, its grips moved by δ(t) along the edge normals, one node pinned in z."""
    solid = Solid(sample.mesh, material)
    schedule = EdgeSchedule()
    grips = grips_of(solid, attachment, sample.size)
    for name, axis, sign in (("left", 0, -1.0), ("right", 0, 1.0), ("bottom", 1, -1.0), ("top", 1, 1.0)):
        solid.add_dirichlet(nodes=grips.nodes[name], value=schedule.edge_value(axis, sign), components=[axis])
        if grips.pinned:
            solid.add_dirichlet(nodes=grips.nodes[name], value=0.0, components=[1 - axis])
    width, height, _ = sample.size
    X = solid.space.dof_coordinates
    centre = int(np.argmin((X[0] - width / 2) ** 2 + (X[1] - height / 2) ** 2 + X[2] ** 2))
    solid.add_dirichlet(nodes=[centre], value=0.0, components=[2])
    return solid, schedule, grips


def edge_tensions(solid: Solid, residual: np.ndarray, sample: Sample, grips: Grips) -> np.ndarray:
    """(T1, T2) in N/m: right grips' x reaction / H and top grips' y reaction / W (reference lengths)."""
    width, height, _ = sample.size
    return grips.tensions(solid, residual, width, height)


@dataclass
class ProtocolRun:
    """One protocol's solve: targets, final edge displacements, the path and the final state."""

    ratio: tuple[float, float]
    targets: np.ndarray
    delta: np.ndarray  # final (δx, δy), m
    path_stretch: np.ndarray  # (n, 2) edge stretches 1 + δ/L along the ramp and corrections
    path_tension: np.ndarray  # (n, 2) edge tensions (N/m) at the same states
    u: np.ndarray
    load_factor: float  # of the final state (1 + corrections: one load-factor unit per stage)
    corrections: int
    iterations: int
    timings: dict  # solver wall time: assembly (RVE solves included), sparse solves, set-up
    solid: Solid = field(repr=False)
    material: RVEMaterial = field(repr=False)
    grips: Grips = field(repr=False)

    @property
    def tension_error(self) -> float:
        return float(np.abs(self.path_tension[-1] - self.targets).max())


def _homogeneous_guess(sample: Sample, material: RVEMaterial, goal: np.ndarray, max_networks: int = 12):
    """Edge displacements and dT/dδ from the homogeneous model on (up to) ``max_networks`` distinct networks."""
    distinct = list({id(net): net for net in sample.networks}.values())
    pick = np.linspace(0, len(distinct) - 1, min(max_networks, len(distinct))).round().astype(int)
    rves = RVEMaterial([distinct[i] for i in pick], material.matrix, material.fiber, n_points=1,
                       psi=material.psi, fiber_diameter=material.fiber_diameter)
    width, height, thickness = sample.size
    model = HomogeneousBiaxial(rves, thickness)
    state = model.solve(goal, increments=6)[-1]
    _, A = model.evaluate(state.stretches)
    K = np.array([[A[i, i, j, j] for j in range(3)] for i in range(3)])
    # condense λ3 (P33 = 0): dT_i/dλ_j for i, j in 1..2
    condensed = thickness * (K[:2, :2] - np.outer(K[:2, 2], K[2, :2]) / K[2, 2])
    lengths = np.array([width, height])
    return (state.stretches[:2] - 1.0) * lengths, condensed / lengths[None, :]


def run_protocol(sample: Sample, material: RVEMaterial, ratio: tuple[float, float],
                 max_tension: float = data.MAX_TENSION_N_PER_M, steps: int = 6, tolerance: float = 0.01,
                 max_corrections: int = 6, callbacks: Sequence = (), progress: bool = False,
                 rtol: float = 1e-8, attachment: Attachment = UNIFORM_EDGES) -> ProtocolRun:
    """Solve one protocol on ``sample`` held by ``attachment`` with a fresh (or reference-state) ``material``."""
    goal = targets(ratio, max_tension)
    solid, schedule, grips = biaxial_problem(sample, material, attachment)
    delta, jacobian = _homogeneous_guess(sample, material, goal)
    width, height, _ = sample.size
    lengths = np.array([width, height])
    stretches, tensions = [np.ones(2)], [np.zeros(2)]

    def record(event):
        if event.step > 0:
            stretches.append(1.0 + schedule(event.load_factor) / lengths)
            tensions.append(edge_tensions(solid, event.result.residuals[-1], sample, grips))

    schedule.add(1.0, delta)
    result = solve(solid, steps=steps, progress=progress, rtol=rtol, callbacks=[record, *callbacks])
    iterations = result.iterations
    timings = dict(result.timings)
    u, t = result.u(), 1.0
    corrections = 0
    while np.abs(tensions[-1] - goal).max() > tolerance * max_tension:
        if corrections == max_corrections:
            raise RuntimeError(f"protocol {ratio}: edge tensions {tensions[-1]} N/m not within "
                               f"{tolerance * max_tension} N/m of {goal} after {max_corrections} corrections")
        step = np.linalg.solve(jacobian, goal - tensions[-1])
        before = tensions[-1].copy()
        delta = delta + step
        schedule.add(t + 1.0, delta)
        result = solve(solid, steps=[t + 1.0], u0=u, t0=t, progress=progress, rtol=rtol,
                       callbacks=[record, *callbacks])
        iterations += result.iterations
        timings = {key: timings.get(key, 0.0) + value for key, value in result.timings.items()}
        u, t = result.u(), t + 1.0
        corrections += 1
        change = tensions[-1] - before  # Broyden's rank-one update of dT/dδ
        jacobian = jacobian + np.outer(change - jacobian @ step, step) / (step @ step)
    return ProtocolRun(tuple(ratio), goal, delta, np.array(stretches), np.array(tensions), u, t, corrections,
                       iterations, timings, solid, material, grips)
