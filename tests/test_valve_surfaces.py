"""Contact surfaces of Abaqus inputs on the valve model's hexes (skvalve.valve.surfaces): a flat synthetic shell deck
against closed forms (face counts, positions and normals of both skins and the rim), and the shipped inputs against
counts and faces taken from the input's own connectivity. The shipped-input tests skip when the data are absent
(Texas TriValve, Mathur et al. 2022: 1.0 CC BY-NC-SA 4.0, 1.1 CC BY 4.0)."""

import logging

import numpy as np
import pytest

from skvalve.fem.contact import SurfaceContact
from skvalve.fem.space import Space
from skvalve.io.abaqus import HEX_FACE_NODES, read_model, trivalve_inputs
from skvalve.valve.model import valve_model
from skvalve.valve.surfaces import CONTACT_SURFACES_1_0, contact_surface, contact_surface_names, thinnest_stack

NX, NY, THICKNESS, LAYERS = 3, 2, 0.2, 2


def shell_deck(face: str = "SPOS", contact: bool = True, second_plate_at: float | None = None) -> str:
    """NX x NY unit S4R quads in the plane z = 0 (normals +z), one element-face surface ``Skin``; optionally a copy
    of the plate at height ``second_plate_at`` (in the same surface)."""
    lines = ["*Part, name=P", "*Node"]
    heights = [0.0] if second_plate_at is None else [0.0, second_plate_at]
    per_plate = (NX + 1) * (NY + 1)
    for k, z in enumerate(heights):
        for j in range(NY + 1):
            lines += [f"{1 + k * per_plate + j * (NX + 1) + i}, {float(i)}, {float(j)}, {z!r}" for i in range(NX + 1)]
    lines.append("*Element, type=S4R, elset=Leaf")
    for k in range(len(heights)):
        for j in range(NY):
            for i in range(NX):
                a = 1 + k * per_plate + j * (NX + 1) + i
                lines.append(f"{1 + k * NX * NY + j * NX + i}, {a}, {a + 1}, {a + NX + 2}, {a + NX + 1}")
    lines += ["*Shell Section, elset=Leaf, material=M", f"{THICKNESS}, 5", "*End Part",
              "*Assembly, name=A", "*Instance, name=I, part=P", "*End Instance",
              "*Surface, type=ELEMENT, name=Skin", f"I.Leaf, {face}", "*End Assembly",
              "*Material, name=M",
              "*Anisotropic Hyperelastic, user, formulation=invariant, type=compressible, properties=4",
              "0.001, 20., 0.0001, 15.", "*Surface Interaction, name=Touch", "*Friction", "0.001,",
              "*Step, name=Close", "*Static", "0.1, 1.0"]
    lines += ["*Contact Pair, interaction=Touch", "Skin,"] if contact else []
    return "\n".join([*lines, "*End Step"]) + "\n"


def _build(tmp_path, **kwargs):
    path = tmp_path / "shells.inp"
    path.write_text(shell_deck(**kwargs))
    abaqus = read_model(path)
    return abaqus, valve_model(abaqus, layers=LAYERS)


def _normals_and_centres(surface, X):
    Q = X[surface.quads]
    normal = np.cross(Q[:, 2] - Q[:, 0], Q[:, 3] - Q[:, 1])
    return normal / np.linalg.norm(normal, axis=1, keepdims=True), Q.mean(axis=1)


