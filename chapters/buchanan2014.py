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
# # Buchanan & Sacks 2014 — the layered aortic leaflet in flexure
#
# *Interlayer micromechanics of the aortic heart valve leaflet*, Biomech Model Mechanobiol 13:813–826.
#
# The paper asks whether the three layers of the aortic leaflet (fibrosa, spongiosa, ventricularis) slide over each
# other when the leaflet bends. It (i) fixes a constitutive form with Rivlin's exact bending solution (Fig. 3),
# (ii) runs a tri-layer FE strip with a spongiosa shear modulus from 1 Pa to 45 kPa (Figs. 4, 9), (iii) measures
# transmural stretch with edge markers (Appendix 1), and (iv) fits a *bimodular* neo-Hookean bilayer whose neutral
# axis sits at 0.35 (WC) and 0.79 (AC) of the thickness (Fig. 8, Tables 2–3).
#
# This chapter recomputes what can be computed without the authors' raw data; every number the text quotes is
# computed in a cell and checked there. Not reproducible here: the experimental M–Δκ curves (Figs. 3, 5), measured
# transmural profiles (Figs. 6, 10), the silicone validation (Table 1) and the fitted μ = 45 kPa (Sect. 3.1).
# Conventions: mm, kPa; normalised thickness 0 = ventricularis face, 1 = fibrosa face; AC bending stretches the
# fibrosa face, WC the ventricularis face.

# %%
import matplotlib.pyplot as plt
import numpy as np
from scipy.optimize import brentq

from skvalve.analytic.rivlin import bend
from skvalve.papers.buchanan2014 import data as b14
from skvalve.papers.buchanan2014 import fe as b14_fe
from skvalve.papers.buchanan2014 import figures, models, rows
from skvalve.papers.buchanan2014 import sliding as b14_sl
from skvalve.papers.table import format_table

plt.rcParams["figure.dpi"] = 150

# %% [markdown]
# ## 1. Rivlin's solution and the Ogden family (Fig. 3)
#
# Bending a block to a sector, incompressibility gives $\lambda(Y)^2 = 2aY + c$ ($a$ = change of curvature), radial
# equilibrium gives $d\sigma_{rr} = \hat W'(\lambda)\,d\lambda$, and traction-free faces fix $c$ (see the exercise
# `exercises/rivlin_bending.ipynb`). `bend` handles any incompressible law and piecewise layers. The paper normalised
# M–Δκ at Δκ = 0.28 mm⁻¹ and found α ≈ 2 (neo-Hookean) matched the shape (r² = 0.93); the experimental curve is not
# published as numbers, so only the model family is shown. At these strains (at most 6 %) every α ≤ 10 gives a line
# within 0.01 of straight (M(0.14)/M(0.28) = 0.5), which is why the shape constrains α only weakly; α = 30 departs by
# about 0.09.

# %%
figures.figure_3()
plt.show()
kappa = np.array([0.14, b14.FIG3_MAX_CURVATURE])
ratio = {alpha: models.ogden_normalised_moment(alpha, kappa)[0] for alpha in b14.FIG3_ALPHAS}
for alpha, value in ratio.items():
    print(f"alpha = {alpha:>4}: M(0.14)/M(0.28) = {value:.4f}  (linear: 0.5)")
face_strain = bend([(b14.MODEL_STRIP.thickness, models.trilayer(b14.MU_OUTER)[0][1])], 0.28).lambda_top - 1
print(f"largest fibre strain at Δκ = 0.28: {face_strain:.4f}")
assert face_strain <= 0.06
assert all(abs(value - 0.5) < 0.01 for alpha, value in ratio.items() if alpha <= 10)
assert abs(ratio[30.0] - 0.5 + 0.09) < 0.005

# %% [markdown]
# ## 2. Bonding study (Figs. 4 and 9): what pure bending can and cannot show
#
# With μF = μV = 45 kPa and μS from 1 Pa to 45 kPa the paper found measurable sliding only for μS < 1 kPa. A key
# point for reproducing it: in **pure bending** the bonded layered block deforms *exactly* as Rivlin's solution for
# any μS > 0 — $\lambda^2 = 2aY + c$ holds through all layers, there is no shear and hence no sliding; μS only shifts
# the neutral axis, by less than 0.05 of the thickness. Sliding needs a moment varying along the strip and ends free
# to slip, which the paper's pin-ended end loading (axial load P, M = P·y) provides — computed in Sect. 7. The figure
# brackets the answer: solid lines are bonded (Rivlin), the dashed line is the fully unbonded limit (each layer
# bending alone about its own neutral axis — the saw-tooth of Fig. 4 at μS = 1 Pa).

