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
# # Exercise: the Abaqus smooth-step amplitude
#
# The Texas TriValve inputs of Mathur et al. (2022, mathur2022) ramp every load with an Abaqus
# ``*Amplitude, definition=SMOOTH STEP``. Between two points $(t_0, A_0)$ and $(t_1, A_1)$ it is
#
# $$ A(t) = A_0 + (A_1 - A_0)\,\xi^3\,(10 - 15\xi + 6\xi^2), \qquad \xi = \frac{t - t_0}{t_1 - t_0}, $$
#
# and it holds $A_0$ before $t_0$ and $A_1$ after $t_1$. The diseased-valve input stages the closure with two of
# them: the papillary muscles move over $0 \le t \le 0.5$, then the transvalvular pressure rises over
# $0.5 \le t \le 1.5$. The worked solution is in `smooth_step_amplitude_solution.ipynb`.
#
# **Tasks.**
# 1. Find the polynomial of lowest degree $s(\xi)$ with $s(0) = 0$, $s(1) = 1$ and zero first **and** second
#    derivatives at both ends. Show that it is $\xi^3(10 - 15\xi + 6\xi^2)$ and that it is unique.
# 2. What are the largest rate $\max s'$ and the largest acceleration $\max |s''|$, and where do they occur? Compare
#    with a linear ramp of the same duration.
# 3. Show that $s(\xi) + s(1 - \xi) = 1$ (the ramp is point-symmetric about its midpoint).
# 4. Write the papillary and pressure amplitudes of the staged closure with `skvalve.fem.amplitudes.SmoothStep` and
#    plot $A(t)$, $\dot A$ and $\ddot A$ for $0 \le t \le 1.5$. Why does a quasi-static *explicit* analysis prefer
#    this ramp to a linear one, and why is it harmless for an implicit (Newton) solution?
#
# The cell below builds the two amplitudes.

# %%
import numpy as np

from skvalve.fem.amplitudes import SmoothStep

papillary = SmoothStep(times=(0.0, 0.5), values=(0.0, 1.0), name="papillary motion")
pressure = SmoothStep(times=(0.5, 1.5), values=(0.0, 1.0), name="pressure")
t = np.linspace(0.0, 1.5, 7)
print("t         ", np.round(t, 3))
print("papillary ", np.round(papillary(t), 4))
print("pressure  ", np.round(pressure(t), 4))
assert papillary(0.25) == 0.5 and pressure(1.0) == 0.5  # midpoints, by the symmetry of task 3
