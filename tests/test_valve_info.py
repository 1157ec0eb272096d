"""Valve model summary and picture: counts against the hand-written deck, files written, shipped 1.1 model."""

import logging

import numpy as np
import pytest
from matplotlib import image
from test_io_abaqus_model import DECK

from skvalve.io.abaqus import read_model, trivalve_inputs
from skvalve.valve.info import plot_layers, summarise, valve_info


@pytest.fixture(scope="module")
def deck(tmp_path_factory):
    path = tmp_path_factory.mktemp("info") / "deck.inp"
    path.write_text(DECK)
    return path


def test_summary_counts_and_text(deck):
    summary = summarise(deck)
    assert summary.n_nodes == 14
    assert summary.elements_by_type == {"C3D8R": 1, "T3D2": 1, "S4R": 1}
    assert summary.element_sets["Block-1.All"] == 2 and summary.node_sets["Block-1.Bottom"] == 4
    assert summary.surfaces["Block-1.Top"] == "1 faces (S2 x1)"
    assert [m.name for m in summary.materials] == ["Leaf", "String"]
    assert summary.initial_boundary_groups[0] == "displacement dof 1 = 0 on 4 nodes (amplitude -, op=MOD)"
    (step,) = summary.steps
    assert step.loads == ["P = 0.00567 on Block-1.Top (amplitude Table)"]
    assert sorted(step.boundary_groups) == ["displacement dof 3 = -1.5 on 1 nodes (amplitude Ramp, op=NEW)",
                                            "displacement dofs 1-2 = 0 on 1 nodes (amplitude Ramp, op=NEW)"]
    assert summary.ignored["Density"][0] == 1
    text = summary.to_text()
    for expected in ("*hyperelastic ogden (n=1): 2, 10, 0.001", "Amplitudes:", "Ramp: SMOOTH STEP, (0.5, 0), (1.5, 1)",
                     "pair Bottom / PlateTop (Touch, KINEMATIC)", "MPC LINK x1", "*Output x1"):
        assert expected in text


def test_valve_info_writes_summary_and_picture(deck, tmp_path):
    summary = valve_info(deck, tmp_path / "out")
    text_file, picture = summary.outputs
    assert text_file.read_text() == summary.to_text()
    pixels = image.imread(picture)
    assert pixels.shape[:2] == (780, 1560)
    assert len(np.unique(pixels.reshape(-1, pixels.shape[2]), axis=0)) > 10  # something was drawn
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["summary.txt", "undeformed.png"]


@pytest.mark.skipif("1.1-healthy" not in trivalve_inputs(), reason="Texas TriValve 1.1 healthy input not present")
def test_layers_of_the_healthy_1_1_valve():
    """Texas TriValve 1.1 (CC BY 4.0): three leaflets by their shells, 4166 truss chordae (counted with awk)."""
    logging.getLogger("skvalve.io.abaqus.reader").setLevel(logging.ERROR)
    model = read_model(trivalve_inputs()["1.1-healthy"])
    layers = {label: data for label, _, data in plot_layers(model)}
    assert list(layers) == ["Anterior leaflet", "Posterior leaflet", "Septal leaflet", "Chordae"]
    assert len(layers["Chordae"]) == 4166
    shells = sum(len(layers[f"{name} leaflet"]) for name in ("Anterior", "Posterior", "Septal"))
    assert shells == 8283
