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
# # Exercise: the RVE stress from its boundary forces (thomas2019 Eq. 5 from Eq. 4)
#
# Thomas, Lai & Amini (2019, thomas2019, Sect. 2.4) define the macroscopic stress of a representative volume element
# (RVE) as the volume average of the microscopic stress (Eq. 4),
#
# $$ S_{ij} = \frac{1}{V}\int_V s_{ij}\,dV , $$
#
# and, "on applying Green's theorem and assuming microscopic equilibrium ($s_{ij,i} = 0$)", evaluate it for a fiber
# network from the forces at the boundary cross-links only (Eq. 5),
#
# $$ S_{ij} = \frac{1}{V}\sum_{\text{boundary cross-links}} x_i f_j . $$
#
# The worked solution is in `rve_divergence_theorem_solution.ipynb`.
#
# **Tasks.**
# 1. *Continuum.* Show that $s_{kj,k} = 0$ implies $s_{ij} = (x_i\,s_{kj})_{,k}$, and use the divergence theorem to
#    write $\int_V s_{ij}\,dV$ as a boundary integral of $x_i$ times the traction $t_j = s_{kj} n_k$. Check it with
#    sympy on the unit square for a stress derived from an Airy stress function (automatically in equilibrium).
# 2. *Discrete.* A network of straight fibers (tension $f$ along the unit vector $e = d/\ell$ from end $a$ to end
#    $b$) is held by external forces $R_n$ at its cross-links. Show that
#    $\sum_{\text{all nodes}} x_n \otimes R_n = \sum_{\text{fibers}} (f/\ell)\, d \otimes d$ for **any** positions,
#    and that the sum reduces to the boundary cross-links (Eq. 5) exactly when the interior cross-links are in
#    equilibrium. Why is the result independent of the origin of $x$, and why is it symmetric?
# 3. *Numerically.* For the small network below, compare `skvalve.networks.rve.solve_rve` (which reports the fiber
#    sum) with `skvalve.networks.rve.boundary_stress` (Eq. 5 over the boundary nodes). Then evaluate both sums with
#    the interior nodes placed affinely, $x = FX$, instead of at equilibrium: what goes wrong?
#
# The cell below builds a network with two interior cross-links and ten boundary cross-links, and a fiber law with
# illustrative parameters (the identity holds for any law).

# %%
import numpy as np

from skvalve.materials.exponential_fiber import ExponentialFiber
from skvalve.networks.network import FACE_NAMES, Network
from skvalve.networks.rve import boundary_stress, solve_rve

nodes = np.array([
    [-0.1, 0.05, 0.0], [0.15, -0.05, 0.05],  # interior
    [-0.5, 0.1, 0.0], [0.5, -0.1, 0.1], [-0.1, 0.5, 0.0], [-0.1, -0.5, 0.1], [-0.1, 0.0, -0.5],
    [-0.1, 0.1, 0.5], [0.2, 0.5, 0.0], [0.15, -0.5, 0.0], [0.1, 0.0, -0.5], [0.2, -0.1, 0.5],
])
face = np.array([-1, -1, 0, 1, 3, 2, 4, 5, 3, 2, 4, 5])  # index into FACE_NAMES, -1 = interior
fibers = np.array([[0, 1], [0, 2], [0, 4], [0, 5], [0, 6], [0, 7], [1, 3], [1, 8], [1, 9], [1, 10], [1, 11]])
network = Network(nodes, fibers, boundary=face >= 0, face=face)
fiber = ExponentialFiber(E_f=1.0, A_f=1.0, beta=5.0, lambda_c=1.2)  # illustrative, not the paper's
F = np.array([[1.15, 0.05, 0.0], [0.0, 1.05, 0.0], [0.0, 0.0, 0.85]])
print(f"{network.n_fibers} fibers, {int(network.boundary.sum())} boundary cross-links on faces "
      f"{sorted({FACE_NAMES[f] for f in face if f >= 0})}")
assert all(abs(nodes[n]).max() == 0.5 for n in np.flatnonzero(network.boundary))  # on the faces of the unit cube
for tool in (solve_rve, boundary_stress):
    print(f"{tool.__name__}: {tool.__doc__.splitlines()[0]}")
