r"""buchanan2014 pin-ended end loading and interlayer sliding (Sect. 2.2, Fig. 2b, Figs. 4 and 9).

Every section x of a pin-ended strip carries the pin force P (horizontal, along the pin-to-pin line)
and so the moment M(x) = P·y(x), y the deflection from that line (Eq. 2 at the centre marker). Unlike
pure bending, M varies along the strip: the layers' axial forces change along x, which needs interlayer
shear through the spongiosa. A soft spongiosa shears, the outer layers slip over each other and Λ1
jumps across the spongiosa. (In pure bending with glued end sections the net slip must vanish, so the
bonded Rivlin profile results for any μS > 0.) A shear-lag estimate puts the length over which composite
action develops at ~ (E'·h_outer·h_S / μS)^(1/2): ≈ 1 mm for μS = 1 kPa, the half length 7 mm for μS ≈ 20 Pa.

Model (:func:`fe_end_loading`): plane strain, 14 mm × 0.4 mm, tri-layer 25/30/45 %, mixed Q2/Q1, half
model about mid-length (``u1 = 0`` at X = 0, exact for the symmetric buckling mode). Each end is glued
into a sleeve: the last 0.5 mm is a stiff incompressible region (100× the outer modulus), as the
cyanoacrylate-glued steel sleeves of Sect. 2.4; it holds the layers together at the ends and spreads the
pin force (a point force on the tissue is singular, and on a soft spongiosa it would not reach the outer
layers). The pin is the end-face node nearest mid-thickness (Y = 0.22 mm); it is held vertically and moved
by δ·t towards the centre (displacement control passes the load maximum of load control). A straight strip
under axial compression bifurcates: a transverse force at the centre-line mid-point selects the branch
(down for WC, which stretches the ventricularis face; up for AC) and is ramped to zero by t = 0.01, so
every reported state carries the pin load alone.

Measured at the centre section per converged step: the centre line is the material line through the
pins; fits x(X) = b1X + b3X³ and y(X) = c0 + c1X² + c2X⁴ on X ≤ 1 mm give the curvature κ = 2c1/b1²
(the strip is straight, so Δκ = κ) and the bending angle per reference length a = 2c1/b1. M three ways:
P·y (pin reaction × deflection), the moment of the symmetry-plane reactions about the centre-line
point, and ∫σ11 (y − y_c) dy over the deformed section (Gauss points per layer, dy = F22 dY).
Λ1 = √(U11² + U12²).

Sliding measure: straight lines fitted to Λ1 in the ventricularis and in the fibrosa, extrapolated to
the spongiosa's mid-plane, differ by J (fibrosa − ventricularis). S = J(μS) − J(45 kPa) (the bonded
run removes the profile's slight nonlinearity and the discretisation error). "Measurable" means
``|S| > 0.0141``, the experimental error of Λ1 (Sect. 3.4): that decides whether the experiment of Fig. 10
could have seen sliding; the tracking resolution 0.001 (Appendix 1) gives a second, lower threshold.
"""

from __future__ import annotations

import numpy as np

from ...fem import ConvergenceError, Solid
from ...materials import IncompressibleNeoHookean
from .data import CURVATURES, LAMBDA_EXPERIMENT_ERROR, MODEL_STRIP, MU_OUTER
from .fe import strip_mesh
from .models import SIGN, trilayer

__all__ = [
    "SLEEVE_LENGTH", "SLEEVE_STIFFENING", "PERTURBATION", "PERTURBATION_OFF", "SHORTENING", "SLIDING_SPONGIOSA_MODULI",
    "SLIDING_SPONGIOSA_MODULI_DEFAULT", "fe_end_loading", "at_curvature", "interface_jump", "sliding_study",
    "sliding_threshold",
]


