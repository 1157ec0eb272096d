r"""Figures of a Texas TriValve state: the valve seen from the atrium (stress), the coaptation map, the orifice.

Model files: Mathur et al. (2022), Texas TriValve 1.0, CC BY-NC-SA 4.0 (credited on every figure). Each figure
is a 2D projection drawn with :class:`~matplotlib.collections.PolyCollection` (no 3D axes: fast, deterministic)
and written as PNG by :func:`skvalve.papers.plotting.save_figure` (atomic, at least 900 px wide).

**The view** (:func:`atrial_projection`). The annulus is the boundary loop of the chosen leaflet surface
(default the mid surface) nearest to the input's annulus node set, as for the orifice area of
:func:`skvalve.valve.geometry.orifice_area`. Its least-squares plane (centroid :math:`c`, unit normal
:math:`n`) is the picture plane. The atrium is on the side away from the papillary muscles: the model's
vertices that no leaflet hex uses (chordae and papillary nodes) lie on the ventricular side, so :math:`n` is
oriented to point away from their mean (without such vertices, away from the mean of all vertices: the
leaflets hang into the ventricle in the open configuration). At end-systole this is the
direction in which the transvalvular pressure pushes the leaflets. The viewer looks along :math:`-n`; a point
:math:`x` is drawn at :math:`(e_1\cdot(x - c), e_2\cdot(x - c))` with :math:`e_1` the global :math:`x` axis
projected on the plane (the :math:`y` axis if :math:`x` is nearly normal to it) and :math:`e_2 = n\times e_1`,
so the picture is not mirrored; faces are painted far to near (painter's algorithm, depth :math:`n\cdot x`).

* :func:`atrial_view_stress`: the outer faces of the leaflet hexes (the boundary faces of the hex mesh), each
  coloured by the maximum principal Cauchy stress of the hex it bounds (kPa;
  :func:`skvalve.valve.outputs.max_principal_cauchy`), the colour range the minimum and maximum shown, and the
  annulus.
* :func:`coaptation_map`: the contact surface's faces all of whose nodes carry IPC barrier force (those of
  :meth:`~skvalve.fem.contact.IPCContact.contact_area`), coloured by the mean of their nodes' contact pressure
  (:meth:`~skvalve.fem.contact.IPCContact.nodal_pressure`, kPa) over the valve in grey, with the coaptation
  area (their current area) in the title: seen from the atrium in the
  state itself, and, as in the paper's Fig. 7b, where they lie in the open (end-diastolic, reference)
  configuration, there on the valve unrolled about the annulus axis (:func:`unrolled`), since from the atrium
  the open leaflets, hanging nearly parallel to the axis, project onto a ring a few millimetres wide.
* :func:`orifice_outline`: the annulus loop projected on its best-fit plane, the polygon whose area is Table 2's
  orifice area (shoelace of the drawn polygon, equal to :func:`~skvalve.valve.geometry.loop_area`), with each
  leaflet's projected faces and its part of the valve's free edge (boundary edges of the leaflet surface that lie
  neither on the annulus loop nor between two leaflets).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.figure import Figure

from ...fem.contact import oriented_quads
from ...valve.geometry import annulus_nodes, best_fit_plane, boundary_loops, leaflet_surfaces, union_surface
from ...valve.outputs import abaqus_positions, max_principal_cauchy
from ...valve.setup import ValveSetup
from ..plotting import readable_style, save_figure
from .data import CREDIT

__all__ = ["AtrialProjection", "StressFigure", "CoaptationFigure", "OrificeFigure", "atrial_projection",
           "annulus_loop", "outer_faces", "atrial_view_stress", "unrolled", "coaptation_map", "orifice_outline",
           "write_figures", "shoelace_area"]

MPA_TO_KPA = 1e3
FIGURE_SIZE = (7.0, 6.4)  # inches: 1050 x 960 px at the papers' 150 dpi
LEAFLET_COLOURS = ("#4c72b0", "#dd8452", "#55a868", "#c44e52", "#8172b3")
LEAFLET_FILLS = ("#c9d6ec", "#f6dcc8", "#cfe7d5", "#eccbcc", "#dcd6ec")


@dataclass
class AtrialProjection:
    """The picture plane seen from the atrium: centroid, normal towards the atrium (the viewer), in-plane axes."""

    origin: np.ndarray
    normal: np.ndarray
    axes: np.ndarray  # (2, 3): e1, e2 with e1 x e2 = normal

    def __call__(self, points: np.ndarray) -> np.ndarray:
        """In-plane coordinates (..., 2) of points (..., 3)."""
        return (np.asarray(points) - self.origin) @ self.axes.T

    def depth(self, points: np.ndarray) -> np.ndarray:
        """Height towards the viewer (larger is nearer)."""
        return (np.asarray(points) - self.origin) @ self.normal


@dataclass
class StressFigure:
    """:func:`atrial_view_stress`: PNG path, the figure, the drawn faces (mesh vertex indices), their hexes and
    stresses (kPa), in draw order."""

    path: Path
    figure: Figure
    faces: np.ndarray
    elements: np.ndarray
    stress_kpa: np.ndarray


@dataclass
class CoaptationFigure:
    """:func:`coaptation_map`: PNG path, figure, contact faces drawn (indices into the surface's quads) and their
    pressures (kPa, draw order), and the coaptation area (mm²)."""

    path: Path
    figure: Figure
    faces: np.ndarray
    pressure_kpa: np.ndarray
    coaptation_area: float


@dataclass
class OrificeFigure:
    """:func:`orifice_outline`: PNG path, figure, the projected annulus polygon (n, 2) and its area (mm²)."""

    path: Path
    figure: Figure
    polygon: np.ndarray
    area: float


def shoelace_area(polygon: np.ndarray) -> float:
    """Area of a simple planar polygon (n, 2), vertices in order: :math:`\\tfrac12|\\sum x_i y_{i+1} - x_{i+1} y_i|`."""
    x, y = np.asarray(polygon, dtype=float).T
    return float(0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y)))


def _valve_surface(setup: ValveSetup, u: np.ndarray, surface: str
                   ) -> tuple[np.ndarray, dict[str, np.ndarray], np.ndarray]:
    """Current points and per-leaflet faces of a leaflet surface, and its annulus loop (indices into the points)."""
    x = abaqus_positions(setup, u)
    points, faces = union_surface(leaflet_surfaces(setup.abaqus), surface, x)
    annulus = x[annulus_nodes(setup.abaqus)]
    loops = boundary_loops(np.concatenate(list(faces.values())))

    def distance(loop: np.ndarray) -> float:
        gaps = np.linalg.norm(points[loop][:, None, :] - annulus[None, :, :], axis=2)
        return float(gaps.min(axis=1).mean())

    return points, faces, min(loops, key=distance)


def annulus_loop(setup: ValveSetup, u: np.ndarray, surface: str = "mid") -> np.ndarray:
    """Current coordinates (n, 3) of the annulus loop of a leaflet surface (module docstring), in loop order."""
    points, _, loop = _valve_surface(setup, u, surface)
    return points[loop]


def _atrium_side(setup: ValveSetup, u: np.ndarray, origin: np.ndarray, normal: np.ndarray) -> float:
    """+1 if ``normal`` points to the atrium at state ``u``, else -1 (ventricular markers: module docstring)."""
    x = _current(setup, u)
    markers = x[setup.leaflet_of_vertex < 0]
    if markers.size == 0:
        markers = x
    height = float(((markers - origin) @ normal).mean())
    if height == 0.0:
        raise ValueError("cannot tell the atrium from the ventricle: the model's vertices lie on the annulus plane")
    return -np.sign(height)


def atrial_projection(setup: ValveSetup, u: np.ndarray, surface: str = "mid",
                      loop: np.ndarray | None = None) -> AtrialProjection:
    """The view from the atrium on the best-fit plane of the current annulus loop (module docstring).

    ``loop``: the annulus loop's coordinates (n, 3) if already known (default :func:`annulus_loop`)."""
    loop = annulus_loop(setup, u, surface) if loop is None else loop
    origin, normal = best_fit_plane(loop)
    normal = normal * _atrium_side(setup, u, origin, normal)
    axis = np.eye(3)[0] if abs(normal[0]) < 0.9 else np.eye(3)[1]
    e1 = axis - (axis @ normal) * normal
    e1 /= np.linalg.norm(e1)
    return AtrialProjection(origin, normal, np.stack([e1, np.cross(normal, e1)]))


def outer_faces(setup: ValveSetup) -> tuple[np.ndarray, np.ndarray]:
    """Boundary faces of the hex mesh, cyclic and outward (n, 4) vertex indices, and the hex each bounds (n,)."""
    mesh = setup.model.mesh
    facets = mesh.boundary_facets()
    owners = mesh.f2t[0, facets]
    inside = mesh.p[:, mesh.t[:, owners]].mean(axis=1).T
    return oriented_quads(mesh.p.T, mesh.facets[:, facets].T, inside), owners


def _current(setup: ValveSetup, u: np.ndarray) -> np.ndarray:
    return setup.model.mesh.p.T + u[: setup.problem.space.n_u].reshape(-1, 3)


def _painted(projection: AtrialProjection, corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Projected polygons (n, k, 2) and the far-to-near order of faces with corners (n, k, 3)."""
    order = np.argsort(projection.depth(corners.mean(axis=1)), kind="stable")
    return projection(corners), order


def _frame(ax, projection: AtrialProjection, annulus: np.ndarray, title: str) -> None:
    ring = projection(annulus)
    ax.plot(*np.vstack([ring, ring[:1]]).T, color="black", lw=1.6, label="annulus")
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xlabel("mm (seen from the atrium)")
    ax.set_ylabel("mm")
    ax.set_title(title)


def _new_figure() -> Figure:
    return Figure(figsize=FIGURE_SIZE, layout="constrained")


def _caption(fig: Figure, t: float, credit: str) -> None:
    fig.suptitle(f"model: {credit}; step time t = {t:.4g}", fontsize=9)


def atrial_view_stress(setup: ValveSetup, u: np.ndarray, t: float, path, credit: str = CREDIT,
                       cmap: str = "viridis", limits: tuple[float, float] | None = None,
                       upper_percentile: float | None = None) -> StressFigure:
    """The valve seen from the atrium, outer hex faces coloured by maximum principal Cauchy stress (kPa).

    ``limits``: colour range (kPa), default the smallest and largest stress shown; values outside it take the
    end colours (the colour bar is then extended), e.g. to keep the stress risers at the chordae insertions
    from flattening the rest of the map. ``upper_percentile`` (with no ``limits``): the range from the smallest stress
    shown to this percentile of the faces' stresses (on the closed 1.0 diseased valve the largest, 4 MPa at the
    annulus rim, flattens the leaflets' 50-150 kPa into one colour; :func:`write_figures` uses the 99th).
    """
    if upper_percentile is not None and not (0.0 < upper_percentile <= 100.0):
        raise ValueError(f"upper_percentile must lie in (0, 100]; got {upper_percentile!r}")
    quads, owners = outer_faces(setup)
    x = _current(setup, u)
    ring = annulus_loop(setup, u)
    projection = atrial_projection(setup, u, loop=ring)
    polygons, order = _painted(projection, x[quads])
    stress = max_principal_cauchy(setup, u)[owners[order]] * MPA_TO_KPA
    with readable_style():
        fig = _new_figure()
        ax = fig.add_subplot()
        faces = PolyCollection(polygons[order], array=stress, cmap=cmap, edgecolors="face", linewidths=0.2)
        low, high = (float(stress.min()), float(stress.max())) if limits is None else limits
        if limits is None and upper_percentile is not None:
            high = float(np.percentile(stress, upper_percentile))
        faces.set_clim(low, high)
        ax.add_collection(faces)
        extend = {(False, False): "neither", (True, False): "min", (False, True): "max", (True, True): "both"}[
            (bool(stress.min() < low), bool(stress.max() > high))]
        fig.colorbar(faces, ax=ax, label="max principal Cauchy stress (kPa)", shrink=0.85, extend=extend)
        _frame(ax, projection, ring, "Valve seen from the atrium: maximum principal Cauchy stress")
        _caption(fig, t, credit)
        save_figure(fig, path)
    return StressFigure(Path(path), fig, quads[order], owners[order], stress)


def unrolled(projection: AtrialProjection, corners: np.ndarray, radius: float) -> np.ndarray:
    """Polygons (n, k, 2) of faces with corners (n, k, 3) on the valve unrolled about the annulus axis.

    Horizontal: arc length ``radius`` x angle about the axis through the annulus centroid along its normal
    (counter-clockwise seen from the atrium, 0 on :math:`e_1`); vertical: height above the annulus plane. A face
    crossing the seam at angle ±π is drawn whole past +π.
    """
    planar = projection(corners)
    angle = np.arctan2(planar[..., 1], planar[..., 0])
    seam = (angle.max(axis=1) - angle.min(axis=1)) > np.pi
    angle[seam] = np.where(angle[seam] < 0.0, angle[seam] + 2.0 * np.pi, angle[seam])
    return np.stack([radius * angle, projection.depth(corners)], axis=-1)


def coaptation_map(setup: ValveSetup, u: np.ndarray, t: float, path, pressure: np.ndarray | None = None,
                   credit: str = CREDIT, cmap: str = "Reds") -> CoaptationFigure:
    """Contact pressure (kPa) of the coapting faces: seen from the atrium, and on the unrolled open valve (Fig. 7b).

    Top: the state ``u`` seen from the atrium, the valve in grey and the coapting faces in colour on top. Bottom,
    like the paper's Fig. 7b: the same faces where they lie in the open (end-diastolic, reference) configuration, on
    the valve unrolled about the annulus axis (:func:`unrolled`): seen from the atrium the open leaflets hang nearly
    parallel to the axis and project onto a thin ring. ``pressure``: nodal contact pressures at ``u`` (MPa, one per
    scalar node), default ``setup.contact.nodal_pressure(u, t)``. A face coapts when all its nodes carry pressure
    and is coloured by their mean; the coaptation area is the faces' current area (that of
    :meth:`~skvalve.fem.contact.IPCContact.contact_area`).
    """
    contact = setup.contact
    quads = contact.surface.quads
    n_nodes = contact.space.n_scalar
    pressure = contact.nodal_pressure(u, t) if pressure is None else np.asarray(pressure, dtype=float)
    if pressure.shape != (n_nodes,):
        raise ValueError(f"coaptation map: nodal pressures of shape {pressure.shape} for {n_nodes} nodes")
    touching = np.flatnonzero(pressure[quads].min(axis=1) > 0.0)
    face_pressure = pressure[quads].mean(axis=1)
    x, X = _current(setup, u), setup.model.mesh.p.T
    Q = x[quads[touching]]
    area = float(0.5 * np.linalg.norm(np.cross(Q[:, 2] - Q[:, 0], Q[:, 3] - Q[:, 1]), axis=1).sum())
    valve_quads, _ = outer_faces(setup)
    ring = annulus_loop(setup, u)
    projection = atrial_projection(setup, u, loop=ring)
    reference_ring = annulus_loop(setup, np.zeros_like(u))
    reference = atrial_projection(setup, u, loop=reference_ring)
    radius = float(np.linalg.norm(reference(reference_ring), axis=1).mean())
    valve, valve_order = _painted(projection, x[valve_quads])
    polygons, order = _painted(projection, Q)
    values = face_pressure[touching][order] * MPA_TO_KPA
    # unrolled: painted from the outside in (seen from the axis), contact faces on top
    strip = unrolled(reference, X[valve_quads], radius)
    strip_order = np.argsort(-np.linalg.norm(reference(X[valve_quads].mean(axis=1)), axis=1), kind="stable")
    contact_strip = unrolled(reference, X[quads[touching[order]]], radius)
    with readable_style():
        fig = Figure(figsize=(8.0, 10.0), layout="constrained")
        top, bottom = fig.subplots(2, 1, height_ratios=[2.2, 1.0])
        top.add_collection(PolyCollection(valve[valve_order], facecolors="#f2f2f2", edgecolors="#b0b0b0",
                                          linewidths=0.2))
        bottom.add_collection(PolyCollection(strip[strip_order], facecolors="#f7f7f7", edgecolors="#c8c8c8",
                                             linewidths=0.2))
        if touching.size:
            for ax, shapes in ((top, polygons[order]), (bottom, contact_strip)):
                faces = PolyCollection(shapes, array=values, cmap=cmap, edgecolors="face", linewidths=0.2)
                faces.set_clim(float(values.min()), float(values.max()))
                ax.add_collection(faces)
            fig.colorbar(faces, ax=[top, bottom], label="contact pressure (kPa)", shrink=0.6)
        else:
            top.text(0.5, 0.5, "no contact", transform=top.transAxes, ha="center", va="center")
        _frame(top, projection, ring, f"Coaptation: contact pressure, coaptation area {area:.1f} mm²")
        annulus = unrolled(reference, reference_ring[:, None], radius)[:, 0]
        annulus = annulus[np.argsort(annulus[:, 0], kind="stable")]
        bottom.plot(*annulus.T, color="black", lw=1.2)
        bottom.set_aspect("equal")
        bottom.autoscale_view()
        bottom.set_xlabel("arc length about the annulus axis (mm), on the open valve (end-diastole, as Fig. 7b)")
        bottom.set_ylabel("height above\nannulus plane (mm)")
        _caption(fig, t, credit)
        save_figure(fig, path)
    return CoaptationFigure(Path(path), fig, touching[order], values, area)


def _free_edges(faces: dict[str, np.ndarray], annulus: set[tuple[int, int]]) -> dict[str, np.ndarray]:
    """Per leaflet, its boundary edges (m, 2) on the valve's boundary but not on the annulus loop."""
    def edges_of(quads: np.ndarray) -> np.ndarray:
        return np.sort(np.stack([quads, np.roll(quads, -1, axis=1)], axis=-1).reshape(-1, 2), axis=1)

    keys, counts = np.unique(edges_of(np.concatenate(list(faces.values()))), axis=0, return_counts=True)
    valve_boundary = {tuple(edge) for edge in keys[counts == 1].tolist()} - annulus
    free = {}
    for name, quads in faces.items():
        own = [tuple(edge) for edge in edges_of(quads).tolist()]
        free[name] = np.array([edge for edge in own if edge in valve_boundary], dtype=np.int64).reshape(-1, 2)
    return free


def orifice_outline(setup: ValveSetup, u: np.ndarray, t: float, path, surface: str = "mid",
                    credit: str = CREDIT) -> OrificeFigure:
    """The annulus polygon on its best-fit plane (Table 2's orifice) with the leaflets and their free edges."""
    points, faces, ring = _valve_surface(setup, u, surface)
    loop_points = points[ring]
    projection = atrial_projection(setup, u, surface, loop_points)
    polygon = projection(loop_points)
    area = shoelace_area(polygon)
    annulus_edges = {tuple(sorted(edge)) for edge in zip(ring.tolist(), np.roll(ring, -1).tolist(), strict=True)}
    free = _free_edges(faces, annulus_edges)
    with readable_style():
        fig = _new_figure()
        ax = fig.add_subplot()
        every = np.concatenate(list(faces.values()))
        fills = np.repeat([LEAFLET_FILLS[k % len(LEAFLET_FILLS)] for k in range(len(faces))],
                          [len(quads) for quads in faces.values()])
        polygons, order = _painted(projection, points[every])
        ax.add_collection(PolyCollection(polygons[order], facecolors=fills[order], edgecolors="none"))
        for k, (name, edges) in enumerate(free.items()):
            ax.add_collection(LineCollection(projection(points[edges]), colors=LEAFLET_COLOURS[k % 5], linewidths=2.0,
                                             label=f"{name.lower()} leaflet: free edge"))
        ax.fill(*polygon.T, facecolor="none", edgecolor="#a0a0a0", hatch="//", lw=0.0, label="orifice")
        _frame(ax, projection, loop_points, f"Orifice: annulus on its best-fit plane, area {area:.1f} mm²")
        fig.legend(loc="outside lower center", ncol=3, frameon=False)
        _caption(fig, t, credit)
        save_figure(fig, path)
    return OrificeFigure(Path(path), fig, polygon, area)


def write_figures(setup: ValveSetup, u: np.ndarray, t: float, out, stem: str = "mathur2022",
                  credit: str = CREDIT) -> list[Path]:
    """The three figures of a state as ``<out>/<stem>_{atrial_stress,coaptation,orifice}.png`` (the stress coloured
    up to its 99th percentile).

    ``credit``: the model's source and licence, printed on each figure (default the 1.0 inputs')."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    return [atrial_view_stress(setup, u, t, out / f"{stem}_atrial_stress.png", credit=credit,
                               upper_percentile=99.0).path,
            coaptation_map(setup, u, t, out / f"{stem}_coaptation.png", credit=credit).path,
            orifice_outline(setup, u, t, out / f"{stem}_orifice.png", credit=credit).path]
