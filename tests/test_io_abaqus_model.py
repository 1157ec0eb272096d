"""Abaqus model reader on a hand-written deck: every kind of keyword the Texas TriValve inputs use.

Expected values are written by hand from the deck (coordinates after a 90 degree instance rotation,
set contents, face labels), not taken from the reader.
"""

import logging

import pytest

from skvalve.io.abaqus import AbaqusParseError, read_materials, read_model

DECK = """** a two-part model: a cube of one C3D8R brick with a truss hanging from it
*Heading
 test deck
*Part, name=Block
*Node, nset=Block_Nodes
1, 0., 0., 0.
2, 1., 0., 0.
3, 1., 1., 0.
4, 0., 1., 0.
*Node
5, 0., 0., 1.
6, 1., 0., 1.
7, 1., 1., 1.
8, 0., 1., 1.
9, 0.5, 0.5, -1.
*Element, type=C3D8R, elset=Brick
1, 1, 2, 3, 4, 5, 6,
7, 8
*Element, type=T3D2, elset=Chord
2, 9, 1
*Nset, nset=Bottom, generate
1, 4, 1
*Nset, nset=Odd
1, 3, 5, 7
*Elset, elset=All
Brick, Chord
*Surface, type=ELEMENT, name=Top
Brick, S2
*Solid Section, elset=Brick, material=Leaf
,
*Solid Section, elset=Chord, material=String
0.25,
*End Part
*Part, name=Plate
*Node
1, 0., 0., 0.
2, 1., 0., 0.
3, 1., 1., 0.
4, 0., 1., 0.
*Element, type=S4R, elset=Plate
1, 1, 2, 3, 4
*Shell Section, elset=Plate, material=Leaf
0.65, 5
*End Part
*Assembly, name=A
*Instance, name=Block-1, part=Block
*End Instance
*Instance, name=Plate-1, part=Plate
10., 0., 0.
10., 0., 0., 10., 0., 1., 90.
*End Instance
*Node
1, 5., 5., 5.
*Nset, nset=RP
1
*Nset, nset=Tip, instance=Block-1
9
*Elset, elset=_Bottom_S1, internal, instance=Block-1
1
*Surface, type=ELEMENT, name=Bottom
_Bottom_S1, S1
*Surface, type=ELEMENT, name=PlateTop
Plate-1.Plate, SPOS
*MPC
LINK, RP, Tip
*End Assembly
*Amplitude, name=Ramp, definition=SMOOTH STEP
0.5, 0., 1.5, 1.
*Amplitude, name=Table
0., 0., 1., 2., 2., 3.
*Material, name=Leaf
*Density
1e-9,
*Anisotropic Hyperelastic, user, formulation=invariant,
 properties=4
1.0e-03, 20.0, 1.0e-4, 15.0
*Material, name=String
*Hyperelastic, OGDEN, N=1
2.0, 10.0, 1e-3
*Surface Interaction, name=Touch
1.,
*Friction
0.01,
*Surface Behavior, pressure-overclosure=HARD
*Boundary
Block-1.Bottom, ENCASTRE
*Step, name=Load, nlgeom=YES
*Static
0.1, 2.0
*Boundary, op=NEW, amplitude=Ramp
Block-1.9, 3, 3, -1.5
RP, 1, 2
*Dsload, amplitude=Table
Block-1.Top, P, 0.00567
*Contact Pair, interaction=Touch, mechanical constraint=KINEMATIC
Bottom, PlateTop
*Contact, op=NEW
*Contact Inclusions
Bottom,
*Contact Property Assignment
 , , Touch
*Output, field, variable=PRESELECT
*End Step
"""


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    path = tmp_path_factory.mktemp("deck") / "deck.inp"
    path.write_text(DECK)
    return read_model(path)


