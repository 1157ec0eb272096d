"""The clip repair as a model: multi-step load history in total time (skvalve.valve.history) and the rigid clip arms as
kinematic obstacles (skvalve.valve.clip).

Closed forms: Rodrigues' rotation of a point; Abaqus's smooth step S(x) = 10x^3 - 15x^4 + 6x^5 for the amplitudes of
the shipped 1.0 clip input (Amp-1: 0 -> 1 over step time 0.5-1; s2_Amp-1: 1 -> 0 over 0-0.5; Amp-3: 0 -> 1 over
0-0.5) in its three steps (periods 1, 0.5, 1); single-step inputs checked against value x amplitude(step time) read
straight from the input's *Boundary lines. Small decks are written here; the shipped input (Texas TriValve 1.0,
Mathur et al. 2022, CC BY-NC-SA 4.0) is read once per module and its tests skip when it is absent.
"""

import logging

import ipctk
import numpy as np
import pytest
from _mini_valve import write_mini_valve
from scipy.spatial import cKDTree

from skvalve.fem.contact.surface import ContactSurface
from skvalve.fem.contact.tie import ObstacleTie
from skvalve.io.abaqus import Location, Transform, read_model, trivalve_inputs
from skvalve.valve.clip import rodrigues, transform_axes
from skvalve.valve.history import amplitude_table
from skvalve.valve.model import valve_model
from skvalve.valve.setup import valve_setup
from skvalve.valve.support import UnsupportedInputError, check_supported, unsupported_features

INPUTS = trivalve_inputs()
P = 0.00567  # MPa, the clip input's *Dsload
ANGLES = {"Clip-1-1": 1.134464, "Clip-1-2": -1.134464, "Clip-2-1": 0.610865, "Clip-2-2": -0.610865}


def smooth(x):
    x = np.clip(x, 0.0, 1.0)
    return 10 * x**3 - 15 * x**4 + 6 * x**5


@pytest.fixture(scope="module")
def clip():
    if "1.0-clipping" not in INPUTS:
        pytest.skip("Texas TriValve 1.0 clipping input not present (../shared/data)")
    logging.getLogger("skvalve.io.abaqus.reader").setLevel(logging.ERROR)
    abaqus = read_model(INPUTS["1.0-clipping"])
    return abaqus, valve_model(abaqus)


# ---------------------------------------------------------------- closed forms, no data
def test_rodrigues_against_the_closed_form():
    """R(theta e) v = v cos + (e x v) sin + e (e.v)(1 - cos); a quarter turn about z takes x to y."""
    assert rodrigues([0, 0, 2.0], np.pi / 2) @ [1.0, 0, 0] == pytest.approx([0, 1.0, 0], abs=1e-15)
    rng = np.random.default_rng(3)
    for _ in range(5):
        e = rng.normal(size=3)
        e /= np.linalg.norm(e)
        v, theta = rng.normal(size=3), rng.uniform(-3, 3)
        expected = v * np.cos(theta) + np.cross(e, v) * np.sin(theta) + e * (e @ v) * (1 - np.cos(theta))
        R = rodrigues(3.0 * e, theta)
        assert R @ v == pytest.approx(expected, abs=1e-14)
        assert R.T @ R == pytest.approx(np.eye(3), abs=1e-14) and np.linalg.det(R) == pytest.approx(1.0)


def test_transform_axes_follow_the_rectangular_definition():
    """a on the local 1-axis, b in the 1-2 plane: e3 = a x b / |a x b|."""
    axes = transform_axes(Transform("T", np.zeros(1, int), "R", [2.0, 0, 0, 1.0, 1.0, 0], Location("x", 1)))
    assert axes == pytest.approx(np.eye(3), abs=1e-15)
    a, b = np.array([0.3, -1.2, 0.5]), np.array([1.0, 0.4, 0.2])
    axes = transform_axes(Transform("T", np.zeros(1, int), "R", [*a, *b], Location("x", 1)))
    assert axes @ axes.T == pytest.approx(np.eye(3), abs=1e-14)
    assert axes[2] == pytest.approx(np.cross(a, b) / np.linalg.norm(np.cross(a, b)), abs=1e-14)
    assert axes[0] == pytest.approx(a / np.linalg.norm(a)) and axes[1] @ b > 0


