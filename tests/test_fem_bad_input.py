"""Bad input to the FE layer gets a named error, never a silently wrong answer (issue 12 items 1–2).

Each test here failed on the code before the fix: tangled hexes ran and gave wrong reactions, a body
without supports was reported as an inverted element, interior facets took a pressure, NaN options
were accepted, and an output failure lost the converged steps.
"""

import numpy as np
import pytest
import skfem

from skvalve.fem import (
    ConvergenceError,
    OutputError,
    Problem,
    SingularSystemError,
    Solid,
    Space,
    TangledMeshError,
    solve,
)
from skvalve.fem.meshes import box
from skvalve.materials import NeoHookean

LAW = NeoHookean(1.0, 2.0)


def _node_outside_neighbours():
    mesh = box(2)
    p = mesh.p.copy()
    p[:, 13] = [1.4, 0.5, 0.5]  # the centre node pushed outside the block
    return skfem.MeshHex(p, mesh.t)


def test_node_pushed_outside_its_neighbours_is_named():
    mesh = _node_outside_neighbours()
    with pytest.raises(TangledMeshError, match="tangled element") as info:
        Solid(mesh, LAW)
    moved = np.flatnonzero((mesh.t == 13).any(axis=0))
    assert set(info.value.elements) <= set(moved) and info.value.elements.size > 0


def test_scrambled_hex_node_order_is_named():
    mesh = box(2)
    t = mesh.t.copy()
    t[[0, 1], 5] = t[[1, 0], 5]  # swap two nodes of element 5
    with pytest.raises(TangledMeshError) as info:
        Space(skfem.MeshHex(mesh.p, t))
    assert info.value.elements.tolist() == [5]


def test_consistently_oriented_meshes_pass():
    Space(box(2))
    Space(box(2, kind="tet"))
    mirrored = box(2)
    Space(skfem.MeshHex(mirrored.p * np.array([[-1.0], [1.0], [1.0]]), mirrored.t))  # all negative: consistent


def test_body_without_supports_is_reported_as_singular_not_inverted():
    solid = Solid(box(2), LAW)
    solid.add_pressure("right", 0.1)
    with pytest.raises(SingularSystemError, match="supports"):
        solid.solve(steps=2, progress=False, solver="scipy")


def test_partly_supported_body_is_singular():
    solid = Solid(box(2), LAW)
    solid.add_dirichlet("left", 0.0, components=[0])  # sliding freely in y and z, rotating about x
    solid.add_nodal_force(lambda X: X[0] == 1.0, [0.01, 0.0, 0.0])
    with pytest.raises(SingularSystemError):
        solid.solve(steps=1, progress=False, solver="scipy")


def test_pressure_on_interior_facets_is_rejected():
    solid = Solid(box(2), LAW)
    interior = np.setdiff1d(np.arange(solid.mesh.nfacets), solid.mesh.boundary_facets())[:3]
    with pytest.raises(ValueError, match="interior facet"):
        solid.add_pressure(interior, 1.0)


@pytest.mark.parametrize(("option", "value"), [
    ("rtol", float("nan")), ("rtol", -1.0), ("energy_tol", float("nan")), ("max_line_search", -1),
    ("max_iter", 0), ("max_cutbacks", 1.5), ("t0", float("nan")),
])
def test_bad_newton_options_are_named(option, value):
    solid = Solid(box(1), LAW).add_dirichlet("left", 0.0)
    with pytest.raises(ValueError, match=option):
        solid.solve(steps=1, progress=False, **{option: value})


def test_output_failure_keeps_the_converged_steps():
    solid = Solid(box(1), LAW).add_dirichlet("left", 0.0).add_dirichlet("right", 0.1, components=[0])

    def disk_full(event):
        if event.step == 2:
            raise OSError(28, "No space left on device")

    with pytest.raises(OutputError, match="load step 2") as info:
        solid.solve(steps=3, progress=False, callbacks=[disk_full])
    assert info.value.last_converged.load_factors == pytest.approx([0.0, 1 / 3, 2 / 3])


def test_failed_attempts_rewind_and_converged_steps_commit():
    """The problem's stateful terms see commit after each converged step and rewind after each failure."""

    class Recorder:
        load_dependent = False
        symmetric = True
        name = "recorder"

        def __init__(self):
            self.events = []

        def connectivity(self):
            return []

        def assemble(self, u, t, tangent, step):
            from skvalve.fem import Contribution

            return Contribution()

        def commit(self):
            self.events.append("commit")

        def rewind(self):
            self.events.append("rewind")

    solid = Solid(box(1), LAW).add_dirichlet("left", 0.0).add_dirichlet("right", 2.5, components=[0])
    recorder = solid.add_term(Recorder())
    with pytest.raises(ConvergenceError):
        solid.solve(steps=[0.02, 1.0], max_iter=3, max_cutbacks=1, progress=False)
    assert recorder.events == ["commit", "rewind", "rewind"]


def test_resume_from_a_converged_state_gives_the_same_result():
    def build():
        return Solid(box(2), LAW).add_dirichlet("left", 0.0).add_dirichlet("right", 0.3, components=[0])

    full = build().solve(steps=4, progress=False, rtol=1e-12)
    first = build().solve(steps=[0.25, 0.5], progress=False, rtol=1e-12)
    resumed = build().solve(steps=4, progress=False, rtol=1e-12, u0=first.u(), t0=0.5)
    assert resumed.load_factors == [0.5, 0.75, 1.0]
    assert np.abs(resumed.u() - full.u()).max() <= 1e-12 * np.abs(full.u()).max()


