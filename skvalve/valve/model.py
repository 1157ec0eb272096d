r"""A whole-valve model for the implicit solver, built from an Abaqus input (Texas TriValve).

:func:`valve_model` turns an :class:`~skvalve.io.abaqus.AbaqusModel` into a :class:`ValveModel`:

* **leaflets**: the C3D8R bricks of the 1.0 inputs as they are, or the S4R midsurface shells of the
  1.1 inputs extruded into ``layers`` hexes through the section thickness (:mod:`.extrude`); one
  ``LeeSacks`` law per leaflet from the ``VUANISO_ISO`` properties :math:`(C_0, D, C_1, C_2)`
  (mathur2022 Eq. 1 as shipped, :class:`~skvalve.materials.LeeSacks`). They run on the F-bar
  (mean-dilatation) hexahedron :class:`~skvalve.fem.elements.fbar.FBarTerm`, which does not lock at the
  leaflets' :math:`\nu \approx 0.495`; ``solid="q1"`` gives the locking full-integration hexahedron
  for comparison;
* **chordae**: the T3D2 trusses with their section area and the 3-term Ogden law in uniaxial stress,
  as tension-only cables (:class:`~skvalve.materials.uniaxial.TensionOnly`); chains of two-bar nodes
  are collapsed into one cable between branch points with the chain's path length as rest length and
  dangling bars are dropped (:mod:`.chordae`), so the implicit tangent has no zero-stiffness direction;
* **conditions**: every ``*Boundary`` line of the steps (and of the model level) as a prescribed displacement of
  mesh nodes, following the multi-step history of :mod:`.history` (value times its amplitude in step time; an
  amplitude-free condition is held constant in a dynamic step or ramped in a static one; carried into later steps
  with its end value, or replaced). A condition on a shell node holds the whole fibre of extruded nodes through the
  thickness; rotational dofs and nodes that are not part of the model are skipped and noted;
* **pressure**: each ``*Dsload`` ``P`` on an element-face surface as a follower pressure (load stiffness included)
  on the corresponding mesh facets, with its history over the steps;
* **LINK MPCs** (the 1.0 annuloplasty ring): stiff penalty bars between the linked vertices, axial
  rigidity ``link_factor`` times the stiffest chord's, so a link's relative length change is its force over
  that rigidity (:mod:`.links`); other ``*MPC`` types are refused with their file line;
* **clip arms** (the 1.0 clip repair): rigid ``R3D4`` arms turned about their reference nodes as kinematic
  obstacles (:mod:`.clip`), ``ValveModel.obstacles`` for the closure's IPC contact (:mod:`.setup`).

The solver's load factor is the **total time** over all steps (0 to ``end_time``; a one-step input's step time):
``solve(problem, steps=times)``; ``ValveModel.steps`` gives each step's name, start and period. ``step=k`` builds
step ``k`` alone (its step time). Mesh vertices are numbered chordae-only nodes first, then the leaflet nodes,
because scikit-fem counts ``max(cells) + 1`` vertices. Contact among the leaflets is the closure's business
(issue 11). Inputs with parts the model cannot represent are refused with their file lines (:mod:`.support`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import skfem

from ..fem.contact.obstacles import Obstacle
from ..fem.elements.constitutive import MaterialRegions
from ..fem.elements.fbar import FBarTerm
from ..fem.elements.hyperelastic import HyperelasticTerm
from ..fem.elements.truss import Truss
from ..fem.errors import TangledMeshError
from ..fem.loads import FollowerPressure
from ..fem.problem import Problem
from ..fem.space import Space
from ..io.abaqus import HEX_FACE_NODES, AbaqusModel
from ..materials import LeeSacks
from ..materials.uniaxial import OgdenUniaxial, TensionOnly
from .chordae import CollapsedChordae, collapse_chains, insertion_patches
from .clip import ClipArm, clip_arms
from .extrude import extrude_shell, hex_corner_jacobians
from .history import (
    NodalCondition,
    PressureLoad,
    StepWindow,
    amplitude_table,
    condition_histories,
    load_histories,
    nodal_conditions,
    selected_steps,
    step_windows,
)
from .links import LINK_FACTOR, Links, link_constraints, link_nodes
from .support import check_supported

__all__ = ["ValveModel", "NodalCondition", "PressureLoad", "Chordae", "valve_model"]

#: scikit-fem's hexahedron node order in terms of the Abaqus (VTK) C3D8 order.
ABAQUS_TO_SKFEM_HEX = np.array([0, 4, 3, 1, 7, 5, 2, 6])
_SHELL_TYPES = ("S4", "S4R", "S4R5")
_BRICK_TYPES = ("C3D8", "C3D8R", "C3D8H", "C3D8RH", "C3D8I")
_TRUSS_TYPES = ("T3D2", "T3D2H")


@dataclass
class Chordae:
    """Cables between mesh vertices: ends, rest lengths, areas, law of each cable, the reduction done, and each
    cable's force-free slack stretch (reference end-to-end distance / rest length)."""

    ends: np.ndarray
    rest_length: np.ndarray
    area: np.ndarray
    law_index: np.ndarray
    laws: list[OgdenUniaxial]
    law_names: list[str]
    reduction: CollapsedChordae
    slack_stretch: np.ndarray


