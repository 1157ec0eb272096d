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
# # Solution: the RVE stress from its boundary forces (thomas2019 Eq. 5 from Eq. 4)
#
# Worked solution of `rve_divergence_theorem.ipynb`. Try the problem first.
#
# ## 1. Continuum: Eq. 4 → a boundary integral
#
# With $x_{i,k} = \delta_{ik}$ and equilibrium $s_{kj,k} = 0$,
#
# $$ (x_i\,s_{kj})_{,k} = \delta_{ik}\,s_{kj} + x_i\,s_{kj,k} = s_{ij} , $$
#
# so by the divergence theorem (Green's theorem in 2D)
#
# $$ \int_V s_{ij}\,dV = \int_V (x_i s_{kj})_{,k}\,dV = \oint_{\partial V} x_i\,s_{kj} n_k\,dA
#    = \oint_{\partial V} x_i\,t_j\,dA . $$
#
# Only the boundary positions and tractions enter. Below, sympy checks this on the unit square
# $[0, 1]^2$ for the stress of an Airy function $\phi$: $s_{11} = \phi_{,22}$, $s_{22} = \phi_{,11}$,
# $s_{12} = -\phi_{,12}$, which satisfies $s_{kj,k} = 0$ identically.

# %%
import sympy as sp

x1, x2 = sp.symbols("x1 x2", real=True)
phi = x1**3 * x2**2 - 2 * x1**4 + 3 * x1 * x2**3 + x1**2 * x2 + x1**5 * x2**2
s = sp.Matrix([[sp.diff(phi, x2, 2), -sp.diff(phi, x1, x2)], [-sp.diff(phi, x1, x2), sp.diff(phi, x1, 2)]])
assert all(sp.simplify(sp.diff(s[0, j], x1) + sp.diff(s[1, j], x2)) == 0 for j in range(2))  # s_kj,k = 0

volume_integral = s.applyfunc(lambda c: sp.integrate(c, (x1, 0, 1), (x2, 0, 1)))
x = sp.Matrix([x1, x2])
# the four edges of the square: (outward normal, fixed coordinate and its value, variable of integration)
edges = [((1, 0), {x1: 1}, x2), ((-1, 0), {x1: 0}, x2), ((0, 1), {x2: 1}, x1), ((0, -1), {x2: 0}, x1)]
boundary_integral = sp.zeros(2, 2)
for normal, on_edge, variable in edges:
    traction = s.T * sp.Matrix(normal)  # t_j = s_kj n_k
    boundary_integral += (x * traction.T).subs(on_edge).applyfunc(lambda c, v=variable: sp.integrate(c, (v, 0, 1)))
print("∫ s dA =", sp.simplify(volume_integral))
print("∮ x ⊗ t ds − ∫ s dA =", sp.simplify(boundary_integral - volume_integral))
assert sp.simplify(boundary_integral - volume_integral) == sp.zeros(2, 2)

# %% [markdown]
# ## 2. Discrete: the sum over boundary cross-links
#
# A fiber from $a$ to $b$ with tension $f$ pulls node $a$ with $+f e$ and node $b$ with $-f e$. The external force
# that holds node $n$ is minus the sum of the fiber forces on it, $R_n$. Summing by fibers,
#
# $$ \sum_n x_n \otimes R_n = \sum_{\text{fibers}} \big(x_a \otimes (-f e) + x_b \otimes f e\big)
#    = \sum_{\text{fibers}} (x_b - x_a) \otimes f e = \sum_{\text{fibers}} \frac{f}{\ell}\, d \otimes d $$
#
# for any positions: this is the discrete divergence theorem (summation by parts). At equilibrium $R_n = 0$ at every
# interior cross-link, so only the boundary cross-links remain: Eq. 5. The fiber form is symmetric ($d \otimes d$),
# and the boundary form does not depend on the origin because $\sum_n R_n = 0$ (each fiber's two end forces
# cancel), so $\sum_n (x_n + c) \otimes R_n = \sum_n x_n \otimes R_n$.
#
# ## 3. Numerically, on the small network of the problem

# %%
import numpy as np

from skvalve.materials.exponential_fiber import ExponentialFiber
from skvalve.networks.network import Network
from skvalve.networks.rve import boundary_stress, solve_rve

nodes = np.array([
    [-0.1, 0.05, 0.0], [0.15, -0.05, 0.05],  # interior
    [-0.5, 0.1, 0.0], [0.5, -0.1, 0.1], [-0.1, 0.5, 0.0], [-0.1, -0.5, 0.1], [-0.1, 0.0, -0.5],
    [-0.1, 0.1, 0.5], [0.2, 0.5, 0.0], [0.15, -0.5, 0.0], [0.1, 0.0, -0.5], [0.2, -0.1, 0.5],
])
face = np.array([-1, -1, 0, 1, 3, 2, 4, 5, 3, 2, 4, 5])
fibers = np.array([[0, 1], [0, 2], [0, 4], [0, 5], [0, 6], [0, 7], [1, 3], [1, 8], [1, 9], [1, 10], [1, 11]])
network = Network(nodes, fibers, boundary=face >= 0, face=face)
fiber = ExponentialFiber(E_f=1.0, A_f=1.0, beta=5.0, lambda_c=1.2)
F = np.array([[1.15, 0.05, 0.0], [0.0, 1.05, 0.0], [0.0, 0.0, 0.85]])