def test_problem_rejects_objects_that_are_not_terms():
    with pytest.raises(TypeError, match="assemble"):
        Problem(Space(box(1)), [object()])


def test_checkpoint_resume_reproduces_an_uninterrupted_run(tmp_path):
    """Stop after step 2 of 4 (a callback raising, as an interrupt would), resume from disk, compare."""
    from skvalve.io.checkpoint import Checkpoint, resume

    def build():
        return Solid(box(2), LAW).add_dirichlet("left", 0.0).add_dirichlet("right", 0.3, components=[0])

    full = build().solve(steps=4, progress=False, rtol=1e-12)

    def interrupt(event):
        if event.step == 2:
            raise RuntimeError("interrupted")

    with pytest.raises(OutputError):
        build().solve(steps=4, progress=False, rtol=1e-12, callbacks=[Checkpoint(tmp_path), interrupt])
    problem = build()
    t0, u0 = resume(problem, tmp_path)
    assert t0 == 0.5
    resumed = problem.solve(steps=4, progress=False, rtol=1e-12, t0=t0, u0=u0, callbacks=[Checkpoint(tmp_path)])
    assert np.abs(resumed.u() - full.u()).max() <= 1e-12 * np.abs(full.u()).max()
    assert sorted(p.name for p in tmp_path.glob("step_*.npz")) == [f"step_0000{k}.npz" for k in (1, 2, 3, 4)]
    (tmp_path / "step_00004.npz").write_bytes(b"truncated")
    with pytest.raises(ValueError, match="step_00004.npz is damaged"):
        resume(build(), tmp_path)


def test_fully_prescribed_problem_gives_its_reactions():
    """Every dof prescribed (a homogeneous stretch): no Newton iteration, reactions = closed form."""
    solid = Solid(box(1), LAW)
    solid.add_dirichlet(lambda X: np.ones(X.shape[1], dtype=bool), lambda X, t: np.array([0.2 * t * X[0],
                                                                                       0 * X[1], 0 * X[2]]))
    result = solid.solve(steps=2, progress=False)
    assert result.iterations == 0
    force = result.reaction(lambda X: X[0] == 1.0)[0]
    # confined (lateral stretch 1) uniaxial stretch: P11 of the law at F = diag(1.2, 1, 1) on a unit face
    F = np.diag([1.2, 1.0, 1.0])
    assert force == pytest.approx(LAW.pk1(F)[0, 0], rel=1e-12)


def test_vertices_without_cells_keep_their_coordinates():
    """A vertex used by no cell (a truss-only node) is a dof at its own place, not at the origin."""
    mesh = box(1)
    p = np.hstack([[[2.0], [3.0], [4.0]], mesh.p])  # scikit-fem counts max(t) + 1 vertices: put it first
    space = Space(skfem.MeshHex(p, mesh.t + 1))
    assert np.allclose(space.dof_coordinates[:, 0], [2.0, 3.0, 4.0])
    assert np.allclose(space.dof_coordinates[:, 1:9], mesh.p)


def test_absolute_floor_decides_unloaded_steps():
    """A stage with no load (pressure switched on at t > 0.5): relative residuals are round-off / round-off;
    atol decides those steps, and the loaded ones still meet rtol."""
    def build():
        return Solid(box(2), LAW).add_dirichlet("left", 0.0).add_pressure("right", lambda t: 0.05 * max(t - 0.5, 0))

    with pytest.raises(ValueError, match="atol"):
        build().solve(steps=4, progress=False, atol=-1.0)
    result = build().solve(steps=[0.25, 0.5, 0.75, 1.0], progress=False, atol=1e-10)
    assert result.load_factors == [0.0, 0.25, 0.5, 0.75, 1.0]
    assert np.abs(result.u(2)).max() == 0.0 and np.abs(result.u()).max() > 1e-3


def test_line_search_refuses_a_step_that_blows_the_residual_up():
    """A term whose reported tangent is 1000x too soft sends Newton far off: even the shortest line-search step
    makes |R| grow ~1e5-fold (finite), which must end in a cut-back (finally ConvergenceError naming it), never an
    accepted state (before the guard, the shortest step was taken whatever |R| became)."""
    from skvalve.fem import Blocks, Contribution

    class WrongTangent:
        load_dependent, symmetric, supports, name = True, True, True, "cubic springs"

        def __init__(self, space):
            self.dofs = np.arange(space.n_dofs).reshape(-1, 1)

        def connectivity(self):
            return [self.dofs]

        def assemble(self, u, t, tangent, step):
            internal = u + u**3 - t  # exact tangent 1 + 3u^2; reported 1000x too small
            k = 1e-3 * (1.0 + 3.0 * u**2)[:, None, None] if tangent else None
            return Contribution(internal=internal, external=None, blocks=[Blocks(self.dofs, k)])

        def commit(self):
            pass

        def rewind(self):
            pass

    space = Space(box(1))
    problem = Problem(space, [WrongTangent(space)])
    with pytest.raises(ConvergenceError, match="residual grows") as info:
        solve(problem, steps=1, progress=False, max_cutbacks=2, max_iter=3)
    assert info.value.last_converged.load_factors == [0.0]