@dataclass
class ValveModel:
    """Leaflet hexes, chordae cables, nodal conditions and pressures on one mesh (module docstring); ``steps`` the
    input's steps on the total-time axis, ``arms`` the rigid clip arms and ``obstacles`` their contact surfaces."""

    source: str
    mesh: skfem.MeshHex
    element_source: np.ndarray
    regions: np.ndarray
    region_names: list[str]
    laws: list[LeeSacks]
    chordae: Chordae
    conditions: list[NodalCondition]
    pressures: list[PressureLoad]
    end_time: float
    vertex_source: np.ndarray
    notes: list[str] = field(default_factory=list)
    links: Links | None = None
    steps: list[StepWindow] = field(default_factory=list)
    arms: list[ClipArm] = field(default_factory=list)
    obstacles: list[Obstacle] = field(default_factory=list)

    def step_index(self, t: float) -> int:
        """The step that total time ``t`` falls in (a step's end belongs to it; 0 without steps)."""
        starts = [w.start for w in self.steps]
        return max(int(np.searchsorted(starts, t, side="left")) - 1, 0) if starts else 0

    def counts(self) -> dict[str, int]:
        """Sizes: hexes, vertices, cables, collapsed chain nodes, dropped bars, conditions, pressure facets."""
        red = self.chordae.reduction
        return {"hexes": int(self.mesh.nelements), "vertices": int(self.mesh.p.shape[1]),
                "cables": int(self.chordae.ends.shape[0]), "collapsed_chain_nodes": int(red.interior_nodes.size),
                "dropped_bars": int(red.dropped_bars.size),
                "constrained_dofs": int(sum(c.vertices.size for c in self.conditions)),
                "pressure_facets": int(sum(p.facets.size for p in self.pressures)),
                "links": self.links.size if self.links is not None else 0}

    def submodel(self, regions: list[int], chordae: bool = False) -> ValveModel:
        """The leaflets of the given region numbers alone: their hexes, conditions and pressure, and the cables
        whose two ends lie on them. ``chordae``: also the chordae trees that hold them (the cables between their
        vertices and nodes of no hex, branch points and papillary tips, less the branches that lead to no kept
        leaflet). For smoke tests and studies."""
        keep = np.isin(self.regions, regions)
        if not np.any(keep):
            raise ValueError(f"no hexes in regions {regions}; the model has regions 0..{len(self.region_names) - 1}")
        cells = self.mesh.t[:, keep]
        used = np.unique(cells)
        if chordae:
            used = np.union1d(used, self._holding_chordae_nodes(used))
        new = np.full(self.mesh.p.shape[1], -1)
        new[used] = np.arange(used.size)
        mesh = skfem.MeshHex(np.ascontiguousarray(self.mesh.p[:, used]), np.ascontiguousarray(new[cells]))
        ch = self.chordae
        inside = np.all(new[ch.ends] >= 0, axis=1)
        chordae = Chordae(new[ch.ends[inside]], ch.rest_length[inside], ch.area[inside], ch.law_index[inside],
                          ch.laws, ch.law_names, ch.reduction, ch.slack_stretch[inside])
        conditions = [NodalCondition(new[c.vertices[new[c.vertices] >= 0]], c.component, c.value, c.amplitude,
                                     c.ramp_time, c.history) for c in self.conditions]
        conditions = [c for c in conditions if c.vertices.size]
        lookup = _facet_lookup(mesh)
        pressures = []
        for load in self.pressures:
            corners = new[self.mesh.facets[:, load.facets]]
            mine = np.all(corners >= 0, axis=0)
            facets = [lookup.get(tuple(sorted(col))) for col in corners[:, mine].T.tolist()]
            facets = np.array([f for f in facets if f is not None], dtype=np.int64)
            if facets.size:
                pressures.append(PressureLoad(load.surface, facets, load.magnitude, load.amplitude, load.ramp_time,
                                              load.history))
        names = ", ".join(self.region_names[r] for r in regions)
        return ValveModel(self.source, mesh, self.element_source[keep], self.regions[keep], self.region_names,
                          self.laws, chordae, conditions, pressures, self.end_time, self.vertex_source[used],
                          self.notes + [f"submodel of {names}: {int(inside.sum())} of {inside.size} cables kept"],
                          self.links.subset(new) if self.links is not None else None, self.steps, self.arms,
                          self.obstacles)

    def _holding_chordae_nodes(self, leaflet_vertices: np.ndarray) -> np.ndarray:
        """The nodes of no hex on the chordae that reach ``leaflet_vertices``: cables whose ends are leaflet vertices
        or nodes of no hex, pruned of dangling branches (a free end of degree one), until none is left."""
        n = self.mesh.p.shape[1]
        in_hex = np.zeros(n, dtype=bool)
        in_hex[self.mesh.t] = True
        mine = np.zeros(n, dtype=bool)
        mine[leaflet_vertices] = True
        allowed = mine | ~in_hex
        ends = self.chordae.ends[np.all(allowed[self.chordae.ends], axis=1)]
        prescribed = np.zeros(n, dtype=bool)
        for condition in self.conditions:
            prescribed[condition.vertices] = True
        while ends.size:
            degree = np.bincount(ends.ravel(), minlength=n)
            dangling = (degree == 1) & ~mine & ~prescribed
            keep = ~np.any(dangling[ends], axis=1)
            if keep.all():
                break
            ends = ends[keep]
        nodes = np.unique(ends)
        return nodes[~in_hex[nodes]]

    def problem(self, solid: str = "fbar", slack_fraction: float = 1e-6, transition: float = 0.01,
                insertion: str = "node", compression: bool = False) -> Problem:
        """A :class:`~skvalve.fem.Problem` of the model (load factor = total time).

        ``solid``: ``"fbar"`` (F-bar mean-dilatation hexes, default) or ``"q1"`` (full integration, locks).
        ``slack_fraction``: slack stiffness of the cables relative to their small-strain modulus. The default
        :math:`10^{-6}` keeps a slack cable (:math:`10^{-6}\\times 3\\sum\\mu_i \\approx 10^{-4}` MPa for the
        TriValve chordae) well below the leaflets' :math:`C_0 = 10^{-3}` MPa. Each cable is force-free in the
        reference state (slack stretch = reference end-to-end distance / path length).
        ``transition``: stretch interval over which a cable's slope ramps from slack to taut (C1, for Newton).
        ``insertion``: ``"node"`` (the input's point attachment) or ``"patch"`` (each cable end on the leaflet
        spread over the vertices of the cells around it: :func:`~skvalve.valve.chordae.insertion_patches`).
        ``compression``: cables that are one input truss (force-free length = reference length) carry their law in
        compression too, as the input's truss elements with a hyperelastic law do (it has no ``*No Compression``);
        collapsed chains stay tension-only (a chain of pin-jointed trusses buckles at its hinges).
        """
        space = Space(self.mesh)
        materials = MaterialRegions(self.mesh, list(self.laws), self.regions)
        if solid == "fbar":
            leaflets = FBarTerm(space, materials)
        elif solid == "q1":
            leaflets = HyperelasticTerm(space, materials)
        else:
            raise ValueError(f"solid must be 'fbar' or 'q1'; got {solid!r}")
        problem = Problem(space, [leaflets])
        ch = self.chordae
        cables = [TensionOnly(law, slack_fraction, transition) for law in ch.laws]
        law_index = ch.law_index
        if compression:  # laws k + n: the plain law, both ways, for the single trusses
            single = np.isclose(ch.slack_stretch, 1.0, rtol=0.0, atol=1e-9)
            law_index = np.where(single, ch.law_index + len(ch.laws), ch.law_index)
            cables = cables + list(ch.laws)
        if insertion not in ("node", "patch"):
            raise ValueError(f"insertion must be 'node' or 'patch'; got {insertion!r}")
        if ch.ends.shape[0]:
            ends, rest, slack = ch.ends, ch.rest_length, ch.slack_stretch
            if insertion == "patch":
                ends, rest, slack = insertion_patches(self.mesh.t, self.mesh.p, ch.ends, ch.rest_length)
            problem.add_term(Truss(space, ends, ch.area, cables, law_index, rest, slack, name="chordae"))
        if self.links is not None and self.links.size:
            problem.add_term(self.links.term(space))
        for load in self.pressures:
            problem.add_term(FollowerPressure(space, load.facets, load.at))
        for condition in self.conditions:
            problem.add_dirichlet(nodes=condition.vertices, value=_ValueAt(condition), components=[condition.component])
        return problem