# %%
figures.figure_4_bounds()
plt.show()
H = b14.MODEL_STRIP.thickness
bonded_axes = []
for mu_s in b14.SPONGIOSA_MODULI:
    sol = bend(models.trilayer(mu_s, H), -0.2)
    bonded_axes.append(sol.normalised_neutral_axis)
    print(f"muS = {mu_s:>6} kPa: bonded NA = {sol.normalised_neutral_axis:.4f},  "
          f"Lambda1 faces = {sol.lambda_bottom:.4f} / {sol.lambda_top:.4f}")
assert max(bonded_axes) - min(bonded_axes) < 0.05

# %% [markdown]
# ## 3. The bimodular bilayer (Table 3, Fig. 8, Table 2)
#
# Fibrosa 60 % / ventricularis 40 %, Eq. 4 with the Table 3 moduli (μ+ in tension, μ− in compression of the
# circumferential fibre). Rivlin gives the neutral axis at the centre of a long strip in pure bending. An independent
# check at small curvature: a linear bimodular beam (plane-strain modulus $E' = 4\mu^\pm$ on either side of the
# neutral axis, in each layer) has its neutral axis where the axial force $\int E'(Y)\,(Y - Y_n)\,dY$ vanishes.

# %%
bilayer = models.bimodular_bilayer()
Hs = b14.SPECIMEN_STRIP.thickness
thicknesses = [h for h, _ in bilayer]
moduli = [b14.TABLE3[name] for name, _ in b14.BILAYER_FRACTIONS]


def linear_beam_neutral_axis(direction: str) -> float:
    """Y_n / H of a linear bimodular beam: zero axial force, tension on the side the bending stretches."""
    def axial_force(yn: float) -> float:
        total, y0 = 0.0, 0.0
        for h, m in zip(thicknesses, moduli, strict=True):
            for lo, hi in ((y0, min(max(yn, y0), y0 + h)), (max(min(yn, y0 + h), y0), y0 + h)):
                below = hi <= yn + 1e-15
                tension = below if direction == "WC" else not below  # WC stretches the bottom face
                mu = m.mu_tension if tension else m.mu_compression
                total += 4 * mu * 0.5 * ((hi - yn) ** 2 - (lo - yn) ** 2)
            y0 += h
        return total
    return brentq(axial_force, 0.0, Hs, xtol=1e-14) / Hs


print(f"{'dk':>5} {'AC Rivlin':>10} {'AC sim (T2)':>12} {'AC exp (T2)':>16} {'WC Rivlin':>10} {'WC sim (T2)':>12} "
      f"{'WC exp (T2)':>16}")
rivlin_table2 = {}
for kappa, row in b14.TABLE2.items():
    ac = models.neutral_axis(bilayer, "AC", kappa)
    wc = models.neutral_axis(bilayer, "WC", kappa)
    rivlin_table2[kappa] = (ac, wc)
    print(f"{kappa:>5} {ac:>10.4f} {row.ac_simulation:>12.4f} {row.ac_experiment:>9.4f}±{row.ac_sd:.4f} {wc:>10.4f} "
          f"{row.wc_simulation:>12.4f} {row.wc_experiment:>9.4f}±{row.wc_sd:.4f}")
print()
fig8 = {}
for d in ("WC", "AC"):
    fig8[d] = (models.neutral_axis(bilayer, d, 0.2), models.neutral_axis(bilayer, d, 1e-4), linear_beam_neutral_axis(d),
               models.tension_modulus_for_neutral_axis(d, b14.FIG8_NEUTRAL_AXIS[d]))
    print(f"Fig. 8 {d}: paper {b14.FIG8_NEUTRAL_AXIS[d]:.2f}, Rivlin {fig8[d][0]:.3f}, Rivlin at Δκ = 1e-4 "
          f"{fig8[d][1]:.4f}, linear beam {fig8[d][2]:.4f}; tension modulus needed for the paper's value: "
          f"{fig8[d][3]:.0f} kPa")
