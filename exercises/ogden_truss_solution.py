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
# # Solution: the force in an incompressible Ogden truss (chordae tendineae)
#
# Worked solution of `ogden_truss.ipynb` (mathur2022 Eq. 2; Abaqus ``T3D2`` trusses). Try the problem first.
#
# ## 1. Principal stretches
#
# Uniaxial stress along direction 1: the lateral directions are equivalent, $\lambda_2 = \lambda_3$, and
# incompressibility $\lambda_1\lambda_2\lambda_3 = 1$ gives $(\lambda_1, \lambda_2, \lambda_3) =
# (\lambda, \lambda^{-1/2}, \lambda^{-1/2})$.
#
# ## 2a. Nominal stress as the derivative of the reduced energy
#
# $W(\lambda) = \sum_i \frac{2\mu_i}{\alpha_i^2}(\lambda^{\alpha_i} + 2\lambda^{-\alpha_i/2} - 3)$ is the energy per
# reference volume. A virtual change $d\lambda$ of a bar of reference length $L_0$ and area $A_0$ does work
# $N\,L_0\,d\lambda = A_0 L_0\,dW$, so $N/A_0 = P = dW/d\lambda$ (the lateral faces are free and do no work).

# %%
import numpy as np
import sympy as sp

lam, mu_i, alpha_i = sp.symbols("lambda mu_i alpha_i", positive=True)
term = 2 * mu_i / alpha_i**2 * (lam**alpha_i + 2 * lam ** (-alpha_i / 2) - 3)  # one Ogden term, reduced
P_energy = sp.diff(term, lam)
P_paper = 2 * mu_i / alpha_i * (lam ** (alpha_i - 1) - lam ** (-alpha_i / 2 - 1))
print("dW/dλ − (2μ/α)(λ^(α−1) − λ^(−α/2−1)) =", sp.simplify(P_energy - P_paper))
assert sp.simplify(P_energy - P_paper) == 0

# %% [markdown]
# ## 2b. The same from the Cauchy stresses
#
# For an incompressible isotropic solid $\sigma_a = \lambda_a\,\partial W/\partial\lambda_a - p$. The lateral faces
# are free: $\sigma_2 = 0$ fixes $p = \lambda_2\,\partial W/\partial\lambda_2$, hence
# $\sigma_1 = \lambda_1 W_{,1} - \lambda_2 W_{,2}$ and $P = \sigma_1/\lambda$ (nominal = Cauchy × current area /
# reference area $= \sigma_1 \lambda^{-1}$).

# %%
l1, l2, l3 = sp.symbols("lambda_1 lambda_2 lambda_3", positive=True)
W3 = 2 * mu_i / alpha_i**2 * (l1**alpha_i + l2**alpha_i + l3**alpha_i - 3)
on_path = {l1: lam, l2: lam ** sp.Rational(-1, 2), l3: lam ** sp.Rational(-1, 2)}
sigma_1 = (l1 * sp.diff(W3, l1) - l2 * sp.diff(W3, l2)).subs(on_path)
print("σ1/λ − P =", sp.simplify(sigma_1 / lam - P_paper))
assert sp.simplify(sp.expand(sigma_1 / lam - P_paper)) == 0

# %% [markdown]
# ## 3. Small strain
#
# $dP/d\lambda = \frac{2\mu_i}{\alpha_i}\big((\alpha_i - 1)\lambda^{\alpha_i-2} + (\tfrac{\alpha_i}{2}+1)
# \lambda^{-\alpha_i/2-2}\big)$, at $\lambda = 1$: $\frac{2\mu_i}{\alpha_i}\cdot\frac{3\alpha_i}{2} = 3\mu_i$.
# Summed over the terms, $E = 3\sum_i\mu_i = 3G$: Poisson's ratio ½.

# %%
E_small = sp.simplify(sp.diff(P_paper, lam).subs(lam, 1))
print("dP/dλ at λ = 1:", E_small)
assert sp.simplify(E_small - 3 * mu_i) == 0

# %% [markdown]
# ## 4. Why $N = A_0 P$ is exact
#
# The current area is $A = A_0\lambda_2\lambda_3 = A_0/\lambda$, so $N = \sigma_1 A = \sigma_1 A_0/\lambda = A_0 P$.
# No approximation: an incompressible bar changes its area exactly as $1/\lambda$.
#
# ## 5. Numerical checks
#
# Three independent routes for a three-term law: the closed form above, the 3D `Ogden` law solved in homogeneous
# uniaxial stress (`analytic.homogeneous.uniaxial`, which finds the pressure from the free lateral faces), and the
# truss law `OgdenUniaxial`. Its slope is checked against central differences of $P$.