def test_nodes_of_all_blocks_and_instances_with_transform(model):
    assert model.nodes.shape == (9 + 4 + 1, 3)
    block = model.node_indices("Block-1.Block_Nodes")
    assert len(block) == 4
    assert model.nodes[model.node_indices("Block-1.7")[0]] == pytest.approx([1, 1, 1])
    # plate node (1, 1, 0): translated by (10, 0, 0), then turned 90 degrees about the z axis through (10, 0, 0)
    assert model.nodes[model.node_indices("Plate-1.3")[0]] == pytest.approx([9.0, 1.0, 0.0])
    assert model.nodes[model.node_indices("Plate-1.2")[0]] == pytest.approx([10.0, 1.0, 0.0])
    assert model.nodes[model.node_indices("1")[0]] == pytest.approx([5, 5, 5])
    with pytest.raises(KeyError):
        model.node_indices("Plate-1.99")


def test_elements_sets_and_generate(model):
    assert model.elements_by_type() == {"C3D8R": 1, "T3D2": 1, "S4R": 1}
    (brick,) = model.blocks_of_type("C3D8R")
    assert model.node_labels[brick.connectivity[0]].tolist() == [1, 2, 3, 4, 5, 6, 7, 8]
    assert brick.elset == "Block-1.Brick" and brick.scope == "Block-1"
    assert sorted(model.node_labels[model.node_set("block-1.bottom").indices]) == [1, 2, 3, 4]
    assert sorted(model.node_labels[model.node_set("Block-1.Odd").indices]) == [1, 3, 5, 7]
    assert len(model.element_set("Block-1.All").indices) == 2
    assert model.node_labels[model.node_set("Tip").indices].tolist() == [9]


def test_surfaces_sections_and_materials(model):
    top = model.surface("Block-1.Top")
    assert [f.face for f in top.faces] == ["S2"]
    assert model.surface("Bottom").faces[0].face == "S1"
    assert model.surface("PlateTop").faces[0].face == "SPOS"
    sections = {s.elset: s for s in model.sections}
    assert sections["Block-1.Chord"].area == 0.25 and sections["Block-1.Brick"].thickness is None
    assert sections["Plate-1.Plate"].thickness == 0.65 and sections["Plate-1.Plate"].integration_points == 5
    # the keyword line continued after a trailing comma keeps properties=4
    leaf = model.material("LEAF").option("anisotropic")
    assert leaf.parameters["properties"] == "4" and leaf.data == [1e-3, 20.0, 1e-4, 15.0]
    assert model.material("String").option("hyperelastic").data == [2.0, 10.0, 1e-3]


def test_amplitudes_conditions_loads_contact(model):
    ramp, table = model.amplitude("ramp"), model.amplitude("Table")
    assert ramp.definition == "SMOOTH STEP" and ramp.times.tolist() == [0.5, 1.5]
    assert table.definition == "TABULAR" and table.values.tolist() == [0.0, 2.0, 3.0]
    initial = model.boundary_conditions
    assert [(bc.first_dof, bc.value) for bc in initial] == [(d, 0.0) for d in range(1, 7)]
    assert sorted(model.node_labels[initial[0].nodes]) == [1, 2, 3, 4]
    (step,) = model.steps
    assert step.nlgeom and step.procedure == "static" and step.time_period == 2.0
    tip, rp = step.boundary_conditions
    assert (tip.first_dof, tip.last_dof, tip.value, tip.amplitude, tip.op) == (3, 3, -1.5, "Ramp", "NEW")
    assert (rp.first_dof, rp.last_dof, rp.value) == (1, 2, 0.0)
    (load,) = step.distributed_loads
    assert (load.surface, load.load_type, load.magnitude) == ("Block-1.Top", "P", 0.00567)
    (pair,) = step.contact_pairs
    assert pair.surfaces == ("Bottom", "PlateTop") and pair.interaction == "Touch"
    assert step.general_contact.inclusions == [("Bottom",)]
    assert model.interactions["TOUCH"].friction == 0.01
    (mpc,) = model.mpcs
    assert mpc.mpc_type == "LINK" and [len(n) for n in mpc.nodes] == [1, 1]


