"""LINK MPCs in the valve model (skvalve.valve.links): a fixed cube, a LINK and a chord pulled along one line, against
the closed-form series solution of a linear penalty bar and an Ogden cable; refusal of other MPC types with the file
line; the 1.0 annuloplasty's six links against the input's nodes (skipped when the data are absent: Texas TriValve,
Mathur et al. 2022, CC BY-NC-SA 4.0)."""

import logging

import numpy as np
import pytest
from scipy.optimize import brentq

from skvalve.fem.solvers.newton import solve
from skvalve.io.abaqus import read_model, trivalve_inputs
from skvalve.valve.links import LINK_FACTOR
from skvalve.valve.model import valve_model

AREA, MU, ALPHA, PULL = 0.4, 2.0, 10.0, 0.2
CUBE = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
DECK = "\n".join([
    "*Node", *(f"{k + 1}, {x}., {y}., {z}." for k, (x, y, z) in enumerate(CUBE)), "9, 0., 0., 2.", "10, 0., 0., 4.",
    "*Element, type=C3D8R, elset=Leaf", "1, 1, 2, 3, 4, 5, 6, 7, 8",
    "*Element, type=T3D2, elset=Chord", "2, 9, 10",
    "*Nset, nset=Cube", "1, 2, 3, 4, 5, 6, 7, 8",
    "*Solid Section, elset=Leaf, material=M", "*Solid Section, elset=Chord, material=C", f"{AREA},",
    "*Material, name=M", "*Anisotropic Hyperelastic, user, formulation=invariant, type=compressible, properties=4",
    "0.001, 20., 0.0001, 15.",
    "*Material, name=C", "*Hyperelastic, OGDEN, N=1", f"{MU}, {ALPHA}, 0.001",
    "*MPC", "LINK, 5, 9",
    "*Boundary", "Cube, ENCASTRE",
    "*Amplitude, name=Ramp, definition=SMOOTH STEP", "0., 0., 1., 1.",
    "*Step, name=Pull", "*Static", "0.25, 1.",
    "*Boundary, amplitude=Ramp", f"10, 3, 3, {PULL}", "10, 1, 2, 0.", "9, 1, 2, 0.",
    "*End Step"]) + "\n"


@pytest.fixture
def deck(tmp_path):
    path = tmp_path / "link.inp"
    path.write_text(DECK)
    return path


def _cable_stress(stretch: float) -> float:
    """Nominal stress of the chord as the model takes it: one-term Ogden in uniaxial stress (written out here) plus
    the default slack spring 1e-6 x 3 mu (lambda - 1); taut well past the 1 % transition."""
    ogden = 2 * MU / ALPHA * (stretch ** (ALPHA - 1) - stretch ** (-ALPHA / 2 - 1))
    return ogden + 1e-6 * 3 * MU * (stretch - 1.0)


def test_link_length_changes_by_its_force_over_the_stated_rigidity(deck):
    """Cube fixed; node 5 (on the cube) -LINK- node 9 -chord- node 10 pulled by 0.2 mm along the line (nodes 9 and 10
    held on the line: unloaded bars have no transverse stiffness). Series solution: the link (rest length 1)
    stretches by delta with EA delta = A P_c((2 + 0.2 - delta) / 2)."""
    model = valve_model(read_model(deck))
    links = model.links
    rigidity = LINK_FACTOR * 3 * MU * AREA  # the only chord: E_c = 3 mu
    assert links.size == 1 and links.rigidity == pytest.approx(rigidity, rel=1e-14)
    assert links.length.tolist() == [1.0]
    problem = model.problem()
    result = solve(problem, [0.25, 0.5, 0.75, 1.0], rtol=1e-10, atol=1e-12, progress=False, solver="scipy")
    u = result.solutions[-1]
    delta = brentq(lambda d: rigidity * d - AREA * _cable_stress((2.0 + PULL - d) / 2.0), 0.0, 0.01, xtol=1e-16)
    change = links.relative_change(model.mesh.p.T, u)
    assert change[0] == pytest.approx(delta, rel=1e-8)
    # the stated tolerance: relative change = force / EA; here about 1.2e-4 for a 0.29 N chord force
    chord = next(term for term in problem.terms if getattr(term, "name", "") == "chordae")
    force = chord.response(u).axial_force[0]
    assert change[0] == pytest.approx(force / rigidity, rel=1e-8)
    assert 1e-4 < change[0] < 2e-4
    # without the link the cable would dangle: the link is what carries node 9
    assert model.counts()["cables"] == 1 and model.counts()["links"] == 1


def test_other_mpc_types_are_refused_with_their_line(deck, tmp_path):
    path = tmp_path / "beam.inp"
    path.write_text(DECK.replace("LINK, 5, 9", "BEAM, 5, 9"))
    with pytest.raises(ValueError, match=r"beam\.inp:\d+: \*MPC BEAM is not modelled") as info:
        valve_model(read_model(path))
    assert f":{DECK.splitlines().index('LINK, 5, 9') + 1}:" in str(info.value)


def test_link_to_a_node_outside_the_model_names_the_label(deck, tmp_path):
    path = tmp_path / "stray.inp"
    stray = DECK.replace("10, 0., 0., 4.", "10, 0., 0., 4.\n11, 5., 5., 5.")
    path.write_text(stray.replace("LINK, 5, 9", "LINK, 5, 11"))
    with pytest.raises(ValueError, match=r"LINK joins node\(s\) \[11\]"):
        valve_model(read_model(path))


@pytest.mark.skipif("1.0-annuloplasty" not in trivalve_inputs(), reason="Texas TriValve 1.0 annuloplasty not found")
def test_annuloplasty_links_chain_the_septal_annulus():
    """Six LINK MPCs (F_Set-k, L_Set-k) chain node labels 54-50-46-42-38-34-30; each link's rest length is the
    distance between those nodes in the input; rigidity 1e3 x max(3 sum(mu) x area) of the three chordae."""
    logging.getLogger("skvalve.io.abaqus.reader").setLevel(logging.ERROR)
    abaqus = read_model(trivalve_inputs()["1.0-annuloplasty"])
    model = valve_model(abaqus)
    links = model.links
    labels = abaqus.node_labels[model.vertex_source[links.ends]]
    assert labels.tolist() == [[54, 50], [50, 46], [46, 42], [42, 38], [38, 34], [34, 30]]
    X = model.mesh.p.T
    np.testing.assert_allclose(X[links.ends], abaqus.nodes[model.vertex_source[links.ends]], atol=0)
    expected = np.linalg.norm(abaqus.nodes[abaqus.node_indices("Leaflet_Instance.54")]
                              - abaqus.nodes[abaqus.node_indices("Leaflet_Instance.50")])
    assert links.length[0] == pytest.approx(expected, rel=1e-14)
    assert np.all((links.length > 2.0) & (links.length < 2.2))
    chords = {s.material: s.area for s in abaqus.sections if s.area is not None}
    reference = max(3 * sum(abaqus.material(name).option("hyperelastic").data[0:6:2]) * area
                    for name, area in chords.items())
    assert links.rigidity == pytest.approx(LINK_FACTOR * reference, rel=1e-12)
    assert [loc.line for loc in links.locations] == [67955, 67957, 67959, 67961, 67963, 67965]
    problem = model.problem()
    assert sum(getattr(term, "name", "") == "links" for term in problem.terms) == 1
