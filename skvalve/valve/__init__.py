"""skvalve.valve: whole-valve models (mathur2022 Texas TriValve) built on the Abaqus reader.

Geometry measures (:mod:`.geometry`) and the model summary and picture (:mod:`.info`).
"""

from .geometry import LeafletSurfaces, ValveAreas, annulus_nodes, leaflet_surfaces, loop_area, valve_areas
from .info import ModelSummary, plot_undeformed, summarise, valve_info

__all__ = [
    "LeafletSurfaces", "ValveAreas", "annulus_nodes", "leaflet_surfaces", "loop_area", "valve_areas",
    "ModelSummary", "plot_undeformed", "summarise", "valve_info",
]