SLEEVE_LENGTH = 0.5  # mm of each end glued into the stiff sleeve (the pin acts on the sleeve)
SLEEVE_STIFFENING = 100.0  # sleeve modulus / outer-layer modulus: rigid next to the tissue
PERTURBATION = 4e-4  # kPa·mm, transverse force at the centre (half model) that selects the buckling branch
PERTURBATION_OFF = 0.01  # load factor at which that force has been ramped back to zero
SHORTENING = 2.8  # mm, pin displacement of the half model at t = 1 (past Δκ = 0.3 for every μS)
SLIDING_SPONGIOSA_MODULI = (0.001, 0.01, 0.1, 1.0, 10.0, 45.0)  # kPa, the full sweep (1 Pa … 45 kPa)
SLIDING_SPONGIOSA_MODULI_DEFAULT = (0.1, 1.0, 10.0, 45.0)  # kPa, the coarse sweep of the default run (Δκ = 0.2)


def fe_end_loading(layers: list, direction: str = "WC", nx: int = 28, ny_per_layer: int = 2,
                   perturbation: float = PERTURBATION, steps: int = 30, shortening: float = SHORTENING,
                   n_profile: int = 41) -> dict:
    r"""Pin-ended strip loaded by an axial pin displacement (Sect. 2.2, Fig. 2b), plane strain, Q2/Q1.

    Half model ``0 ≤ X ≤ L/2`` (symmetry ``u1 = 0`` at X = 0). The last :data:`SLEEVE_LENGTH` of the strip is a
    stiff region (:data:`SLEEVE_STIFFENING` × the stiffest layer), the glued steel sleeve; the pin is the
    end-face node nearest mid-thickness, held vertically and moved by ``shortening·t`` towards the centre;
    a transverse ``perturbation`` force at the centre selects the branch and is gone by t = 0.01. For every
    converged step after that (a very soft spongiosa may stop converging before t = 1: the converged part is
    kept, ``load_factor`` says how far it got) the centre section gives: the curvature of the centre line
    :math:`\kappa = y''/x'^2` and the bending angle per
    unit length :math:`a = y''/x'` (even/odd polynomial fits of the deformed centre line over X ≤ 1 mm), the
    pin force P, the deflection y of the centre-line mid-point from the pin-to-pin line, M = P·y (Eq. 2), the
    section moment from the symmetry-plane reactions and from the integral of σ11 over the deformed section,
    and Λ1 = √(U11² + U12²) through the thickness.
    """
    if direction not in SIGN:
        raise ValueError(f"direction must be 'AC' or 'WC'; got {direction!r}")
    if perturbation <= 0.0:
        raise ValueError(f"perturbation must be positive (kPa·mm); got {perturbation}")
    half_length, H = MODEL_STRIP.length / 2, float(sum(h for h, _ in layers))
    mesh, regions = strip_mesh(layers, half_length, nx, ny_per_layer)
    x_centres = mesh.p[0, mesh.t].mean(axis=0)
    regions = np.where(x_centres > half_length - SLEEVE_LENGTH, len(layers), regions)
    if not np.any(np.isclose(mesh.p[0], half_length - SLEEVE_LENGTH)):
        raise ValueError(f"nx = {nx} puts no node line at the sleeve edge X = {half_length - SLEEVE_LENGTH}")
    stiffest = max(m.parameters().get("mu", 0.0) for _, m in layers)
    materials = [m for _, m in layers] + [IncompressibleNeoHookean(SLEEVE_STIFFENING * stiffest)]
    y_nodes = np.unique(mesh.p[1][np.isclose(mesh.p[0], half_length)])
    y_pin = float(y_nodes[np.argmin(np.abs(y_nodes - H / 2))])  # centre line: the material line through the pins
    on_pin = lambda X: np.isclose(X[0], half_length) & np.isclose(X[1], y_pin)
    on_centre = lambda X: np.isclose(X[0], 0.0)
    solid = Solid(mesh, materials, formulation="up", regions=regions)
    solid.add_dirichlet(on_centre, 0.0, components=[0])
    solid.add_dirichlet(on_pin, np.array([-shortening, 0.0]))
    # WC stretches the ventricularis (bottom) face: push the centre down (−Y), for AC up; released at t_off
    push = lambda t: np.array([0.0, SIGN[direction] * perturbation * max(0.0, 1.0 - t / PERTURBATION_OFF)])
    solid.add_nodal_force(lambda X: on_centre(X) & np.isclose(X[1], y_pin), push, ramp=False)
    factors = (np.arange(1, steps + 1) / steps) ** 2  # the deflection grows like √shortening
    try:
        result = solid.solve(steps=factors, rtol=1e-6, max_cutbacks=4, progress=False)
    except ConvergenceError as err:  # a very soft spongiosa: keep the converged part of the path
        result = err.last_converged

    X_line = np.linspace(0.0, 1.0, 9)
    line = np.array([X_line, np.full_like(X_line, y_pin)])
    Y = np.linspace(0.0, H, n_profile)
    section = np.array([np.zeros_like(Y), Y])
    g, w = np.polynomial.legendre.leggauss(6)
    y_cuts = np.cumsum([0.0] + [h for h, _ in layers])
    Yq = np.concatenate([0.5 * (y1 - y0) * g + 0.5 * (y1 + y0) for y0, y1 in zip(y_cuts[:-1], y_cuts[1:], strict=True)])
    wq = np.concatenate([0.5 * (y1 - y0) * w for y0, y1 in zip(y_cuts[:-1], y_cuts[1:], strict=True)])
    quad = np.array([np.zeros_like(Yq), Yq])
    keys = ("kappa", "a", "P", "N_reaction", "y", "M_Py", "M_reaction", "M_stress", "N_stress", "stretch")
    out = {k: [] for k in keys}
    released = np.nonzero(np.asarray(result.load_factors) >= PERTURBATION_OFF)[0]
    for step in released:
        u = result.evaluate("displacement", line, step=step)
        x_def, y_def = line[0] + u[0], line[1] + u[1]
        b1 = np.polyfit(X_line, x_def, 3)[-2]  # x(X) odd: b1 = x'(0)
        c = np.polynomial.polynomial.polyfit(X_line**2, y_def, 2)  # y(X) even: y''(0) = 2 c1
        y_centre = float(c[0])
        out["kappa"].append(abs(2 * c[1]) / b1**2)
        out["a"].append(abs(2 * c[1]) / b1)
        P = -float(result.reaction(on_pin, step=step)[0])
        out["P"].append(P)
        out["N_reaction"].append(float(result.reaction(on_centre, step=step)[0]))
        out["y"].append(y_centre - y_pin)
        out["M_Py"].append(-P * (y_centre - y_pin))  # sign: positive when the ventricularis face is stretched
        out["M_reaction"].append(-result.reaction_moment(on_centre, [0.0, y_centre], step=step))
        uq = result.evaluate("displacement", quad, step=step)
        s11 = result.evaluate("cauchy", quad, step=step)[0, 0]
        dy = result.evaluate("deformation_gradient", quad, step=step)[1, 1]  # dy/dY on the section (x' = 0)
        out["M_stress"].append(-float(np.sum(wq * dy * s11 * (quad[1] + uq[1] - y_centre))))
        out["N_stress"].append(float(np.sum(wq * dy * s11)))
        U = result.evaluate("stretch_tensor", section, step=step)
        out["stretch"].append(np.hypot(U[0, 0], U[0, 1]))
    out = {k: np.array(v) for k, v in out.items()}
    out.update(load_factor=float(result.load_factors[-1]), Y=Y, H=H, elements=mesh.nelements, layers=layers,
               direction=direction, y_pin=y_pin, load_factors=np.asarray(result.load_factors)[released])
    return out


