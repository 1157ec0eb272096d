"""skvalve: heart-valve tissue mechanics on scikit-fem.

Reproduces, explains and extends
- Buchanan & Sacks (2014), layered aortic leaflet in flexure,
- Thomas et al. (2019), multiscale (FE^2) tricuspid leaflet with collagen-fiber networks,
- Mathur et al. (2022), the Texas TriValve whole tricuspid-valve model.

The everyday names live here (one flat namespace); each comes from one subpackage, lowest layer
first: constitutive laws (:mod:`skvalve.materials`), closed-form solutions (:mod:`skvalve.analytic`),
the finite-element solver (:mod:`skvalve.fem`), collagen-fiber networks (:mod:`skvalve.networks`),
input and output (:mod:`skvalve.io`). Paper data and reproductions are in :mod:`skvalve.papers`.

Examples
--------
>>> import numpy as np
>>> import skvalve as sv
>>> law = sv.NeoHookean.from_shear_poisson(2.1, 0.49)
>>> round(float(sv.uniaxial(sv.IncompressibleNeoHookean(1.0), 2.0).cauchy[0]), 12)   # mu (l^2 - 1/l)
3.5
"""

from .analytic import biaxial, equibiaxial, uniaxial
from .analytic.rivlin import BendingSolution, bend, moment_curvature
from .analytic.strainmap import fit_strain_map
from .fem import (
    ConvergenceError,
    NonPositiveJacobianError,
    Problem,
    Result,
    SingularSystemError,
    Solid,
    SolverError,
    TangledMeshError,
    Term,
    solve,
)
from .io.timeseries import TimeSeriesWriter
from .materials import (
    BimodularNeoHookean,
    ExponentialFiber,
    Hyperelastic,
    IncompressibleNeoHookean,
    LeeSacks,
    NeoHookean,
    Ogden,
)
from .networks import Network, RVEBatch, orientation_tensor, solve_rve
from .networks.generate import generate

__version__ = "0.1.0"

__all__ = [
    "__version__",
    # materials
    "Hyperelastic", "NeoHookean", "IncompressibleNeoHookean", "Ogden", "LeeSacks", "BimodularNeoHookean",
    "ExponentialFiber",
    # closed forms
    "uniaxial", "biaxial", "equibiaxial", "bend", "moment_curvature", "BendingSolution", "fit_strain_map",
    # finite elements
    "Solid", "Problem", "Term", "solve", "Result", "TimeSeriesWriter", "SolverError", "ConvergenceError",
    "NonPositiveJacobianError", "SingularSystemError", "TangledMeshError",
    # networks
    "Network", "generate", "solve_rve", "RVEBatch", "orientation_tensor",
]