def test_ignored_keywords_are_listed_with_lines(model):
    names = {item.keyword for item in model.ignored}
    assert {"Heading", "Density", "Output"} <= names
    density = next(i for i in model.ignored if i.keyword == "Density")
    assert DECK.splitlines()[density.location.line - 1].startswith("*Density")


@pytest.mark.parametrize(("old", "new", "message"), [
    ("2, 9, 1\n", "2, 9, 77\n", "undefined node 77"),
    ("Brick, S2\n", "Brick, S7\n", "face S7"),
    ("1, 4, 1\n*Nset, nset=Odd", "1, 4, 0\n*Nset, nset=Odd", "GENERATE"),
    ("*Dsload, amplitude=Table", "*Dsload, amplitude=Nope", "unknown amplitude"),
    ("Block-1.9, 3, 3, -1.5", "Block-1.9, 7, 7, -1.5", "degree of freedom 7"),
    ("*Static\n", "*Cload\n", "Cload"),
    ("*Output, field", "*Frobnicate, field", "not supported"),
    ("Bottom, PlateTop", "Bottom, Nowhere", "unknown surface"),
    ("0.65, 5", "-0.65, 5", "positive thickness"),
    ("LINK, RP, Tip", "LINK, RP", "an MPC line is"),
    ("LINK, RP, Tip", "LINK, Tip, Tip", "joins a node to itself"),
    ("LINK, RP, Tip", "LINK, Tip, Block-1.Bottom", "1 and 4 node"),
])
def test_bad_input_names_file_line_and_keyword(tmp_path, old, new, message):
    assert old in DECK
    path = tmp_path / "bad.inp"
    path.write_text(DECK.replace(old, new, 1))
    with pytest.raises(AbaqusParseError, match=message) as info:
        read_model(path)
    assert "bad.inp:" in str(info.value)
    line = info.value.location.line
    assert 1 <= line <= DECK.count("\n") + 1


def test_link_mpc_pairs_a_node_set_with_one_node(tmp_path):
    """``LINK, p, a`` with a set p and one node a pairs every node of p with a (in set order)."""
    path = tmp_path / "links.inp"
    path.write_text(DECK.replace("LINK, RP, Tip", "LINK, Block-1.Bottom, RP", 1))
    model = read_model(path)
    (mpc,) = model.mpcs
    pairs = mpc.pairs()
    assert model.node_labels[pairs[:, 0]].tolist() == [1, 2, 3, 4]
    assert model.node_scopes[pairs[:, 1]].tolist() == [model.scopes.index("")] * 4
    assert model.node_labels[pairs[:, 1]].tolist() == [1] * 4
    assert mpc.location.line == DECK.splitlines().index("LINK, RP, Tip") + 1


def test_link_mpc_of_a_set_with_itself_names_the_data_line(tmp_path):
    path = tmp_path / "links.inp"
    path.write_text(DECK.replace("LINK, RP, Tip", "LINK, Block-1.Bottom, Block-1.Bottom", 1))
    with pytest.raises(AbaqusParseError, match="itself") as info:
        read_model(path)
    assert info.value.location.line == DECK.splitlines().index("LINK, RP, Tip") + 1


def test_redefined_element_keeps_last_definition_with_a_warning(tmp_path):
    path = tmp_path / "dup.inp"
    path.write_text("*Node\n1, 0, 0, 0\n2, 1, 0, 0\n3, 2, 0, 0\n*Element, type=T3D2\n1, 1, 2\n1, 2, 3\n")
    model = read_model(path)
    (block,) = model.element_blocks
    assert model.node_labels[block.connectivity].tolist() == [[2, 3]]
    assert model.warnings and model.warnings[0].location.line == 6


def test_node_set_of_an_element_set(tmp_path):
    path = tmp_path / "nodes_of.inp"
    path.write_text("*Node\n1, 0, 0, 0\n2, 1, 0, 0\n3, 2, 0, 0\n4, 3, 0, 0\n*Element, type=T3D2, elset=E\n"
                    "7, 2, 3\n8, 3, 4\n*Nset, nset=N, elset=E\n")
    model = read_model(path)
    assert sorted(model.node_labels[model.node_set("n").indices]) == [2, 3, 4]