figures.figure_8()
plt.show()

# %% [markdown]
# **Theory and paper disagree, and the direction of the disagreement is informative.**
#
# * *Qualitatively* the Table 3 moduli reproduce Fig. 8: in WC the neutral axis sits near the fibrosa/ventricularis
#   interface (the fibrosa is almost entirely compressed), in AC it moves deep into the fibrosa. The trends with Δκ
#   also have the paper's sign (AC falls, WC rises with curvature, Table 2).
# * *Quantitatively* pure bending with Table 3 gives 0.418 (WC) and 0.717 (AC) at Δκ = 0.2 (the linear beam: 0.403
#   and 0.729), not 0.35 and 0.79. Reaching the paper's centre values would need a tension modulus about twice
#   Table 3's (116 kPa instead of 65 kPa in the ventricularis, 318 kPa instead of 139.5 kPa in the fibrosa). What
#   differs: the paper's model had the specimens' fitted **initial curvature** (κ0, not published), was
#   **end-loaded** (axial load plus moment, not pure bending), and its moduli were fitted at the **edge** where
#   warping pulls the neutral axis to 0.5–0.6 (Table 2), then read at the centre. None of κ0, the loads or the fitted
#   edge profiles are given, so the 0.35/0.79 cannot be recomputed from the printed parameters.
# * The Table 2 "simulation" and "experiment" columns are edge values (Sect. 3.4); the Rivlin centre value is not
#   expected to match them, and it does not.

# %%
for d, (rivlin, small, beam, needed) in fig8.items():
    assert abs(small - beam) < 1e-3  # Rivlin → the linear bimodular beam as Δκ → 0
    assert abs(rivlin - {"WC": 0.418, "AC": 0.717}[d]) < 5e-4 and abs(beam - {"WC": 0.403, "AC": 0.729}[d]) < 5e-4
    assert abs(rivlin - b14.FIG8_NEUTRAL_AXIS[d]) > 0.05  # the disagreement with Fig. 8 discussed above
    layer = {"WC": "ventricularis", "AC": "fibrosa"}[d]
    assert 1.7 < needed / b14.TABLE3[layer].mu_tension < 2.4  # "about twice"
assert round(fig8["WC"][3]) == 116 and round(fig8["AC"][3]) == 318
ac, wc = np.array([rivlin_table2[k] for k in sorted(rivlin_table2)]).T
assert np.all(np.diff(ac) < 0) and np.all(np.diff(wc) > 0)  # AC falls, WC rises with Δκ, as in Table 2
assert all(0.5 <= b14.TABLE2[k].ac_simulation <= 0.65 and 0.45 <= b14.TABLE2[k].wc_simulation <= 0.6
           for k in b14.TABLE2)  # the edge values "0.5-0.6"
assert all(abs(rivlin_table2[k][0] - b14.TABLE2[k].ac_simulation) > 0.05 for k in b14.TABLE2)  # does not match

# %% [markdown]
# ## 4. Transmural stretch extremes (Sect. 3.3)
#
# Measured AC extremes of Λ1 against the Rivlin bilayer (specimen thickness 0.318 mm); the paper's experimental error
# of Λ1 is ±0.0141. At Δκ = 0.1 both extremes and at Δκ = 0.3 the maximum agree within that error; the minimum at
# Δκ = 0.3 is 0.039 lower than measured.

# %%
for kappa, (lmax, lmin) in b14.AC_STRETCH_EXTREMES.items():
    sol = bend(bilayer, kappa)
    print(f"dk = {kappa}: max Lambda1 paper {lmax:.3f} / Rivlin {sol.lambda_top:.4f};  "
          f"min Lambda1 paper {lmin:.3f} / Rivlin {sol.lambda_bottom:.4f}")
    assert abs(sol.lambda_top - lmax) <= b14.LAMBDA_EXPERIMENT_ERROR
    if kappa == 0.1:
        assert abs(sol.lambda_bottom - lmin) <= b14.LAMBDA_EXPERIMENT_ERROR
    else:
        assert abs(lmin - sol.lambda_bottom - 0.039) < 5e-4

