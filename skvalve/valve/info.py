"""What is in an Abaqus valve model: a readable summary and a picture of the undeformed valve.

:func:`valve_info` is what ``skvalve valve info FILE --out DIR`` runs: it reads the file, writes
``summary.txt`` and ``undeformed.png`` into ``DIR`` and returns the :class:`ModelSummary`.
"""

from __future__ import annotations

import os
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

from ..io.abaqus import AbaqusModel, read_model
from .geometry import LEAFLETS, leaflet_surfaces

__all__ = ["MaterialSummary", "StepSummary", "ModelSummary", "summarise", "summarise_model", "plot_undeformed",
           "valve_info", "LEAFLET_COLOURS"]

LEAFLET_COLOURS = {"Anterior": "#1f77b4", "Posterior": "#2ca02c", "Septal": "#d62728"}
CHORDAE_COLOUR = "#555555"


@dataclass
class MaterialSummary:
    """A material: name and its options as (keyword, parameters, values)."""

    name: str
    options: list[tuple[str, dict[str, str], list[float]]]


@dataclass
class StepSummary:
    """A step: procedure and time, boundary conditions grouped, loads and contact in words."""

    name: str
    procedure: str
    time_period: float
    boundary_groups: list[str]
    loads: list[str]
    contact: list[str]


@dataclass
class ModelSummary:
    """Counts and definitions of a read model (see :meth:`to_text`)."""

    path: Path
    parse_seconds: float
    n_nodes: int
    elements_by_type: dict[str, int]
    element_sets: dict[str, int]
    node_sets: dict[str, int]
    surfaces: dict[str, str]
    sections: list[str]
    materials: list[MaterialSummary]
    amplitudes: list[str]
    initial_boundary_groups: list[str]
    steps: list[StepSummary]
    constraints: list[str]
    interactions: list[str]
    ignored: dict[str, tuple[int, str]]
    warnings: list[str]
    outputs: list[Path] = field(default_factory=list)

    def to_text(self) -> str:
        """The summary as plain text, one section per topic."""
        lines = [f"Model {self.path.name} (read in {self.parse_seconds:.2f} s)", "",
                 f"Nodes: {self.n_nodes}", "Elements by type:"]
        lines += [f"  {kind:<10} {count:>8}" for kind, count in self.elements_by_type.items()]

        def block(title: str, rows: list[str]) -> None:
            lines.extend(["", f"{title}:"] + [f"  {row}" for row in rows] if rows else ["", f"{title}: none"])

        block("Element sets (elements)", [f"{name:<50} {n:>8}" for name, n in self.element_sets.items()])
        block("Node sets (nodes)", [f"{name:<50} {n:>8}" for name, n in self.node_sets.items()])
        block("Surfaces", [f"{name:<40} {text}" for name, text in self.surfaces.items()])
        block("Sections", self.sections)
        rows = []
        for material in self.materials:
            rows.append(material.name)
            for keyword, parameters, values in material.options:
                params = ", ".join(f"{k}={v}" for k, v in parameters.items())
                numbers = ", ".join(f"{v:.6g}" for v in values)
                rows.append(f"    *{keyword}{' (' + params + ')' if params else ''}: {numbers}")
        block("Materials (file units)", rows)
        block("Amplitudes", self.amplitudes)
        block("Boundary conditions outside steps", self.initial_boundary_groups)
        for step in self.steps:
            block(f"Step {step.name!r}: {step.procedure}, time {step.time_period:g}",
                  [f"boundary  {g}" for g in step.boundary_groups] + [f"load      {g}" for g in step.loads]
                  + [f"contact   {g}" for g in step.contact])
        block("Constraints", self.constraints)
        block("Surface interactions", self.interactions)
        block("Ignored by the implicit model", [f"*{k} x{n}: {why}" for k, (n, why) in self.ignored.items()])
        block("Reader warnings", self.warnings)
        return "\n".join(lines) + "\n"


