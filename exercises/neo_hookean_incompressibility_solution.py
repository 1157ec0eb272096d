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
# # Solution: why $\nu \to \tfrac12$ makes the compressible neo-Hookean solid incompressible
#
# Worked solution of `neo_hookean_incompressibility.ipynb` (the homework problem of Appendix A of Thomas, Lai &
# Amini (2019), "A computational multi-scale approach to investigate mechanically-induced changes in tricuspid valve
# anterior leaflet microstructure", Acta Biomaterialia). Try the problem first.

# %% [markdown]
# ## Part 1 — the Cauchy stress for a principal-frame deformation (symbolic)

# %%
import numpy as np
import sympy as sp
from IPython.display import display

l1, l2, l3, G = sp.symbols("lambda_1 lambda_2 lambda_3 G", positive=True)
nu = sp.symbols("nu", real=True)
F = sp.diag(l1, l2, l3)
B = F * F.T
J = F.det()
sigma = G / J * (B - sp.eye(3)) + 2 * G * nu / (J * (1 - 2 * nu)) * sp.log(J) * sp.eye(3)
sigma = sp.simplify(sigma)
display(B, J)

# %%
eq15 = sp.diag(*[G / J * (lam**2 - 1 + 2 * nu / (1 - 2 * nu) * sp.log(J)) for lam in (l1, l2, l3)])
difference = sp.simplify(sigma - eq15)
print("sigma - Eq. 15 =", difference)
assert difference == sp.zeros(3, 3)
sigma[0, 0]

# %% [markdown]
# The off-diagonal entries vanish because $B$ is diagonal when $F$ is; the diagonal reproduces Eq. 15 exactly.
#
# The same expression must come out of the package's implementation (`NeoHookean.from_shear_poisson(G, nu)`),
# which is written as a strain energy, not as Eq. 15:

# %%
from skvalve.materials import NeoHookean

sigma_fn = sp.lambdify((l1, l2, l3, G, nu), eq15, "numpy")
rng = np.random.default_rng(0)
worst = 0.0
for _ in range(5):
    lam = rng.uniform(0.7, 1.4, 3)
    g, v = 2.1, rng.uniform(0.0, 0.49)
    ours = NeoHookean.from_shear_poisson(g, v).cauchy(np.diag(lam)[:, :, None])[..., 0]
    exact = np.array(sigma_fn(*lam, g, v), dtype=float)
    worst = max(worst, np.max(np.abs(ours - exact)) / np.max(np.abs(exact)))
print(f"max relative difference, skvalve vs Eq. 15: {worst:.1e}")
assert worst < 1e-13

# %% [markdown]
# ## Part 2 — $\nu \to \tfrac12$ forces $J \to 1$
#
# The trace of Eq. 15 is
#
# $$\operatorname{tr}\sigma = \frac{G}{J}\big(\lambda_1^2+\lambda_2^2+\lambda_3^2-3\big)
#   + \frac{6G\nu}{J(1-2\nu)}\ln J ,$$
#
# so
#
# $$\ln J = \frac{1-2\nu}{6G\nu}\Big[J\operatorname{tr}\sigma - G\big(\lambda_1^2+\lambda_2^2+\lambda_3^2-3\big)\Big].$$
#
# For finite stress and finite stretches the bracket stays bounded, while the prefactor vanishes like $1-2\nu$:
# $\ln J \to 0$, i.e. $J \to 1$. Equivalently: if $\ln J$ stayed non-zero, the pressure term
# $\frac{2G\nu}{J(1-2\nu)}\ln J$ would diverge.
# Let sympy do the algebra:

# %%
trace_sigma, logJ = sp.symbols("trace_sigma ell", real=True)  # ell stands for ln J
I1 = l1**2 + l2**2 + l3**2
trace_equation = sp.Eq(trace_sigma, G / J * (I1 - 3) + 6 * G * nu / (J * (1 - 2 * nu)) * logJ)
ell = sp.solve(trace_equation, logJ)[0]
display(sp.factor(ell))
limit = sp.limit(ell, nu, sp.Rational(1, 2))
print("lim_{nu -> 1/2} ln J =", limit)
assert limit == 0

# %% [markdown]
# The expression also tells us **how fast**: $\ln J \approx (1-2\nu)\,c$ with
# $c = \big[\operatorname{tr}\sigma - G(\lambda_1^2+\lambda_2^2+\lambda_3^2-3)\big]/(3G)$ evaluated on the
# incompressible limit ($J = 1$, $\nu = \tfrac12$).
#
# ## Part 3 — numerical check under a fixed uniaxial load
#
# In the limit the material is incompressible neo-Hookean, whose uniaxial nominal stress is
# $P = G(\lambda - \lambda^{-2})$. For $P = 1$ kPa and $G = 2.1$ kPa that fixes $\lambda$, the Cauchy stress
# $\sigma_1 = P\lambda$ and hence the predicted constant $c$:

# %%
from scipy.optimize import brentq

G_paper, P_load = 2.1, 1.0  # kPa; G from thomas2019 (Results)
lam_limit = brentq(lambda lam: G_paper * (lam - lam**-2) - P_load, 1.0, 3.0, xtol=1e-15)
c_predicted = (P_load * lam_limit - G_paper * (lam_limit**2 + 2 / lam_limit - 3)) / (3 * G_paper)
print(f"incompressible stretch lambda = {lam_limit:.10f}, predicted ln J / (1 - 2 nu) -> c = {c_predicted:.8f}")

# %% [markdown]
# Now the compressible law itself: for each $\nu$ find the axial stretch at which the nominal stress equals $P$,
# with the lateral stretch solved from traction-free lateral faces
# (`skvalve.analytic.homogeneous.uniaxial(..., incompressible=False)`).

# %%
from skvalve.analytic.homogeneous import uniaxial

rows = []
for poisson in (0.3, 0.45, 0.49, 0.499, 0.4999, 0.49999, 0.499999):
    law = NeoHookean.from_shear_poisson(G_paper, poisson)

    def load_imbalance(stretch: float, law: NeoHookean = law) -> float:
        return uniaxial(law, stretch, incompressible=False).nominal[0] - P_load

    lam = brentq(load_imbalance, 1.0, 3.0, xtol=1e-15)
    state = uniaxial(law, lam, incompressible=False)
    rows.append((poisson, lam, state.J - 1.0, np.log(state.J) / (1 - 2 * poisson), state.cauchy[1],
                 law.bulk_modulus))

print(f"{'nu':>9} {'lambda':>13} {'J - 1':>11} {'lnJ/(1-2nu)':>12}  lateral stress (kPa)")
for poisson, lam, jm1, ratio, lateral, _ in rows:
    print(f"{poisson:9.6f} {lam:13.10f} {jm1:11.3e} {ratio:12.8f}  {lateral:.1e}")
print(f"{'limit':>9} {lam_limit:13.10f} {0.0:11.3e} {c_predicted:12.8f}   (incompressible, exact)")

# %%
import matplotlib.pyplot as plt

plt.rcParams["figure.dpi"] = 150

one_minus_2nu = np.array([1 - 2 * r[0] for r in rows])
jm1 = np.array([r[2] for r in rows])
fig, ax = plt.subplots(figsize=(4.5, 3.2))
ax.loglog(one_minus_2nu, jm1, "o", label="NeoHookean, P = 1 kPa")
ax.loglog(one_minus_2nu, c_predicted * one_minus_2nu, "k--", label=r"$c\,(1-2\nu)$ (predicted)")
ax.set(xlabel=r"$1 - 2\nu$", ylabel=r"$J - 1$", title="volume change under fixed load")
ax.legend()
plt.show()

# slope 1 on the log-log plot: J - 1 is proportional to 1 - 2 nu once nu > 0.49
slope = np.polyfit(np.log(one_minus_2nu[2:]), np.log(jm1[2:]), 1)[0]
print(f"log-log slope of J - 1 against 1 - 2 nu (nu >= 0.49): {slope:.4f}")
assert abs(slope - 1) < 0.01
# the stretch converges to the incompressible one, and ln J / (1 - 2 nu) to c, both to O(1 - 2 nu)
assert abs(rows[-1][1] - lam_limit) < 10 * (1 - 2 * rows[-1][0])
assert abs(rows[-1][3] - c_predicted) < 10 * (1 - 2 * rows[-1][0])
# lateral faces traction free up to round-off of the (huge) bulk modulus times the stretch tolerance
assert all(abs(r[4]) < 1e-13 * r[5] for r in rows)

# %% [markdown]
# **Conclusion.** Under a fixed, finite load $J - 1$ decreases in proportion to $1 - 2\nu$ (slope 1 on the log–log
# plot) and $\ln J/(1-2\nu)$ converges to the constant $c$ predicted from the incompressible solution, while the axial
# stretch converges to the incompressible neo-Hookean value. So $\nu \to \tfrac12$ enforces $J \to 1$ at large strain
# as well, not only in linear elasticity. In a finite-element model, though, a $\nu$ close to $\tfrac12$ makes the bulk
# modulus $\lambda + 2G/3$ huge compared with $G$; that is why nearly incompressible solids are usually discretised
# with mixed (displacement–pressure) elements.
