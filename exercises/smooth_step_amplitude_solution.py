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
# # Solution: the Abaqus smooth-step amplitude
#
# Worked solution of `smooth_step_amplitude.ipynb` (mathur2022, the TriValve inputs' ``SMOOTH STEP``). Try the
# problem first.
#
# ## 1. The lowest-degree polynomial with zero slope and curvature at both ends
#
# Six conditions ($s$, $s'$, $s''$ at $\xi = 0$ and at $\xi = 1$) fix the six coefficients of a quintic; a quartic
# has only five. $s(0) = s'(0) = s''(0) = 0$ leaves $s = \xi^3(a + b\xi + c\xi^2)$, and the three conditions at
# $\xi = 1$ are a linear system for $a, b, c$ with a non-singular matrix, so the quintic is unique.

# %%
import sympy as sp

xi = sp.symbols("xi", real=True)
coefficients = sp.symbols("a0:6")
s = sum(c * xi**k for k, c in enumerate(coefficients))
conditions = [s.subs(xi, 0), s.subs(xi, 1) - 1]
conditions += [sp.diff(s, xi, order).subs(xi, end) for order in (1, 2) for end in (0, 1)]
solution = sp.solve(conditions, coefficients, dict=True)
print("solutions:", solution)
assert len(solution) == 1  # six independent conditions, six coefficients: unique
smooth = sp.expand(s.subs(solution[0]))
print("s(ξ) =", sp.factor(smooth))
assert sp.expand(smooth - xi**3 * (10 - 15 * xi + 6 * xi**2)) == 0
# a quartic cannot satisfy the six conditions
quartic = s.subs(coefficients[5], 0)
quartic_conditions = [quartic.subs(xi, 0), quartic.subs(xi, 1) - 1]
quartic_conditions += [sp.diff(quartic, xi, order).subs(xi, end) for order in (1, 2) for end in (0, 1)]
assert sp.solve(quartic_conditions, coefficients[:5], dict=True) == []

# %% [markdown]
# ## 2. Largest rate and acceleration
#
# $s'(\xi) = 30\xi^2(1-\xi)^2$ is largest at $\xi = \tfrac12$: $\max s' = \tfrac{15}{8} = 1.875$, i.e. 1.875 times
# the constant rate of a linear ramp. $s''(\xi) = 60\xi(1-\xi)(1-2\xi)$ has its extremes where
# $s''' = 60(1 - 6\xi + 6\xi^2) = 0$, at $\xi = \tfrac12 \mp \tfrac{\sqrt3}{6}$, with
# $\max|s''| = \tfrac{10}{\sqrt3} \approx 5.774$. A linear ramp has zero acceleration inside but a jump of its rate
# at both ends: an infinite acceleration (a Dirac impulse) that starts stress waves in an explicit dynamic analysis.

# %%
rate, acceleration = sp.diff(smooth, xi), sp.diff(smooth, xi, 2)
assert sp.factor(rate - 30 * xi**2 * (1 - xi) ** 2) == 0
assert sp.factor(acceleration - 60 * xi * (1 - xi) * (1 - 2 * xi)) == 0
peak_rate = rate.subs(xi, sp.Rational(1, 2))
extremes = sp.solve(sp.diff(smooth, xi, 3), xi)
peak_acceleration = max(abs(acceleration.subs(xi, x)) for x in extremes)
print("max s' =", peak_rate, "at ξ = 1/2;  |s''| largest at ξ =", extremes, ":", sp.nsimplify(peak_acceleration))
assert peak_rate == sp.Rational(15, 8)
assert sp.simplify(peak_acceleration - 10 / sp.sqrt(3)) == 0
assert sorted(extremes, key=float) == sorted([sp.Rational(1, 2) - sp.sqrt(3) / 6, sp.Rational(1, 2) + sp.sqrt(3) / 6],
                                             key=float)

# %% [markdown]
# ## 3. Point symmetry
#
# $s(\xi) + s(1-\xi) = 1$ for every $\xi$: the ramp is its own mirror image about $(\tfrac12, \tfrac12)$, so it
# passes the middle value at mid-time and spends equal time getting started and coming to rest.