def at_curvature(run: dict, curvature_change: float) -> dict:
    """Quantities of :func:`fe_end_loading` at a curvature change Δκ = κ − κ0, linear in κ between steps."""
    dk = run["kappa"]  # straight reference strip: Δκ = κ
    if not dk[0] <= curvature_change <= dk[-1]:
        raise ValueError(f"Δκ = {curvature_change} outside the computed range {dk[0]:.3g}…{dk[-1]:.3g}")
    k = int(np.clip(np.searchsorted(dk, curvature_change), 1, len(dk) - 1))
    s = (curvature_change - dk[k - 1]) / (dk[k] - dk[k - 1])
    out = {key: (1 - s) * run[key][k - 1] + s * run[key][k] for key in
           ("kappa", "a", "P", "N_reaction", "y", "M_Py", "M_reaction", "M_stress", "N_stress", "stretch")}
    return out


def interface_jump(layers: list, Y: np.ndarray, stretch: np.ndarray) -> float:
    r"""Λ1 jump across the spongiosa: the straight lines fitted to Λ1 in the ventricularis and in the fibrosa,
    extrapolated to the spongiosa's mid-plane, differ by (fibrosa − ventricularis); zero for a profile that
    is linear through the whole thickness (bonded, Rivlin: λ² = 2aY + c is nearly linear)."""
    cuts = np.cumsum([0.0] + [h for h, _ in layers])
    mid = 0.5 * (cuts[1] + cuts[2])
    ends = []
    for y0, y1 in ((cuts[0], cuts[1]), (cuts[2], cuts[3])):
        inside = (Y >= y0 - 1e-12) & (Y <= y1 + 1e-12)
        ends.append(np.polyval(np.polyfit(Y[inside], stretch[inside], 1), mid))
    return float(ends[1] - ends[0])


