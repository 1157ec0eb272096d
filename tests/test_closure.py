"""The closure driver (skvalve.valve.closure) on a small contact problem, and its contact surface and staging on
the shipped diseased Texas TriValve input (skipped when the input is absent)."""

from dataclasses import replace
from types import SimpleNamespace

import meshio
import numpy as np
import pytest
import skfem

from skvalve.fem import Problem, Space
from skvalve.fem.amplitudes import SmoothStep
from skvalve.fem.constitutive import MaterialRegions
from skvalve.fem.contact import ContactSurface, SurfaceContact
from skvalve.fem.damping import DampingSchedule, ViscousDamping
from skvalve.fem.errors import ConvergenceError
from skvalve.fem.hyperelastic import HyperelasticTerm
from skvalve.fem.ptc import PseudoTransientOptions
from skvalve.fem.trust_region import TrustRegionOptions, TrustRegionResult, TrustRegionStep
from skvalve.io.abaqus import read_model, trivalve_input
from skvalve.materials import NeoHookean
from skvalve.papers.mathur2022 import reproduce as reproduce_module
from skvalve.valve import relaxation as relaxation_module
from skvalve.valve.closure import (
    ClosureOptions,
    ClosureSetup,
    _PenaltyFrom,
    closure_setup,
    contact_surface,
    load_factors,
    run_closure,
    write_log,
)
from skvalve.valve.model import valve_model
from skvalve.valve.outputs import ClosureWriter
from skvalve.valve.relaxation import (
    EveryLoadFactor,
    relax_closure,
    relaxation_options,
)


def _blocks_setup(shortening: float, damped: bool = True, blend: float = 0.0) -> ClosureSetup:
    """Two unit cubes (2x2x2 hexes each) on rollers, the top face pushed down by ``shortening`` x t/end."""
    bottom = skfem.MeshHex.init_tensor(*(np.linspace(0, 1, 3),) * 3)
    top = skfem.MeshHex.init_tensor(*(np.linspace(0, 1, 3),) * 2, np.linspace(1, 2, 3))
    mesh = skfem.MeshHex(np.hstack([bottom.p, top.p]), np.hstack([bottom.t, top.t + bottom.p.shape[1]]))
    space = Space(mesh)
    problem = Problem(space, [HyperelasticTerm(space, MaterialRegions(mesh, NeoHookean(1.0, 2.0)))])
    surface = ContactSurface.from_facets(mesh, mesh.facets_satisfying(lambda X: np.abs(X[2] - 1) < 1e-9, True))
    contact = problem.add_term(SurfaceContact(space, surface, 50.0, smoothing=0.01, blend=blend))
    damping = problem.add_term(ViscousDamping(space, DampingSchedule(0.5, t_off=1.0))) if damped else None
    for axis in range(3):
        problem.add_dirichlet(lambda X, a=axis: X[a] == 0.0, 0.0, components=[axis])
    problem.add_dirichlet(lambda X: X[2] == 2.0, lambda X, t: -shortening * t / 1.5 * np.ones_like(X), components=[2])
    return ClosureSetup(None, None, problem, contact, damping, np.zeros(mesh.p.shape[1], dtype=int))


def test_load_factors_follow_the_two_stages():
    factors = load_factors(ClosureOptions(papillary_steps=5, pressure_steps=4))
    np.testing.assert_allclose(factors, [0.1, 0.2, 0.3, 0.4, 0.5, 0.75, 1.0, 1.25, 1.5])
    np.testing.assert_allclose(load_factors(ClosureOptions(papillary_steps=2, end=0.25)), [0.125, 0.25])


def test_closure_driver_reaches_the_end_with_damping_off_and_records_the_run():
    setup = _blocks_setup(0.15)
    options = ClosureOptions(papillary_steps=2, pressure_steps=2, rtol=1e-7, solver="scipy")
    run = run_closure(setup, options, progress=False)
    assert run.error is None
    assert run.load_factors == pytest.approx([0.0, 0.25, 0.5, 1.0, 1.5])
    assert run.contact_pairs[-1] == 18  # 9 nodes of each face, two passes
    assert sum(run.iterations) > 0 and run.seconds > 0 and run.peak_memory_mb > 0
    assert run.undamped_residual[1] < 1e-6  # the damping is off at t >= 1: the end state is undamped equilibrium


