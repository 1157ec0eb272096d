"""Inflation of thick-walled incompressible neo-Hookean vessels: skvalve.fem vs closed form.

Writes ``inflation.png`` next to this script. Run: ``python docs/figures/fem/make_inflation_figure.py``.
Left: octant of a sphere A = 1 <= R <= B = 1.5, curved Q2/Q1 hexahedra (24 cells), symmetry planes.
Right: quarter of a cylinder in plane strain, curved Q2/Q1 quadrilaterals (4 x 6).
Follower pressure on the inner surface in both.
"""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from skvalve.fem import Solid  # noqa: E402
from skvalve.fem.meshes import annulus_sector, spherical_shell_octant  # noqa: E402
from skvalve.materials import IncompressibleNeoHookean  # noqa: E402

A, B, MU = 1.0, 1.5, 1.0


def sphere_pressure(a):
    """p = mu [g(lb) - g(la)], g(l) = l^-4/2 + 2/l, b^3 = B^3 + a^3 - A^3 (docs/fem.md)."""
    b = np.cbrt(B**3 + a**3 - A**3)
    la, lb = a / A, b / B
    return MU * (0.5 * lb**-4 + 2.0 / lb - 0.5 * la**-4 - 2.0 / la)


def cylinder_pressure(a):
    """p = mu [ln(la/lb) + (lb^-2 - la^-2)/2], b^2 = B^2 + a^2 - A^2 (docs/fem.md)."""
    b = np.sqrt(B**2 + a**2 - A**2)
    la, lb = a / A, b / B
    return MU * (np.log(la / lb) + 0.5 * (lb**-2 - la**-2))


def inflate(mesh, planes, p_max, steps, probe):
    solid = Solid(mesh, IncompressibleNeoHookean(MU), formulation="up")
    for axis, name in planes:
        solid.add_dirichlet(name, 0.0, components=[axis])
    solid.add_pressure("inner", p_max)
    result = solid.solve(steps=steps, progress=False)
    a = np.array([A + result.evaluate("displacement", probe, step=k)[0, 0] for k in range(len(result))])
    return a, p_max * np.array(result.load_factors)


def main() -> Path:
    cases = [
        ("sphere (3D, Q2/Q1 hex, 24 cells)", sphere_pressure,
         inflate(spherical_shell_octant(A, B, 2, 2), [(0, "x0"), (1, "y0"), (2, "z0")], 0.47, 10,
                 np.array([[A], [0.0], [0.0]]))),
        ("cylinder (plane strain, Q2/Q1 quad, 4x6)", cylinder_pressure,
         inflate(annulus_sector(A, B, 4, 6), [(1, "theta0"), (0, "theta1")], 0.38, 10, np.array([[A], [0.0]]))),
    ]
    fig, axes = plt.subplots(1, 2, figsize=(8.4, 3.4))
    for ax, (title, exact, (a_fe, p_fe)) in zip(axes, cases, strict=True):
        a = np.linspace(A, a_fe.max() * 1.03, 300)
        error = np.max(np.abs(p_fe - exact(a_fe))) / p_fe.max()
        ax.plot(a / A, exact(a) / MU, "k-", label="closed form")
        ax.plot(a_fe / A, p_fe / MU, "o", mfc="none", color="C3", label="skvalve.fem")
        ax.set_xlabel("inner stretch a/A")
        ax.set_ylabel("pressure p/μ")
        ax.set_title(f"{title}\nmax |Δp| / p_max = {error:.1e}", fontsize=9)
        ax.legend(frameon=False, loc="lower right")
        print(f"{title}: max pressure error / p_max = {error:.2e}")
    fig.tight_layout()
    out = Path(__file__).with_name("inflation.png")
    fig.savefig(out, dpi=80)
    print(f"wrote {out}")
    return out


if __name__ == "__main__":
    main()