# ---------------------------------------------------------------- the shipped clip input
def test_steps_and_pressure_history_of_the_clip_input(clip):
    _, model = clip
    assert [(w.name, w.start, w.period) for w in model.steps] == [("Annulus Approximation", 0.0, 1.0),
                                                                  ("Clip capture", 1.0, 0.5), ("Clip close", 1.5, 1.0)]
    assert model.end_time == 2.5
    assert [model.step_index(t) for t in (0.0, 0.5, 1.0, 1.2, 1.5, 2.0, 2.5)] == [0, 0, 0, 1, 1, 2, 2]
    (load,) = model.pressures
    closed = {0.25: 0.0, 0.75: P * smooth(0.5), 1.0: P, 1.1: P * (1 - smooth(0.2)), 1.25: P * (1 - smooth(0.5)),
              1.5: 0.0, 2.0: 0.0, 2.25: P * smooth(0.5), 2.4: P * smooth(0.8), 2.5: P}
    for t, expected in closed.items():
        assert load.at(t) == pytest.approx(expected, abs=1e-15), t
    assert load.at(1.25) == pytest.approx(P / 2) and load.at(2.25) == pytest.approx(P / 2)


def test_annulus_conditions_are_carried_with_their_end_value(clip):
    """Step 1 prescribes the annulus with Amp-3 (0 -> 1 over 0-0.5); steps 2 and 3 keep the end value (OP=MOD)."""
    _, model = clip
    moving = [c for c in model.conditions if c.value != 0.0]
    assert moving and model.counts()["constrained_dofs"] == 702
    for c in moving:
        for t, factor in ((0.1, smooth(0.2)), (0.3, smooth(0.6)), (0.9, 1.0), (1.2, 1.0), (2.2, 1.0), (2.5, 1.0)):
            assert c.at(t) == pytest.approx(c.value * factor, abs=1e-14)


def test_arm_angles_follow_amp3_in_step_3(clip):
    _, model = clip
    assert {arm.name: arm.angle.at(2.5) for arm in model.arms} == pytest.approx(ANGLES, abs=1e-15)
    for arm in model.arms:
        theta = ANGLES[arm.name]
        for t in (0.0, 0.7, 1.2, 1.5, 1.6, 1.75, 1.9, 2.0, 2.3, 2.5):
            expected = theta * smooth((t - 1.5) / 0.5)
            assert arm.angle.at(t) == pytest.approx(expected, abs=1e-15), (arm.name, t)


def test_arms_are_the_placed_instances_turning_about_the_transform_axis(clip):
    """The arm vertices as the reader placed them (translation, then rotation about a-b): mapped back to the part
    frame with the instance rotation, the four arms coincide; the Transform's e3 is each arm's hinge (the part's
    x-axis), pointing opposite ways on the two arms of a clip; the whole facet surface is the arms' two contact
    surfaces."""
    abaqus, model = clip
    assert [arm.name for arm in model.arms] == list(ANGLES) and len(model.obstacles) == 4
    part = []
    for arm in model.arms:
        instance = abaqus.instances[arm.name.upper()]
        a, b, degrees = instance.rotation
        R = rodrigues(b - a, np.radians(degrees))
        assert arm.centre == pytest.approx(instance.translation, abs=1e-12)
        part.append((arm.vertices - arm.centre) @ R)  # R^T (x - c)
        assert abs(R @ [1.0, 0, 0] @ arm.axis) == pytest.approx(1.0, abs=1e-9)
        assert arm.vertices.shape == (3546, 3) and arm.triangles.shape == (2 * 3544, 3)
        faces = [abaqus.surface(f"{arm.name}.{name}").faces[0].elements for name in ("Contact_Surf", "Slide_Surf")]
        body = next(body for body in abaqus.rigid_bodies if body.reference_node == arm.reference_node)
        assert np.array_equal(np.sort(np.concatenate(faces)), np.sort(body.elements))
    for other in part[1:]:
        assert other == pytest.approx(part[0], abs=1e-9)
    assert model.arms[0].axis == pytest.approx(model.arms[1].axis)  # one Transform per clip
    assert model.arms[2].axis == pytest.approx(model.arms[3].axis)


