"""The shipped Texas TriValve inputs as implicit models: counts, chordae reduction, no zero-stiffness direction in
the chordae, pressure facets and conditions. Skips when the data (../shared/data) are absent. Data: Mathur et al.
2022, Texas TriValve 1.0 (CC BY-NC-SA 4.0) and 1.1 (CC BY 4.0)."""

import numpy as np
import pytest

from skvalve.fem import FollowerPressure
from skvalve.fem.elements.truss import LawAssignment
from skvalve.io.abaqus import HEX_FACE_NODES, read_model, trivalve_inputs
from skvalve.materials.uniaxial import TensionOnly
from skvalve.valve.chordae import collapse_chains, tangent_on_free_nodes
from skvalve.valve.extrude import hex_corner_jacobians
from skvalve.valve.model import valve_model

INPUTS = trivalve_inputs()
pytestmark = pytest.mark.skipif(not INPUTS, reason="Texas TriValve inputs not found (../shared/data)")

#: hexes expected from the files' element counts (C3D8R as they are; S4R x 4 layers)
EXPECTED_HEXES = {"1.0-diseased": 18920, "1.0-annuloplasty": 18920, "1.0-clipping": 18920,
                  "1.1-healthy": 4 * 8283, "1.1-diseased": 4 * 10520}


@pytest.fixture(scope="module")
def models():
    out = {}
    for key, path in INPUTS.items():
        abaqus = read_model(path)
        out[key] = (abaqus, valve_model(abaqus, partial=key == "1.0-clipping"))  # clip arms: step 1 alone
    return out


def _truss_bars(abaqus):
    return np.vstack([b.connectivity for b in abaqus.element_blocks if b.element_type == "T3D2"])


@pytest.mark.parametrize("key", sorted(EXPECTED_HEXES))
def test_shipped_input_becomes_a_model(models, key):
    if key not in models:
        pytest.skip(f"{key} not present")
    abaqus, model = models[key]
    counts = model.counts()
    assert counts["hexes"] == EXPECTED_HEXES[key]
    assert counts["pressure_facets"] > 0 and counts["constrained_dofs"] > 0 and counts["cables"] > 0
    # every bar is in exactly one cable or dropped; the cables' rest lengths are the chains' path lengths
    red = model.chordae.reduction
    bars = red.bars
    assert np.array_equal(np.unique(bars, axis=0), np.unique(_truss_bars(abaqus), axis=0))
    used = np.concatenate(red.chains + [red.dropped_bars])
    assert np.array_equal(np.sort(used), np.arange(bars.shape[0]))
    length = np.linalg.norm(abaqus.nodes[bars[:, 1]] - abaqus.nodes[bars[:, 0]], axis=1)
    assert np.allclose(red.rest_length, [length[c].sum() for c in red.chains])
    assert np.all(red.straight_length <= red.rest_length * (1 + 1e-12))
    # cable ends sit on the mesh vertices of the same points
    X = model.mesh.p.T
    ends = model.chordae.ends
    assert np.allclose(X[ends], abaqus.nodes[red.ends], atol=1e-12)
    # positively oriented hexes (scikit-fem checks its own Jacobians)
    abaqus_order = model.mesh.t.T[:, np.argsort([0, 4, 3, 1, 7, 5, 2, 6])]
    assert np.all(hex_corner_jacobians(X, abaqus_order) > 0)


def test_diseased_chordae_reduction_matches_the_issue_counts(models):
    """1.0 diseased: 1160 free chord nodes, 1092 of them between exactly two bars, one dangling."""
    if "1.0-diseased" not in models:
        pytest.skip("1.0 diseased not present")
    abaqus, model = models["1.0-diseased"]
    red = model.chordae.reduction
    assert red.interior_nodes.size == 1092
    assert red.dropped_nodes.size == 1 and red.dropped_bars.size == 1
    assert abaqus.node_labels[red.dropped_nodes[0]] == 25514
    assert model.pressures[0].facets.size == 4730  # S1 faces of the three outer element sets
    amp = model.conditions[-1].amplitude
    assert amp is not None and amp(0.5) == 1.0  # papillary tips: Amp-2 reaches its value at t = 0.5