# %%
assert sp.expand(smooth + smooth.subs(xi, 1 - xi) - 1) == 0
print("s(ξ) + s(1 − ξ) − 1 =", sp.expand(smooth + smooth.subs(xi, 1 - xi) - 1))

# %% [markdown]
# ## 4. The staged closure of the TriValve (papillary motion, then pressure)
#
# With $\xi = (t - t_0)/(t_1 - t_0)$ the time derivatives are $\dot A = s'(\xi)/(t_1 - t_0)$ and
# $\ddot A = s''(\xi)/(t_1 - t_0)^2$. The library's `SmoothStep` is checked against the derived polynomial and its
# derivatives against central differences; the plot shows that rate and acceleration are continuous everywhere,
# including where the pressure ramp starts at $t = 0.5$, just as the papillary motion comes to rest.

# %%
import matplotlib.pyplot as plt
import numpy as np

from skvalve.fem.amplitudes import SmoothStep

plt.rcParams["figure.dpi"] = 150
papillary = SmoothStep(times=(0.0, 0.5), values=(0.0, 1.0), name="papillary motion")
pressure = SmoothStep(times=(0.5, 1.5), values=(0.0, 1.0), name="pressure")
polynomial = sp.lambdify(xi, smooth, "numpy")
t = np.linspace(0.0, 1.5, 1501)
assert np.allclose(papillary(t), polynomial(np.clip(t / 0.5, 0, 1)), atol=1e-14, rtol=0)
assert np.allclose(pressure(t), polynomial(np.clip(t - 0.5, 0, 1)), atol=1e-14, rtol=0)

h = 1e-4
fig, axes = plt.subplots(1, 3, figsize=(10, 3), sharex=True)
for amplitude, duration in ((papillary, 0.5), (pressure, 1.0)):
    value = amplitude(t)
    rate_fd = (amplitude(t + h) - amplitude(t - h)) / (2 * h)
    acceleration_fd = (amplitude(t + h) - 2 * value + amplitude(t - h)) / h**2
    axes[0].plot(t, value, label=amplitude.name)
    axes[1].plot(t, rate_fd)
    axes[2].plot(t, acceleration_fd)
    print(f"{amplitude.name:>16}: max rate {rate_fd.max():.4f} (15/8 / {duration} = {1.875 / duration:.4f}), "
          f"max |acceleration| {np.abs(acceleration_fd).max():.3f} (10/√3 / {duration}² = "
          f"{10 / np.sqrt(3) / duration**2:.3f})")
    assert abs(rate_fd.max() - 1.875 / duration) < 1e-3 / duration
    assert abs(np.abs(acceleration_fd).max() - 10 / np.sqrt(3) / duration**2) < 1e-2 / duration**2
    # no jump anywhere: between samples dt apart the rate changes by at most max|A''| dt and the acceleration by at
    # most max|A'''| dt = 60 dt / duration^3 (a linear ramp's rate would jump by 1 / duration)
    dt = t[1] - t[0]
    assert np.abs(np.diff(rate_fd)).max() <= 1.01 * 10 / np.sqrt(3) / duration**2 * dt
    assert np.abs(np.diff(acceleration_fd)).max() <= 1.01 * 60 / duration**3 * dt
axes[0].set(xlabel="t (step time)", ylabel="A(t)", title="amplitude")
axes[1].set(xlabel="t (step time)", ylabel="dA/dt", title="rate")
axes[2].set(xlabel="t (step time)", ylabel="d²A/dt²", title="acceleration")
axes[0].legend(fontsize=8)
plt.tight_layout()
plt.show()

# %% [markdown]
# **Why the smooth step.** In a quasi-static *explicit* analysis (as in mathur2022) inertia is real: a load
# switched on with a jump in rate excites waves that must die out before the state is quasi-static. Zero rate and
# zero acceleration at both ends of every ramp keep the kinetic energy small, and the two stages join without a
# kink. For an *implicit* Newton solution without inertia only the sequence of states matters, not how fast they
# are reached: the smooth step merely spaces the load steps more densely near the ends of each stage (where
# $s' \to 0$), and the end state is the same as with a linear ramp.