def test_double_sided_shell_surface_is_both_skins_and_the_rim(tmp_path):
    abaqus, model = _build(tmp_path)
    assert contact_surface_names(abaqus) == ("Skin",)
    surface = contact_surface(abaqus, model)
    perimeter_edges = 2 * (NX + NY)
    assert surface.quads.shape == (2 * NX * NY + LAYERS * perimeter_edges, 4)
    n, c = _normals_and_centres(surface, model.mesh.p.T)
    top, bottom = np.isclose(c[:, 2], THICKNESS / 2), np.isclose(c[:, 2], -THICKNESS / 2)
    assert top.sum() == bottom.sum() == NX * NY
    np.testing.assert_allclose(n[top], [[0, 0, 1]] * NX * NY, atol=1e-12)       # SPOS: away from the stack, +z
    np.testing.assert_allclose(n[bottom], [[0, 0, -1]] * NX * NY, atol=1e-12)   # SNEG: -z
    rim = ~(top | bottom)
    outward = np.zeros_like(c)
    outward[np.isclose(c[:, 0], 0), 0], outward[np.isclose(c[:, 0], NX), 0] = -1.0, 1.0
    outward[np.isclose(c[:, 1], 0), 1], outward[np.isclose(c[:, 1], NY), 1] = -1.0, 1.0
    assert np.all(np.isclose(c[rim, 0], 0) | np.isclose(c[rim, 0], NX) | np.isclose(c[rim, 1], 0)
                  | np.isclose(c[rim, 1], NY))
    np.testing.assert_allclose(n[rim], outward[rim], atol=1e-12)
    # the rim covers the whole thickness: the side faces' area is perimeter x thickness
    Q = model.mesh.p.T[surface.quads]
    area = 0.5 * np.linalg.norm(np.cross(Q[:, 2] - Q[:, 0], Q[:, 3] - Q[:, 1]), axis=1)
    assert area[rim].sum() == pytest.approx(2 * (NX + NY) * THICKNESS, rel=1e-12)
    assert area[~rim].sum() == pytest.approx(2 * NX * NY, rel=1e-12)
    # every face is a boundary facet of the mesh
    boundary = {tuple(sorted(f)) for f in model.mesh.facets[:, model.mesh.boundary_facets()].T.tolist()}
    assert all(tuple(sorted(q)) in boundary for q in surface.quads.tolist())


@pytest.mark.parametrize(("face", "z"), [("SPOS", 1.0), ("SNEG", -1.0)])
def test_single_sided_shell_surface_keeps_the_written_side(tmp_path, face, z):
    abaqus, model = _build(tmp_path, face=face)
    surface = contact_surface(abaqus, model, double_sided=False)
    n, c = _normals_and_centres(surface, model.mesh.p.T)
    assert surface.quads.shape == (NX * NY, 4)
    np.testing.assert_allclose(c[:, 2], z * THICKNESS / 2, atol=1e-12)
    np.testing.assert_allclose(n, [[0, 0, z]] * NX * NY, atol=1e-12)


def test_the_two_skins_are_not_contact_within_the_thinnest_stack(tmp_path):
    """The skins of one stack are a thickness apart with opposing normals: a penetration depth above it sees the
    unloaded shell in contact with itself; a quarter of :func:`thinnest_stack` sees nothing."""
    abaqus, model = _build(tmp_path)
    assert thinnest_stack(model, abaqus) == pytest.approx(THICKNESS, rel=1e-12)
    surface = contact_surface(abaqus, model)
    space = Space(model.mesh)
    u = np.zeros(space.n_dofs)
    deep = SurfaceContact(space, surface, 1.0, max_penetration=1.5 * THICKNESS, exclude_rings=1)
    assert deep.active_pairs(u).size > 0
    shallow = SurfaceContact(space, surface, 1.0, max_penetration=0.25 * thinnest_stack(model, abaqus), exclude_rings=1)
    assert shallow.active_pairs(u).size == 0


