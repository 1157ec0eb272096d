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
# # Exercise: Rivlin's pure bending of an incompressible block
#
# A block $0 \le X \le L$, $0 \le Y \le H$ (plane strain, unit width) is bent into a circular sector,
#
# $$ r = r(Y), \qquad \theta = a X, \qquad z = Z, $$
#
# where $a$ is the bending angle per unit reference length. Buchanan & Sacks (2014, buchanan2014, Sect. 2.2) used
# this solution (Rivlin 1949) to choose the Ogden exponent; skvalve uses it as the exact reference for the leaflet
# strip. The worked solution is in `rivlin_bending_solution.ipynb`.
#
# **Tasks.**
# 1. Write the principal stretches and use incompressibility to show $\lambda(Y)^2 = 2aY + c$.
# 2. With $\hat W(\lambda) = W(\mathrm{diag}(\lambda, 1/\lambda, 1))$ show $d\sigma_{rr} = \hat W'(\lambda)\,d\lambda$
#    and that traction-free faces require the *equal-energy* condition
#    $\hat W(\lambda_\mathrm{top}) = \hat W(\lambda_\mathrm{bottom})$.
# 3. For neo-Hookean $\hat W = \tfrac{\mu}{2}(\lambda^2 + \lambda^{-2} - 2)$ find $c$, the neutral axis and the
#    moment, and check them against `skvalve.analytic.rivlin.bend`.
# 4. Show that the moment tends to Euler–Bernoulli $M = E' I a$ with the plane-strain modulus $E' = 4\mu$.
#
# The cell below sets up sympy and shows what `bend` returns for one layer of neo-Hookean material.

# %%
import sympy as sp

from skvalve.analytic.rivlin import bend
from skvalve.materials import IncompressibleNeoHookean

Y, a, mu, H = sp.symbols("Y a mu H", positive=True)
r = sp.Function("r")
solution = bend([(0.4, IncompressibleNeoHookean(45.0))], 0.2)  # one 0.4 mm layer, mu = 45 kPa, a = 0.2 / mm
print(f"neutral axis {solution.neutral_axis:.6f} mm, moment {solution.moment:.6f} kPa mm^2 per unit width, "
      f"face stretches {solution.lambda_bottom:.6f} / {solution.lambda_top:.6f}")
assert 0 < solution.neutral_axis < 0.2  # moves towards the compressed face
