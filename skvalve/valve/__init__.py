"""skvalve.valve: whole-valve models (mathur2022 Texas TriValve) built on the Abaqus reader.

Geometry measures (:mod:`.geometry`) and the model summary and picture (:mod:`.info`).
The implicit model (:mod:`.model`): leaflet hexes (shells extruded by :mod:`.extrude`), chordae cables
(chains collapsed by :mod:`.chordae`), conditions and follower pressure with amplitudes.
"""

from .chordae import CollapsedChordae, collapse_chains
from .extrude import ExtrudedShell, extrude_shell
from .geometry import LeafletSurfaces, ValveAreas, annulus_nodes, leaflet_surfaces, loop_area, valve_areas
from .info import ModelSummary, plot_undeformed, summarise, valve_info
from .model import ValveModel, valve_model

__all__ = [
    "LeafletSurfaces", "ValveAreas", "annulus_nodes", "leaflet_surfaces", "loop_area", "valve_areas",
    "ModelSummary", "plot_undeformed", "summarise", "valve_info",
    "CollapsedChordae", "collapse_chains", "ExtrudedShell", "extrude_shell", "ValveModel", "valve_model",
]