def test_pseudo_transient_closure_ends_where_the_load_stepped_one_does():
    """Blocks pressed into contact: Ψtc (no equilibrium on the way, the damping its own) must reach the undamped
    equilibrium that damped Newton load steps reach, with the same contact pairs."""
    options = ClosureOptions(papillary_steps=2, pressure_steps=2, rtol=1e-9, solver="scipy")
    newton = run_closure(_blocks_setup(0.15), options, progress=False)
    relaxed = relax_closure(_blocks_setup(0.15, damped=False), 1.5,
                            PseudoTransientOptions(damping=0.5, first_step=0.05, max_load_step=0.25, rtol=1e-9,
                                                   solver="scipy"), progress=False)
    assert relaxed.error is None and relaxed.load_factors[-1] == 1.5
    assert relaxed.contact_pairs[-1] == newton.contact_pairs[-1] == 18
    np.testing.assert_allclose(relaxed.u, newton.u, atol=1e-8)
    assert relaxed.undamped_residual[1] < 1e-9
    with pytest.raises(ValueError, match="damping=0"):
        relax_closure(_blocks_setup(0.15), 1.5, progress=False)
    # blended contact (matching faces: every node on a vertex or an edge, shares summing to one or more) closes to
    # the same equilibrium, its facing factors committed with each accepted step
    blended = relax_closure(_blocks_setup(0.15, damped=False, blend=0.1), 1.5,
                            PseudoTransientOptions(damping=0.5, first_step=0.05, max_load_step=0.25, rtol=1e-9,
                                                   solver="scipy"), progress=False)
    assert blended.error is None and blended.contact_pairs[-1] == 18
    np.testing.assert_allclose(blended.u, newton.u, atol=1e-8)


def test_a_trust_region_at_the_held_load_ends_where_the_load_stepped_closure_does():
    """Ψtc brings the load to its end and the energy trust region relaxes there (``held``): blocks pressed into
    blended contact reach the equilibrium that damped Newton load steps reach, with the same contact pairs."""
    options = ClosureOptions(papillary_steps=2, pressure_steps=2, rtol=1e-9, solver="scipy")
    newton = run_closure(_blocks_setup(0.15, blend=0.1), options, progress=False)
    seen = []
    relaxed = relax_closure(_blocks_setup(0.15, damped=False, blend=0.1), 1.5,
                            PseudoTransientOptions(damping=0.5, first_step=0.05, max_load_step=0.25, rtol=1e-9,
                                                   solver="scipy"), progress=False,
                            held=TrustRegionOptions(rtol=1e-9, solver="scipy"), callbacks=[seen.append])
    assert relaxed.error is None and relaxed.load_factors[-1] == 1.5
    assert any(isinstance(event, TrustRegionStep) for event in seen)  # the held relaxation was the trust region's
    assert relaxed.contact_pairs[-1] == newton.contact_pairs[-1] == 18
    np.testing.assert_allclose(relaxed.u, newton.u, atol=1e-8)
    assert relaxed.undamped_residual[1] < 1e-9


def test_held_stages_hand_on_their_state_and_end_where_one_stage_does():
    """Held stages (``held`` a sequence): a first stage of projected steps that passes its ``max_steps`` hands its last
    state to the next, which ends at the equilibrium of the damped Newton load steps; the run records each stage's
    steps. A failing last stage is the run's error."""
    options = ClosureOptions(papillary_steps=2, pressure_steps=2, rtol=1e-9, solver="scipy")
    newton = run_closure(_blocks_setup(0.15, blend=0.1), options, progress=False)
    ptc = PseudoTransientOptions(damping=0.5, first_step=0.05, max_load_step=0.25, rtol=1e-9, solver="scipy")
    stages = [TrustRegionOptions(rtol=1e-9, solver="scipy", project=True, max_steps=1),
              TrustRegionOptions(rtol=1e-9, solver="scipy")]
    staged = relax_closure(_blocks_setup(0.15, damped=False, blend=0.1), 1.5, ptc, progress=False, held=stages)
    assert staged.error is None and len(staged.stage_steps) == 2 and staged.stage_steps[0] == 1
    assert staged.stage_steps[1] >= 1
    np.testing.assert_allclose(staged.u, newton.u, atol=1e-8)
    assert staged.undamped_residual[1] < 1e-9
    failing = relax_closure(_blocks_setup(0.15, damped=False, blend=0.1), 1.5, ptc, progress=False,
                            held=[stages[0], replace(stages[1], max_steps=1)])
    assert failing.error is not None and "1 steps without converging" in failing.error



