"""Valve geometry measures against closed forms, on the Texas TriValve 1.0 diseased input, and the closure
measures of the 1.1 shell inputs against the inputs' own shells measured independently here.

Closed forms: inscribed n-gon areas of a circle and an ellipse (n/2 R^2 sin(2 pi/n), n/2 a b sin(2 pi/n)),
rigidly moved and saddle-warped loops, planar quads in a tilted plane (shoelace in the plane), the
faceted cylinder (n rectangles of chord width 2 R sin(theta/2n)), the bilinear hyperbolic-paraboloid
patch z = x y (area by independent adaptive quadrature), and offset cylinders (radius R + d).
"""

import logging

import numpy as np
import pytest
from scipy import integrate
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from skvalve.io.abaqus import read_model, trivalve_inputs
from skvalve.papers.mathur2022.data import LEAFLET_THICKNESS, TABLE2_AREAS
from skvalve.valve.geometry import (
    annulus_nodes,
    boundary_loops,
    centre_region,
    face_areas,
    leaflet_surfaces,
    loop_area,
    offset_points,
    orifice_area,
    surface_area,
    valve_areas,
)
from skvalve.valve.model import valve_model
from skvalve.valve.outputs import abaqus_positions, closure_measures
from skvalve.valve.setup import valve_setup

ROTATION = Rotation.from_rotvec([0.3, -1.1, 0.7]).as_matrix()
SHIFT = np.array([4.0, -2.0, 9.0])


def _ellipse(a, b, n, warp=0.0):
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.column_stack([a * np.cos(t), b * np.sin(t), warp * np.cos(2 * t)])


