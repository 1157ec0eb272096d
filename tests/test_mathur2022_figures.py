"""Figures of a Texas TriValve state (skvalve.papers.mathur2022.figures) on the shipped diseased input at the
open configuration and at synthetic displacements (skipped when the input is absent; no closure is run)."""

import re
import struct

import numpy as np
import pytest
from matplotlib.collections import PolyCollection

from skvalve.io.abaqus import trivalve_input
from skvalve.papers.mathur2022 import figures
from skvalve.valve.outputs import closure_measures, max_principal_cauchy
from skvalve.valve.setup import valve_setup

DISEASED = trivalve_input()
pytestmark = pytest.mark.skipif(DISEASED is None, reason="Texas TriValve input not found (../shared/data)")


@pytest.fixture(scope="module")
def setup():
    return valve_setup(DISEASED)


def _rotation(axis, degrees: float) -> np.ndarray:
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    angle = np.radians(degrees)
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def _displacement(setup, mapping) -> np.ndarray:
    """Dof vector of the displacement x(X) - X for a map of the reference vertices (n, 3) -> (n, 3)."""
    X = setup.model.mesh.p.T
    u = np.zeros(setup.problem.space.n_dofs)
    u[: setup.problem.space.n_u] = (mapping(X) - X).ravel()
    return u


def _widening(X: np.ndarray) -> np.ndarray:
    """A smooth, non-uniform map: horizontal stretch growing from 0 at the lowest node to about 10 %."""
    centre = X.mean(axis=0)
    x = X.copy()
    x[:, :2] = centre[:2] + (1.0 + 0.004 * (X[:, 2:] - X[:, 2].min())) * (X[:, :2] - centre[:2])
    return x


def _png_width(path) -> int:
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    return struct.unpack(">I", data[16:20])[0]


def _shoelace(polygon: np.ndarray) -> float:
    x, y = polygon[:, 0], polygon[:, 1]
    return 0.5 * abs(float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)))


def _polys(figure) -> list[PolyCollection]:
    return [c for ax in figure.axes for c in ax.collections
            if isinstance(c, PolyCollection) and c.get_array() is not None]


def test_write_figures_gives_three_wide_pngs_of_the_open_valve(setup, tmp_path):
    paths = figures.write_figures(setup, np.zeros(setup.problem.space.n_dofs), 0.0, tmp_path / "figs")
    assert [p.name for p in paths] == ["mathur2022_atrial_stress.png", "mathur2022_coaptation.png",
                                       "mathur2022_orifice.png"]
    for path in paths:
        assert _png_width(path) >= 600
    assert sorted(p.name for p in (tmp_path / "figs").iterdir()) == sorted(p.name for p in paths)  # no temporaries


@pytest.mark.parametrize("degrees", [0.0, 35.0, 180.0])
def test_orifice_polygon_area_is_the_table2_orifice_and_the_view_turns_with_the_valve(setup, tmp_path, degrees):
    rotation = _rotation([1.0, 2.0, 0.5], degrees)
    u = _displacement(setup, lambda X: (X - 3.0) @ rotation.T + 1.0)
    result = figures.orifice_outline(setup, u, 0.0, tmp_path / "orifice.png")
    expected = closure_measures(setup, u, 0.0).orifice["mid"]
    assert _shoelace(result.polygon) == pytest.approx(expected, rel=1e-9)
    assert result.area == pytest.approx(expected, rel=1e-9)
    title = result.figure.axes[0].get_title()
    assert float(re.search(r"area ([0-9.]+) mm", title).group(1)) == pytest.approx(expected, abs=0.05)
    assert "Mathur et al. 2022" in result.figure.get_suptitle() and "CC BY-NC-SA 4.0" in result.figure.get_suptitle()
    # the viewer's side follows the valve: a rigid motion carries the normal along (a 180 degree turn flips it)
    reference = figures.atrial_projection(setup, np.zeros_like(u))
    turned = figures.atrial_projection(setup, u)
    np.testing.assert_allclose(turned.normal, rotation @ reference.normal, atol=1e-9)
    assert _png_width(result.path) >= 600


def test_the_view_is_from_the_atrium_and_not_mirrored(setup):
    projection = figures.atrial_projection(setup, np.zeros(setup.problem.space.n_dofs))
    X = setup.model.mesh.p.T
    # the open leaflets hang into the ventricle: below the annulus plane seen from the atrium
    assert np.mean(projection.depth(X[setup.leaflet_of_vertex >= 0])) < -3.0
    np.testing.assert_allclose(np.cross(*projection.axes), projection.normal, atol=1e-12)
    np.testing.assert_allclose(projection.axes @ projection.axes.T, np.eye(2), atol=1e-12)


def test_stress_colours_are_the_owning_hexes_stresses_in_kpa_over_their_range(setup, tmp_path):
    u = _displacement(setup, _widening)
    result = figures.atrial_view_stress(setup, u, 1.0, tmp_path / "stress.png")
    mesh = setup.model.mesh
    # each drawn face is a face of the hex whose colour it carries, and only boundary faces are drawn once each
    assert all(np.isin(face, mesh.t[:, element]).all() for face, element in zip(result.faces, result.elements,
                                                                                  strict=True))
    assert len({tuple(sorted(face)) for face in result.faces.tolist()}) == len(result.faces)
    expected = max_principal_cauchy(setup, u)[result.elements] * 1e3
    np.testing.assert_allclose(result.stress_kpa, expected, rtol=1e-12)
    (faces,) = _polys(result.figure)
    np.testing.assert_allclose(faces.get_array(), expected, rtol=1e-12)
    assert faces.get_clim() == pytest.approx((expected.min(), expected.max()), rel=1e-12)
    assert expected.max() - expected.min() > 1.0  # kPa: the map is not flat
    # painted far to near seen from the atrium
    projection = figures.atrial_projection(setup, u)
    x = mesh.p.T + u.reshape(-1, 3)
    assert np.all(np.diff(projection.depth(x[result.faces].mean(axis=1))) >= 0.0)
    assert _png_width(result.path) >= 600


