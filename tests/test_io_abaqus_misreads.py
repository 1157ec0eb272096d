"""Silent misreads of the former material-only reader (issue 10), each fixed and pinned here.

Every test below failed on the reader before the rewrite (checked by running this file against the old
``skvalve/io/abaqus.py`` of commit b3e45e7): it either returned wrong numbers or raised something other
than a located :class:`AbaqusParseError`.
"""

import pytest

from skvalve.io.abaqus import AbaqusParseError, read_materials

OGDEN2 = "*Material, name=Chord\n*Hyperelastic, OGDEN, N=2\n{data}\n"


def _write(tmp_path, text, name="deck.inp"):
    path = tmp_path / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    return path


def test_file_cut_inside_the_last_number_is_an_error(tmp_path):
    # "1e-9" cut to "1" used to be read as a density of 1.0
    path = _write(tmp_path, "*Material, name=M\n*Density\n1")
    with pytest.raises(AbaqusParseError, match=r"deck.inp:3.*truncated"):
        read_materials(path)


@pytest.mark.parametrize(("keyword", "data"), [
    ("*Hyperelastic, OGDEN, N=3", "1., 2., 3., 4., 5., 6., 1e-3, 0."),  # 8 of 3N = 9
    ("*Anisotropic Hyperelastic, user, formulation=invariant, properties=4", "1e-3, 20., 1e-4"),
    ("*Density", ""),
])
def test_too_few_values_for_the_declared_count(tmp_path, keyword, data):
    path = _write(tmp_path, f"*Material, name=M\n{keyword}\n{data}\n*Material, name=N\n")
    with pytest.raises(AbaqusParseError, match="expected .* data values"):
        read_materials(path)


def test_blank_field_keeps_its_position(tmp_path):
    path = _write(tmp_path, OGDEN2.format(data="1.5, , 0.25, -4.0, 1e-3, 0"))
    assert read_materials(path)["Chord"].option("hyperelastic").data == [1.5, 0.0, 0.25, -4.0, 1e-3, 0.0]


@pytest.mark.parametrize("second", ["Leaf", "LEAF", "leaf"])
def test_duplicate_material_name_is_an_error(tmp_path, second):
    path = _write(tmp_path, f"*Material, name=Leaf\n*Density\n1.\n*Material, name={second}\n*Density\n2.\n")
    with pytest.raises(AbaqusParseError, match=r"deck.inp:4.*already defined at line 1"):
        read_materials(path)


@pytest.mark.parametrize("token", ["nan", "inf", "-Infinity", "1e999", "\u0661\u0662", "1_000"])
def test_non_numbers_are_rejected_with_their_line(tmp_path, token):
    path = _write(tmp_path, OGDEN2.format(data=f"1.5, 2.0, 0.25, {token}, 1e-3, 0"))
    with pytest.raises(AbaqusParseError, match=r"deck.inp:3"):
        read_materials(path)


def test_byte_order_mark_does_not_hide_the_first_material(tmp_path):
    path = _write(tmp_path, "*Material, name=First\n*Density\n1e-9\n".encode("utf-8-sig"))
    assert read_materials(path)["First"].option("density").data == [1e-9]


def test_include_is_read_relative_to_the_including_file(tmp_path):
    _write(tmp_path, "*Material, name=A\n*Density\n1.\n*Include, input=more/b.inp\n", "lib/a.inp")
    _write(tmp_path, "*Material, name=B\n*Density\n2.\n", "lib/more/b.inp")
    path = _write(tmp_path, "*Include, input=lib/a.inp\n*Material, name=C\n*Density\n3.\n")
    materials = read_materials(path)
    assert {name: m.option("density").data for name, m in materials.items()} == {"A": [1.0], "B": [2.0], "C": [3.0]}


def test_include_cycle_is_detected(tmp_path):
    _write(tmp_path, "*Include, input=b.inp\n", "a.inp")
    _write(tmp_path, "*Material, name=B\n*Include, input=a.inp\n", "b.inp")
    with pytest.raises(AbaqusParseError, match="cycle"):
        read_materials(tmp_path / "a.inp")


def test_missing_include_names_the_file(tmp_path):
    path = _write(tmp_path, "*Include, input=nowhere.inp\n")
    with pytest.raises(AbaqusParseError, match="nowhere.inp"):
        read_materials(path)


def test_keyword_line_continued_after_a_trailing_comma(tmp_path):
    path = _write(tmp_path, "*Material, name=Leaf\n*Anisotropic Hyperelastic, user, formulation=invariant,\n"
                            "  properties=4\n1e-3, 20., 1e-4, 15.\n")
    option = read_materials(path)["Leaf"].option("anisotropic")
    assert option.parameters["properties"] == "4" and option.data == [1e-3, 20.0, 1e-4, 15.0]


def test_latin1_byte_in_a_comment_is_harmless(tmp_path):
    path = _write(tmp_path, b"** r\xe9sum\xe9 of the model\n*Material, name=M\n*Density\n1e-9\n")
    assert read_materials(path)["M"].option("density").data == [1e-9]


def test_latin1_byte_in_data_names_the_line(tmp_path):
    path = _write(tmp_path, b"** ok\n*Material, name=M\n*Density\n1e-9\xb5\n")
    with pytest.raises(AbaqusParseError, match=r"deck.inp:4"):
        read_materials(path)