def _ring(radii, n):
    """Quad mesh between concentric circles: points and faces."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    points = np.concatenate([np.column_stack([r * np.cos(t), r * np.sin(t), np.zeros(n)]) for r in radii])
    faces = [[i * n + j, i * n + (j + 1) % n, (i + 1) * n + (j + 1) % n, (i + 1) * n + j]
             for i in range(len(radii) - 1) for j in range(n)]
    return points, np.array(faces)


def _cylinder(radius, angle, height, n, rows=3, closed=False):
    count = n if closed else n + 1
    t = np.linspace(0, angle, count, endpoint=not closed)
    z = np.linspace(0, height, rows + 1)
    points = np.array([[radius * np.cos(a), radius * np.sin(a), h] for h in z for a in t])
    faces = [[r * count + j, r * count + (j + 1) % count, (r + 1) * count + (j + 1) % count, (r + 1) * count + j]
             for r in range(rows) for j in range(n)]
    return points, np.array(faces)


@pytest.mark.parametrize("n", [8, 50, 400])
def test_circle_and_ellipse_loops(n):
    exact = 0.5 * n * np.sin(2 * np.pi / n)
    assert loop_area(_ellipse(3.0, 3.0, n)) == pytest.approx(9.0 * exact, rel=1e-12)
    assert loop_area(_ellipse(5.0, 2.0, n)) == pytest.approx(10.0 * exact, rel=1e-12)


def test_loop_area_converges_to_pi_r_squared_at_second_order():
    errors = [abs(loop_area(_ellipse(2.0, 2.0, n)) - 4 * np.pi) for n in (32, 64, 128)]
    orders = np.log2(np.array(errors[:-1]) / errors[1:])
    assert orders == pytest.approx([2.0, 2.0], abs=0.01)


def test_loop_area_is_that_of_the_best_fit_plane():
    loop = _ellipse(5.0, 2.0, 60)
    moved = loop @ ROTATION.T + SHIFT
    assert loop_area(moved) == pytest.approx(loop_area(loop), rel=1e-12)
    # a saddle (z = h cos 2t) has best-fit plane z = 0: its orifice is the flat ellipse's
    saddle = _ellipse(5.0, 2.0, 60, warp=1.5) @ ROTATION.T + SHIFT
    assert loop_area(saddle) == pytest.approx(loop_area(loop), rel=1e-12)
    order = np.random.default_rng(0).permutation(60)
    assert loop_area(moved[order], np.argsort(order)) == pytest.approx(loop_area(loop), rel=1e-12)


def test_planar_quads_in_a_tilted_plane():
    rng = np.random.default_rng(1)
    quads = []
    while len(quads) < 20:  # convex quads: corners on an ellipse, no gap of half a turn or more
        angles = np.sort(rng.uniform(0, 2 * np.pi, 4))
        if np.max(np.diff(np.append(angles, angles[0] + 2 * np.pi))) >= 0.9 * np.pi:
            continue
        a, b = rng.uniform(0.5, 2.0, 2)
        quads.append(np.column_stack([a * np.cos(angles), b * np.sin(angles), np.zeros(4)]))
    quads = np.array(quads)
    x, y = quads[..., 0], quads[..., 1]
    shoelace = 0.5 * np.abs(np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1))
    points = quads.reshape(-1, 3) @ ROTATION.T + SHIFT
    faces = np.arange(len(points)).reshape(-1, 4)
    assert face_areas(points, faces) == pytest.approx(shoelace, rel=1e-12)
    triangles = np.concatenate([faces[:, [0, 1, 2]], faces[:, [0, 2, 3]]])
    assert surface_area(points, triangles) == pytest.approx(shoelace.sum(), rel=1e-12)


def test_faceted_cylinder_patch():
    radius, angle, height = 3.0, 1.2, 2.0
    areas = []
    for n in (10, 20, 40):
        points, faces = _cylinder(radius, angle, height, n)
        areas.append(surface_area(points, faces))
        assert areas[-1] == pytest.approx(height * n * 2 * radius * np.sin(angle / (2 * n)), rel=1e-12)
    errors = np.abs(np.array(areas) - radius * angle * height)
    assert np.log2(errors[:-1] / errors[1:]) == pytest.approx([2.0, 2.0], abs=0.02)


def test_curved_bilinear_quad():
    corners = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 1], [0, 1, 0]])  # exactly the surface z = x y
    exact, _ = integrate.dblquad(lambda y, x: np.sqrt(1 + x * x + y * y), 0, 1, 0, 1, epsabs=1e-12)
    assert surface_area(corners, np.array([[0, 1, 2, 3]])) == pytest.approx(exact, rel=2e-5)


def test_boundary_loops_and_orifice_of_a_ring():
    points, faces = _ring([1.0, 2.0, 3.5], 48)
    loops = boundary_loops(faces)
    assert sorted(len(loop) for loop in loops) == [48, 48]
    outer = 0.5 * 48 * np.sin(2 * np.pi / 48) * 3.5**2
    moved = points @ ROTATION.T + SHIFT
    assert orifice_area(moved, faces, moved[-48:]) == pytest.approx(outer, rel=1e-12)
    assert orifice_area(moved, faces, moved[:5]) == pytest.approx(outer / 3.5**2, rel=1e-12)


def test_offset_of_a_closed_cylinder_scales_its_area():
    points, faces = _cylinder(2.0, 2 * np.pi, 1.0, 64, closed=True)
    base = surface_area(points, faces)
    for distance in (0.3, -0.3):
        # the faces wind with outward normals, so +distance moves outwards: radius 2 + distance
        assert surface_area(offset_points(points, faces, distance), faces) == pytest.approx(
            base * (2.0 + distance) / 2.0, rel=1e-12)


def test_centre_region_of_a_square_is_a_central_disc():
    n = 60
    grid = np.linspace(-1, 1, n + 1)
    points = np.array([[x, y, 0.0] for y in grid for x in grid])
    faces = np.array([[j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i]
                      for j in range(n) for i in range(n)])
    chosen = centre_region(points @ ROTATION.T + SHIFT, faces, fraction=0.1)
    area = face_areas(points, faces[chosen]).sum()
    assert 0.4 <= area <= 0.4 + (2 / n) ** 2
    centroids = points[faces[chosen]].mean(axis=1)
    assert np.linalg.norm(centroids.mean(axis=0)) < 2 / n
    radius = np.sqrt(0.4 / np.pi)
    assert np.linalg.norm(centroids, axis=1).max() == pytest.approx(radius, abs=2 / n)


INPUTS = trivalve_inputs()


@pytest.mark.skipif("1.0-diseased" not in INPUTS, reason="Texas TriValve 1.0 diseased input not present")
def test_trivalve_diseased_orifice_and_leaflets():
    """Texas TriValve 1.0 (Mathur et al. 2022, CC BY-NC-SA 4.0), undeformed diseased valve."""
    logging.getLogger("skvalve.io.abaqus.reader").setLevel(logging.ERROR)
    model = read_model(INPUTS["1.0-diseased"])
    surfaces = leaflet_surfaces(model)
    areas = valve_areas(surfaces, model.nodes, annulus_nodes(model))
    # Table 2 is at end-systole, but the diseased annulus is held in place (zero-displacement BCs on its
    # atrial nodes): the undeformed mid-surface orifice must match Table 2 to within 2 %
    assert areas.orifice["mid"] == pytest.approx(TABLE2_AREAS["orifice"].diseased, rel=0.02)
    assert areas.orifice["atrial"] < areas.orifice["mid"] < areas.orifice["ventricular"]
    # the annulus found geometrically on the atrial surface is the set of nodes held by the BCs
    fixed = np.unique(np.concatenate([bc.nodes for bc in model.steps[0].boundary_conditions
                                      if bc.amplitude == "Amp-1"]))
    atrial = np.concatenate([s.atrial for s in surfaces.values()])
    annulus = min(boundary_loops(atrial), key=lambda loop: len(np.setdiff1d(loop, fixed)))
    assert sorted(annulus) == sorted(fixed)
    # Steiner: a 0.78 mm layer's mid-surface area is the mean of its faces' areas to O(t^2 K)
    for leaflet in areas.leaflet.values():
        mean = 0.5 * (leaflet["atrial"] + leaflet["ventricular"])
        assert leaflet["mid"] == pytest.approx(mean, rel=2e-3)
        assert leaflet["atrial"] < leaflet["mid"] < leaflet["ventricular"]
    # paper section 2.8: leaflet thickness (ventricular to atrial face of each brick column)
    for surface in surfaces.values():
        ventricular = model.nodes[surface.ventricular].mean(axis=1)
        atrial = model.nodes[surface.atrial].mean(axis=1)
        assert np.median(cKDTree(atrial).query(ventricular)[0]) == pytest.approx(LEAFLET_THICKNESS, abs=0.01)
    for name, faces in areas.centre_faces.items():
        assert areas.centre_area[name] == pytest.approx(0.1 * areas.leaflet[name]["mid"], rel=0.05)
        assert len(faces) > 10


def _band_deck(radius, thickness, height, n, rows, layers):
    """A cylindrical band of bricks (``layers`` through the thickness, outermost = pressure-loaded S1),
    split into three leaflets of n/3 sectors each; annulus node set at z = 0."""
    def node(i, j, k):
        return 1 + i * n * (rows + 1) + k * n + (j % n)

    lines = ["*Node"]
    for i in range(layers + 1):
        r = radius + thickness / 2 - i * thickness / layers
        for k in range(rows + 1):
            for j in range(n):
                x, y = (float(v) for v in r * np.array([np.cos(2 * np.pi * j / n), np.sin(2 * np.pi * j / n)]))
                lines.append(f"{node(i, j, k)}, {x!r}, {y!r}, {height * k / rows!r}")
    lines.append("*Element, type=C3D8R")
    sectors = {name: [] for name in ("Anterior", "Posterior", "Septal")}
    outer = []
    label = 0
    for i in range(layers):
        for k in range(rows):
            for j in range(n):
                label += 1
                bottom = [node(i, j, k), node(i, j, k + 1), node(i, j + 1, k + 1), node(i, j + 1, k)]
                top = [node(i + 1, j, k), node(i + 1, j, k + 1), node(i + 1, j + 1, k + 1), node(i + 1, j + 1, k)]
                lines.append(", ".join(str(v) for v in [label, *bottom, *top]))
                sectors[list(sectors)[3 * j // n]].append(label)
                if i == 0:
                    outer.append(label)
    for name, labels in sectors.items():
        lines += [f"*Elset, elset={name}_Leaflet_Elements", *(f"{v}," for v in labels)]
    lines += ["*Elset, elset=Outer", *(f"{v}," for v in outer), "*Surface, name=Ventricular", "Outer, S1",
              "*Nset, nset=Annular_Nodes", *(f"{node(i, j, 0)}," for i in range(layers + 1) for j in range(n)),
              "*Step", "*Static", "*Dsload", "Ventricular, P, 0.005", "*End Step"]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("layers", [3, 4])
def test_leaflet_surfaces_of_a_brick_band(tmp_path, layers):
    radius, thickness, height, n, rows = 10.0, 0.8, 6.0, 24, 4
    path = tmp_path / "band.inp"
    path.write_text(_band_deck(radius, thickness, height, n, rows, layers))
    logging.getLogger("skvalve.io.abaqus.reader").setLevel(logging.ERROR)
    model = read_model(path)
    surfaces = leaflet_surfaces(model)
    for scale in (1.0, 1.1):  # the reference and a uniformly dilated configuration
        areas = valve_areas(surfaces, scale * model.nodes, annulus_nodes(model))
        for which, r in (("ventricular", radius + thickness / 2), ("mid", radius), ("atrial", radius - thickness / 2)):
            band = scale**2 * height * n * 2 * r * np.sin(np.pi / n)  # faceted cylinder of radius r
            assert areas.total(which) == pytest.approx(band, rel=1e-12)
            assert areas.leaflet["Septal"][which] == pytest.approx(band / 3, rel=1e-12)
            assert areas.orifice[which] == pytest.approx(scale**2 * 0.5 * n * r**2 * np.sin(2 * np.pi / n), rel=1e-12)


def _shell_band_deck(radius, thickness, height, n, rows, triangles=False):
    """A cylindrical band of S4R quads (or S3 halves of them) in three leaflet sectors, annulus at z = 0, a
    Lee-Sacks (VUANISO_ISO) material; returns the deck and the element labels of each sector."""
    lines = ["*Node"]
    for k in range(rows + 1):
        for j in range(n):
            x, y = (float(v) for v in radius * np.array([np.cos(2 * np.pi * j / n), np.sin(2 * np.pi * j / n)]))
            lines.append(f"{1 + k * n + j}, {x!r}, {y!r}, {height * k / rows!r}")
    lines.append("*Element, type=S3" if triangles else "*Element, type=S4R")
    names = ("Anterior", "Posterior", "Septal")
    sectors = {name: [] for name in names}
    for k in range(rows):
        for j in range(n):
            label = 1 + k * n + j
            corners = [1 + k * n + j, 1 + k * n + (j + 1) % n, 1 + (k + 1) * n + (j + 1) % n, 1 + (k + 1) * n + j]
            pieces = [(label, corners[:3]), (label + rows * n, [corners[0], *corners[2:]])] if triangles else \
                [(label, corners)]
            for number, nodes in pieces:
                lines.append(", ".join(str(v) for v in [number, *nodes]))
                sectors[names[3 * j // n]].append(number)
    for name, labels in sectors.items():
        lines += [f"*Elset, elset={name}_Leaflet_Elements", *(f"{v}," for v in labels),
                  f"*Shell Section, elset={name}_Leaflet_Elements, material=M", f"{thickness}, 5"]
    lines += ["*Material, name=M", "*Anisotropic Hyperelastic, user, formulation=invariant, properties=4",
              "0.001, 20.0, 0.000124, 4.57",
              "*Surface, name=Leaflets", *(f"{name}_Leaflet_Elements, SPOS" for name in names),
              "*Nset, nset=Annular_Nodes", *(f"{j + 1}," for j in range(n)),
              "*Step", "*Static", "*Dsload", "Leaflets, P, 0.003", "*End Step"]
    return "\n".join(lines) + "\n", sectors


@pytest.mark.parametrize("triangles", [False, True])
def test_leaflet_surfaces_of_a_shell_band(tmp_path, triangles):
    """S4R band: the mid surface is the shells', SPOS (outward here) the ventricular side at +t/2. The same band
    of S3 triangles (each rectangle split in two): the same mid-surface and orifice areas."""
    radius, thickness, height, n, rows = 10.0, 0.65, 6.0, 24, 4
    deck, sectors = _shell_band_deck(radius, thickness, height, n, rows, triangles)
    path = tmp_path / "shells.inp"
    path.write_text(deck)
    logging.getLogger("skvalve.io.abaqus.reader").setLevel(logging.ERROR)
    model = read_model(path)
    surfaces = leaflet_surfaces(model)
    for name, surface in surfaces.items():  # each face knows its shell element
        labels = np.concatenate([b.labels for b in model.element_blocks])[surface.elements]
        assert sorted(labels.tolist()) == sorted(sectors[name])
    areas = valve_areas(surfaces, model.nodes, annulus_nodes(model))
    # triangles: the offset surfaces move along unequally weighted nodal normals, only the mid surface is exact
    checked = [("mid", radius)] if triangles else \
        [("ventricular", radius + thickness / 2), ("mid", radius), ("atrial", radius - thickness / 2)]
    for which, r in checked:
        assert areas.total(which) == pytest.approx(height * n * 2 * r * np.sin(np.pi / n), rel=1e-12)
        assert areas.orifice[which] == pytest.approx(0.5 * n * r**2 * np.sin(2 * np.pi / n), rel=1e-12)


# ----------------------------------------------------------------------------------------------------
# Texas TriValve 1.1 (Mathur et al. 2022 data, CC BY-NC-SA 4.0): shell midsurfaces extruded into hexes.
# closure_measures against the input's own shell connectivity, re-read and measured here independently.

SHELL_INPUTS = [key for key in ("1.1-healthy", "1.1-diseased") if key in INPUTS]
GAUSS_POINTS, GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(3)


@pytest.fixture(scope="module", params=SHELL_INPUTS or [pytest.param(None, marks=pytest.mark.skip(
    reason="Texas TriValve 1.1 inputs not present"))])
def shell_valve(request):
    """(valve_setup of one 1.1 input, the input read independently, its leaflet shell quads by leaflet)."""
    logging.getLogger("skvalve.io.abaqus.reader").setLevel(logging.ERROR)
    path = INPUTS[request.param]
    model = read_model(path)
    rows = {int(e): row for block in model.element_blocks
            for e, row in zip(block.indices, block.connectivity, strict=True)}
    quads = {}
    for leaflet in ("Anterior", "Posterior", "Septal"):
        (elements,) = [s.indices for key, s in model.element_sets.items()
                       if key.endswith(f".{leaflet.upper()}_LEAFLET_ELEMENTS")]
        quads[leaflet] = np.array([rows[int(e)] for e in elements])
    return valve_setup(path), model, quads


def _bilinear_tangent_cross(corners):
    """x_xi x x_eta of the bilinear quads x = a + b xi + c eta + d xi eta at the 3 x 3 Gauss points: (m, 9, 3)."""
    x0, x1, x2, x3 = (corners[:, k] for k in range(4))
    b, c, d = (-x0 + x1 + x2 - x3) / 4, (-x0 - x1 + x2 + x3) / 4, (x0 - x1 + x2 - x3) / 4
    return np.stack([np.cross(b + d * eta, c + d * xi) for xi in GAUSS_POINTS for eta in GAUSS_POINTS], axis=1)


def _quad_area(cross, cofactor=None):
    """Areas sum_gauss w |cof(F) (X_xi x X_eta)| of quads (reference tangents, linear map F)."""
    weights = np.outer(GAUSS_WEIGHTS, GAUSS_WEIGHTS).ravel()
    cofactor = np.eye(3) if cofactor is None else cofactor
    return (np.linalg.norm(cross @ cofactor.T, axis=2) * weights).sum(axis=1)


def _annulus_loop(model, quads):
    """The Annular_Nodes set ordered by angle about its centroid in its best-fit plane; checked to be a loop of
    free edges of the leaflet shells. Returns (loop node indices, unit normal of the plane)."""
    (annulus,) = [s.indices for key, s in model.node_sets.items() if key.endswith(".ANNULAR_NODES")]
    points = model.nodes[annulus]
    centred = points - points.mean(axis=0)
    _, _, vt = np.linalg.svd(centred)
    loop = annulus[np.argsort(np.arctan2(centred @ vt[1], centred @ vt[0]))]
    all_quads = np.concatenate(list(quads.values()))
    edges = np.sort(np.stack([all_quads, np.roll(all_quads, -1, axis=1)], axis=-1).reshape(-1, 2), axis=1)
    keys, counts = np.unique(edges, axis=0, return_counts=True)
    free = {tuple(k) for k in keys[counts == 1].tolist()}
    assert all(tuple(sorted(pair)) in free for pair in zip(loop.tolist(), np.roll(loop, -1).tolist(), strict=True))
    return loop, vt[2]


def _shoelace_area(points, normal):
    """|n . 1/2 sum x_i x x_{i+1}| of a closed polygon."""
    return abs(0.5 * np.cross(points, np.roll(points, -1, axis=0)).sum(axis=0) @ normal)


def test_trivalve_shell_reference_measures(shell_valve):
    """u = 0: the leaflet areas are the shells' bilinear areas, the orifice the annulus polygon's, no stress."""
    setup, model, quads = shell_valve
    u = np.zeros(setup.problem.space.n_dofs)
    assert np.array_equal(abaqus_positions(setup, u), model.nodes)
    measures = closure_measures(setup, u, 0.0)
    total = 0.0
    for leaflet, faces in quads.items():
        corners = model.nodes[faces]
        area = _quad_area(_bilinear_tangent_cross(corners)).sum()
        assert measures.per_leaflet_area[leaflet]["mid"] == pytest.approx(area, rel=1e-12)
        # the flat-quad vector area 1/2 |d1 x d2| is a lower bound, within the quads' small warp
        flat = 0.5 * np.linalg.norm(np.cross(corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 1]), axis=1)
        assert flat.sum() <= area <= flat.sum() * (1 + 1e-3)
        total += area
    assert measures.leaflet_area["mid"] == pytest.approx(total, rel=1e-12)
    loop, normal = _annulus_loop(model, quads)
    assert measures.orifice["mid"] == pytest.approx(_shoelace_area(model.nodes[loop], normal), rel=1e-12)
    assert measures.centre_stress == {"Anterior": 0.0, "Posterior": 0.0, "Septal": 0.0}


def _lee_sacks_max_principal(F, c0, D, c1, c2):
    """Homogeneous closed form of c0/2 (I1b-3) + c1/2 (exp(c2 (I1b-3)^2) - 1) + (J-1)^2/D:
    sigma = 2/J dW/dI1b dev(b_bar) + 2 (J-1)/D I, largest eigenvalue."""
    J = np.linalg.det(F)
    b_bar = J ** (-2.0 / 3.0) * F @ F.T
    x = np.trace(b_bar) - 3.0
    w1 = 0.5 * c0 + c1 * c2 * x * np.exp(c2 * x * x)
    sigma = 2.0 / J * w1 * (b_bar - np.trace(b_bar) / 3.0 * np.eye(3)) + 2.0 * (J - 1.0) / D * np.eye(3)
    return np.linalg.eigvalsh(sigma)[-1]


def test_trivalve_shell_measures_under_a_uniform_stretch(shell_valve):
    """u = (F - I) X on every vertex, F = diag(1.1, 1, 1): shell nodes move to F X, areas map by cof F, the
    centre stress is the homogeneous Lee-Sacks closed form with the input's parameters."""
    setup, model, quads = shell_valve
    F = np.diag([1.1, 1.0, 1.0])
    cofactor = np.linalg.det(F) * np.linalg.inv(F).T
    X = setup.model.mesh.p.T
    u = np.zeros(setup.problem.space.n_dofs)
    u[: setup.problem.space.n_u] = (X @ (F - np.eye(3)).T).ravel()
    shell_nodes = np.unique(np.concatenate(list(quads.values())))
    x = abaqus_positions(setup, u)
    np.testing.assert_allclose(x[shell_nodes], model.nodes[shell_nodes] @ F.T, rtol=0, atol=1e-12 * np.abs(X).max())
    measures = closure_measures(setup, u, 0.0)
    for leaflet, faces in quads.items():
        area = _quad_area(_bilinear_tangent_cross(model.nodes[faces]), cofactor).sum()
        assert measures.per_leaflet_area[leaflet]["mid"] == pytest.approx(area, rel=1e-12)
    loop, _ = _annulus_loop(model, quads)
    reference = model.nodes[loop]
    vector_area = cofactor @ (0.5 * np.cross(reference, np.roll(reference, -1, axis=0)).sum(axis=0))
    stretched = reference @ F.T
    normal = np.linalg.svd(stretched - stretched.mean(axis=0))[2][2]
    assert measures.orifice["mid"] == pytest.approx(abs(vector_area @ normal), rel=1e-12)
    for leaflet, value in measures.centre_stress.items():
        (section,) = [s for s in model.sections if s.elset.upper().endswith(f".{leaflet.upper()}_LEAFLET_ELEMENTS")]
        c0, D, c1, c2 = model.material(section.material).option("anisotropic hyperelastic").data
        assert value == pytest.approx(_lee_sacks_max_principal(F, c0, D, c1, c2), rel=1e-9)