# %%
import matplotlib.pyplot as plt

from skvalve.analytic.homogeneous import uniaxial
from skvalve.materials import Ogden
from skvalve.materials.uniaxial import OgdenUniaxial

plt.rcParams["figure.dpi"] = 150
mu, alpha = (0.05, 0.02, 0.01), (2.0, 8.0, 20.0)  # MPa, illustrative
stretch = np.linspace(0.8, 1.25, 91)
closed_form = sum(2 * m / a * (stretch ** (a - 1) - stretch ** (-a / 2 - 1)) for m, a in zip(mu, alpha, strict=True))
solid = uniaxial(Ogden(mu=mu, alpha=alpha), stretch).nominal[0]
truss, slope = OgdenUniaxial(mu, alpha).nominal_stress(stretch)
h = 1e-6
slope_fd = (OgdenUniaxial(mu, alpha).nominal_stress(stretch + h)[0]
            - OgdenUniaxial(mu, alpha).nominal_stress(stretch - h)[0]) / (2 * h)
scale = np.max(np.abs(closed_form))
print(f"max |3D Ogden − closed form| / max|P| = {np.max(np.abs(solid - closed_form)) / scale:.1e}")
print(f"max |OgdenUniaxial − closed form| / max|P| = {np.max(np.abs(truss - closed_form)) / scale:.1e}")
print(f"max |dP/dλ − central difference| / max|dP/dλ| = {np.max(np.abs(slope - slope_fd)) / np.max(slope):.1e}")
print(f"E = dP/dλ(1) = {OgdenUniaxial(mu, alpha).nominal_stress(1.0)[1]:.6f} MPa, 3 Σμ = {3 * sum(mu):.6f} MPa")
assert np.max(np.abs(solid - closed_form)) < 1e-10 * scale
assert np.max(np.abs(truss - closed_form)) < 1e-12 * scale
assert np.max(np.abs(slope - slope_fd)) < 1e-6 * np.max(slope)
assert abs(OgdenUniaxial(mu, alpha).nominal_stress(1.0)[1] - 3 * sum(mu)) < 1e-14

fig, ax = plt.subplots(figsize=(5, 3.4))
ax.plot(stretch, closed_form, "k", label="closed form")
ax.plot(stretch[::6], solid[::6], "o", mfc="none", label="3D Ogden, homogeneous uniaxial")
ax.plot(stretch, 3 * sum(mu) * (stretch - 1), "C3--", label=r"small strain $3\sum\mu_i(\lambda-1)$")
ax.set(xlabel=r"stretch $\lambda$", ylabel="nominal stress P (MPa)", title="incompressible three-term Ogden")
ax.legend(fontsize=8)
plt.show()

# %% [markdown]
# ## The Texas TriValve chordae
#
# With the chordae parameters of the TriValve input (read from the authors' file when it is available; see
# `skvalve.papers.mathur2022.data`) and the chordae diameters of Sect. 2.8, the force of one chord is
# $N = \tfrac{\pi}{4} d^2 P(\lambda)$. The fitted exponents differ widely between the chordae
# of the three leaflets (printed below); all three stiffen within a few per cent of stretch.

# %%
import logging

from skvalve.papers.mathur2022 import data as mathur2022

path = mathur2022.trivalve_input()
if path is None:
    print("Texas TriValve input not found: set $SKVALVE_TRIVALVE to show the chordae forces")
else:
    logging.getLogger("skvalve.io").setLevel(logging.ERROR)  # the reader logs the keywords it does not use
    chordae = mathur2022.read_trivalve_materials(path).chordae
    stretch = np.linspace(1.0, 1.06, 61)
    fig, ax = plt.subplots(figsize=(5, 3.4))
    for leaflet, parameters in chordae.items():
        area = np.pi / 4 * mathur2022.CHORDAE_DIAMETER[leaflet] ** 2  # mm^2
        force = area * OgdenUniaxial(parameters.mu, parameters.alpha).nominal_stress(stretch)[0]  # MPa mm^2 = N
        ax.plot(stretch, force, label=f"{leaflet} (d = {mathur2022.CHORDAE_DIAMETER[leaflet]} mm)")
        exponents = ", ".join(f"{a:.3g}" for a in parameters.alpha)
        print(f"{leaflet:>9}: alpha = {exponents};  N(1.03) = {np.interp(1.03, stretch, force):.4f} N, "
              f"N(1.06) = {force[-1]:.4f} N")
        assert np.all(np.diff(force) > 0)  # monotonic in tension
    ax.set(xlabel=r"stretch $\lambda$", ylabel="chord force N (N)", title="Texas TriValve chordae (mathur2022)")
    ax.legend(fontsize=8)
    plt.show()