def test_arms_turn_by_the_prescribed_angles_and_close(clip):
    """At the end of step 3 every vertex has turned by theta about the axis through the reference node (measured as a
    signed angle about e3); the two arms of each clip, 156.7 and 96.7 degrees apart, both close to the same
    26.7 degrees: the signs and the axis bring the arms together."""
    _, model = clip
    for arm in model.arms:
        x = model.obstacles[model.arms.index(arm)].at(2.5)
        r0, r1 = arm.vertices - arm.centre, x - arm.centre
        e = arm.axis
        p0, p1 = r0 - np.outer(r0 @ e, e), r1 - np.outer(r1 @ e, e)
        far = np.linalg.norm(p0, axis=1) > 1.0
        angle = np.arctan2(np.cross(p0[far], p1[far]) @ e, np.einsum("ij,ij->i", p0[far], p1[far]))
        assert angle == pytest.approx(np.full(angle.size, ANGLES[arm.name]), abs=1e-12)
        assert r1 @ e == pytest.approx(r0 @ e, abs=1e-12)
        assert model.obstacles[model.arms.index(arm)].at(0.0) == pytest.approx(arm.vertices, abs=1e-15)

    def opening(first, second, t):
        e = first.axis
        d = [(arm.at(t) - arm.centre).mean(axis=0) for arm in (first, second)]
        d = [v - (v @ e) * e for v in d]
        return np.degrees(np.arccos(d[0] @ d[1] / np.linalg.norm(d[0]) / np.linalg.norm(d[1])))

    arms = model.arms
    assert [opening(arms[0], arms[1], 0.0), opening(arms[2], arms[3], 0.0)] == pytest.approx([156.709, 96.709],
                                                                                             abs=1e-3)
    assert opening(arms[0], arms[1], 2.5) == pytest.approx(opening(arms[2], arms[3], 2.5), abs=1e-3)
    assert opening(arms[0], arms[1], 2.5) == pytest.approx(26.709, abs=1e-3)
    # the two arms of a clip turn towards each other by the input's angle each: the opening shrinks by twice it
    for first, second, turn in ((arms[0], arms[1], 1.134464), (arms[2], arms[3], 0.610865)):
        shrink = opening(first, second, 0.0) - opening(first, second, 2.5)
        assert shrink == pytest.approx(2.0 * np.degrees(turn), abs=1e-6)


def _arm_leaflet_distance(surface_x, surface_triangles, arm_x, arm_triangles):
    """Exact smallest distance between the leaflet surface and one arm (ipctk, on the leaflet triangles near the arm),
    whether they cross, and the vertex-to-vertex upper bound."""
    bound = cKDTree(surface_x).query(arm_x)[0].min()
    edges = [np.linalg.norm(x[t] - x[np.roll(t, 1, axis=1)], axis=2).max()
             for x, t in ((surface_x, surface_triangles), (arm_x, arm_triangles))]
    close = cKDTree(arm_x).query(surface_x, distance_upper_bound=1.01 * bound + sum(edges))[0] < np.inf
    keep = surface_triangles[np.any(close[surface_triangles], axis=1)]
    V = np.vstack([surface_x, arm_x])
    F = np.vstack([keep, arm_triangles + surface_x.shape[0]]).astype(np.int32)
    mesh = ipctk.CollisionMesh(V, ipctk.edges(F), F)
    patches = np.zeros(V.shape[0], dtype=np.int32)
    patches[surface_x.shape[0]:] = 1
    mesh.can_collide = ipctk.make_vertex_patches_filter(patches)  # arm-leaflet pairs only
    collisions = ipctk.NormalCollisions()
    collisions.build(mesh, V, 1.01 * bound)
    distance = np.sqrt(collisions.compute_minimum_distance(mesh, V)) if len(collisions) else np.inf
    return distance, ipctk.has_intersections(mesh, V), bound