def test_a_relaxation_resumed_at_its_converged_state_keeps_it():
    """Resumed from the equilibrium it reached, the held trust region takes no step (none is recorded): the run still
    keeps that state, with its undamped residual (it kept none, and a resumed converged valve was not measured)."""
    ptc = PseudoTransientOptions(damping=0.5, first_step=0.05, max_load_step=0.25, rtol=1e-9, solver="scipy")
    held = TrustRegionOptions(rtol=1e-9, solver="scipy")
    first = relax_closure(_blocks_setup(0.15, damped=False, blend=0.1), 1.5, ptc, progress=False, held=held)
    assert first.error is None and first.undamped_residual[1] < 1e-9
    again = relax_closure(_blocks_setup(0.15, damped=False, blend=0.1), 1.5, ptc, progress=False, held=held,
                          u0=first.u, t0=1.5)
    assert again.error is None and again.load_factors == [1.5]
    np.testing.assert_array_equal(again.u, first.u)
    assert again.undamped_residual[1] < 1e-9


def test_a_held_relaxation_that_fails_before_its_first_step_reports_the_error_and_keeps_the_start(monkeypatch,
                                                                                              tmp_path):
    """Resumed at the held load, a trust region that raises at once (a bug, or giving up with no step taken) is
    recorded as the run's error with the load factor of the start, and with the state it was handed as the kept state
    when the error carries it: no IndexError from an empty history, and its log is written."""
    ptc = PseudoTransientOptions(damping=0.5, first_step=0.05, max_load_step=0.25, rtol=1e-9, solver="scipy")
    setup = _blocks_setup(0.15, damped=False, blend=0.1)
    u0 = np.zeros(setup.problem.space.n_dofs)

    def broken(problem, t, u, options, **kwargs):
        raise ValueError("einsum failed")

    monkeypatch.setattr(relaxation_module, "trust_region", broken)
    run = relax_closure(setup, 1.5, ptc, progress=False, u0=u0, t0=1.5, held=TrustRegionOptions(solver="scipy"))
    assert run.error == "ValueError: einsum failed" and run.load_factors == [1.5] and run.u is None
    assert run.iterations == [0] and run.contact_pairs == [0]  # the log lists one row per load factor
    write_log(run, tmp_path / "closure_log.txt")
    assert "error ValueError: einsum failed" in (tmp_path / "closure_log.txt").read_text()

    handed = []

    def giving_up(problem, t, u, options, **kwargs):
        handed.append(u.copy())  # the start: u0 with the held load's prescribed values
        error = ConvergenceError("no shift gives a positive definite step matrix")
        error.last_state = TrustRegionResult(u=u, load_factor=t)
        raise error

    monkeypatch.setattr(relaxation_module, "trust_region", giving_up)
    run = relax_closure(_blocks_setup(0.15, damped=False, blend=0.1), 1.5, ptc, progress=False, u0=u0, t0=1.5,
                        held=TrustRegionOptions(solver="scipy"))
    assert run.error.startswith("ConvergenceError") and run.load_factors == [1.5]
    np.testing.assert_array_equal(run.u, handed[0])
    assert run.undamped_residual[1] > 0.0  # the blocks pressed 0.15 into each other are not in equilibrium

def test_contact_pairs_closer_than_exclude_within_in_the_reference_are_never_active():
    """The two faces at z = 1 coincide in the reference: pressed 0.1 into each other, every node pairs (9 per face,
    two passes). A node over a triangle lies at most its circumradius (0.37 here) from the centroid in the
    reference: excluded within 0.4, none pairs (what keeps rim nodes off their own leaflet's inner face); within 0.1
    (below the smallest vertex-centroid distance, 0.24), all still do."""
    setup = _blocks_setup(0.15)
    X = setup.problem.space.dof_coordinates
    u = np.zeros(setup.problem.space.n_dofs)
    u[2::3][X[2] > 1.0 + 1e-9] -= 0.1
    top_face = np.flatnonzero(np.isclose(X[2], 1.0))
    top_face = top_face[top_face >= 27]  # the top block's copy of the face
    u[3 * top_face + 2] -= 0.1
    contact = setup.contact
    assert contact.active_pairs(u).size == 18
    contact.exclude_within = 0.1
    assert contact.active_pairs(u).size == 18
    contact.exclude_within = 0.4
    assert contact.active_pairs(u).size == 0
    with pytest.raises(ValueError, match="exclude_within"):
        SurfaceContact(setup.problem.space, contact.surface, 1.0, exclude_within=-1.0)


