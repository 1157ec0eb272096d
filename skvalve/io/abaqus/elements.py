"""Element library facts the reader needs: nodes per element type and the face labels of each family."""

from __future__ import annotations

__all__ = ["NODES_PER_ELEMENT", "FACE_LABELS", "SHELL_FACE_LABELS", "HEX_FACE_NODES", "is_shell_like"]

#: Nodes per element for the element types the reader accepts (Abaqus element library names).
NODES_PER_ELEMENT: dict[str, int] = {
    **dict.fromkeys(["C3D8", "C3D8R", "C3D8H", "C3D8RH", "C3D8I", "C3D8IH"], 8),
    **dict.fromkeys(["C3D4", "C3D4H"], 4), **dict.fromkeys(["C3D10", "C3D10H", "C3D10M"], 10),
    **dict.fromkeys(["C3D6", "C3D6H"], 6), **dict.fromkeys(["C3D20", "C3D20R", "C3D20H", "C3D20RH"], 20),
    **dict.fromkeys(["S4", "S4R", "S4R5", "M3D4", "M3D4R", "R3D4", "SFM3D4", "SFM3D4R", "CPE4", "CPS4", "CAX4"], 4),
    **dict.fromkeys(["S3", "S3R", "M3D3", "R3D3", "SFM3D3", "CPE3", "CPS3", "CAX3"], 3),
    **dict.fromkeys(["T3D2", "T3D2H", "T2D2", "B31", "CONN3D2", "SPRINGA", "DASHPOTA"], 2),
    **dict.fromkeys(["T3D3", "B32"], 3), **dict.fromkeys(["MASS", "ROTARYI"], 1),
}
#: Face labels accepted on an element-based surface, by element family.
FACE_LABELS: dict[int, tuple[str, ...]] = {
    8: ("S1", "S2", "S3", "S4", "S5", "S6"), 20: ("S1", "S2", "S3", "S4", "S5", "S6"),
    4: ("S1", "S2", "S3", "S4"), 10: ("S1", "S2", "S3", "S4"), 6: ("S1", "S2", "S3", "S4", "S5"),
}
SHELL_FACE_LABELS = ("SPOS", "SNEG")
#: Corner nodes (0-based, element order) of the faces S1..S6 of an 8-node brick, outward normal by the
#: right-hand rule (Abaqus Analysis User's Guide, "Three-dimensional solid element library").
HEX_FACE_NODES: dict[str, tuple[int, int, int, int]] = {
    "S1": (0, 3, 2, 1), "S2": (4, 5, 6, 7), "S3": (0, 1, 5, 4),
    "S4": (1, 2, 6, 5), "S5": (2, 3, 7, 6), "S6": (3, 0, 4, 7),
}


def is_shell_like(element_type: str) -> bool:
    """Shell, membrane, surface and rigid-surface elements (faces SPOS/SNEG)."""
    return element_type.startswith(("S3", "S4", "M3D", "R3D", "SFM3D"))
