"""``skvalve valve close`` end to end on the two-leaflet stand-in valve with a clip arm (:mod:`tests._mini_valve`,
``arm=``; ~20 s): the valve closes in the deck's first step (to 1.5), then a rigid R3D4 plate hinged outside leaflet
A turns by 0.4 rad in a second step (to 2.0) and sweeps into that leaflet, as the 1.0 clip input's arms do.

The arm joins the contact when it starts to turn and grips what it touches from then on (the closure's rules for the
clip input). Its sweep is longer than any gap the barrier leaves, so the steps start from a state where it pushes
(:mod:`skvalve.fem.contact.push`). Checked against what the model must satisfy whatever the code does: the static
residual of the end state, no intersection, the arm's final plane (closed form) with leaflet A on its free side
where the arm-less closure leaves some of it behind that plane, and the global balance: the reactions at annulus and
papillary tips, the arm's forces on the leaflets and the pressure sum to zero.
"""

import numpy as np
import pytest
from _mini_valve import write_mini_valve

from skvalve.cli import main
from skvalve.fem.contact.tie import ObstacleTie
from skvalve.valve.run import relative_residual
from skvalve.valve.setup import pressure_forces, valve_setup
from skvalve.valve.state import read_state

TURN = 0.4  # rad
GAP, THICKNESS = 4.0, 0.4


@pytest.fixture(scope="module")
def clipped(tmp_path_factory):
    """The arm-less and the clip deck, each closed by ``skvalve valve close``: their setups and kept states."""
    folder = tmp_path_factory.mktemp("mini_clip")
    runs = {}
    for name, arm in (("plain", None), ("clip", TURN)):
        deck = write_mini_valve(folder / f"{name}.inp", gap=GAP, thickness=THICKNESS, arm=arm)
        assert main(["valve", "close", str(deck), "--out", str(folder / name), "--quiet"]) == 0
        setup, kept = valve_setup(deck), read_state(folder / name / "state.npz")
        setup.problem.restore(kept.terms)  # the terms' committed state: the arm's grips
        runs[name] = (setup, kept)
    return runs


def test_the_clip_closure_converges_without_intersection(clipped):
    setup, kept = clipped["clip"]
    assert kept.phase == "done" and kept.t == 2.0
    residual, _ = setup.problem.assemble(kept.u, kept.t, tangent=False)
    setup.problem.commit()
    assert relative_residual(setup, residual) <= 1e-6  # recomputed from the kept state
    assert not setup.contact.intersects(kept.u, kept.t)
    (tie,) = [term for term in setup.problem.terms if isinstance(term, ObstacleTie)]
    assert tie.captured.size > 0  # the arm grips what it touches


def _side_of_arm(setup, u: np.ndarray, t: float) -> np.ndarray:
    """Signed distance of every leaflet A vertex (x > 0 at rest) from the arm's plane at ``t`` (its hinge at
    (gap/2 + thickness + 0.5, ., 0), turned by TURN about y: normal (cos, 0, -sin) x-wards), positive on the
    leaflets' side, within the arm's extent."""
    X = setup.model.mesh.p.T
    x = X + u[: setup.problem.space.n_u].reshape(-1, 3)
    hinge = np.array([0.5 * GAP + THICKNESS + 0.5, 4.0, 0.0])
    theta = TURN if t >= 2.0 else 0.0
    normal = np.array([np.cos(theta), 0.0, -np.sin(theta)])
    down = np.array([-np.sin(theta), 0.0, -np.cos(theta)])  # along the plate, from the hinge to its lower edge
    leaflet_a = (X[:, 0] > 0.0) & np.isin(np.arange(X.shape[0]), setup.model.mesh.t)
    along = (x - hinge) @ down
    inside = leaflet_a & (along > 1.0) & (along < 7.5) & (np.abs(x[:, 1] - 4.0) < 2.0)
    return -(x[inside] - hinge) @ normal


def test_the_arm_pushes_leaflet_a_to_its_free_side(clipped):
    """Where the arm-less closure leaves leaflet A vertices behind the arm's final plane (they would be crossed),
    the clip closure has every one of them on the free side, the nearest within the barrier's range."""
    setup, kept = clipped["clip"]
    plain_setup, plain = clipped["plain"]
    behind = _side_of_arm(plain_setup, plain.u, 2.0)
    assert np.sum(behind < 0.0) >= 3  # the arm's sweep crosses the arm-less leaflet
    side = _side_of_arm(setup, kept.u, 2.0)
    assert side.min() > 0.0 and side.min() < setup.contact.dhat


def test_reactions_arm_forces_and_pressure_balance(clipped):
    """The sum of every nodal force is zero: leaflets, chordae and the leaflets' contact with each other are
    internal, so the reactions, the arm's forces on the leaflets (its barrier pairs and grips) and the pressure's
    resultant sum to zero (to the residual left); the arm carries a share of the load."""
    setup, kept = clipped["clip"]
    problem = setup.problem
    residual, tangent = problem.assemble(kept.u, kept.t, tangent=False)
    n_u = problem.space.n_u
    fixed = np.zeros(problem.space.n_dofs, dtype=bool)
    fixed[problem.pattern.fixed] = True
    reactions = np.array([residual[:n_u][c::3][fixed[:n_u][c::3]].sum() for c in range(3)])
    pressure = pressure_forces(problem, kept.u, kept.t)
    resultant = np.array([pressure[:n_u][c::3].sum() for c in range(3)])
    arm = np.zeros(3)
    for term, contribution in zip(problem.terms, tangent.contributions, strict=True):
        if term is setup.contact or isinstance(term, ObstacleTie):
            arm += contribution.internal[:n_u].reshape(-1, 3).sum(axis=0)  # body-body pairs cancel
    total = np.abs(pressure[:n_u]).reshape(-1, 3).sum(axis=0).max()
    np.testing.assert_allclose(reactions - arm, -resultant, atol=1e-6 * total)
    assert np.linalg.norm(arm) > 0.05 * np.linalg.norm(resultant)