@pytest.mark.parametrize("key", ["1.0-diseased", "1.1-healthy"])
def test_collapsed_chordae_have_no_zero_stiffness_direction(models, key):
    """Smallest eigenvalue of the chordae tangent on the nodes only chordae hold (leaflet and papillary nodes held):
    zero before the collapse (every two-bar node has two transverse mechanisms), positive after."""
    if key not in models:
        pytest.skip(f"{key} not present")
    abaqus, model = models[key]
    ch = model.chordae
    X = model.mesh.p.T
    held = np.arange(model.mesh.t.min(), X.shape[0])  # leaflet vertices (chordae-only vertices come first)
    papillary = np.unique(np.concatenate([c.vertices for c in model.conditions]))
    fixed = np.union1d(held, papillary)
    cables = LawAssignment([TensionOnly(law, 1e-6, 0.01) for law in ch.laws], ch.law_index, ch.ends.shape[0])
    slack = np.minimum(ch.reduction.straight_length / ch.rest_length, 1.0)
    K, free = tangent_on_free_nodes(ch.ends, X, ch.rest_length, ch.area, cables, fixed, slack)
    eigenvalues = np.linalg.eigvalsh(K)
    assert free.size > 0 and eigenvalues[0] > 1e-12 * eigenvalues[-1]
    # before: the uncollapsed bars; a transverse direction at a two-bar node has zero stiffness
    bars = _truss_bars(abaqus)
    solid = np.unique(np.concatenate([b.connectivity.ravel() for b in abaqus.element_blocks
                                      if b.element_type != "T3D2"]))
    anchored = np.union1d(solid, np.concatenate([bc.nodes for s in abaqus.steps for bc in s.boundary_conditions]))
    red = collapse_chains(bars, abaqus.nodes, anchored)
    node = int(red.interior_nodes[0])
    incident = np.flatnonzero((bars == node).any(axis=1))
    laws = LawAssignment(ch.laws[0], None, incident.size)
    rest = np.linalg.norm(abaqus.nodes[bars[incident, 1]] - abaqus.nodes[bars[incident, 0]], axis=1)
    K0, free0 = tangent_on_free_nodes(bars[incident], abaqus.nodes, rest, np.full(incident.size, 0.3), laws,
                                      np.setdiff1d(np.unique(bars[incident]), [node]))
    assert free0.tolist() == [node]
    assert np.linalg.eigvalsh(K0)[0] <= 1e-12 * np.abs(K0).max()


def test_compression_gives_the_single_trusses_their_plain_law(models):
    """``problem(compression=True)``: the cables that are one input truss (slack stretch 1) carry the Ogden law of
    their group at a shortening (as the input's T3D2 trusses with *Hyperelastic, OGDEN do), the collapsed chains only
    their slack spring; without it every cable is slack when shortened."""
    if "1.0-diseased" not in models:
        pytest.skip("1.0 diseased not present")
    _, model = models["1.0-diseased"]
    ch = model.chordae
    single = np.abs(ch.slack_stretch - 1.0) <= 1e-9
    assert 0 < single.sum() < single.size
    stretch = 0.9 * np.minimum(ch.slack_stretch, 1.0)  # every cable shortened below its force-free stretch
    for compression in (True, False):
        truss = next(t for t in model.problem(insertion="node", compression=compression).terms
                     if type(t).__name__ == "Truss")
        P, _ = truss.laws.evaluate(stretch, truss.slack_stretch)
        law_P = np.array([ch.laws[k].nominal_stress(np.array([s]))[0][0] for k, s in zip(ch.law_index, stretch,
                                                                                          strict=True)])
        if compression:
            assert np.allclose(P[single], law_P[single], rtol=1e-12)
        assert np.all(np.abs(P[~single if compression else slice(None)]) < 1e-3 * np.abs(law_P).max())


def test_diseased_pressure_and_conditions_follow_the_input(models):
    """Total follower-pressure force in the reference state = -p(t) x the vector area of the Abaqus faces (outward
    by the right-hand rule of the face definitions), with p(t) = 0.00567 MPa x SMOOTH STEP(0.5, 1.5); the papillary
    tips are at -14 mm x SMOOTH STEP(0, 0.5)."""
    if "1.0-diseased" not in models:
        pytest.skip("1.0 diseased not present")
    abaqus, model = models["1.0-diseased"]
    problem = model.problem()
    pressure = next(term for term in problem.terms if isinstance(term, FollowerPressure))
    u = np.zeros(problem.space.n_dofs)
    total = pressure.assemble(u, 1.5, False).external.reshape(-1, 3).sum(axis=0)
    connectivity = {int(i): row for b in abaqus.element_blocks for i, row in zip(b.indices, b.connectivity,
                                                                                  strict=True)}
    area = np.zeros(3)
    for group in abaqus.surface("Leaflet_Surfaces_Outer").faces:
        for e in group.elements:
            x = abaqus.nodes[connectivity[int(e)][list(HEX_FACE_NODES[group.face])]]
            area += 0.5 * np.cross(x[2] - x[0], x[3] - x[1])
    assert np.allclose(total, -0.00567 * area, rtol=1e-10, atol=1e-12 * np.abs(area).max())
    half = 0.5 ** 3 * (10 - 15 * 0.5 + 6 * 0.25)  # the smooth step half-way
    assert np.allclose(pressure.assemble(u, 1.0, False).external.reshape(-1, 3).sum(axis=0), -0.00567 * half * area)
    assert np.allclose(pressure.assemble(u, 0.5, False).external, 0.0)
    dofs, values = problem.constrained(0.25)
    tips = np.flatnonzero(np.isclose(values, -14.0 * half))
    assert tips.size == 32 and np.all(dofs[tips] % 3 == 2)
    assert np.allclose(np.delete(values, tips), 0.0)
