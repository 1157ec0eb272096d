"""FE² coupling of fiber-network RVEs to the macroscale (Thomas et al. 2019, §2.4).

material     : :class:`RVEMaterial`, σ = σ_matrix (Eq. 10) + σ_fiber (Eq. 8) and dP/dF at every Gauss point
affine       : :class:`AffineFiberModel`, the affine (no force balance) fiber network, a reference model
homogeneous  : :class:`HomogeneousBiaxial`, uniform biaxial stretch of a set of RVEs (fast RVE-level model)
fields       : Gauss-point strain/stress of a solve, :class:`GaussPointWriter` (VTU callback)
checkpoint   : :class:`Checkpoint` (callback) and :func:`resume` for interrupted runs
progress     : :class:`FE2Progress`, a progress bar with Newton iterations and RVE throughput
correction   : size of the Chandran–Barocas term of Eq. 11 (not included in the balance)
"""

from .affine import AffineFiberModel
from .checkpoint import Checkpoint, load_checkpoint, resume
from .fields import GaussPointWriter, gauss_fields
from .homogeneous import HomogeneousBiaxial
from .material import RVEFailure, RVEMaterial, RVEMaterialState, cauchy_to_pk1
from .progress import FE2Progress

__all__ = [
    "AffineFiberModel", "Checkpoint", "FE2Progress", "GaussPointWriter", "HomogeneousBiaxial", "RVEFailure",
    "RVEMaterial", "RVEMaterialState", "cauchy_to_pk1", "gauss_fields", "load_checkpoint", "resume",
]