def sliding_study(spongiosa_moduli=SLIDING_SPONGIOSA_MODULI, curvatures=CURVATURES, direction: str = "WC",
                  **mesh) -> dict:
    r"""Figs. 4/9: Λ1 at the centre section for each μS (outer layers 45 kPa) and Δκ, and the sliding measure
    S = J(μS) − J(45 kPa), J the :func:`interface_jump` (the bonded run removes the small curvature of the
    Rivlin profile and the discretisation error)."""
    if MU_OUTER not in spongiosa_moduli:
        raise ValueError(f"spongiosa_moduli must contain the bonded reference μS = {MU_OUTER} kPa")
    runs = {mu: fe_end_loading(trilayer(mu), direction, **mesh) for mu in spongiosa_moduli}
    Y = runs[MU_OUTER]["Y"]
    profiles = {(mu, k): at_curvature(run, k)["stretch"] for mu, run in runs.items() for k in curvatures}
    jump = {key: interface_jump(trilayer(key[0]), Y, p) for key, p in profiles.items()}
    sliding = {(mu, k): jump[(mu, k)] - jump[(MU_OUTER, k)] for mu, k in jump}
    return {"runs": runs, "Y": Y, "H": runs[MU_OUTER]["H"], "profiles": profiles, "sliding": sliding,
            "moduli": tuple(spongiosa_moduli), "curvatures": tuple(curvatures), "direction": direction}


def sliding_threshold(study: dict, curvature: float, limit: float = LAMBDA_EXPERIMENT_ERROR) -> float:
    """μS (kPa) below which ``|S|`` exceeds ``limit``: linear interpolation of ``|S|`` in log μS between the sweep's
    bracketing values; NaN-free — raises ValueError when the sweep does not bracket the limit."""
    moduli = np.array(sorted(study["moduli"]))
    s = np.array([abs(study["sliding"][(mu, curvature)]) for mu in moduli])
    above = np.nonzero(s > limit)[0]
    if above.size == 0 or above[-1] == len(moduli) - 1:
        raise ValueError(f"the μS sweep {tuple(moduli)} does not bracket |S| = {limit} at Δκ = {curvature}")
    i = above[-1]
    t = (s[i] - limit) / (s[i] - s[i + 1])
    return float(10 ** ((1 - t) * np.log10(moduli[i]) + t * np.log10(moduli[i + 1])))