def test_the_closure_setup_takes_the_arms_clear_of_the_leaflets(clip):
    """valve_setup passes the arms to IPCContact, which raises if they intersect the leaflets at t = 0; the arms are
    3.11 (Clip-1-1), 5.62, 8.36 and 4.24 mm from the open leaflets' hex boundary (measured)."""
    abaqus, model = clip
    setup = valve_setup(abaqus, model=model)
    assert setup.contact.obstacles == model.obstacles and setup.contact.n_body < setup.contact.rest.shape[0]
    assert not setup.contact.intersects(np.zeros(setup.problem.space.n_dofs), 0.0)
    surface = ContactSurface.from_facets(model.mesh, model.mesh.boundary_facets())
    local = np.full(model.mesh.p.shape[1], -1)
    local[surface.nodes] = np.arange(surface.nodes.size)
    X = model.mesh.p.T[surface.nodes]
    expected = {"Clip-1-1": 3.114, "Clip-1-2": 5.621, "Clip-2-1": 8.356, "Clip-2-2": 4.237}
    for arm in model.arms:
        distance, crossing, bound = _arm_leaflet_distance(X, local[surface.triangles], arm.vertices, arm.triangles)
        assert not crossing and distance <= bound
        assert distance == pytest.approx(expected[arm.name], abs=1e-3)


def test_the_clip_input_is_accepted_with_its_approximations_noted(clip):
    abaqus, model = clip
    assert unsupported_features(abaqus) == []
    notes = check_supported(abaqus)
    assert any(":75482: Rough_Interaction" in n and "tie after capture" in n for n in notes)
    assert all(n in model.notes for n in notes)
    assert sum(n.startswith("clip arm ") for n in model.notes) == 4
    assert any(n.startswith("clip arms in contact from") for n in model.notes)


def test_the_arms_are_in_contact_from_the_start_and_grip_from_when_they_turn(clip):
    """Contact with the arms from total time 0: the open leaflets clear every arm there (the barrier's start), and the
    arms' facets face the leaflets (the positive side, to which the input's one-sided rigid surfaces push). The tie
    (rough, no-separation contact) captures only from 1.5, the start of "Clip close" where the arms start to turn: a
    leaflet vertex placed on an arm is free at 1.49 and captured at 1.5."""
    abaqus, model = clip
    starts = {w.name: w.start for w in model.steps}
    assert [o.active_from for o in model.obstacles] == [0.0] * 4
    assert all(arm.angle.at(starts["Clip close"]) == 0.0 != arm.angle.at(model.end_time) for arm in model.arms)
    setup = valve_setup(abaqus, model=model)
    u = np.zeros(setup.problem.space.n_dofs)
    assert setup.contact.positions(u, 0.0).shape[0] == setup.contact.rest.shape[0]  # arms in the collision mesh
    assert not setup.contact.intersects(u, 0.0)
    leaflets = setup.problem.space.mesh.p[:, setup.contact.nodes].T
    for obstacle in model.obstacles:  # the 50 leaflet vertices nearest each arm lie on its facets' positive side
        corners = obstacle.vertices[obstacle.triangles]
        centroids = corners.mean(axis=1)
        normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        distance, nearest = cKDTree(centroids).query(leaflets)
        close = np.argsort(distance)[:50]
        side = np.einsum("ij,ij->i", leaflets[close] - centroids[nearest[close]], normals[nearest[close]])
        assert np.all(side > 0.0), obstacle.name
    assert not any("rotational boundary" in n or "outside the model" in n for n in model.notes)
    (tie,) = [term for term in setup.problem.terms if isinstance(term, ObstacleTie)]
    assert tie.obstacles == model.obstacles and np.array_equal(tie.nodes, setup.contact.nodes)
    assert tie.capture_from == [starts["Clip close"]] * 4
    arm = model.obstacles[0]
    node = int(setup.contact.nodes[0])
    for t, captured in ((1.49, 0), (1.5, 1)):
        moved = u.copy()
        moved[3 * node:3 * node + 3] = arm.at(t)[0] - setup.problem.space.mesh.p[:, node]
        tie.assemble(moved, t, True, None)
        tie.commit()
        assert tie.captured.size == captured
    assert tie.captured.tolist() == [node]


