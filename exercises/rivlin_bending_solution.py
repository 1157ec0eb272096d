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
# # Solution: Rivlin's pure bending of an incompressible block
#
# Worked solution of `rivlin_bending.ipynb` (buchanan2014 Sect. 2.2; Rivlin 1949). Try the problem first.
#
# ## 1. Kinematics
#
# The stretches are $\lambda_\theta = r\,d\theta/dX = a r$, $\lambda_r = dr/dY$, $\lambda_z = 1$.
# Incompressibility $\lambda_r \lambda_\theta \lambda_z = 1$ is the ODE $a\,r\,r' = 1$:

# %%
import sympy as sp

Y, a, mu, H = sp.symbols("Y a mu H", positive=True)
c = sp.symbols("c", positive=True)
r = sp.Function("r")
solution = sp.dsolve(sp.Eq(a * r(Y) * r(Y).diff(Y), 1), r(Y))
r_Y = (solution[0] if isinstance(solution, list) else solution).rhs  # ± branches square to the same λ²
print("r(Y) =", r_Y)
lam_squared = sp.expand((a * r_Y) ** 2)
print("lambda(Y)^2 =", lam_squared)
assert sp.simplify(sp.diff(lam_squared, Y) - 2 * a) == 0  # lambda^2 = 2 a Y + const

# %% [markdown]
# So $\lambda^2 = 2aY + c$ with one constant $c$ (the constant of integration times $a^2$).
#
# ## 2. Equilibrium and the equal-energy condition
#
# Principal Cauchy stresses satisfy $\sigma_{\theta\theta} - \sigma_{rr} = \lambda \hat W'(\lambda)$ (the pressure
# drops out of the difference). Radial equilibrium $d\sigma_{rr}/dr = (\sigma_{\theta\theta} - \sigma_{rr})/r$ with
# $\lambda = a r$, $dr/r = d\lambda/\lambda$ gives $d\sigma_{rr} = \hat W'(\lambda)\,d\lambda$, hence
# $\sigma_{rr}(\lambda) = \hat W(\lambda) - \hat W(\lambda_\mathrm{bottom})$ when the bottom face is free, and the top
# face is free only if $\hat W(\lambda_\mathrm{top}) = \hat W(\lambda_\mathrm{bottom})$.
#
# ## 3. Neo-Hookean: $c$, neutral axis, moment

# %%
lam = sp.symbols("lambda", positive=True)
W = mu / 2 * (lam**2 + lam**-2 - 2)
lam_b, lam_t = sp.sqrt(c), sp.sqrt(2 * a * H + c)
# W(λ) = W(1/λ): the non-trivial root of the equal-energy condition is λ_t λ_b = 1
assert sp.simplify(W.subs(lam, 1 / lam) - W) == 0
c_exact = [s for s in sp.solve(sp.Eq(c * (c + 2 * a * H), 1), c) if s.subs({a: 1, H: 1}).is_positive][0]
neutral_axis = (1 - c_exact) / (2 * a)  # λ = 1
s = sp.symbols("s", positive=True)  # s = λ² = 2aY + c, dY = ds / 2a
sigma_rr = (W - W.subs(lam, lam_b)).subs(lam, sp.sqrt(s))
moment = -sp.integrate(sigma_rr / (2 * a), (s, c, 1 / c)) / a  # M = -(1/a) ∫ σ_rr dY
print("c =", c_exact)
print("M =", sp.simplify(moment))

# %%
from skvalve.analytic.rivlin import bend
from skvalve.materials import IncompressibleNeoHookean

values = {mu: 45.0, H: 0.4}
print(f"{'Δκ (1/mm)':>10} {'NA exact':>12} {'NA bend':>12} {'M exact':>14} {'M bend':>14}")
for kappa in (0.1, 0.2, 0.3, 2.0):
    sol = bend([(0.4, IncompressibleNeoHookean(45.0))], kappa)
    subs = {**values, a: kappa}
    na = float(neutral_axis.subs(subs))
    m = float(moment.subs({c: c_exact}).subs(subs))
    print(f"{kappa:>10} {na:>12.8f} {sol.neutral_axis:>12.8f} {m:>14.8f} {sol.moment:>14.8f}")
    assert abs(sol.neutral_axis - na) < 1e-10 and abs(sol.moment / m - 1) < 1e-9

# %% [markdown]
# ## 4. Small curvature: Euler–Bernoulli
#
# Expanding the exact moment in $a$ gives the beam law. For plane strain and $\nu = 1/2$ the modulus is
# $E' = E/(1-\nu^2) = 4\mu$ (with $E = 3\mu$), and $I = H^3/12$ per unit width.

# %%
M_series = sp.series(moment.subs(c, c_exact), a, 0, 3).removeO()
print("M ≈", sp.simplify(M_series))
assert sp.simplify(M_series.coeff(a, 1) - 4 * mu * H**3 / 12) == 0
assert M_series.coeff(a, 2) == 0  # M is odd in a: no quadratic term
small = bend([(0.4, IncompressibleNeoHookean(45.0))], 1e-3)
bending_stiffness = 4 * 45.0 * 0.4**3 / 12  # E'I per unit width, kPa mm^4 / mm
print("bend M/Δκ at Δκ=1e-3:", small.moment / 1e-3, " E'I =", bending_stiffness)
assert abs(small.moment / (1e-3 * bending_stiffness) - 1) < 1e-5  # the next term is O((aH)^2)
for kappa, thickness in ((0.3, 0.4), (0.3, 0.3)):
    leaflet = bend([(thickness, IncompressibleNeoHookean(45.0))], kappa)
    softening = 1 - leaflet.moment / (kappa * 4 * 45.0 * thickness**3 / 12)
    print(f"H = {thickness} mm, Δκ = {kappa}: NA/H = {leaflet.normalised_neutral_axis:.4f}, "
          f"1 - M/(E'I a) = {softening:.2e}")
    assert 0.45 < leaflet.normalised_neutral_axis < 0.5 and 0 < softening < 0.05  # the take-away below

# %% [markdown]
# **Take-away.** The neutral axis moves towards the compressed face as the curvature grows
# ($Y_n/H = (1-c)/(2aH) < 1/2$), and the moment softens slightly below $E'Ia$. Both effects are of order $aH$,
# i.e. a few per cent for the leaflet ($H \approx 0.3$–$0.4$ mm, $\Delta\kappa \le 0.3$ mm⁻¹).