# %% [markdown]
# ## 5. Marker strain mapping (Appendix 1, Eqs. 5–7)
#
# `skvalve.analytic.strainmap` fits the quadratic displacement surface of Eq. 5 to tracked markers, differentiates it
# (Eq. 6), and polar-decomposes F (Eq. 7). Here synthetic markers are placed on the edge of the Rivlin bilayer bent AC
# to Δκ = 0.2 mm⁻¹, moved rigidly (rotation 0.3 rad) and perturbed with 0.5 µm noise. The method recovers the rotation
# to 1e-3 rad, the neutral axis to 0.005 of the thickness and Λ1 to 2e-3 — near the paper's tracking resolution of
# 0.001.

# %%
from skvalve.analytic.strainmap import fit_strain_map

rng = np.random.default_rng(7)
sol = bend(bilayer, 0.2)
X = np.column_stack([7.0 + 0.3 * (rng.random(150) - 0.5), Hs * rng.random(150)])
lam = sol.profile(X[:, 1])[0]
r, theta = lam / sol.a, sol.a * (X[:, 0] - 7.0)
x = np.column_stack([7.0 + r * np.sin(theta), sol.neutral_axis + r * np.cos(theta) - 1 / sol.a])
rot = np.array([[np.cos(0.3), np.sin(0.3)], [-np.sin(0.3), np.cos(0.3)]])
x = x @ rot + 0.0005 * rng.standard_normal(x.shape)
smap = fit_strain_map(X, x)
Y = np.linspace(0, Hs, 50)
rotation = float(smap.stretch(7.0, Hs / 2)[1])
marker_axis = smap.neutral_axis(7.0) / Hs
stretch_error = np.max(np.abs(smap.axial_stretch(7.0, Y) - sol.profile(Y)[0]))
print(f"r^2 (u, v) = {smap.r2_u:.4f}, {smap.r2_v:.4f};  rotation recovered {rotation:.4f} rad (exact 0.3)")
print(f"neutral axis: markers {marker_axis:.4f}, exact {sol.normalised_neutral_axis:.4f}")
print(f"max |Lambda1 error| = {stretch_error:.2e}")
fig, ax = plt.subplots(figsize=(6, 3.6))
ax.plot(Y / Hs, sol.profile(Y)[0], "k", label="Rivlin (exact)")
ax.plot(Y / Hs, smap.axial_stretch(7.0, Y), "C3--", label="Eqs. 5–7 from noisy markers")
ax.set(xlabel=figures.THICKNESS_LABEL, ylabel=figures.STRETCH_LABEL)
ax.legend()
plt.show()
assert abs(rotation - 0.3) < 1e-3 and abs(marker_axis - sol.normalised_neutral_axis) < 5e-3 and stretch_error < 2e-3

# %% [markdown]
# ## 6. The finite-element strip (Sect. 2.2)
#
# Now the strip as a finite-element model, built step by step with `skvalve.fem`: plane strain, the tri-layer
# 25/30/45 % with μS = 10 kPa, mixed Q2/Q1 elements (quadratic displacement, linear pressure, as in the paper). Only
# half of a short strip is modelled: mid-length X = 0 is a symmetry plane. Pure bending is imposed by moving the end
# face X = L/2 rigidly, as the cross-section of a circular arc of curvature $a$: the end face turns by $aL/2$ about a
# pivot on the neutral fibre, whose height is found so that the end face carries no axial force (a secant iteration
# starting from Rivlin's neutral axis).

# %%
import skfem

from skvalve.fem import Solid

layers = models.trilayer(10.0, H)  # [(thickness, law)], bottom up: ventricularis, spongiosa, fibrosa
half_length, curvature = 1.2, 0.2  # mm, 1/mm
rivlin = bend(layers, curvature)