def _boundary_groups(conditions) -> list[str]:
    """Boundary conditions grouped by (amplitude, op, dof range, value): node counts per group."""
    groups: dict[tuple, set[int]] = {}
    for bc in conditions:
        key = (bc.amplitude or "-", bc.op, bc.first_dof, bc.last_dof, bc.value, bc.kind)
        groups.setdefault(key, set()).update(bc.nodes.tolist())
    rows = []
    for (amplitude, op, first, last, value, kind), nodes in sorted(groups.items(), key=lambda kv: str(kv[0])):
        dofs = f"dof {first}" if first == last else f"dofs {first}-{last}"
        rows.append(f"{kind.lower()} {dofs} = {value:g} on {len(nodes)} nodes (amplitude {amplitude}, op={op})")
    return rows


def summarise_model(model: AbaqusModel, parse_seconds: float = 0.0) -> ModelSummary:
    """The :class:`ModelSummary` of an already read model."""
    surfaces = {}
    for surface in model.surfaces.values():
        labels: Counter[str] = Counter()
        for group in surface.faces:
            labels[group.face] += len(group.elements)
        count = sum(len(f.elements) for f in surface.faces)
        surfaces[surface.name] = f"{count} faces ({', '.join(f'{k} x{v}' for k, v in sorted(labels.items()))})"
    sections = []
    for s in model.sections:
        extra = [f"area {s.area:g}" if s.area is not None else "", f"thickness {s.thickness:g}"
                 if s.thickness is not None else "", f"{s.integration_points} points" if s.integration_points else ""]
        sections.append(f"{s.kind} on {s.elset} ({len(s.elements)} el.): {s.material}"
                        + "".join(f", {e}" for e in extra if e))
    materials = [MaterialSummary(m.name, [(o.keyword, o.parameters, o.data) for o in m.options])
                 for m in model.materials.values()]
    amplitudes = [f"{a.name}: {a.definition}, " + ", ".join(f"({t:g}, {v:g})" for t, v in zip(a.times, a.values,
                                                                                                  strict=True))
                  for a in model.amplitudes.values()]
    steps = []
    for step in model.steps:
        loads = [f"{d.load_type} = {d.magnitude:g} on {d.surface} (amplitude {d.amplitude or '-'})"
                 for d in step.distributed_loads]
        loads += [f"force {c.magnitude:g} dof {c.dof} on {c.target}" for c in step.concentrated_loads]
        contact = [f"pair {' / '.join(p.surfaces)} ({p.interaction}, {p.mechanical_constraint or '-'})"
                   for p in step.contact_pairs]
        if step.general_contact is not None:
            contact += [f"general contact, inclusion {' / '.join(i for i in inc if i) or 'all exterior'}"
                        for inc in step.general_contact.inclusions]
        steps.append(StepSummary(step.name, step.procedure or "-", step.time_period,
                                 _boundary_groups(step.boundary_conditions), loads, contact))
    constraints = [f"MPC {kind} x{n}" for kind, n in Counter(m.mpc_type for m in model.mpcs).items()]
    constraints += [f"rigid body on {r.elset} ({len(r.elements)} el.), reference node "
                    f"{model.node_labels[r.reference_node]}" for r in model.rigid_bodies]
    constraints += [f"connector {'/'.join(c.connection_types)} on {c.elset}" for c in model.connector_sections]
    constraints += [f"transform {t.transform_type} on {t.nset} ({len(t.nodes)} nodes)" for t in model.transforms]
    interactions = [f"{i.name}: friction {'rough' if i.rough else i.friction}, pressure-overclosure "
                    f"{i.pressure_overclosure}{' (no separation)' if i.no_separation else ''}"
                    for i in model.interactions.values()]
    ignored: dict[str, tuple[int, str]] = {}
    for item in model.ignored:
        count, _ = ignored.get(item.keyword, (0, ""))
        ignored[item.keyword] = (count + 1, item.reason)
    return ModelSummary(
        model.path, parse_seconds, len(model.nodes), model.elements_by_type(),
        {s.name: len(s.indices) for s in model.element_sets.values()},
        {s.name: len(s.indices) for s in model.node_sets.values()}, surfaces, sections, materials, amplitudes,
        _boundary_groups(model.boundary_conditions), steps, constraints, interactions, ignored,
        [f"{w.location}: {w.message}" for w in model.warnings])


def summarise(path: str | os.PathLike) -> ModelSummary:
    """Read an Abaqus input and summarise it."""
    start = time.perf_counter()
    model = read_model(path)
    return summarise_model(model, time.perf_counter() - start)


