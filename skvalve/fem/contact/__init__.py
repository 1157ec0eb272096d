"""Contact of surfaces: the IPC barrier that never lets surfaces pass through, and the older penalty law.

* :mod:`.ipc` -- :class:`IPCContact`: Incremental Potential Contact (ipctk) of a body's boundary with itself, with
  kinematic :class:`Obstacle` surfaces and fixed :class:`Plane` s; collision-free step fractions for every solver,
  optional lagged friction, contact pressure and area. The method of choice.
* :mod:`.surface` -- :class:`ContactSurface`: boundary quads of hexes, oriented and split into triangles.
* :mod:`.obstacles` -- :class:`Obstacle` (prescribed motion), :class:`Plane`.
* :mod:`.penalty` (with :mod:`.blend`, :mod:`.geometry`, :mod:`.laws`, :mod:`.clearance`) -- :class:`SurfaceContact`:
  node-to-triangle penalty contact with a search depth. Kept for the valve runs that were made with it; a penalty
  with a search depth admits pass-through minima by construction (docs/fem.md).
"""

from .ipc import Friction, IntersectionError, IPCContact, barrier_pressure, stiffness_for_pressure
from .obstacles import Obstacle, Plane
from .penalty import ActivePairs, SurfaceContact, gap_derivatives
from .surface import ContactSurface, oriented_quads

__all__ = ["IPCContact", "Friction", "IntersectionError", "barrier_pressure", "stiffness_for_pressure", "Obstacle",
           "Plane", "ContactSurface", "oriented_quads", "SurfaceContact", "ActivePairs", "gap_derivatives"]