def test_relaxation_controls_and_sampled_output():
    """The valve's pseudo-transient stages: the papillary stage with a tight stretch trust region and nothing else,
    the pressure stage with stiffness-proportional (none once held) and local damping and the overrides. The output
    sampler passes one event per 0.05 of load factor, whatever the step count."""
    (until, first), (last_until, last) = relaxation_options(0.5, rtol=1e-7)
    assert until == 0.5 and first.max_strain_increment == 0.05 and first.stiffness_damping == 0.0
    assert first.local_damping == 1.0 and first.rtol == 1e-3
    assert last_until == np.inf and last.rtol == 1e-7 and last.stiffness_damping == 1e-3 and last.local_damping == 10
    assert last.held_stiffness_damping == 0.0  # none once the pressure is held
    assert first.fill == last.fill == 0.8  # both grow the step only to 0.8 of the trust regions
    assert len(relaxation_options(0.0)) == 1  # everything ramps together: one stage
    seen = []
    sampler = EveryLoadFactor(lambda event: seen.append(event.load_factor), 0.05)
    for t in np.concatenate([np.linspace(0.0, 0.2, 81), np.full(5, 0.2)]):
        sampler(SimpleNamespace(load_factor=float(t)))
    assert seen == pytest.approx([0.0, 0.05, 0.1, 0.15, 0.2])
    with pytest.raises(ValueError, match="spacing"):
        EveryLoadFactor(print, 0.0)


def test_contact_penalty_switches_on_by_a_smooth_step():
    ramp = _PenaltyFrom(2.0, 0.5, 0.1)
    assert ramp(0.49) == 0.0 and ramp(0.5) == 0.0 and ramp(0.6) == ramp(1.0) == 2.0
    assert ramp(0.55) == pytest.approx(1.0, rel=1e-14)  # S(1/2) = 1/2
    values = [ramp(t) for t in np.linspace(0.5, 0.6, 21)]
    assert np.all(np.diff(values) > 0)
    assert _PenaltyFrom(2.0, 0.5)(0.5) == 2.0  # no ramp: a switch


def test_a_failed_closure_reports_where_it_stopped_and_keeps_the_last_state():
    setup = _blocks_setup(1.9)  # would push the top block through the bottom one and invert elements
    options = ClosureOptions(papillary_steps=2, pressure_steps=2, max_cutbacks=1, max_iter=6, solver="scipy",
                             max_increment=None)  # full Newton steps: the first one inverts elements
    run = run_closure(setup, options, progress=False)
    assert run.error is not None and "load factor" in run.error
    assert run.u is not None and np.all(np.isfinite(run.u))
    assert run.load_factors[-1] < 1.5


DISEASED = trivalve_input()


@pytest.mark.skipif(DISEASED is None, reason="Texas TriValve input not found (../shared/data)")
def test_contact_surface_of_the_shipped_valve_lies_on_the_boundary_and_faces_outward():
    abaqus = read_model(DISEASED)
    model = valve_model(abaqus)
    surface = contact_surface(abaqus, model)
    n_faces = sum(len(group.elements) for name in ("LEAFLET_SURFACES_INNER", "LEAFLET_RIM_TIP")
                  for group in abaqus.surface(name).faces)
    assert n_faces >= surface.quads.shape[0] > 0.9 * n_faces  # duplicates between the two surfaces dropped
    mesh = model.mesh
    boundary = {tuple(sorted(f)) for f in mesh.facets[:, mesh.boundary_facets()].T.tolist()}
    assert all(tuple(sorted(q)) in boundary for q in surface.quads.tolist())
    # outward: the face normal points away from the centroid of the hex that owns the face
    X, cells = mesh.p.T, mesh.t.T
    cells_of: dict[int, set] = {}
    for e, cell in enumerate(cells.tolist()):
        for v in cell:
            cells_of.setdefault(v, set()).add(e)
    Q = X[surface.quads]
    normal = np.cross(Q[:, 2] - Q[:, 0], Q[:, 3] - Q[:, 1])
    for q, n in zip(surface.quads.tolist(), normal, strict=True):
        (owner,) = set.intersection(*(cells_of[v] for v in q))
        assert np.dot(n, X[q].mean(axis=0) - X[cells[owner]].mean(axis=0)) > 0
    # the staging of the closure matches the input's amplitudes: papillary Amp-2 ends at 0.5, pressure Amp-1 at 1.5
    assert abaqus.amplitude("Amp-2").times[-1] == pytest.approx(0.5)
    assert abaqus.amplitude("Amp-1").times[-1] == pytest.approx(1.5)
    assert load_factors(ClosureOptions())[-1] == pytest.approx(abaqus.steps[0].time_period)
    # the search depth: bricks default to the mean edge of the surface's faces; contact_depth sets it
    edges = np.linalg.norm(Q - np.roll(Q, 1, axis=1), axis=2)
    default = closure_setup(options=ClosureOptions(), abaqus=abaqus, model=model).contact
    assert default.max_penetration == pytest.approx(edges.mean(), rel=1e-12)
    shallow = closure_setup(options=ClosureOptions(contact_depth=0.2), abaqus=abaqus, model=model).contact
    assert shallow.max_penetration == 0.2
    # the rounding of the contact pressure: 1 % of the mean face edge unless contact_smoothing sets it
    assert default.smoothing == pytest.approx(0.01 * edges.mean(), rel=1e-12)
    rounded = closure_setup(options=ClosureOptions(contact_smoothing=0.05), abaqus=abaqus, model=model).contact
    assert rounded.smoothing == 0.05


