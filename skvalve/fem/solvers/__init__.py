"""The solvers of a :class:`~skvalve.fem.problem.Problem`: how a sum of terms is brought to equilibrium.

- :mod:`.newton`: load-controlled Newton–Raphson with line search and cut-back (:func:`~.newton.solve`);
- :mod:`.incremental`: load steps solved as minimisations of the incremental potential, with a collision-free line
  search (:func:`~.incremental.incremental_potential`);
- :mod:`.ptc` (options in :mod:`.ptc_options`): pseudo-transient continuation at a held load;
- :mod:`.trust_region` (options and records in :mod:`.trust_region_options`, the step in :mod:`.trust_steps`): the
  energy trust region at a held load;
- :mod:`.block_relaxation`: a few cheap dofs brought to equilibrium with the rest held;
- :mod:`.damping`: the viscous pseudo-mass term of damped load paths;
- :mod:`.linsolve`: sparse direct solves that keep their symbolic analysis;
- :mod:`.soft_modes`: the softest modes of a state (why a held solve creeps).
"""
