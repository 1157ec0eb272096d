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
# # Exercise: why $\nu \to \tfrac12$ makes the compressible neo-Hookean solid incompressible
#
# *From the homework problem in Appendix A of Thomas, Lai & Amini (2019), "A computational multi-scale approach to
# investigate mechanically-induced changes in tricuspid valve anterior leaflet microstructure", Acta Biomaterialia
# (thomas2019).* The worked solution is in `neo_hookean_incompressibility_solution.ipynb`.
#
# The non-collagenous matrix of the leaflet is modelled with the compressible neo-Hookean law of Bonet & Wood
# (thomas2019 Eq. 10 / Eq. 13),
#
# $$\sigma = \frac{G}{J}\,(B - I) + \frac{2G\nu}{J(1-2\nu)}\,\ln J \; I ,$$
#
# with shear modulus $G$, Poisson's ratio $\nu$, $B = F F^T$ and $J = \det F$. For small strains it reduces to
# linear elasticity, where $\nu \to \tfrac12$ means incompressibility. Does that remain true at **large** strains?
#
# **Tasks.**
#
# 1. Take a deformation gradient in its principal frame, $F = \operatorname{diag}(\lambda_1, \lambda_2, \lambda_3)$
#    (thomas2019 Eq. 14). Compute $B$ and the Cauchy stress, and show that it is diagonal with entries
#    $\sigma_{aa} = \frac{G}{J}\big[\lambda_a^2 - 1 + \frac{2\nu}{1-2\nu}\ln J\big]$ (thomas2019 Eq. 15).
# 2. Show that as $\nu \to \tfrac12$ any deformation that produces a **finite** stress must have $\ln J \to 0$,
#    i.e. $J \to 1$. *Hint: take the trace of the stress.*
# 3. Check this numerically with `skvalve.materials.NeoHookean`: hold a uniaxial nominal stress $P = 1$ kPa fixed
#    (with the paper's $G = 2.1$ kPa), let $\nu \to \tfrac12$ and watch $J$. How fast does $J - 1$ go to zero?
#    Predict the limit of $\ln J/(1-2\nu)$ from the incompressible solution.
#
# The cell below sets up the symbols and the tools; the rest is yours.

# %%
import numpy as np
import sympy as sp

from skvalve.analytic.homogeneous import uniaxial
from skvalve.materials import NeoHookean

l1, l2, l3, G = sp.symbols("lambda_1 lambda_2 lambda_3 G", positive=True)
nu = sp.symbols("nu", real=True)
F = sp.diag(l1, l2, l3)
# Task 1: build B and J from F, write Eq. 13 with sympy and compare it with Eq. 15.
# Task 3: NeoHookean.from_shear_poisson(2.1, nu) is the law; uniaxial(law, stretch, incompressible=False)
#         solves the lateral stretch from traction-free faces and returns .nominal, .J, .cauchy.
law = NeoHookean.from_shear_poisson(2.1, 0.3)
state = uniaxial(law, 1.2, incompressible=False)
print(f"nu = 0.3, axial stretch 1.2: nominal stress {state.nominal[0]:.4f} kPa, J = {state.J:.4f}")
assert np.isclose(law.mu, 2.1) and np.isclose(law.lmbda, 2 * 2.1 * 0.3 / (1 - 2 * 0.3))  # Lamé λ = 2Gν/(1−2ν)