def plot_layers(model: AbaqusModel) -> list[tuple[str, str, np.ndarray]]:
    """What :func:`plot_undeformed` draws: (label, "faces" | "lines", node-index array) per layer.

    Leaflets (sets ``*<Leaflet>_Leaflet_Elements``) by their ventricular or shell surface; chordae (2-node
    truss elements) as lines; any other surface elements (e.g. rigid clips) in grey.
    """
    layers: list[tuple[str, str, np.ndarray]] = []
    try:
        surfaces = leaflet_surfaces(model)
    except ValueError:
        surfaces = {}
    for name in LEAFLETS:
        if name in surfaces:
            s = surfaces[name]
            layers.append((f"{name} leaflet", "faces", s.ventricular if s.ventricular is not None else s.mid_lower))
    trusses = [b.connectivity for b in model.element_blocks if b.element_type.startswith("T3D")]
    if trusses:
        layers.append(("Chordae", "lines", np.concatenate(trusses)[:, :2]))
    others = [b.connectivity for b in model.element_blocks
              if b.connectivity.shape[1] in (3, 4) and not (surfaces and b.element_type.startswith(("S3", "S4")))]
    if others:
        layers.append(("Other surfaces", "faces", np.concatenate([o[:, :3] for o in others])
                       if any(o.shape[1] == 3 for o in others) else np.concatenate(others)))
    if not any(kind == "faces" for _, kind, _ in layers) and not trusses:
        layers.append(("Nodes", "points", np.arange(len(model.nodes))))
    return layers


def plot_undeformed(model: AbaqusModel, out_dir: str | os.PathLike, name: str = "undeformed.png") -> Path:
    """Write a PNG of the undeformed valve, leaflets coloured, chordae as lines; returns its path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    x = model.nodes
    figure = Figure(figsize=(13, 6.5), dpi=120)
    FigureCanvasAgg(figure)
    layers = plot_layers(model)
    low, high = x.min(axis=0), x.max(axis=0)
    centre, half = 0.5 * (low + high), 0.5 * float(np.max(high - low)) or 1.0
    for panel, (elevation, azimuth, title) in enumerate([(35, -60, "oblique"), (90, -90, "viewed along -z")], start=1):
        axes = figure.add_subplot(1, 2, panel, projection="3d")
        handles = []
        for label, kind, data in layers:
            if kind == "faces":
                colour = LEAFLET_COLOURS.get(label.split()[0], "#bbbbbb")
                collection = Poly3DCollection(x[data], facecolors=colour, edgecolors="none", alpha=0.85, label=label)
                axes.add_collection3d(collection)
            elif kind == "lines":
                collection = Line3DCollection(x[data], colors=CHORDAE_COLOUR, linewidths=0.6, label=label)
                axes.add_collection3d(collection)
            else:
                collection = axes.scatter(*x[data].T, s=1, color="k", label=label)
            handles.append(collection)
        axes.set(xlim=(centre[0] - half, centre[0] + half), ylim=(centre[1] - half, centre[1] + half),
                 zlim=(centre[2] - half, centre[2] + half), xlabel="x (mm)", ylabel="y (mm)", zlabel="z (mm)")
        axes.set_box_aspect((1, 1, 1))
        axes.view_init(elev=elevation, azim=azimuth)
        axes.set_title(title, fontsize=10)
        if panel == 1:
            axes.legend(handles=handles, loc="upper left", fontsize=9)
        else:
            axes.set_zticks([])
            axes.set_zlabel("")
    figure.suptitle(f"{model.path.name}: undeformed", fontsize=12)
    target = out / name
    partial = out / f".{name}.partial"
    figure.savefig(partial, format="png")
    os.replace(partial, target)
    return target


def valve_info(path: str | os.PathLike, out_dir: str | os.PathLike) -> ModelSummary:
    """Read ``path``, write ``summary.txt`` and ``undeformed.png`` into ``out_dir``, return the summary."""
    start = time.perf_counter()
    model = read_model(path)
    summary = summarise_model(model, time.perf_counter() - start)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    text_path = out / "summary.txt"
    partial = out / ".summary.txt.partial"
    partial.write_text(summary.to_text())
    os.replace(partial, text_path)
    summary.outputs = [text_path, plot_undeformed(model, out)]
    return summary