# ---------------------------------------------------------------- single-step inputs as before
def _expected_conditions(abaqus, model, t):
    """{(vertex, component): value} from the last *Boundary line of each dof: value x amplitude(t), or the static
    ramp value x min(t / period, 1), or the value (the one-step rules)."""
    amplitudes, _ = amplitude_table(abaqus)
    (step,) = abaqus.steps
    static = step.procedure.lower().startswith("static")
    last = {}
    for bc in list(abaqus.boundary_conditions) + list(step.boundary_conditions):
        for dof in range(bc.first_dof, min(bc.last_dof, 3) + 1):
            for g in bc.nodes:
                last[(int(g), dof - 1)] = bc
    out = {}
    for v, g in enumerate(model.vertex_source):
        for component in range(3):
            bc = last.get((int(g), component))
            if bc is None:
                continue
            if bc.amplitude is not None:
                out[(v, component)] = bc.value * amplitudes[bc.amplitude.upper()](t)
            else:
                out[(v, component)] = bc.value * (min(max(t / step.time_period, 0.0), 1.0) if static else 1.0)
    return out


STATIC_DECK = [
    "*Node", "1, 0., 0., 0.", "2, 1., 0., 0.", "3, 1., 1., 0.", "4, 0., 1., 0.",
    "5, 0., 0., 1.", "6, 1., 0., 1.", "7, 1., 1., 1.", "8, 0., 1., 1.",
    "*Element, type=C3D8R, elset=Leaf", "1, 1, 2, 3, 4, 5, 6, 7, 8", "*Solid Section, elset=Leaf, material=M",
    "*Surface, type=ELEMENT, name=Top", "Leaf, S2", "*Material, name=M",
    "*Anisotropic Hyperelastic, user, formulation=invariant, type=compressible, properties=4",
    "0.001, 20., 0.0001, 15.",
    "*Boundary", "1, 1, 3", "2, 1, 3", "3, 1, 3", "4, 1, 3",
    "*Step, name=Close", "*Static", "0.5, 2.", "*Boundary", "1, 3, 3, -0.2", "*Dsload", "Top, P, 0.001", "*End Step",
]


@pytest.mark.parametrize("deck", ["mini", "static", "1.0-diseased"])
def test_a_single_step_input_gives_the_conditions_and_pressure_it_always_had(deck, tmp_path):
    if deck == "mini":
        path = write_mini_valve(tmp_path / "mini.inp")
    elif deck == "static":
        path = tmp_path / "static.inp"
        path.write_text("\n".join(STATIC_DECK) + "\n")
    else:
        if deck not in INPUTS:
            pytest.skip(f"{deck} not present")
        path = INPUTS[deck]
    abaqus = read_model(path)
    model = valve_model(abaqus)
    (step,) = abaqus.steps
    assert model.end_time == step.time_period and len(model.steps) == 1 and model.steps[0].start == 0.0
    assert model.obstacles == [] and model.arms == []
    (load,) = model.pressures
    (line,) = step.distributed_loads
    static = step.procedure.lower().startswith("static")
    for t in np.linspace(-0.1, step.time_period + 0.2, 23):
        expected = _expected_conditions(abaqus, model, t)
        got = {(int(v), c.component): c.at(t) for c in model.conditions for v in c.vertices}
        assert got == expected  # exactly: the same arithmetic as the one-step model
        amplitude = None if line.amplitude is None else abaqus.amplitude(line.amplitude)
        if amplitude is not None:
            factor = float(np.interp(t, amplitude.times, amplitude.values)) if amplitude.definition == "TABULAR" \
                else smooth((t - amplitude.times[0]) / (amplitude.times[1] - amplitude.times[0]))
        else:
            factor = min(max(t / step.time_period, 0.0), 1.0) if static else 1.0
        assert load.at(t) == pytest.approx(line.magnitude * factor, abs=1e-15)


