"""What the reader knows while it walks the cards: scopes, the open material/step, the lists so far."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from .lexer import Card
from .materials import AbaqusMaterial, MaterialOption
from .mesh import MeshScope
from .model import (
    MPC,
    Amplitude,
    BoundaryCondition,
    ConcentratedLoad,
    ConnectorSection,
    ContactPair,
    DistributedLoad,
    GeneralContact,
    IgnoredKeyword,
    ReadWarning,
    RigidBody,
    Step,
    SurfaceInteraction,
    Transform,
)

__all__ = ["ParseState"]


@dataclass
class ParseState:
    """Mutable reader state. ``scope`` is the part being read or the assembly (the global model)."""

    path: Path
    assembly: MeshScope = field(default_factory=lambda: MeshScope(""))
    parts: dict[str, MeshScope] = field(default_factory=dict)
    #: scope of each ``*Part`` card (by id), made in the first pass over nodes and elements
    part_scopes: dict[int, MeshScope] = field(default_factory=dict)
    part_names: list[str] = field(default_factory=list)
    scope: MeshScope | None = None
    in_part: bool = False
    in_assembly: bool = False
    assembly_seen: bool = False
    open_instance: Card | None = None
    material: AbaqusMaterial | None = None
    interaction: SurfaceInteraction | None = None
    contact: GeneralContact | None = None
    step: Step | None = None
    last_option: MaterialOption | None = None
    materials: dict[str, AbaqusMaterial] = field(default_factory=dict)
    amplitudes: dict[str, Amplitude] = field(default_factory=dict)
    interactions: dict[str, SurfaceInteraction] = field(default_factory=dict)
    boundary_conditions: list[BoundaryCondition] = field(default_factory=list)
    distributed_loads: list[DistributedLoad] = field(default_factory=list)
    concentrated_loads: list[ConcentratedLoad] = field(default_factory=list)
    contact_pairs: list[ContactPair] = field(default_factory=list)
    mpcs: list[MPC] = field(default_factory=list)
    rigid_bodies: list[RigidBody] = field(default_factory=list)
    connector_sections: list[ConnectorSection] = field(default_factory=list)
    transforms: list[Transform] = field(default_factory=list)
    steps: list[Step] = field(default_factory=list)
    ignored: list[IgnoredKeyword] = field(default_factory=list)
    #: reader warnings outside the mesh scopes (an empty material, a cut last keyword line, ...)
    warnings: list[ReadWarning] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.scope = self.assembly

    def model_scope(self, card: Card) -> MeshScope:
        """The assembly scope, for keywords that are not allowed inside a part."""
        if self.in_part:
            raise card.error("not allowed inside *Part (expected in the assembly or model data)")
        return self.assembly