@pytest.mark.parametrize("overlap", [0.01, -0.01])
def test_two_stacked_shell_plates_touch_on_their_facing_skins(tmp_path, overlap):
    """A second plate at height h - overlap: its SNEG skin dips ``overlap`` into the first plate's SPOS skin. The
    written surface is SPOS only; the double-sided mapping finds the contact, every pair joins the two facing skins
    with gap -overlap, and the resultant on the upper plate is penalty x overlap x (the tributary areas of both
    skins, two passes); a positive gap (overlap < 0) gives no pair."""
    abaqus, model = _build(tmp_path, second_plate_at=THICKNESS - overlap)
    surface = contact_surface(abaqus, model)
    space = Space(model.mesh)
    penalty = 2.0
    contact = SurfaceContact(space, surface, penalty, max_penetration=0.25 * thinnest_stack(model, abaqus),
                             smoothing=0.0)
    u = np.zeros(space.n_dofs)
    pairs = contact.active_pairs(u)
    if overlap < 0:
        assert pairs.size == 0
        return
    X = model.mesh.p.T
    lower_top, upper_bottom = THICKNESS / 2, THICKNESS / 2 - overlap
    on = {z: np.flatnonzero(np.isclose(X[:, 2], z)) for z in (lower_top, upper_bottom)}
    assert np.array_equal(np.unique(pairs.node), np.union1d(on[lower_top], on[upper_bottom]))
    triangle_z = X[surface.triangles[pairs.triangle]][:, :, 2]
    node_z = X[pairs.node, 2]
    assert np.all(np.isclose(triangle_z, np.where(np.isclose(node_z, lower_top), upper_bottom, lower_top)[:, None]))
    np.testing.assert_allclose(pairs.gap, -overlap, rtol=1e-12)
    force = contact.assemble(u, 0.0, False, None).internal[: space.n_u].reshape(-1, 3)
    upper = np.unique(model.mesh.t[:, model.element_source >= NX * NY])  # hexes of the second plate's shells
    areas = np.zeros(X.shape[0])
    areas[surface.nodes] = surface.nodal_area
    expected = penalty * overlap * (areas[on[lower_top]].sum() + areas[on[upper_bottom]].sum())
    assert -force[upper, 2].sum() == pytest.approx(expected, rel=1e-12)  # pushes the upper plate up
    assert force[:, 2].sum() == pytest.approx(0.0, abs=1e-14)


def test_inputs_without_contact_have_no_default_surfaces(tmp_path):
    abaqus, model = _build(tmp_path, contact=False)
    with pytest.raises(ValueError, match="no contact surfaces"):
        contact_surface(abaqus, model)
    assert contact_surface(abaqus, model, names=["Skin"]).quads.shape[0] > 0


INPUTS = trivalve_inputs()


def _read(key):
    if key not in INPUTS:
        pytest.skip(f"Texas TriValve {key} input not found (../shared/data)")
    logging.getLogger("skvalve.io.abaqus.reader").setLevel(logging.ERROR)
    abaqus = read_model(INPUTS[key])
    return abaqus, valve_model(abaqus)


def _check_outward_and_on_the_boundary(surface, model):
    mesh = model.mesh
    boundary = {tuple(sorted(f)) for f in mesh.facets[:, mesh.boundary_facets()].T.tolist()}
    assert all(tuple(sorted(q)) in boundary for q in surface.quads.tolist())
    # the hex owning each face: the facet's only neighbour element
    lookup = {tuple(sorted(f)): k for k, f in enumerate(mesh.facets.T.tolist())}
    facets = np.array([lookup[tuple(sorted(q))] for q in surface.quads.tolist()])
    owner = mesh.f2t[0, facets]
    X = mesh.p.T
    n, c = _normals_and_centres(surface, X)
    assert np.all(np.einsum("ij,ij->i", n, c - X[mesh.t[:, owner].T].mean(axis=1)) > 0)