def strip_mesh(nx: int, ny_per_layer: int) -> tuple[skfem.MeshQuad, np.ndarray]:
    """Quadrilaterals on 0 ≤ X ≤ L/2, 0 ≤ Y ≤ H with the layer interfaces on element edges; layer of each element."""
    cuts = np.cumsum([0.0] + [h for h, _ in layers])
    y = np.concatenate([[0.0]] + [np.linspace(y0, y1, ny_per_layer + 1)[1:]
                                  for y0, y1 in zip(cuts[:-1], cuts[1:], strict=True)])
    mesh = skfem.MeshQuad.init_tensor(np.linspace(0.0, half_length, nx + 1), y)
    return mesh, np.searchsorted(cuts[1:-1], mesh.p[1, mesh.t].mean(axis=0))


def end_rotation(pivot: float):
    """Displacement of the end face: rigid rotation by a·t·L/2 (clockwise) carrying the pivot along the arc."""

    def value(X: np.ndarray, t: float) -> np.ndarray:
        a = curvature * t
        out = np.zeros_like(X)
        if a == 0.0:
            return out
        phi, centre = a * half_length, np.array([[half_length], [pivot]])
        R = np.array([[np.cos(phi), np.sin(phi)], [-np.sin(phi), np.cos(phi)]])
        d = X[:2] - centre
        out[:2] = np.array([[np.sin(phi) / a - half_length], [(np.cos(phi) - 1.0) / a]]) + R @ d - d
        return out

    return value


on_end = lambda X: np.isclose(X[0], half_length)
on_symmetry_plane = lambda X: np.isclose(X[0], 0.0)
phi = curvature * half_length  # final rotation of the end face
force_scale = 4 * b14.MU_OUTER * curvature * H**2  # axial force of a fibre stress E'·a·H over the thickness


def solve_strip(mesh: skfem.MeshQuad, layer_of_element: np.ndarray, pivot: float):
    solid = Solid(mesh, [law for _, law in layers], formulation="up", regions=layer_of_element)
    solid.add_dirichlet(on_symmetry_plane, 0.0, components=[0])
    solid.add_dirichlet(on_end, end_rotation(pivot), components=[0, 1])
    result = solid.solve(steps=2, rtol=1e-8, progress=False)
    axial = float(result.reaction(on_end)[:2] @ [np.cos(phi), -np.sin(phi)])  # along the deformed strip axis
    return result, axial


def bend_strip(nx: int, ny_per_layer: int) -> dict:
    mesh, layer_of_element = strip_mesh(nx, ny_per_layer)
    # pure bending: find the pivot height at which the end face carries no axial force (secant iteration,
    # starting from Rivlin's neutral axis)
    pivots, forces = [rivlin.neutral_axis, rivlin.neutral_axis + 0.02 * H], []
    for _ in range(6):
        result, axial = solve_strip(mesh, layer_of_element, pivots[len(forces)])
        forces.append(axial)
        if abs(axial) < 1e-6 * force_scale:
            break
        if len(forces) >= 2:
            pivots.append(pivots[-1] - forces[-1] * (pivots[-1] - pivots[-2]) / (forces[-1] - forces[-2]))
    pivot = pivots[len(forces) - 1]
    # measure at mid-length: Λ1 through the thickness, curvature from λ² = 2aY + c, neutral axis where U11 = 1
    Y = np.linspace(0.0, H, 41)
    U = result.evaluate("stretch_tensor", np.array([np.zeros_like(Y), Y]))
    centre_curvature = 0.5 * np.polyfit(Y, np.hypot(U[0, 0], U[0, 1]) ** 2, 1)[0]
    u11 = lambda y: float(result.evaluate("stretch_tensor", np.array([[0.0], [y]]))[0, 0, 0]) - 1.0
    pivot_now = [np.sin(phi) / curvature, pivot + (np.cos(phi) - 1) / curvature]
    return {"elements": mesh.nelements, "curvature": centre_curvature, "neutral_axis": brentq(u11, 0.0, H, xtol=1e-12),
            "moment": -float(result.reaction_moment(on_end, pivot_now)), "axial_force": forces[-1],
            "solves": len(forces), "pivot": pivot}


