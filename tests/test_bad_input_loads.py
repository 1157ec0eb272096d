"""A load or prescribed value that is not finite at some load factor is named where it is evaluated (issue 35 item 3).

Before the fix a nodal force, pressure or prescribed displacement returning NaN made the residual NaN (or raised a
``ValueError`` that the Newton driver takes for a failed step) and the solve ended, after 6 cut-backs, as a singular
tangent or a convergence failure. Now :class:`~skvalve.fem.errors.LoadError` names the load, its term and the load
factor, at once, from the Newton, pseudo-transient and trust-region drivers alike.
"""

from __future__ import annotations

import numpy as np
import pytest

from skvalve.fem import Solid, solve
from skvalve.fem.errors import LoadError, SolverError
from skvalve.fem.meshes import box
from skvalve.fem.solvers.damping import lumped_volume
from skvalve.fem.solvers.ptc import pseudo_transient
from skvalve.fem.solvers.trust_region import trust_region
from skvalve.materials import NeoHookean

LAW = NeoHookean(1.0, 2.0)


def _supported() -> Solid:
    solid = Solid(box(2), LAW)
    for axis in range(3):
        solid.add_dirichlet(lambda X, a=axis: X[a] == 0.0, 0.0, components=[axis])
    return solid


def force_failing_late(t: float) -> np.ndarray:
    return np.array([0.01 * t, np.nan if t > 0.5 else 0.0, 0.0])


def pressure_failing_late(t: float) -> float:
    return np.inf if t > 0.5 else -0.01 * t


def test_nan_nodal_force_is_named_with_its_load_factor():
    solid = _supported()
    solid.add_nodal_force(lambda X: X[0] == 1.0, force_failing_late)
    with pytest.raises(LoadError, match=r"nodal force.*force_failing_late.*load factor 0\.75") as info:
        solve(solid, steps=4, progress=False)
    assert info.value.term == "nodal force" and info.value.load_factor == 0.75
    assert isinstance(info.value, SolverError) and not isinstance(info.value, ValueError)


def test_infinite_pressure_is_named_with_its_load_factor():
    solid = _supported()
    solid.add_pressure("right", pressure_failing_late)
    with pytest.raises(LoadError, match=r"follower pressure.*pressure_failing_late.*load factor 0\.75"):
        solve(solid, steps=4, progress=False)


def test_a_pressure_that_is_not_a_number_is_named():
    solid = _supported()
    solid.add_pressure("right", lambda t: "0.1")
    with pytest.raises(LoadError, match=r"follower pressure.*<lambda>.*load factor 0\b.*'0\.1'"):
        solve(solid, steps=2, progress=False)


def test_a_pressure_array_is_not_taken_for_a_number():
    solid = _supported()
    solid.add_pressure("right", lambda t: np.array([0.1, 0.2]) * t)
    with pytest.raises(LoadError, match=r"follower pressure.*one number"):
        solve(solid, steps=2, progress=False)


def test_nan_prescribed_displacement_is_named():
    solid = _supported()
    solid.add_dirichlet(lambda X: X[0] == 1.0, lambda X, t: np.where(t > 0.5, np.nan, 0.1 * t) + 0 * X,
                        components=[0])
    with pytest.raises(LoadError, match=r"prescribed displacement.*component.*0.*load factor 0\.75"):
        solve(solid, steps=4, progress=False)


def test_pseudo_transient_and_trust_region_raise_it_too():
    solid = _supported()
    solid.add_pressure("right", pressure_failing_late)
    with pytest.raises(LoadError, match="pressure_failing_late"):
        pseudo_transient(solid, lumped_volume(solid.space), 1.0, progress=False)
    with pytest.raises(LoadError, match=r"load factor 1\b"):
        trust_region(solid, 1.0, np.zeros(solid.space.n_dofs), progress=False)


def test_finite_callable_loads_still_solve():
    solid = _supported()
    solid.add_pressure("right", lambda t: -0.01 * t)
    solid.add_nodal_force(lambda X: X[0] == 1.0, lambda t: [0.0, 0.001 * t, 0.0])
    result = solve(solid, steps=2, progress=False)
    assert np.all(np.isfinite(result.u())) and result.u().any()