class _ValueAt:
    """``value(X, t)`` callable of a :class:`NodalCondition` for ``Problem.add_dirichlet``."""

    def __init__(self, condition: NodalCondition) -> None:
        self.condition = condition

    def __call__(self, X: np.ndarray, t: float) -> np.ndarray:
        return np.asarray(self.condition.at(t))


def _leaflet_law(abaqus: AbaqusModel, name: str) -> LeeSacks:
    material = abaqus.material(name)
    data = material.option("anisotropic hyperelastic").data
    if len(data) != 4:
        raise ValueError(f"material {name!r} (line {material.line}): expected the 4 VUANISO_ISO properties "
                         f"(C0, D, C1, C2); got {len(data)}")
    c0, D, c1, c2 = data
    return LeeSacks(c0, c1, c2, D)


def _chord_law(abaqus: AbaqusModel, name: str) -> OgdenUniaxial:
    material = abaqus.material(name)
    option = material.option("hyperelastic")
    n = int(option.parameters.get("n", "1"))
    data = option.data
    if len(data) < 2 * n:
        raise ValueError(f"material {name!r} (line {material.line}): Ogden N={n} needs {2 * n} values; got {len(data)}")
    return OgdenUniaxial(tuple(data[0:2 * n:2]), tuple(data[1:2 * n:2]))