@pytest.mark.parametrize("key", ["1.1-healthy", "1.1-diseased"])
def test_shipped_shell_valves_contact_surface(key):
    """Both skins of every SPOS shell and the rim along the free edges (counted here from the input's quads), 4
    layers; the SPOS skin is the model's pressure surface (found by the model builder's own facet search)."""
    abaqus, model = _read(key)
    assert [name.upper() for name in contact_surface_names(abaqus)] == ["LEAFLET_SURFACES"]
    assert {g.face for g in abaqus.surface("LEAFLET_SURFACES").faces} == {"SPOS"}
    shells = np.vstack([b.connectivity for b in abaqus.element_blocks if b.element_type == "S4R"])
    edges = np.sort(np.stack([shells, np.roll(shells, -1, axis=1)], axis=2).reshape(-1, 2), axis=1)
    _, uses = np.unique(edges, axis=0, return_counts=True)
    free_edges = int(np.sum(uses == 1))
    layers = model.mesh.nelements // shells.shape[0]
    surface = contact_surface(abaqus, model)
    assert surface.quads.shape[0] == 2 * shells.shape[0] + layers * free_edges
    _check_outward_and_on_the_boundary(surface, model)
    assert 0.6 < thinnest_stack(model, abaqus) <= 0.65 + 1e-9  # section thickness 0.65 mm, thinner where curved
    spos = contact_surface(abaqus, model, double_sided=False)
    lookup = {tuple(sorted(f)): k for k, f in enumerate(model.mesh.facets.T.tolist())}
    facets = np.sort([lookup[tuple(sorted(q))] for q in spos.quads.tolist()])
    np.testing.assert_array_equal(facets, np.sort(model.pressures[0].facets))


def test_shipped_brick_valve_contact_surface():
    """1.0 diseased: the brick faces of LEAFLET_SURFACES_INNER and LEAFLET_RIM_TIP, taken from the input's own
    connectivity and node numbers, are the surface's faces (shared faces once), all outward."""
    abaqus, model = _read("1.0-diseased")
    surface = contact_surface(abaqus, model, names=CONTACT_SURFACES_1_0)
    assert [name.upper() for name in contact_surface_names(abaqus)] == list(CONTACT_SURFACES_1_0)
    conn = {}
    for block in abaqus.element_blocks:
        conn.update(zip(block.indices.tolist(), block.connectivity, strict=True))
    expected = {tuple(sorted(conn[e][list(HEX_FACE_NODES[g.face])].tolist()))
                for name in CONTACT_SURFACES_1_0 for g in abaqus.surface(name).faces for e in g.elements.tolist()}
    found = {tuple(sorted(model.vertex_source[q].tolist())) for q in surface.quads.tolist()}
    assert found == expected and surface.quads.shape[0] == len(expected)
    _check_outward_and_on_the_boundary(surface, model)


def test_the_pressure_loaded_skins_join_the_brick_contact_surface():
    """1.0 diseased: the inner skins and rim tips together with the skin the input loads with pressure
    (``Leaflet_Surfaces_Outer``: the penalty reference of ``benchmarks/contact_ipc.py``) are the union of both
    surfaces, one face per element listed; with a 0.2 mm search depth the two skins of a leaflet (0.39 mm apart) never
    pair in the open valve."""
    abaqus, model = _read("1.0-diseased")
    assert {load.surface.upper() for load in model.pressures} == {"LEAFLET_SURFACES_OUTER"}
    loaded = tuple(dict.fromkeys(load.surface for load in model.pressures))
    both = contact_surface(abaqus, model, CONTACT_SURFACES_1_0 + loaded)
    inner = contact_surface(abaqus, model, CONTACT_SURFACES_1_0)
    outer = contact_surface(abaqus, model, ["Leaflet_Surfaces_Outer"])

    def keys(quads):
        return {tuple(sorted(quad)) for quad in quads.tolist()}

    assert keys(both.quads) == keys(inner.quads) | keys(outer.quads) and len(keys(both.quads)) == both.quads.shape[0]
    listed = sum(len(group.elements) for group in abaqus.surface("Leaflet_Surfaces_Outer").faces)
    assert len(keys(outer.quads)) == listed > 0
    _check_outward_and_on_the_boundary(both, model)
    space = Space(model.mesh)
    contact = SurfaceContact(space, both, 1.0, max_penetration=0.2)
    assert contact.active_pairs(np.zeros(space.n_dofs)).size == 0