def node_forces(positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """External forces R_n that hold each node, and the fiber sum Σ (f/ℓ) d ⊗ d, at the given positions."""
    d = network.fiber_vectors(positions)
    length = np.linalg.norm(d, axis=1)
    tension = fiber.force(length / network.fiber_lengths())  # Eq. 9 at the fiber stretch
    pull = tension[:, None] * d / length[:, None]  # f e, from a towards b
    holding = np.zeros_like(positions)
    np.add.at(holding, network.fibers[:, 0], -pull)  # the fiber pulls a with +f e: R_a = −f e
    np.add.at(holding, network.fibers[:, 1], pull)
    return holding, np.einsum("f,fi,fj->ij", tension / length, d, d)


result = solve_rve(network, F, fiber, psi=0.5, fiber_diameter=None)
x = result.deformed_nodes
R, fiber_sum = node_forces(x)
boundary = network.boundary
all_nodes_sum = x.T @ R
boundary_sum = x[boundary].T @ R[boundary]
print(f"Newton: {result.iterations} iterations, interior |R| = {np.abs(R[~boundary]).max():.1e} (equilibrium)")
print(f"|Σ_all x⊗R − Σ_fibers (f/ℓ) d⊗d| = {np.abs(all_nodes_sum - fiber_sum).max():.1e}  (identity)")
print(f"|Σ_boundary x⊗R − Σ_fibers (f/ℓ) d⊗d| = {np.abs(boundary_sum - fiber_sum).max():.1e}  (Eq. 5)")
print(f"|ΣR| = {np.abs(R.sum(axis=0)).max():.1e};  shift of origin changes Eq. 5 by "
      f"{np.abs((x[boundary] + [0.3, -0.2, 0.7]).T @ R[boundary] - boundary_sum).max():.1e}")
print("library: fiber form (solve_rve) vs Eq. 5 over boundary nodes (boundary_stress):",
      f"{np.abs(result.cauchy - boundary_stress(network, result, fiber, psi=0.5, fiber_diameter=None)).max():.1e}")
print("symmetry of Eq. 5:", f"{np.abs(boundary_sum - boundary_sum.T).max():.1e}")
scale = np.abs(fiber_sum).max()
assert np.abs(R[~boundary]).max() < 1e-9 * np.abs(R).max()
assert np.abs(all_nodes_sum - fiber_sum).max() < 1e-14 * scale
assert np.abs(boundary_sum - fiber_sum).max() < 1e-9 * scale
assert np.abs((x[boundary] + [0.3, -0.2, 0.7]).T @ R[boundary] - boundary_sum).max() < 1e-9 * scale
assert np.abs(result.cauchy - boundary_stress(network, result, fiber, psi=0.5, fiber_diameter=None)).max() < (
    1e-9 * np.abs(result.cauchy).max())
# solve_rve's stress is Eq. 8: the fiber sum times ψ / (L A_f V), here ψ = 0.5, A_f = 1, V = det F
prefactor = 0.5 / (network.total_length * 1.0 * np.linalg.det(F))
assert np.allclose(result.cauchy, prefactor * fiber_sum, rtol=1e-12, atol=1e-14 * scale)

# %% [markdown]
# **Without equilibrium the boundary sum is wrong.** Place the interior nodes affinely ($x = FX$ everywhere): the
# identity over *all* nodes still holds, but the interior nodes now need holding forces, and dropping them (Eq. 5)
# changes the stress — and makes it unsymmetric.

# %%
affine = nodes @ F.T
R_affine, fiber_sum_affine = node_forces(affine)
eq5_affine = affine[boundary].T @ R_affine[boundary]
print(f"affine interior: |R_interior| = {np.abs(R_affine[~boundary]).max():.3f}, "
      f"|Eq. 5 − fiber sum| / |fiber sum| = {np.abs(eq5_affine - fiber_sum_affine).max() / scale:.3f}, "
      f"asymmetry {np.abs(eq5_affine - eq5_affine.T).max() / scale:.3f}")
assert np.abs(affine.T @ R_affine - fiber_sum_affine).max() < 1e-14 * scale
assert np.abs(eq5_affine - fiber_sum_affine).max() > 0.01 * scale
assert np.abs(eq5_affine - eq5_affine.T).max() > 1e-3 * scale

# %% [markdown]
# ## The same on a generated network
#
# A Delaunay network of about 150 fibers (`skvalve.networks.generate.generate`), stretched biaxially. Most of its
# cross-links lie on the boundary, yet Eq. 5 and the fiber form agree to the Newton tolerance.

# %%
from skvalve.networks.generate import generate

delaunay = generate(alpha=30.0, mu=0.0, n_fibers=150, seed=3)
F_biaxial = np.diag([1.12, 1.06, 1 / (1.12 * 1.06)])
result = solve_rve(delaunay, F_biaxial, fiber, psi=0.5, fiber_diameter=None)
eq5 = boundary_stress(delaunay, result, fiber, psi=0.5, fiber_diameter=None)
difference = np.abs(eq5 - result.cauchy).max() / np.abs(result.cauchy).max()
print(f"{delaunay.n_fibers} fibers, {int(delaunay.boundary.sum())} of {len(delaunay.nodes)} cross-links on the "
      f"boundary; relative residual {result.residual:.1e}; |Eq. 5 − fiber form| / |σ| = {difference:.1e}")
assert result.residual < 1e-10 and difference < 1e-8 and delaunay.boundary.mean() > 0.5  # most on the boundary