def valve_model(abaqus: AbaqusModel, layers: int = 4, step: int | None = None, link_factor: float = LINK_FACTOR,
                partial: bool = False) -> ValveModel:
    """Build the :class:`ValveModel` of ``abaqus`` over all its steps (``step`` None; load factor = total time) or of
    step ``step`` alone (load factor = its step time); shells extruded into ``layers`` hexes; LINK MPCs with
    ``link_factor`` times the stiffest chord's axial rigidity.

    Raises :class:`~skvalve.valve.support.UnsupportedInputError` naming the keywords and file lines the model
    cannot represent (:mod:`.support`); ``partial=True`` builds step ``step`` (default the first) alone if it uses
    none of them itself.
    """
    if partial and step is None:
        step = 0
    notes: list[str] = check_supported(abaqus, step, partial)
    steps = selected_steps(abaqus, step)
    windows = step_windows(steps)
    amplitudes, total_time = amplitude_table(abaqus)
    histories = condition_histories(abaqus, steps, windows, amplitudes, total_time)
    elem_type = np.empty(abaqus.n_elements, dtype=object)
    elem_conn: dict[int, np.ndarray] = {}
    for block in abaqus.element_blocks:
        elem_type[block.indices] = block.element_type
        for index, row in zip(block.indices, block.connectivity, strict=True):
            elem_conn[int(index)] = row
    sections = [s for s in abaqus.sections if len(s.elements)]
    solid_sections = [s for s in sections if elem_type[s.elements[0]] in _BRICK_TYPES + _SHELL_TYPES]
    truss_sections = [s for s in sections if elem_type[s.elements[0]] in _TRUSS_TYPES]
    laws = [_leaflet_law(abaqus, s.material) for s in solid_sections]
    region_names = [s.elset for s in solid_sections]

    # ---------------------------------------------------------------- leaflet cells
    shells = any(elem_type[s.elements[0]] in _SHELL_TYPES for s in solid_sections)
    cells, cell_region, cell_source = [], [], []
    for r, section in enumerate(solid_sections):
        cells.append(np.array([elem_conn[int(e)] for e in section.elements]))
        cell_region.append(np.full(len(section.elements), r))
        cell_source.append(np.asarray(section.elements))
    cells_arr, regions, sources = np.vstack(cells), np.concatenate(cell_region), np.concatenate(cell_source)
    shell_sources, ext = sources, None
    if shells:
        thickness = np.concatenate([np.full(len(s.elements), s.thickness) for s in solid_sections])
        shell_nodes = np.unique(cells_arr)
        local = np.full(abaqus.nodes.shape[0], -1)
        local[shell_nodes] = np.arange(shell_nodes.size)
        ext = extrude_shell(abaqus.nodes[shell_nodes], local[cells_arr], thickness, layers)
        solid_points, hexes = ext.nodes, ext.hexes
        regions, sources = regions[ext.shell_element], sources[ext.shell_element]
        mid = layers // 2
        # global node -> its vertex on the midsurface layer (chord attachments) and its whole fibre (conditions)
        solid_vertex_of = {int(g): mid * shell_nodes.size + int(local[g]) for g in shell_nodes}
        fibre_of = {int(g): [k * shell_nodes.size + int(local[g]) for k in range(layers + 1)] for g in shell_nodes}
        notes.append(f"{len(cells_arr)} shells extruded into {layers} layers ({hexes.shape[0]} hexes)")
    else:
        solid_nodes = np.unique(cells_arr)
        local = np.full(abaqus.nodes.shape[0], -1)
        local[solid_nodes] = np.arange(solid_nodes.size)
        solid_points, hexes = abaqus.nodes[solid_nodes], local[cells_arr]
        solid_vertex_of = {int(g): int(local[g]) for g in solid_nodes}
        fibre_of = {g: [v] for g, v in solid_vertex_of.items()}
        det = hex_corner_jacobians(solid_points, hexes)
        bad = np.flatnonzero(np.any(det <= 0.0, axis=1))
        if bad.size:
            raise TangledMeshError(sources[bad], f" in {abaqus.path}")

    # ---------------------------------------------------------------- chordae
    bars, bar_group, areas, law_names = [], [], [], []
    for g, section in enumerate(truss_sections):
        bars.append(np.array([elem_conn[int(e)] for e in section.elements]))
        bar_group.append(np.full(len(section.elements), g))
        areas.append(section.area)
        law_names.append(section.material)
    bars_arr = np.vstack(bars) if bars else np.zeros((0, 2), dtype=np.int64)
    group_arr = np.concatenate(bar_group) if bar_group else np.zeros(0, dtype=np.int64)
    bcs = list(abaqus.boundary_conditions) + [bc for s in steps for bc in s.boundary_conditions]
    bc_nodes = np.unique(np.concatenate([bc.nodes for bc in bcs])) if bcs else np.zeros(0, dtype=np.int64)
    linked = link_nodes(abaqus)
    anchored = np.union1d(np.union1d(np.fromiter(solid_vertex_of.keys(), dtype=np.int64), bc_nodes), linked)
    reduction = collapse_chains(bars_arr, abaqus.nodes, anchored, group_arr)
    if reduction.dropped_bars.size:
        notes.append(f"chordae: dropped {reduction.dropped_bars.size} dangling bar(s) at node(s) "
                     f"{abaqus.node_labels[reduction.dropped_nodes][:10].tolist()} (labels)")
    notes.append("chordae: " + reduction.summary())
    chord_only = np.array([n for n in reduction.kept_nodes if int(n) not in solid_vertex_of], dtype=np.int64)

    # ---------------------------------------------------------------- vertices: chordae-only first
    offset = chord_only.size
    vertex_of = {int(g): offset + v for g, v in solid_vertex_of.items()}
    vertex_of.update({int(g): k for k, g in enumerate(chord_only)})
    fibres = {g: [offset + v for v in vs] for g, vs in fibre_of.items()}
    fibres.update({int(g): [k] for k, g in enumerate(chord_only)})
    points = np.vstack([abaqus.nodes[chord_only], solid_points])
    vertex_source = np.concatenate([chord_only, np.full(solid_points.shape[0], -1)])
    if not shells:
        vertex_source[offset:] = np.unique(cells_arr)
    cells_skfem = (hexes + offset)[:, ABAQUS_TO_SKFEM_HEX]
    mesh = skfem.MeshHex(np.ascontiguousarray(points.T), np.ascontiguousarray(cells_skfem.T))
    ends = np.vectorize(vertex_of.__getitem__, otypes=[np.int64])(reduction.ends) if reduction.ends.size else \
        np.zeros((0, 2), dtype=np.int64)
    chordae = Chordae(ends, reduction.rest_length, np.asarray(areas, dtype=float)[reduction.group], reduction.group,
                      [_chord_law(abaqus, name) for name in law_names], law_names, reduction,
                      np.minimum(reduction.straight_length / reduction.rest_length, 1.0))
    chord_rigidity = max((law.young_modulus * a for law, a in zip(chordae.laws, areas, strict=True)), default=None)
    links = link_constraints(abaqus, vertex_of, points, chord_rigidity, link_factor)
    if links.size:
        notes.append(f"{links.size} LINK MPC(s) as penalty bars, EA = {links.rigidity:.4g} N ({link_factor:g} x the "
                     "stiffest chord's)")

    # ---------------------------------------------------------------- clip arms, conditions and pressure
    arms = clip_arms(abaqus, histories)
    for arm in arms:
        end = arm.angle.at(windows[-1].end)
        notes.append(f"clip arm {arm.name}: {arm.triangles.shape[0]} triangles turning about reference node "
                     f"{int(abaqus.node_labels[arm.reference_node])}, axis {np.round(arm.axis, 6).tolist()}, by "
                     f"{end:.6g} rad ({np.degrees(end):.4g} deg) at the end")
    # the arms are in contact from the start: the leaflets keep the side of each arm they start on, its positive normal
    # side (the R3D4 facets' orientation), to which the input's one-sided rigid surfaces push overclosed nodes; the
    # input's arm contact pairs start with "Clip capture", when the leaflets closed by step 1 overlap three of the four
    # parked arms, a state the barrier cannot start from
    obstacles = [arm.obstacle(0.0) for arm in arms]
    if arms:
        notes.append("clip arms in contact from the start (the input's contact pairs start with its second step, when "
                     "the leaflets closed in step 1 overlap the parked arms): the leaflets stay on each arm's positive "
                     "side, where they start")
    references = {arm.reference_node for arm in arms}
    end_time = windows[-1].end
    ramp = windows[0].period if len(windows) == 1 and windows[0].static else None
    conditions, skipped_nodes, skipped_rotations = nodal_conditions(bcs, histories, fibres, references, ramp)
    if skipped_nodes:
        notes.append(f"{len(skipped_nodes)} constrained node(s) outside the model skipped (e.g. labels "
                     f"{abaqus.node_labels[sorted(skipped_nodes)][:5].tolist()})")
    if skipped_rotations:
        notes.append(f"{skipped_rotations} rotational boundary dof(s) skipped (no rotations on solids)")
    pressures = []
    if steps:
        facet_index = _facet_lookup(mesh)
        for load, history in load_histories(steps, windows, amplitudes, total_time):
            if load.load_type.upper() != "P":
                notes.append(f"*Dsload type {load.load_type} on {load.surface} skipped (only P is modelled)")
                continue
            facets = _surface_facets(abaqus.surface(load.surface), elem_conn, vertex_of, facet_index,
                                     ext, offset, shell_sources)
            defining = [seg for seg in history.segments if seg.location is not None]
            peak = max(defining, key=lambda seg: abs(seg.value))
            pressures.append(PressureLoad(load.surface, facets, peak.value, defining[0].amplitude, ramp, history))
    if step is not None and len(abaqus.steps) > 1:
        notes.append(f"only step {step} ({steps[0].name!r}) modelled; {len(abaqus.steps) - 1} other step(s) not")
    elif len(windows) > 1:
        notes.append("steps on the total-time axis: " + ", ".join(f"{w.name!r} {w.start:g}-{w.end:g}"
                                                                   for w in windows))
    return ValveModel(str(abaqus.path), mesh, sources, regions, region_names, laws, chordae, conditions, pressures,
                      end_time, vertex_source, notes, links, windows, arms, obstacles)