@pytest.mark.parametrize("layers", [1, 3, 4])
def test_shell_nodes_follow_the_middle_of_their_extruded_fibre(tmp_path, layers):
    """abaqus_positions of a shell band extruded into ``layers`` hexes: the input node is the middle layer
    (even) or the mean of the two middle layers (odd). Under u = a |X|^2 e_z the fibre points X +- d n,
    d = h / (2 layers), average to X + a (|X|^2 + d^2) e_z, an even stack's middle node to X + a |X|^2 e_z."""
    radius, thickness = 10.0, 0.65
    path = tmp_path / "shells.inp"
    path.write_text(_shell_band_deck(radius, thickness, 6.0, 24, 4)[0])
    logging.getLogger("skvalve.io.abaqus.reader").setLevel(logging.ERROR)
    abaqus = read_model(path)
    model = valve_model(abaqus, layers=layers)
    setup = valve_setup(abaqus, model=model)
    problem = setup.problem
    X = model.mesh.p.T
    u = np.zeros(problem.space.n_dofs)
    np.testing.assert_allclose(abaqus_positions(setup, u), abaqus.nodes, rtol=0, atol=1e-13 * radius)
    a = 0.01
    u[: problem.space.n_u] = (a * (X**2).sum(axis=1)[:, None] * np.array([0.0, 0.0, 1.0])).ravel()
    d2 = 0.0 if layers % 2 == 0 else (thickness / (2 * layers)) ** 2
    expected = abaqus.nodes + a * ((abaqus.nodes**2).sum(axis=1) + d2)[:, None] * np.array([0.0, 0.0, 1.0])
    np.testing.assert_allclose(abaqus_positions(setup, u), expected, rtol=0, atol=1e-12 * radius)
