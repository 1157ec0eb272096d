"""``skvalve valve close`` end to end on a two-leaflet stand-in valve (:mod:`tests._mini_valve`, ~15 s).

The deck carries the Texas TriValve 1.0 keywords (C3D8R leaflets with the VUANISO_ISO properties, T3D2 Ogden chordae
as two-bar chains, annulus and papillary ``*Boundary`` lines with smooth-step amplitudes, ``*Dsload`` P on the outer
faces), so the command runs the shipped inputs' whole path: read, model, IPC contact from the start, the load path,
the held load, the kept state, the log and the VTU output. Checked against what the model must satisfy whatever the
code does: the static residual of the end state (1e-6 of the pressure's nodal forces), no intersection, the global
balance of reactions and pressure, the leaflets meeting within the barrier's range; a run interrupted part-way and
resumed repeats the uninterrupted one to 1e-10, and a second run repeats the first to the bit. Not checked: the deck's
mirror symmetries. The closed state breaks them (by 0.4-0.65 mm): the free edges meet edge-on and one rides over the
other, and the collision mesh's triangle diagonals are not mirror-symmetric, which decides which one.
"""

from pathlib import Path

import ipctk
import numpy as np
import pytest
from _mini_valve import write_mini_valve

from skvalve.cli import main
from skvalve.fem.contact.ipc import IntersectionError, IPCContact
from skvalve.valve.options import CloseOptions
from skvalve.valve.run import close_valve, relative_residual
from skvalve.valve.setup import pressure_forces, valve_setup
from skvalve.valve.state import read_state

GAP, WIDTH, HEIGHT, NH = 4.0, 8.0, 6.0, 3


@pytest.fixture(scope="module")
def closed(tmp_path_factory):
    """The deck, its setup and the state ``skvalve valve close`` leaves."""
    folder = tmp_path_factory.mktemp("mini")
    deck = write_mini_valve(folder / "mini.inp", gap=GAP, width=WIDTH, height=HEIGHT, nh=NH)
    assert main(["valve", "close", str(deck), "--out", str(folder / "out"), "--quiet"]) == 0
    return deck, folder / "out", valve_setup(deck)


def test_the_command_closes_the_valve(closed):
    deck, out, setup = closed
    kept = read_state(out / "state.npz")
    assert kept.phase == "done" and kept.t == 1.5
    assert (out / "closure.pvd").is_file() and (out / "closure.log").read_text().count("\n") == kept.steps + \
        kept.held_steps
    residual, _ = setup.problem.assemble(kept.u, kept.t, tangent=False)
    setup.problem.commit()
    assert relative_residual(setup, residual) <= 1e-6  # recomputed from the kept state, not read from the log
    assert not setup.contact.intersects(kept.u, kept.t)
    assert setup.contact.active_pairs(kept.u, kept.t) > 0


def test_reactions_balance_the_pressure(closed):
    """The sum of every free and prescribed nodal force is zero: contact, leaflets and chordae are internal, so the
    reactions at annulus and papillary tips carry the pressure's resultant (to the residual left)."""
    _, out, setup = closed
    kept = read_state(out / "state.npz")
    problem = setup.problem
    residual, _ = problem.assemble(kept.u, kept.t, tangent=False)
    pressure = pressure_forces(problem, kept.u, kept.t)
    fixed = np.zeros(problem.space.n_dofs, dtype=bool)
    fixed[problem.pattern.fixed] = True
    n_u = problem.space.n_u
    reactions = np.array([residual[:n_u][c::3][fixed[:n_u][c::3]].sum() for c in range(3)])
    resultant = np.array([pressure[:n_u][c::3].sum() for c in range(3)])
    total = np.abs(pressure[:n_u]).reshape(-1, 3).sum(axis=0).max()  # the pressure's summed magnitude
    np.testing.assert_allclose(reactions, -resultant, atol=1e-6 * total)


def test_the_leaflets_coapt(closed):
    """The leaflets' inner faces (x = +-gap/2 at rest) meet within the barrier's range: some node of one comes closer
    than d^ to a triangle of the other (ipctk's point-triangle distance), and the contact area lies between the
    free-edge strip and the two leaflets' whole faces."""
    _, out, setup = closed
    kept = read_state(out / "state.npz")
    X = setup.model.mesh.p.T
    x = X + kept.u[: setup.problem.space.n_u].reshape(-1, 3)
    a = np.flatnonzero(np.isclose(X[:, 0], 0.5 * GAP))
    triangles = setup.contact.surface.triangles
    b = triangles[np.all(np.isclose(X[triangles, 0], -0.5 * GAP), axis=1)]
    closest = min(np.sqrt(ipctk.point_triangle_distance(x[i], *x[t])) for i in a for t in b)
    assert 0.0 < closest < CloseOptions().contact.dhat
    area = setup.contact.contact_area(kept.u, kept.t)
    strip = WIDTH * HEIGHT / NH  # one row of faces along the free edge
    assert 2 * strip < area < 2 * WIDTH * HEIGHT


def test_an_interrupted_closure_resumes_to_the_uninterrupted_result(closed, tmp_path):
    deck, out, _ = closed
    whole = read_state(out / "state.npz")

    def stop_after_five(state) -> None:
        if state.steps + state.held_steps >= 5:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        close_valve(deck, out=tmp_path, progress=False, callbacks=[stop_after_five])
    assert read_state(tmp_path / "state.npz").steps == 5
    resumed = close_valve(deck, out=tmp_path, resume=True, progress=False)
    assert resumed.converged and resumed.steps == whole.steps and resumed.iterations == whole.iterations
    np.testing.assert_allclose(resumed.u, whole.u, rtol=0.0, atol=1e-10 * np.abs(whole.u).max())


def test_a_second_run_is_bitwise_the_first(closed):
    """The command's run (another call, files written) and a plain call agree to the bit: the path passes a branching
    (the free edges meet edge-on, one leaflet's edge rides over the other's), where ipctk's threaded sums made runs
    differ (``IPCContact(threads=1)``)."""
    deck, out, _ = closed
    again = close_valve(deck, progress=False)
    kept = read_state(out / "state.npz")
    assert again.iterations == kept.iterations
    assert np.array_equal(again.u, kept.u)


def test_the_deck_is_read_as_the_shipped_inputs_are(closed):
    deck, _, setup = closed
    model = setup.model
    assert model.mesh.t.shape[1] == 24 and len(model.pressures) == 1
    assert model.chordae.ends.shape == (6, 2)  # two-bar chains collapsed into one cable each
    assert Path(deck).read_text().startswith("** skvalve test deck")


def test_a_path_state_the_contact_refuses_is_a_cut_back(closed, monkeypatch):
    """A converged path step whose state a term refuses (an intersection among excluded primitives, here faked once
    at the first state past step time 0.5) is cut back like a failed step and the run goes on to the same kind of end;
    the refused state is never accepted."""
    deck, _, _ = closed
    refused: list[float] = []
    original = IPCContact.check_state

    def refuse_once(self, u, t):
        if t > 0.5 and not refused:
            refused.append(t)
            raise IntersectionError(f"faked at load factor {t}")
        return original(self, u, t)

    plain = close_valve(deck, progress=False)
    monkeypatch.setattr(IPCContact, "check_state", refuse_once)
    report = close_valve(deck, progress=False)
    assert len(refused) == 1 and report.converged and report.relative_residual <= 1e-6
    assert report.failed_steps == plain.failed_steps + 1
    assert refused[0] not in [record.t for record in report.records if record.phase == "path"]