def _facet_lookup(mesh: skfem.MeshHex) -> dict[tuple[int, ...], int]:
    facets = np.sort(mesh.facets, axis=0)
    return {tuple(col): k for k, col in enumerate(facets.T.tolist())}


def _surface_facets(surface, elem_conn, vertex_of, facet_index, ext, offset, shell_sources) -> np.ndarray:
    """Mesh facet indices of an element-face surface (bricks: S1..S6; extruded shells: SPOS/SNEG)."""
    found = []
    for group in surface.faces:
        face = group.face.upper()
        if ext is not None:
            hexes = ext.face_hexes(face)
            corner = (4, 5, 6, 7) if face == "SPOS" else (0, 3, 2, 1)  # faces S2 / S1 of the hex
            wanted = np.isin(shell_sources[ext.shell_element[hexes]], group.elements)
            for h in hexes[wanted]:
                found.append(facet_index[tuple(sorted(int(ext.hexes[h, c]) + offset for c in corner))])
        else:
            if face not in HEX_FACE_NODES:
                raise ValueError(f"surface {surface.name!r}: face {face} is not a brick face S1..S6")
            corner = HEX_FACE_NODES[face]
            for e in group.elements:
                conn = elem_conn[int(e)]
                found.append(facet_index[tuple(sorted(vertex_of[int(conn[c])] for c in corner))])
    return np.unique(np.asarray(found, dtype=np.int64))