def test_elements_may_be_named_by_a_set_before_they_are_defined(tmp_path):
    path = tmp_path / "forward.inp"
    path.write_text("*Node\n1, 0, 0, 0\n2, 1, 0, 0\n*Elset, elset=W\n 1,\n*Element, type=CONN3D2\n1, 1, 2\n")
    assert read_model(path).element_set("w").indices.tolist() == [0]


SMALL_BAD = {
    "*Node\n1,0,0,0\n2,1,0,0\n*Element, type=T3D2\n99999999999999999999999, 1, 2\n": "out of range",
    "*Node\n99999999999999999999999,0,0,0\n": "out of range",
    "*Node\n1,0,0,0\n*Nset, nset=A, generate\n1, 99999999999, 1\n": "more than",
    "*Node\n-1,0,0,0\n": "not positive",
    "*Node\n1,0,0,0\n*Node\n1,1,0,0\n": "already defined",
    "*Node\n1,0,0,0\n2,1,0,0\n*Element, type=T3D2\n1, 1,\n": "cut short",
    "*Node\n1,0,0,0\n2,1,0,0\n*Element, type=C3D8R\n1, 1, 2\n": "1 nodes|2 nodes",
    "*Amplitude, name=A\n0, 0, 1\n": "pairs",
    "*Amplitude, name=A, definition=SMOOTH STEP\n0, 0, 0, 1\n": "increase",
    "*Step\n*Static\n": "no \\*End Step",
    "*Part, name=P\n*Node\n1, 1e308, 0, 0\n*End Part\n*Assembly, name=A\n*Instance, name=I, part=P\n1e308, 0, 0\n"
    "*End Instance\n*End Assembly\n": "overflow",
    "*Part, name=P\n*Node\n1, 1, 0, 0\n*End Part\n*Assembly, name=A\n*Instance, name=I, part=P\n0,0,0\n"
    "0,0,0,0,0,0,90\n*End Instance\n*End Assembly\n": "coincide",
    "*Part, name=P\n*End Part\n*Assembly, name=A\n*Instance, name=I, part=Q\n*End Instance\n*End Assembly\n":
        "unknown part",
    "*Node\n1,0,0,0\n*Nset, nset=A, instance=I\n1\n": "only allowed in the assembly",
    "1, 2, 3\n": "before any keyword",
    "*Node\n1,0,0,0\n*Surface, name=S\nE, S1\n": "unknown element set",
    "*Material, name=M\n*Hyperelastic, OGDEN, N=-2\n1\n": "out of range",
    "*Density\n1\n": "outside a \\*Material",
    "*Node, system=C\n1, 1, 0, 0\n": "SYSTEM=R",
    "*Node\n1,0,0,0\n*Boundary\n1, 9\n": "degree of freedom 9",
    "*Material, name=M\n\x00": "NUL",
    "*Node, input=nodes.inp\n": "INPUT=",
}


@pytest.mark.parametrize(("text", "message"), list(SMALL_BAD.items()))
def test_small_bad_decks(tmp_path, text, message):
    path = tmp_path / "small.inp"
    path.write_text(text)
    with pytest.raises(AbaqusParseError, match=message) as info:
        read_model(path)
    assert "small.inp" in str(info.value)


def test_ignored_keywords_are_reported_once(tmp_path, caplog):
    path = tmp_path / "deck.inp"
    path.write_text(DECK)
    with caplog.at_level(logging.WARNING, logger="skvalve.io.abaqus.reader"):
        read_model(path)
    reports = [r for r in caplog.records if "not used by the implicit model" in r.getMessage()]
    assert len(reports) == 1 and "*Density x1" in reports[0].getMessage()


def test_read_materials_agrees_with_read_model(model):
    materials = read_materials(model.path)
    assert list(materials) == list(model.materials)
    for name, material in materials.items():
        assert material.options == model.materials[name].options