@pytest.mark.parametrize("depth", [0.0, -0.1, float("nan"), float("inf"), "0.2"])
def test_a_contact_depth_that_is_not_a_positive_length_is_refused(depth):
    with pytest.raises(ValueError, match="contact_depth"):
        ClosureOptions(contact_depth=depth)


@pytest.mark.parametrize("smoothing", [-0.01, float("nan"), float("inf"), "0.05"])
def test_a_contact_smoothing_that_is_not_a_length_is_refused(smoothing):
    with pytest.raises(ValueError, match="contact_smoothing"):
        ClosureOptions(contact_smoothing=smoothing)


@pytest.mark.parametrize("flag", [1, "yes", None])
def test_contact_loaded_faces_must_be_true_or_false(flag):
    with pytest.raises(ValueError, match="contact_loaded_faces"):
        ClosureOptions(contact_loaded_faces=flag)


@pytest.mark.skipif(DISEASED is None, reason="Texas TriValve input not found (../shared/data)")
def test_the_pressure_loaded_skins_join_the_contact_surface_on_request():
    abaqus = read_model(DISEASED)
    model = valve_model(abaqus)
    faces = [closure_setup(options=ClosureOptions(contact_depth=0.2, contact_loaded_faces=flag), abaqus=abaqus,
                           model=model).contact for flag in (False, True)]
    outer = contact_surface(abaqus, model, ["Leaflet_Surfaces_Outer"])  # the surface the input loads with pressure

    def keys(quads):
        return {tuple(sorted(quad)) for quad in quads.tolist()}

    assert {load.surface.upper() for load in model.pressures} == {"LEAFLET_SURFACES_OUTER"}
    assert keys(faces[1].surface.quads) == keys(faces[0].surface.quads) | keys(outer.quads)
    listed = sum(len(group.elements) for group in abaqus.surface("Leaflet_Surfaces_Outer").faces)
    assert len(keys(outer.quads)) == listed > 0  # one face per element the input lists
    # the two skins of a leaflet never pair in the open valve: 0.39 mm apart, deeper than the 0.2 mm search depth
    assert faces[1].active_pairs(np.zeros(faces[1].space.n_dofs)).size == 0


def test_reproduce_without_the_shipped_input_exits_with_a_message(monkeypatch, capsys):
    module = reproduce_module
    monkeypatch.setattr(module, "trivalve_input", lambda: None)
    with pytest.raises(SystemExit) as exit_info:
        next(module.reproduce(None))
    assert exit_info.value.code == module.EXIT_NO_INPUT == 2
    assert "SKVALVE_TRIVALVE" in capsys.readouterr().err


def test_closure_writer_writes_contact_pressure_and_stress_per_step(tmp_path):
    setup = _blocks_setup(0.15)
    mesh = setup.problem.mesh
    setup.model = SimpleNamespace(mesh=mesh, chordae=SimpleNamespace(ends=np.array([[0, 26]])),
                                  regions=np.zeros(mesh.nelements, dtype=int))
    writer = ClosureWriter(tmp_path / "closure.pvd", setup)
    options = ClosureOptions(papillary_steps=1, pressure_steps=1, rtol=1e-7, solver="scipy")
    run = run_closure(setup, options, callbacks=[writer], progress=False)
    assert run.error is None
    files = sorted(tmp_path.glob("closure_*.vtu"))
    assert len(files) == len(run.load_factors) == 3
    assert (tmp_path / "closure.pvd").read_text().count("<DataSet") == 3
    last = meshio.read(files[-1])
    np.testing.assert_allclose(last.point_data["displacement"].ravel(), run.u)
    pressure = last.point_data["contact_pressure"]
    assert pressure.max() > 0 and np.all(pressure[setup.contact.surface.nodes] > 0)
    # hexes are written in VTK order: every cell has a positive volume in the reference configuration
    hexes = last.cells_dict["hexahedron"]
    P = last.points[hexes]
    jac = np.einsum("ij,ij->i", np.cross(P[:, 1] - P[:, 0], P[:, 3] - P[:, 0]), P[:, 4] - P[:, 0])
    assert np.all(jac > 0)
    assert last.cell_data_dict["max_principal_cauchy"]["hexahedron"].shape == (mesh.nelements,)