studies = {mesh: bend_strip(*mesh) for mesh in ((12, 1), (24, 2))}
errors = []
for fe in studies.values():
    reference = bend(layers, fe["curvature"])  # Rivlin at the curvature the FE has at mid-length
    errors.append((fe["moment"] / reference.moment - 1, fe["neutral_axis"] / reference.neutral_axis - 1))
    print(f"{fe['elements']:>4} elements, {fe['solves']} solves: pivot {fe['pivot'] / H:.4f} H (Rivlin NA "
          f"{rivlin.neutral_axis / H:.4f} H), mid-length Δκ = {fe['curvature']:.4f}, "
          f"M/Rivlin − 1 = {errors[-1][0]:+.2%}, NA/Rivlin − 1 = {errors[-1][1]:+.2%}")
orders = np.log2(np.abs(np.array(errors[0]) / np.array(errors[1])))
print(f"observed order of the moment and neutral-axis errors: {orders[0]:.2f}, {orders[1]:.2f}")
assert all(abs(m) < 0.025 and abs(na) < 0.02 for m, na in errors)  # "to about 2 %"
assert np.all((0.5 < orders) & (orders < 1.5))  # first order, see below
assert all(abs(fe["axial_force"]) < 1e-6 * force_scale for fe in studies.values())


# %% [markdown]
# The FE agrees with Rivlin at the curvature it has at mid-length (the rigid end face disturbs the strip next to
# it), to about 2 % on the coarsest mesh. The error
# falls at first order, not second: the continuous Q1 pressure cannot jump at the layer interfaces where the modulus
# jumps (for a homogeneous strip it is second order, see `tests/test_buchanan2014.py`).
# `skvalve.papers.buchanan2014.fe.fe_pure_bending` wraps this model for the reproduction table and the finer meshes of
# `skvalve reproduce buchanan2014 --full`.
#
# *3D warping (Fig. 7).* A quarter of the specimen-sized strip (2.8 mm wide, 0.318 mm thick; hexahedra, the same
# Q2/Q1 mixed formulation) shows the anticlastic distortion of a rectangular section: Λ1 at the free edge differs from
# Λ1 at the centre, and the edge neutral axis moves. The paper estimated ≈ 0.02 for this edge–centre difference (its
# Fig. 7 used the bimodular model); here the unimodular tri-layer is used on a coarse mesh (the effect is geometric and
# appears without bimodularity); the result stays within the tolerance 0.01 that the paper's "≈" allows.

# %%
warp = b14_fe.warping_study(nx=6, ny=1, nz=4)
figures.figure_7(warp)
plt.show()
for d in ("WC", "AC"):
    w = warp[d]
    difference = np.max(np.abs(w["edge"] - w["centre"]))
    print(f"{d}: {w['elements']} hexes, max |Lambda1 edge - centre| = {difference:.4f} (paper ~0.02); "
          f"NA/H centre {w['neutral_axis'] / warp['H']:.3f}, edge {w['neutral_axis_edge'] / warp['H']:.3f}")
    assert abs(difference - b14.FIG7_WARPING) <= 0.01

# %% [markdown]
# ## 7. End loading and interlayer sliding (Sect. 2.2, Fig. 2b; Figs. 4 and 9)
#
# The paper loaded its model strip through **pins at both ends** with an axial load P at one pin; the centre section
# then carries M = P·y (Eq. 2, y = deflection from the pin-to-pin line) *and* M varies along the strip, so the layers'
# axial forces change with x and the spongiosa must transmit shear. A soft spongiosa shears, the outer layers slip
# and Λ1 jumps across the spongiosa.
#
# *Model* (`skvalve.papers.buchanan2014.sliding.fe_end_loading`, built like the strip above): plane strain,
# 14 × 0.4 mm, tri-layer 25/30/45 %, outer layers 45 kPa, mixed Q2/Q1, symmetry at mid-length. Each end is glued into
# a stiff sleeve (last 0.5 mm, 100 × 45 kPa), like the cyanoacrylate-glued steel sleeves of the experiment; the pin
# is the end-face node nearest mid-thickness, held vertically and pushed towards the centre (displacement control). A
# small transverse force at the centre selects the buckling direction (WC: the ventricularis face is stretched) and
# is back to zero at 1 % of the loading, so every reported state carries the pin load only. To keep this chapter
# short the mesh is coarse (14 elements along the half strip, one per layer) and the pin is pushed only 1.5 mm, far
# enough for Δκ = 0.2; `skvalve reproduce buchanan2014` runs the finer default mesh and `--full` the whole sweep.
#
# *Sliding measure* S: lines fitted to Λ1 in the ventricularis and in the fibrosa, extrapolated to the spongiosa
# mid-plane, differ by J; S = J(μS) − J(45 kPa). Sliding is *measurable* when |S| exceeds the experimental Λ1 error
# 0.0141 (Sect. 3.4) — the quantity that decides what Fig. 10 could have seen.

