"""Shell extrusion: volumes of flat and cylindrical patches against closed forms, orientation checks."""

import numpy as np
import pytest

from skvalve.valve.extrude import extrude_shell, hex_corner_jacobians, hex_volumes


def _grid(nx: int, ny: int):
    x, y = np.meshgrid(np.linspace(0, 2.0, nx + 1), np.linspace(0, 1.0, ny + 1), indexing="ij")
    nodes = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    idx = np.arange(x.size).reshape(nx + 1, ny + 1)
    quads = np.column_stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()])
    return nodes, quads


def test_flat_patch_volume_is_area_times_thickness():
    nodes, quads = _grid(4, 3)
    rng = np.random.default_rng(0)
    nodes[:, :2] += 0.05 * rng.uniform(-1, 1, (nodes.shape[0], 2)) * (np.abs(nodes[:, :2] - [1.0, 0.5]) < [0.9, 0.4])
    ext = extrude_shell(nodes, quads, 0.78, layers=4)
    assert hex_volumes(ext.nodes, ext.hexes).sum() == pytest.approx(2.0 * 1.0 * 0.78, rel=1e-12)
    assert ext.hexes.shape == (4 * quads.shape[0], 8)
    assert np.all(hex_corner_jacobians(ext.nodes, ext.hexes) > 0)
    # the midsurface stays in the middle: layers symmetric about z = 0
    assert np.allclose(ext.nodes[ext.layer_nodes(0), 2], -0.39) and np.allclose(ext.nodes[ext.layer_nodes(4), 2], 0.39)


def _ring(n_theta: int, n_z: int, radius: float, height: float, outward: bool):
    theta = np.linspace(0, 2 * np.pi, n_theta, endpoint=False)
    z = np.linspace(0, height, n_z + 1)
    T, Z = np.meshgrid(theta, z, indexing="ij")
    nodes = np.column_stack([radius * np.cos(T).ravel(), radius * np.sin(T).ravel(), Z.ravel()])
    idx = np.arange(nodes.shape[0]).reshape(n_theta, n_z + 1)
    nxt = np.roll(idx, -1, axis=0)
    quads = np.column_stack([idx[:, :-1].ravel(), nxt[:, :-1].ravel(), nxt[:, 1:].ravel(), idx[:, 1:].ravel()])
    if not outward:
        quads = quads[:, ::-1]
    return nodes, quads


@pytest.mark.parametrize("outward", [True, False])
def test_cylindrical_ring_volume_matches_the_polygonal_prism(outward):
    R, t, H, n = 5.0, 0.78, 2.0, 48
    nodes, quads = _ring(n, 3, R, H, outward)
    ext = extrude_shell(nodes, quads, t, layers=4)
    # averaged normals of a closed ring are exactly radial: the solid is the prism between two n-gons
    polygon = 0.5 * n * np.sin(2 * np.pi / n)
    exact = polygon * ((R + t / 2) ** 2 - (R - t / 2) ** 2) * H
    assert hex_volumes(ext.nodes, ext.hexes).sum() == pytest.approx(exact, rel=1e-12)
    assert np.all(hex_corner_jacobians(ext.nodes, ext.hexes) > 0)
    # SPOS side is outside for outward-oriented quads
    top = np.linalg.norm(ext.nodes[ext.layer_nodes(4), :2], axis=1)
    assert np.allclose(top, (R + t / 2) if outward else (R - t / 2))


def test_inconsistent_orientation_and_overthick_shells_are_reported():
    nodes, quads = _grid(3, 1)
    quads[1] = quads[1, ::-1]
    with pytest.raises(ValueError, match="shell"):
        extrude_shell(nodes, quads, 0.1, 2)
    nodes, quads = _ring(8, 1, 1.0, 1.0, outward=True)
    with pytest.raises(ValueError, match="det J"):
        extrude_shell(nodes, quads, 2.5, 2)  # thicker than the radius: the inner layer turns inside out
