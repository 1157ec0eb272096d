"""A two-leaflet stand-in valve written as an Abaqus deck with the Texas TriValve 1.0 keywords (test helper).

Two flat leaflets of C3D8R bricks hang from a fixed annulus edge (z = 0), mirror images about x = 0, their inner
faces ``gap`` apart. The ventricular pressure (``*Dsload`` P on the outer faces, smooth step over 0.5-1.5 of step time)
pushes them together; each leaflet's free edge hangs on two chordae (two-bar chains from a branch point to a
papillary tip, pulled down by ``pull`` over 0-0.5 of step time), with the Ogden law in uniaxial stress. The deck
is written, not computed: the closure reads it as it reads the shipped inputs.

With ``arm``, a second step turns a rigid R3D4 plate into leaflet A (the clip input's keywords: ``*Rigid Body``,
``*Transform``, the reference node's dof 6), for ``tests/test_valve_close_mini_clip.py``.

By construction the model is symmetric about x = 0 (the two leaflets) and about y = width/2 (each leaflet), and
its reactions balance the pressure: the checks of ``tests/test_valve_close_mini.py``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

#: Lee-Sacks (C0, D, C1, C2) and the chordae's three-term Ogden (mu_i, alpha_i), D: values of the order the shipped
#: 1.0 inputs use (a stand-in, not a fit)
LEAFLET_LAW = (1.0e-2, 20.0, 2.0e-3, 20.0)
CHORD_LAW = (4.0, 20.0, 4.0, 20.0, 4.0, 20.0, 5.0e-4, 0.0, 0.0)
CHORD_AREA = 0.3


def _leaflet(side: float, width: float, height: float, thickness: float, gap: float, nw: int, nh: int):
    """Corner coordinates and bricks of one leaflet (``side`` +1 or -1: which half of x), and which brick face
    (S1 or S2) is the outer one."""
    a, b = np.linspace(0.0, width, nw + 1), np.linspace(0.0, height, nh + 1)
    c = np.array([0.0, thickness])
    A, B, C = np.meshgrid(a, b, c, indexing="ij")
    x = side * (0.5 * gap + C)
    points = np.column_stack([x.ravel(), A.ravel(), -B.ravel()])
    index = np.arange(points.shape[0]).reshape(nw + 1, nh + 1, 2)
    bricks = []
    for i in range(nw):
        for j in range(nh):
            bottom = [index[i, j, 0], index[i + 1, j, 0], index[i + 1, j + 1, 0], index[i, j + 1, 0]]
            top = [index[i, j, 1], index[i + 1, j, 1], index[i + 1, j + 1, 1], index[i, j + 1, 1]]
            bricks.append(bottom + top)
    bricks = np.array(bricks)
    corners = points[bricks]
    jacobian = np.linalg.det(np.stack([corners[:, 1] - corners[:, 0], corners[:, 3] - corners[:, 0],
                                       corners[:, 4] - corners[:, 0]], axis=1))
    if np.all(jacobian < 0.0):  # the mirrored leaflet: bottom and top faces swap
        bricks = bricks[:, [4, 5, 6, 7, 0, 1, 2, 3]]
        outer = "S1"
    else:
        outer = "S2"
    annulus = index[:, 0, :].ravel()
    free_edge = index[:, nh, 1]
    return points, bricks, outer, annulus, free_edge


def write_mini_valve(path: str | Path, pressure: float = 0.004, pull: float = 0.5, width: float = 8.0,
                     height: float = 6.0, thickness: float = 0.4, gap: float = 4.0, nw: int = 4, nh: int = 3,
                     arm: float | None = None) -> Path:
    """Write the deck (module docstring) to ``path`` and return it. Lengths in mm, pressure in MPa.

    ``arm``: a second step (0.5 of step time) in which a rigid R3D4 plate, hinged 0.5 mm outside leaflet A's outer
    face at the annulus, turns by ``arm`` rad about the y-axis (smooth step) and sweeps into that leaflet, as the
    clip input's arms do."""
    nodes, elements, lines = [], [], []
    leaflets = []
    for name, side in (("A", 1.0), ("B", -1.0)):
        points, bricks, outer, annulus, free_edge = _leaflet(side, width, height, thickness, gap, nw, nh)
        offset = len(nodes)
        nodes.extend(points.tolist())
        leaflets.append((name, side, bricks + offset, outer, annulus + offset, free_edge + offset))
    # chordae: a papillary tip below each leaflet, a branch point, two-bar chains to two free-edge nodes
    chords = []
    tips = []
    for name, side, _bricks, _outer, _annulus, free_edge in leaflets:
        tip = len(nodes)
        nodes.append([side * 0.25 * gap, 0.5 * width, -height - 6.0])
        branch = len(nodes)
        nodes.append([side * 0.25 * gap, 0.5 * width, -height - 3.0])
        chords.append((name, tip, branch))
        for attach in (free_edge[1], free_edge[-2]):
            middle = len(nodes)
            nodes.append(0.5 * (np.asarray(nodes[branch]) + np.asarray(nodes[attach])))
            chords.append((name, branch, middle))
            chords.append((name, middle, attach))
        tips.append(tip)

    lines += ["** skvalve test deck: a two-leaflet stand-in valve (tests/_mini_valve.py)", "*Heading",
              " mini valve", "*Part, name=Leaflet", "*Node, nset=Leaflet_Nodes"]
    lines += [f"{k + 1}, {x:.9g}, {y:.9g}, {z:.9g}" for k, (x, y, z) in enumerate(nodes)]
    label = 0
    for name, _side, bricks, _outer, _annulus, _free in leaflets:
        lines.append(f"*Element, type=C3D8R, elset={name}_Leaflet_Elements")
        first = label + 1
        for row in bricks:
            label += 1
            lines.append(f"{label}, " + ", ".join(str(int(n) + 1) for n in row))
        elements.append((name, first, label))
    for name in ("A", "B"):
        lines.append(f"*Element, type=T3D2, elset={name}_Chordae")
        for owner, i, j in chords:
            if owner == name:
                label += 1
                lines.append(f"{label}, {i + 1}, {j + 1}")
    for name, first, last in elements:
        lines += [f"*Elset, elset={name}_Outer, generate", f"{first}, {last}, 1"]
    for name, *_ in leaflets:
        lines += [f"*Solid Section, elset={name}_Leaflet_Elements, material=Leaflet_{name}", ","]
        lines += [f"*Solid Section, elset={name}_Chordae, material=Chordae", f"{CHORD_AREA},"]
    lines.append("*End Part")
    lines += ["*Assembly, name=Assembly", "*Instance, name=Leaflet_Instance, part=Leaflet", "*End Instance"]
    lines.append("*Surface, type=ELEMENT, name=Leaflet_Surfaces_Outer")
    lines += [f"Leaflet_Instance.{name}_Outer, {outer}" for name, _s, _b, outer, _a, _f in leaflets]
    if arm is not None:  # a 4 x 6.5 mm plate below the hinge; its reference node on the hinge, turning about y
        hinge = np.array([0.5 * gap + thickness + 0.5, 0.5 * width, 0.0])
        corners = hinge + np.array([[0.0, -2.0, -1.0], [0.0, 2.0, -1.0], [0.0, 2.0, -7.5], [0.0, -2.0, -7.5]])
        first = len(nodes) + 1
        lines += ["*Node"] + [f"{first + k}, {x:.9g}, {y:.9g}, {z:.9g}" for k, (x, y, z) in enumerate(corners)]
        lines += [f"{first + 4}, {hinge[0]:.9g}, {hinge[1]:.9g}, {hinge[2]:.9g}",
                  "*Element, type=R3D4, elset=Arm", f"{label + 1}, {first}, {first + 1}, {first + 2}, {first + 3}",
                  "*Nset, nset=Arm_RP", f"{first + 4}", "*Rigid Body, ref node=Arm_RP, elset=Arm",
                  "*Transform, nset=Arm_RP", "0., 0., 1., 1., 0., 0."]  # local 3-axis: z x x = y
    lines.append("*End Assembly")
    lines += ["*Amplitude, name=Amp-1, definition=SMOOTH STEP", "0.5, 0., 1.5, 1.",
              "*Amplitude, name=Amp-2, definition=SMOOTH STEP", "0., 0., 0.5, 1."]
    for name, *_ in leaflets:
        lines += [f"*Material, name=Leaflet_{name}", "*Density", "1e-09,",
                  "*anisotropic hyperelastic, user, formulation=invariant, local directions=1, type=compressible, "
                  "properties=4", ", ".join(f"{v:.9g}" for v in LEAFLET_LAW)]
    lines += ["*Material, name=Chordae", "*Density", "1e-9", "*Hyperelastic, OGDEN, N=3",
              ", ".join(f"{v:.9g}" for v in CHORD_LAW)]
    lines += ["*Step, name=Closure, nlgeom=YES", "*Dynamic, Explicit", ", 1.5"]
    for _name, _side, _bricks, _outer, annulus, _free in leaflets:
        for n in annulus:
            lines.append("*Boundary, op=NEW, amplitude=Amp-1")
            lines += [f"Leaflet_Instance.{n + 1}, {d}, {d}, 0.0" for d in (1, 2, 3)]
    for tip in tips:
        lines.append("*Boundary, op=NEW, amplitude=Amp-2")
        lines += [f"Leaflet_Instance.{tip + 1}, 1, 1, 0.0", f"Leaflet_Instance.{tip + 1}, 2, 2, 0.0",
                  f"Leaflet_Instance.{tip + 1}, 3, 3, {-pull:.9g}"]
    if arm is not None:
        lines += ["*Boundary", "Arm_RP, 1, 5", "*Boundary", "Arm_RP, 6, 6, 0."]
    lines += ["*Dsload, op=NEW, amplitude=Amp-1", f"Leaflet_Surfaces_Outer, P, {pressure:.9g}", "*End Step"]
    if arm is not None:
        lines += ["*Step, name=Clip, nlgeom=YES", "*Dynamic, Explicit", ", 0.5", "*Boundary, amplitude=Amp-2",
                  f"Arm_RP, 6, 6, {arm:.9g}", "*End Step"]
    lines.append("")
    path = Path(path)
    path.write_text("\n".join(lines))
    return path
