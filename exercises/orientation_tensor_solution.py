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
# # Solution: the SALS orientation tensor by hand
#
# Worked solution of `orientation_tensor.ipynb` (thomas2019 Eqs. 1–3). Try the problem first.
#
# | bin centre θ | −75° | −45° | −15° | 15° | 45° | 75° |
# |---|---|---|---|---|---|---|
# | count n | 2 | 5 | 12 | 20 | 8 | 3 |
#
# ## Tasks 1–2 (by hand)
#
# $\sum n = 50$. With $c_{15} = \cos^2 15° = 0.93301$, $c_{45} = 0.5$, $c_{75} = 0.06699$:
#
# $H_{11} = [(12+20)\,0.93301 + (5+8)\,0.5 + (2+3)\,0.06699]/50 = 36.6913/50 = 0.73383$,
# $H_{22} = 1 - H_{11} = 0.26617$.
#
# $\sin\theta\cos\theta = \pm0.25$ at ±15° and ±75°, ±0.5 at ±45°:
# $H_{12} = [2(-0.25) + 5(-0.5) + 12(-0.25) + 20(0.25) + 8(0.5) + 3(0.25)]/50 = 3.75/50 = 0.075$.
#
# Eigenvalues $\tfrac12 \pm \sqrt{0.23383^2 + 0.075^2} = 0.5 \pm 0.24556$, so
# $\lambda_1 = 0.25444$, $\lambda_2 = 0.74556$;
# $\alpha = 100\,(1 - 0.25444/0.74556) = 65.87\,\%$ and
# $\mu = \tfrac12\operatorname{atan2}(0.15, 0.46765) = 8.89°$.
#
# ## Task 3: the same with numpy and with `skvalve.networks.orientation`

# %%
import numpy as np

from skvalve.networks.orientation import anisotropy_index, mean_direction, orientation_tensor

centres = np.radians([-75, -45, -15, 15, 45, 75])
counts = np.array([2, 5, 12, 20, 8, 3])
# the hand computation, step by step
H11 = np.sum(counts * np.cos(centres) ** 2) / counts.sum()
H22 = np.sum(counts * np.sin(centres) ** 2) / counts.sum()
H12 = np.sum(counts * np.sin(centres) * np.cos(centres)) / counts.sum()
radius = np.hypot((H11 - H22) / 2, H12)
lam1, lam2 = 0.5 - radius, 0.5 + radius
alpha_hand, mu_hand = 100 * (1 - lam1 / lam2), 0.5 * np.degrees(np.arctan2(2 * H12, H11 - H22))
print(f"by hand : H11 = {H11:.5f}  H22 = {H22:.5f}  H12 = {H12:.5f}  alpha = {alpha_hand:.2f} %  mu = {mu_hand:.2f}°")
H = orientation_tensor(centres, weights=counts)
print(f"library : H11 = {H[0, 0]:.5f}  H22 = {H[1, 1]:.5f}  H12 = {H[0, 1]:.5f}  "
      f"alpha = {anisotropy_index(H):.2f} %  mu = {mean_direction(H):.2f}°")
# the values worked out by hand above, to the digits printed there
assert np.allclose([H11, H22, H12], [0.73383, 0.26617, 0.075], atol=5e-6)
assert abs(alpha_hand - 65.87) < 5e-3 and abs(mu_hand - 8.89) < 5e-3
assert np.allclose(H, [[H11, H12], [H12, H22]], atol=1e-14)
assert abs(anisotropy_index(H) - alpha_hand) < 1e-10 and abs(mean_direction(H) - mu_hand) < 1e-10

# %% [markdown]
# ## Task 4
#
# A bin of width 30° in θ spans $2w = 60°$ in $2\theta$. Over it, $\cos 2\theta$ and $\sin 2\theta$ (the
# deviatoric part of $r\otimes r$) average to their value at the bin centre times
# $\frac{1}{2w}\int_{-w}^{w}\cos\phi\,d\phi = \sin w/w$, while the isotropic part ($\tfrac12 I$) is
# unchanged. With $w = 30°$ the factor is $\sin 30°/(\pi/6) = 0.9549$, the same in every bin, so the
# eigenvectors (and μ) do not change. The deviatoric radius becomes $0.9549 \times 0.24556 = 0.23449$,
# so $\alpha = 100(1 - 0.26551/0.73449) = 63.85\,\%$: binning at the centres over-estimates α by about
# 2 percentage points. The cell checks this with a midpoint quadrature of the piecewise-constant density.

# %%
n_points = 36000  # midpoints: every 30° bin holds 6000 points placed symmetrically about its centre
theta = -np.pi / 2 + (np.arange(n_points) + 0.5) * np.pi / n_points
density = counts[np.minimum(((np.degrees(theta) + 90) // 30).astype(int), 5)]
H_uniform = orientation_tensor(theta, weights=density)
factor = np.sin(np.radians(30)) / np.radians(30)
r = factor * radius
alpha_closed_form = 100 * (1 - (0.5 - r) / (0.5 + r))
print(f"quadrature: alpha = {anisotropy_index(H_uniform):.3f} %   "
      f"closed form: alpha = {alpha_closed_form:.3f} %   (hand: 63.85 %)")
print(f"mean direction unchanged: {mean_direction(H_uniform):.3f}° vs {mean_direction(H):.3f}°")
# midpoint rule with 6000 points per bin: error O(h^2) ~ 1e-8 of the deviatoric part
assert abs(anisotropy_index(H_uniform) - alpha_closed_form) < 1e-6
assert abs(alpha_closed_form - 63.85) < 5e-3
assert abs(mean_direction(H_uniform) - mean_direction(H)) < 1e-6
