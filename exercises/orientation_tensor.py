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
# # Exercise: the SALS orientation tensor by hand
#
# Thomas, Lai & Amini (2019, thomas2019) describe a leaflet's fiber architecture by the orientation tensor
# $H = \oint r\otimes r\,R(\theta)\,d\theta$ (Eq. 1), its anisotropy index $\alpha = 100(1-\lambda_1/\lambda_2)$
# (Eq. 2) and mean direction μ (Eq. 3). The worked solution is in `orientation_tensor_solution.ipynb`.
#
# A SALS measurement gives this histogram of fiber directions (30° bins, counts of fibers):
#
# | bin centre θ | −75° | −45° | −15° | 15° | 45° | 75° |
# |---|---|---|---|---|---|---|
# | count n | 2 | 5 | 12 | 20 | 8 | 3 |
#
# **Tasks.**
# 1. Treat each bin as all its fibers at the bin centre and compute
#    $H_{11} = \sum n\cos^2\theta/\sum n$, $H_{22}$, $H_{12} = \sum n \sin\theta\cos\theta/\sum n$
#    by hand (use $\cos^2 15° = (2+\sqrt3)/4$, $\cos^2 75° = (2-\sqrt3)/4$,
#    $\sin\theta\cos\theta = \tfrac12\sin 2\theta$).
# 2. Find the eigenvalues, α and μ (hint: $\mu = \tfrac12\operatorname{atan2}(2H_{12}, H_{11}-H_{22})$).
# 3. Check with `skvalve.networks.orientation`.
# 4. If the fibers are instead spread uniformly within each bin, the deviatoric part of H shrinks
#    by $\sin w/w$ with $w$ half the bin width in $2\theta$ (here $w = 30°$). Why? What is α then?
#
# The cell below holds the data and the library functions you will check against.

# %%
import numpy as np

from skvalve.networks.orientation import anisotropy_index, mean_direction, orientation_tensor

centres = np.radians([-75, -45, -15, 15, 45, 75])
counts = np.array([2, 5, 12, 20, 8, 3])
help(orientation_tensor)
assert counts.sum() == 50 and callable(anisotropy_index) and callable(mean_direction)
