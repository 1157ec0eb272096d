"""Read Abaqus input files (``.inp``) into an assembled :class:`AbaqusModel`.

Written for the Texas TriValve models (Mathur et al. 2022, Engineering with Computers,
doi:10.1007/s00366-022-01659-w; 1.0 files CC BY-NC-SA 4.0, 1.1 files CC BY 4.0) but general: parts,
instances (translation and rotation), all ``*Node`` blocks, element blocks, node/element sets (with
``generate``), element-face surfaces, sections, materials, amplitudes, boundary conditions, ``*Dsload``,
contact pairs and general contact, ``*MPC``, rigid bodies, connectors, transforms and steps.

Typical use (the numbering and the meaning of each field are documented in :mod:`.model`)::

    model = read_model("Diseased_QuasiStatic.inp")
    model.elements_by_type()                      # {'C3D8R': 18920, 'T3D2': 1783}
    (truss,) = model.blocks_of_type("T3D2")       # labels, connectivity (global node indices), elset
    annulus = model.node_set("Leaflet_Instance.Outer_Annular_Nodes").indices
    model.node_indices("Leaflet_Instance.12")     # a node of an instance, as the file names it
    area = [s.area for s in model.sections if s.elset.endswith("Chordae")]
    ogden = model.material("Anterior_Chordae").option("hyperelastic").data
    (step,) = model.steps                         # .boundary_conditions, .distributed_loads, .contact_pairs
    model.ignored                                 # what the implicit model does not use, with file lines

Modules: :mod:`.lexer` (cards, strict numbers, ``*Include``), :mod:`.model` (the dataclasses),
:mod:`.materials`, :mod:`.mesh` and :mod:`.mesh_cards` (mesh keywords), :mod:`.step_cards` (history and
constraint keywords), :mod:`.reader` (dispatch and assembly).
"""

from __future__ import annotations

import os
from pathlib import Path

from .elements import HEX_FACE_NODES, NODES_PER_ELEMENT
from .errors import AbaqusParseError, Location
from .materials import AbaqusMaterial, MaterialOption
from .model import (
    MPC,
    TWO_NODE_MPC_TYPES,
    AbaqusModel,
    Amplitude,
    BoundaryCondition,
    ConcentratedLoad,
    ConnectorSection,
    ContactPair,
    DistributedLoad,
    ElementBlock,
    ElementSet,
    GeneralContact,
    IgnoredKeyword,
    Instance,
    NodeSet,
    ReadWarning,
    RigidBody,
    Section,
    Step,
    Surface,
    SurfaceFaces,
    SurfaceInteraction,
    Transform,
)
from .reader import IGNORED_KEYWORDS, read_materials, read_model

__all__ = [
    "read_model", "read_materials", "trivalve_input", "trivalve_inputs", "AbaqusParseError", "Location",
    "AbaqusModel", "AbaqusMaterial", "MaterialOption", "ElementBlock", "NodeSet", "ElementSet", "Surface",
    "SurfaceFaces", "Section", "Instance", "Amplitude", "BoundaryCondition", "DistributedLoad", "ConcentratedLoad",
    "ContactPair", "GeneralContact", "SurfaceInteraction", "MPC", "RigidBody", "ConnectorSection", "Transform",
    "Step", "IgnoredKeyword", "ReadWarning", "IGNORED_KEYWORDS", "HEX_FACE_NODES", "NODES_PER_ELEMENT",
    "TWO_NODE_MPC_TYPES",
]

#: Where the shared Texas TriValve data are looked for, relative to the repository root.
DATA_RELATIVE = Path("..") / "shared" / "data"
TRIVALVE_RELATIVE = DATA_RELATIVE / "texas_trivalve" / "Diseased_QuasiStatic.inp"
#: The five shipped inputs, by short key, relative to the data folder.
TRIVALVE_FILES = {
    "1.0-diseased": Path("texas_trivalve") / "Diseased_QuasiStatic.inp",
    "1.0-annuloplasty": Path("texas_trivalve") / "Annuloplasty_QuasiStatic.inp",
    "1.0-clipping": Path("texas_trivalve") / "Clipping_QuasiStatic.inp",
    "1.1-healthy": Path("texas_trivalve_1.1") / "Healthy" / "Healthy_QuasiStatic.inp",
    "1.1-diseased": Path("texas_trivalve_1.1") / "Diseased" / "Diseased_QuasiStatic.inp",
}


def _data_folder() -> Path | None:
    here = Path(__file__).resolve().parents[3]
    for candidate in (here / DATA_RELATIVE, Path.cwd() / DATA_RELATIVE):
        if candidate.is_dir():
            return candidate
    return None


def trivalve_input() -> Path | None:
    """The Texas TriValve 1.0 diseased input if present: ``$SKVALVE_TRIVALVE`` or ``../shared/data/...``.

    ``$SKVALVE_TRIVALVE`` may name the ``.inp`` file or its folder (the diseased input in it, or one level
    down as in ``texas_trivalve_1.1/Diseased/``); a folder without the input gives ``None``. Unset or empty,
    the shared data are searched.

    Raises
    ------
    FileNotFoundError
        When ``$SKVALVE_TRIVALVE`` is set to a path that does not exist (a mistyped path is never replaced by
        another copy of the data).
    """
    env = os.environ.get("SKVALVE_TRIVALVE")
    if env and not Path(env).exists():
        raise FileNotFoundError(f"$SKVALVE_TRIVALVE is set to {env!r}, which does not exist: set it to the Texas "
                                "TriValve .inp file or its folder, or unset it to search ../shared/data")
    if env and Path(env).is_file():
        return Path(env)
    if env and Path(env).is_dir():
        name = TRIVALVE_FILES["1.0-diseased"].name
        found = [Path(env) / name, *sorted(Path(env).glob(f"*/{name}"))]
        return next((path for path in found if path.is_file()), None)
    folder = _data_folder()
    if folder is not None and (folder / TRIVALVE_FILES["1.0-diseased"]).is_file():
        return folder / TRIVALVE_FILES["1.0-diseased"]
    return None


def trivalve_inputs() -> dict[str, Path]:
    """Those of the five shipped Texas TriValve inputs that are present, by key (``"1.1-healthy"``, ...)."""
    folder = _data_folder()
    if folder is None:
        return {}
    return {key: folder / rel for key, rel in TRIVALVE_FILES.items() if (folder / rel).is_file()}