# ---------------------------------------------------------------- a small clip deck, good and bad
CLIP_DECK = STATIC_DECK[:STATIC_DECK.index("*Step, name=Close")] + [
    "*Node", "11, 0., 0., 2.", "12, 1., 0., 2.", "13, 1., 1., 2.", "14, 0., 1., 2.",
    "20, 0.5, 0.5, 2.5", "21, 0.5, 1.9, 2.5",
    "*Element, type=R3D4, elset=Arm", "11, 11, 12, 13, 14",
    "*Nset, nset=RP", "20", "*Nset, nset=RP2", "21", "*Rigid Body, ref node=RP, elset=Arm",
    "*Transform, nset=RP", "0., 1., 0., 0., 0., 1.",
    "*Element, type=CONN3D2, elset=Wire", "12, 20, 21", "*Connector Section, elset=Wire", "Slot,",
    "*Boundary", "RP, 1, 5", "RP2, 1, 3",
    "*Amplitude, name=Smooth, definition=SMOOTH STEP", "0., 0., 0.5, 1.",
    "*Step, name=Load", "*Dynamic, Explicit", ", 1.", "*Boundary, amplitude=Smooth", "RP, 6, 6, 0.",
    "*Dsload, amplitude=Smooth", "Top, P, 0.001", "*End Step",
    "*Step, name=Turn", "*Dynamic, Explicit", ", 0.5", "*Boundary, amplitude=Smooth", "RP, 6, 6, 0.7", "*End Step",
]


def _deck(tmp_path, lines, name="clip.inp"):
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path, path.read_text().splitlines()


def test_a_small_clip_deck_turns_its_arm_about_the_local_3_axis(tmp_path):
    """The Transform (a = y, b = z) makes the local 3-axis global x: the arm turns by 0.7 about x through the
    reference node over step time 0-0.5 of the second step, with no unknowns added."""
    path, _ = _deck(tmp_path, CLIP_DECK)
    abaqus = read_model(path)
    assert unsupported_features(abaqus) == []
    model = valve_model(abaqus)
    (arm,) = model.arms
    assert arm.axis == pytest.approx([1.0, 0, 0]) and model.end_time == 1.5
    centre = np.array([0.5, 0.5, 2.5])
    for t in (0.5, 1.0, 1.1, 1.25, 1.5):
        theta = 0.7 * smooth((t - 1.0) / 0.5)
        c, s = np.cos(theta), np.sin(theta)
        R = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
        assert model.obstacles[0].at(t) == pytest.approx(centre + (arm.vertices - centre) @ R.T, abs=1e-14)
    assert model.problem().space.n_dofs == 3 * 8
    assert model.pressures[0].at(1.2) == 0.001  # carried: Smooth ends at 1 in step 1


@pytest.mark.parametrize("change, keyword, marker, reason", [
    ("RP, 2, 2, 0.1", "*Boundary", "RP, 2, 2, 0.1", "nonzero translation in dof 2"),
    ("RP, 4, 4, 0.2", "*Boundary", "RP, 4, 4, 0.2", "nonzero rotation in dof 4"),  # about the local 1-axis
    (None, "*Connector Section", "*Connector Section", "connector would act"),  # RP2 free in dof 3: the Slot acts
])
def test_a_clip_deck_that_moves_otherwise_is_refused_with_the_line(tmp_path, change, keyword, marker, reason):
    """Refused naming the line that makes the arm move otherwise (or the connector act); the keywords that then
    cannot be represented either (the arm's elements, its Transform, its rotation) are listed too."""
    lines = list(CLIP_DECK)
    if change is None:
        lines[lines.index("RP2, 1, 3")] = "RP2, 1, 2"
    else:
        lines.insert(len(lines) - 1, "*Boundary")
        lines.insert(len(lines) - 1, change)
    path, written = _deck(tmp_path, lines)
    line = next(k + 1 for k, text in enumerate(written) if text.startswith(marker))
    with pytest.raises(UnsupportedInputError) as info:
        valve_model(read_model(path))
    (cause,) = [f for f in info.value.features
                if (f.keyword, f.location.line) == (keyword, line) and reason in f.reason]
    assert f"clip.inp:{line}: {keyword}: {cause.reason}" in str(info.value)
    assert {f.keyword for f in info.value.features} <= {keyword, "*Element, type=R3D4", "*Element, type=CONN3D2",
                                                        "*Transform", "*Boundary", "*Connector Section"}