# %%
coarse = {"nx": 14, "ny_per_layer": 1, "steps": 15, "shortening": 1.5}  # up to Δκ ≈ 0.22
study = b14_sl.sliding_study((0.1, 1.0, b14.MU_OUTER), (0.2,), **coarse)
figures.figure_4_9_end_loading(study)
plt.show()
q = b14_sl.at_curvature(study["runs"][b14.MU_OUTER], 0.2)
euler = [np.pi**2 * 4 * b14.MU_OUTER * H**3 / 12 / length**2 for length in (14.0, 13.0)]
print(f"bonded strip, dk = 0.2: P = {q['P']:.4f} kPa mm, y = {abs(q['y']):.3f} mm; M = P*y = {q['M_Py']:.5f}, "
      f"symmetry-plane reactions {q['M_reaction']:.5f}, integral of sigma11 {q['M_stress']:.5f} kPa mm^2")
print(f"Euler load pi^2 E'I / L^2 (L = 14 / 13 mm): {euler[0]:.4f} / {euler[1]:.4f}")
for mu in study["moduli"]:
    s = study["sliding"][(mu, 0.2)]
    print(f"muS = {1000 * mu:>7g} Pa ({100 * mu / b14.MU_OUTER:6.2f} % of outer): S = {s:+.4f}   "
          f"measurable (> {b14.LAMBDA_EXPERIMENT_ERROR}): {abs(s) > b14.LAMBDA_EXPERIMENT_ERROR}")
threshold = b14_sl.sliding_threshold(study, 0.2)
print(f"threshold muS for |S| = {b14.LAMBDA_EXPERIMENT_ERROR}: {1000 * threshold:.0f} Pa (paper: measurable sliding "
      f"only for muS < {1000 * b14.SLIDING_SPONGIOSA_LIMIT:.0f} Pa)")

# %% [markdown]
# **Reading the numbers beside the paper's.**
#
# * M = P·y at the centre equals the moment of the symmetry-plane reactions (equilibrium, to the Newton tolerance)
#   and the stress resultant ∫σ11 y dy to 1 %; P lies between the Euler loads of a 14 mm and a 13 mm strip (the
#   sleeves shorten the free length), as an elastica at these deflections should.
# * |S| > 0.0141 at μS = 100 Pa and below it at 1 kPa: the threshold of measurable sliding lies between 100 Pa and
#   1 kPa at Δκ = 0.2, so **the paper's "< 1 kPa" is reproduced**.
# * S grows in proportion to Δκ in the full sweep (the paper: "greater bending simply created greater sliding"), and
#   at 10 kPa (22 % of the outer modulus) |S| stays far below both limits, so "**bonded when μS ≥ 25 %**" holds; the
#   numbers are in the reproduction table (`skvalve reproduce buchanan2014 --full`, `docs/buchanan2014.md`).

# %%
assert abs(q["M_Py"] / q["M_reaction"] - 1) < 1e-4 and abs(q["M_stress"] / q["M_Py"] - 1) < 0.01
assert euler[0] < q["P"] < euler[1]
assert abs(study["sliding"][(0.1, 0.2)]) > b14.LAMBDA_EXPERIMENT_ERROR > abs(study["sliding"][(1.0, 0.2)])
assert 0.1 < threshold < b14.SLIDING_SPONGIOSA_LIMIT

# %% [markdown]
# ## 8. The reproduction table
#
# `skvalve reproduce buchanan2014` prints this table (with the FE studies on the default meshes). Rows marked
# `[exact]` compare the solver with closed forms (the exact value stands in the paper column) and must agree; the
# others compare with the paper, and a disagreement says why.

# %%
table = rows.analytic_rows() + rows.closed_form_rows() + rows.warping_rows(warp)
print(format_table(table))
assert not any(row.status.fails_strict for row in table)
