# ---
# jupyter:
#   jupytext:
#     formats: ipynb,py:percent
#     notebook_metadata_filter: kernelspec,jupytext,-jupytext.text_representation.jupytext_version
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Exercise: the force in an incompressible Ogden truss (chordae tendineae)
#
# Mathur et al. (2022, mathur2022) model the chordae tendineae of the Texas TriValve as Abaqus ``T3D2`` trusses of
# an N-term Ogden material (Eq. 2, Abaqus convention),
#
# $$ W(\lambda_1, \lambda_2, \lambda_3) = \sum_{i=1}^{N} \frac{2\mu_i}{\alpha_i^2}
#    \left(\lambda_1^{\alpha_i} + \lambda_2^{\alpha_i} + \lambda_3^{\alpha_i} - 3\right), $$
#
# and Abaqus takes the truss force as the **reference** cross-section times the **nominal** (first Piola–Kirchhoff)
# stress, $N = A_0\,P(\lambda)$, with the material incompressible in uniaxial stress. The worked solution is in
# `ogden_truss_solution.ipynb`.
#
# **Tasks.**
# 1. A truss of stretch $\lambda$ in uniaxial stress: use incompressibility and the symmetry of the lateral
#    directions to write the three principal stretches.
# 2. Derive the nominal stress
#    $$ P(\lambda) = \sum_i \frac{2\mu_i}{\alpha_i}\left(\lambda^{\alpha_i - 1} - \lambda^{-\alpha_i/2 - 1}\right) $$
#    in two ways: (a) as $dW/d\lambda$ of the reduced energy, (b) from the principal Cauchy stresses
#    $\sigma_a = \lambda_a\,\partial W/\partial\lambda_a - p$ with traction-free lateral faces, and
#    $P = \sigma_1/\lambda$.
# 3. Show that the small-strain Young's modulus is $E = dP/d\lambda\,(1) = 3\sum_i \mu_i$, three times the shear
#    modulus $\sum_i\mu_i$, as it must be for an incompressible solid.
# 4. Why is $N = A_0 P$ exact for an incompressible truss, i.e. equal to the current area times the Cauchy stress?
# 5. Check $P(\lambda)$ numerically against `skvalve.materials.Ogden` solved in uniaxial stress by
#    `skvalve.analytic.homogeneous.uniaxial`, and against the truss law `skvalve.materials.uniaxial.OgdenUniaxial`.
#
# The cell below sets up a three-term law (illustrative parameters, MPa; not the paper's) and the tools.

# %%
import numpy as np

from skvalve.analytic.homogeneous import uniaxial
from skvalve.materials import Ogden
from skvalve.materials.uniaxial import OgdenUniaxial

law = Ogden(mu=(0.05, 0.02, 0.01), alpha=(2.0, 8.0, 20.0))  # incompressible (no D)
response = uniaxial(law, 1.1)  # homogeneous uniaxial stress at stretch 1.1
truss = OgdenUniaxial.from_ogden(law)  # the truss law: truss.nominal_stress(stretch) -> (P, dP/dλ)
print(f"stretch 1.1: nominal stress P1 = {response.nominal[0]:.6f} MPa, lateral {response.nominal[1]:.1e} MPa")
assert law.incompressible and abs(response.nominal[1]) < 1e-12 and np.isclose(truss.young_modulus, 3 * 0.08)