# ---------------------------------------------------------------- the history rules on a three-step deck
HISTORY_DECK = STATIC_DECK[:STATIC_DECK.index("*Step, name=Close")] + [
    "*Surface, type=ELEMENT, name=Bottom", "Leaf, S1",
    "*Amplitude, name=Tot, definition=TABULAR, time=TOTAL TIME", "0., 0., 4., 1.",
    "*Amplitude, name=Smooth, definition=SMOOTH STEP", "0., 0., 0.5, 1.",
    "*Step, name=Ramp", "*Static", "0.5, 2.", "*Boundary", "5, 3, 3, 0.1", "*Boundary, amplitude=Tot", "6, 3, 3, 0.4",
    "*Dsload", "Top, P, 0.001", "*End Step",
    "*Step, name=Jump", "*Dynamic, Explicit", ", 1.", "*Dsload", "Top, P, 0.003",
    "*Boundary, amplitude=Smooth", "5, 3, 3, 0.3", "*End Step",
    "*Step, name=Release", "*Static", "0.5, 1.", "*Dsload, op=NEW", "Bottom, P, 0.002", "*End Step",
]


def test_the_history_rules_of_a_three_step_deck(tmp_path):
    """Static ramps from the previous value, a dynamic step's amplitude-free load at once, a redefinition with an
    amplitude in step time, a carried end value, an amplitude in total time followed across steps, and OP=NEW
    releasing a load (ramped down over a static step)."""
    path, _ = _deck(tmp_path, HISTORY_DECK, "history.inp")
    abaqus = read_model(path)
    model = valve_model(abaqus)
    assert [(w.name, w.start, w.end, w.static) for w in model.steps] == [
        ("Ramp", 0.0, 2.0, True), ("Jump", 2.0, 3.0, False), ("Release", 3.0, 4.0, True)]
    node = {int(g): v for v, g in enumerate(model.vertex_source)}
    z = {c.vertices[0]: c for c in model.conditions if c.component == 2 and c.vertices.size == 1}
    top, bottom = (next(p for p in model.pressures if p.surface == name) for name in ("Top", "Bottom"))
    for t in (0.5, 1.5, 2.1, 2.3, 2.7, 3.2, 3.6, 4.0):
        tau2, tau3 = t - 2.0, t - 3.0
        five = 0.1 * t / 2 if t <= 2 else 0.3 * smooth(tau2 / 0.5) if t <= 3 else 0.3
        top_p = 0.001 * t / 2 if t <= 2 else 0.003 if t <= 3 else 0.003 * (1 - tau3)
        bottom_p = 0.0 if t <= 3 else 0.002 * tau3
        assert z[node[abaqus.node_indices("5")[0]]].at(t) == pytest.approx(five, abs=1e-15), t
        assert z[node[abaqus.node_indices("6")[0]]].at(t) == pytest.approx(0.4 * t / 4, abs=1e-15), t
        assert (top.at(t), bottom.at(t)) == pytest.approx((top_p, bottom_p), abs=1e-15), t
    assert top.magnitude == 0.003 and bottom.magnitude == 0.002


def test_a_condition_released_between_steps_is_refused_with_the_line(tmp_path):
    """OP=NEW in the third step frees the leaflet dofs it does not repeat: the implicit model's prescribed dofs are
    the same in every step, so the input is refused at that *Boundary."""
    lines = list(HISTORY_DECK)
    lines[-1:-1] = ["*Boundary, op=NEW", "5, 3, 3, 0.3"]
    path, written = _deck(tmp_path, lines, "release.inp")
    with pytest.raises(UnsupportedInputError) as info:
        valve_model(read_model(path))
    line = len(written) - 1  # the data line of the OP=NEW *Boundary
    (feature,) = info.value.features
    assert (feature.keyword, feature.location.line, feature.step) == ("*Boundary", line, 2)
    assert "13 node dof(s) prescribed in some steps only (13 released" in feature.reason