def test_a_resumed_closure_ends_where_an_uninterrupted_one_does():
    options = ClosureOptions(papillary_steps=2, pressure_steps=2, rtol=1e-9, solver="scipy")
    whole = run_closure(_blocks_setup(0.15), options, progress=False)
    setup = _blocks_setup(0.15)
    first = run_closure(setup, ClosureOptions(papillary_steps=2, end=0.5, rtol=1e-9, solver="scipy"), progress=False)
    resumed = run_closure(_blocks_setup(0.15), options, progress=False, u0=first.u, t0=first.load_factors[-1])
    assert resumed.load_factors == pytest.approx([0.5, 1.0, 1.5])
    np.testing.assert_allclose(resumed.u, whole.u, atol=1e-9)


def test_options_fitted_to_the_staging_of_an_input():
    """1.0 inputs: papillary motion over 0-0.5, pressure over 0.5-1.5; the 1.1 healthy input ramps everything over
    0-1 (no papillary stage, no soft start of the cables)."""
    def stub(start, end):
        pressure = SimpleNamespace(amplitude=SmoothStep((start, end), (0.0, 1.0), "Amp-1"))
        return SimpleNamespace(pressures=[pressure], end_time=end)

    staged = ClosureOptions.for_model(stub(0.5, 1.5), pressure_steps=4)
    assert (staged.end, staged.pressure_start, staged.damping_off) == (1.5, 0.5, 1.25)
    assert staged.cable_stiffening == (0.4, 0.6) and staged.cable_softening == ClosureOptions.cable_softening
    assert staged.contact_from == 0.5 and ClosureOptions.for_model(stub(0.0, 1.0)).contact_from == 0.0
    together = ClosureOptions.for_model(stub(0.0, 1.0), pressure_steps=4)
    fitted = (together.end, together.pressure_start, together.damping_off, together.cable_softening)
    assert fitted == (1.0, 0.0, 0.75, 1.0)
    np.testing.assert_allclose(load_factors(together), [0.25, 0.5, 0.75, 1.0])
    assert ClosureOptions.for_model(stub(0.0, 1.0), damping=0.0).damping == 0.0  # overrides win


def test_staged_damping_schedule():
    """Papillary value before the pressure starts, then c_p (1 - tau)^2 down to zero at t_off."""
    from skvalve.valve.closure import StagedDamping

    schedule = StagedDamping(1e-6, 1e-4, 0.5, 1.25)
    assert schedule(0.0) == schedule(0.49) == 1e-6
    assert schedule(0.5) == 1e-4
    assert schedule(0.875) == pytest.approx(1e-4 * 0.25, rel=1e-14)
    assert schedule(1.25) == schedule(1.5) == 0.0


def test_damping_weights_give_nodes_outside_every_cell_the_median_volume():
    """Two unit hexes and a vertex no cell uses (a chordae branch point): the cell nodes keep their lumped
    volumes (1/8 per cell), the bare node gets the median of those."""
    from skvalve.valve.closure import damping_weights

    mesh = skfem.MeshHex.init_tensor(np.linspace(0, 2, 3), np.linspace(0, 1, 2), np.linspace(0, 1, 2))
    p = np.hstack([[[5.0], [5.0], [5.0]], mesh.p])  # vertex 0 in no cell
    space = Space(skfem.MeshHex(p, mesh.t + 1))
    weights = damping_weights(space)[: space.n_u].reshape(-1, 3)
    assert np.allclose(weights[:, 0], weights[:, 2])
    nodal = weights[1:, 0]
    assert np.allclose(np.sort(nodal), [0.125] * 8 + [0.25] * 4)  # corners of one cell / shared by two
    assert weights[0, 0] == pytest.approx(np.median(nodal))