def test_coaptation_map_shows_the_faces_whose_nodes_all_touch_and_their_area(setup, tmp_path, monkeypatch):
    n_u = setup.problem.space.n_u
    u = np.zeros(setup.problem.space.n_dofs)
    contact = setup.contact
    quads = contact.surface.quads
    X = setup.model.mesh.p.T
    nodes = np.arange(contact.space.n_scalar)
    pressure = np.where(X[nodes, 2] < np.percentile(X[quads].mean(axis=1)[:, 2], 15), 1e-3 * (1.0 + nodes % 7), 0.0)
    result = figures.coaptation_map(setup, u, 1.5, tmp_path / "coaptation.png", pressure=pressure)
    pressed = np.flatnonzero((pressure[quads] > 0).all(axis=1))
    partly = np.flatnonzero((pressure[quads] > 0).any(axis=1) & ~(pressure[quads] > 0).all(axis=1))
    assert pressed.size > 100 and partly.size > 10  # faces across the border are left out, as contact_area does
    np.testing.assert_array_equal(np.sort(result.faces), pressed)
    np.testing.assert_allclose(result.pressure_kpa, pressure[quads[result.faces]].mean(axis=1) * 1e3, rtol=1e-12)
    for faces in _polys(result.figure):  # the view from the atrium and the unrolled open valve
        np.testing.assert_allclose(faces.get_array(), result.pressure_kpa, rtol=1e-12)
        assert faces.get_clim() == pytest.approx((result.pressure_kpa.min(), result.pressure_kpa.max()), rel=1e-12)
    # area of the pressed faces, each split into two triangles (they are near-planar at the open configuration)
    x = X + u[:n_u].reshape(-1, 3)
    Q = x[quads[pressed]]
    triangles = 0.5 * (np.linalg.norm(np.cross(Q[:, 1] - Q[:, 0], Q[:, 2] - Q[:, 0]), axis=1)
                       + np.linalg.norm(np.cross(Q[:, 2] - Q[:, 0], Q[:, 3] - Q[:, 0]), axis=1))
    assert result.coaptation_area == pytest.approx(triangles.sum(), rel=1e-3)
    title = result.figure.axes[0].get_title()
    assert float(re.search(r"area ([0-9.]+) mm", title).group(1)) == pytest.approx(result.coaptation_area, abs=0.05)
    # the same faces and area as the Table 2 coaptation area of the contact term, for the same nodal pressures
    monkeypatch.setattr(contact, "nodal_pressure", lambda u, t: pressure)
    assert figures.coaptation_map(setup, u, 1.5, tmp_path / "default.png").coaptation_area == pytest.approx(
        contact.contact_area(u, 1.5), rel=1e-12)
    with pytest.raises(ValueError, match="nodal pressures"):
        figures.coaptation_map(setup, u, 1.5, tmp_path / "bad.png", pressure=pressure[:-1])


def test_unrolled_map_keeps_arc_length_and_height():
    projection = figures.AtrialProjection(np.zeros(3), np.array([0.0, 0.0, 1.0]), np.eye(3)[:2])
    angles = np.array([0.1, 0.5, 3.1, -3.1])
    corners = np.stack([10 * np.cos(angles), 10 * np.sin(angles), [-1.0, -2.0, -3.0, -4.0]], axis=1)[None]
    strip = figures.unrolled(projection, corners, 10.0)[0]
    # the face crosses the seam at angle pi: its corners past -pi are drawn past +pi, keeping it whole
    np.testing.assert_allclose(strip[:, 0], 10 * np.array([0.1, 0.5, 3.1, 2 * np.pi - 3.1]))
    np.testing.assert_allclose(strip[:, 1], [-1.0, -2.0, -3.0, -4.0])


def test_stress_limits_clip_the_colour_range_and_extend_the_bar(setup, tmp_path):
    u = _displacement(setup, _widening)
    default = figures.atrial_view_stress(setup, u, 0.0, tmp_path / "default.png")
    low, high = np.percentile(default.stress_kpa, [5, 95])
    result = figures.atrial_view_stress(setup, u, 0.0, tmp_path / "limits.png", limits=(low, high))
    (faces,) = _polys(result.figure)
    (free,) = _polys(default.figure)
    assert faces.get_clim() == (low, high)
    assert faces.colorbar.extend == "both" and free.colorbar.extend == "neither"
    np.testing.assert_array_equal(faces.get_array(), free.get_array())  # the values are kept, only the map clips


def test_an_upper_percentile_caps_the_colour_range_at_that_percentile(setup, tmp_path):
    u = _displacement(setup, _widening)
    result = figures.atrial_view_stress(setup, u, 0.0, tmp_path / "capped.png", upper_percentile=50.0)
    (faces,) = _polys(result.figure)
    assert faces.get_clim() == pytest.approx((result.stress_kpa.min(), np.median(result.stress_kpa)), rel=1e-12)
    assert faces.colorbar.extend == "max"
    with pytest.raises(ValueError, match="upper_percentile"):
        figures.atrial_view_stress(setup, u, 0.0, tmp_path / "bad.png", upper_percentile=0.0)
