"""The element terms of a :class:`~skvalve.fem.problem.Problem`: what the bodies contribute.

- :mod:`.hyperelastic`: the total-Lagrangian hyperelastic solid (u or mixed u/p), stresses from
  :mod:`.constitutive` (materials per region) and the compiled kernels :mod:`.fused`, :mod:`.fused_points`;
- :mod:`.fbar`: the F-bar trilinear hex with the element's mean dilatation;
- :mod:`.corner_barrier`: a barrier that keeps trilinear hexes from folding at a corner;
- :mod:`.truss`: two-node trusses (cables).
"""
