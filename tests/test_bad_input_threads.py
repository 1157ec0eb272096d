"""The same FE solve gives bitwise the same displacements with 1 and 2 threads (issue 35 item 2).

The compiled assembly kernels write each element's forces and matrix to its own slots and the scatter into the
global arrays is serial, so the assembly never depended on the thread count. The sparse solve did: MKL PARDISO
takes its thread count from the OpenMP runtime that numba shares (``NUMBA_NUM_THREADS``), and its parallel
factorisation sums in an order that depends on it. Before the fix the two runs below differed in the last bits
(and PARDISO was not even reproducible run to run on larger systems); PARDISO now runs in its conditional
numerical reproducibility mode with a fixed thread count for the reduction order (``iparm[33]``).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import pytest

SOLVE = textwrap.dedent("""
    import hashlib, json, warnings
    import numpy as np
    import numba
    from skvalve.fem import Solid, solve
    from skvalve.fem.meshes import box, distort
    from skvalve.materials import LeeSacks

    warnings.simplefilter("ignore")
    mesh = distort(box(5), amount=0.2, seed=3)
    solid = Solid(mesh, LeeSacks(1.0, 0.5, 2.0, D=0.1))
    for axis in range(3):
        solid.add_dirichlet(lambda X, a=axis: X[a] == 0.0, 0.0, components=[axis])
    solid.add_dirichlet(lambda X: X[0] == 1.0, lambda X, t: np.stack([0.2 * t + 0.05 * t * X[1], 0 * X[1], 0 * X[1]]),
                        components=[0])
    result = solve(solid, steps=3, progress=False)
    digest = lambda a: hashlib.sha256(np.ascontiguousarray(a).tobytes()).hexdigest()
    state = np.sin(np.arange(solid.space.n_dofs)) * 0.01  # the assembly alone, at a state of the test's choosing
    residual, tangent = solid.assemble(state, 0.5, tangent=True)
    print(json.dumps({"threads": numba.get_num_threads(), "solver": result.solver, "u": digest(result.u()),
                      "assembled": [digest(residual), digest(solid.tangent_matrix(tangent).data)],
                      "residual": digest(result.residuals[-1]), "iterations": result.iterations,
                      "max_u": float(np.abs(result.u()).max())}))
""")


def _run(threads: int) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("MKL_NUM_THREADS", "OMP_NUM_THREADS")}
    env["NUMBA_NUM_THREADS"] = str(threads)
    done = subprocess.run([sys.executable, "-c", SOLVE], env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="needs two cores for two threads")
def test_one_and_two_threads_give_bitwise_the_same_solution():
    one, two = _run(1), _run(2)
    assert (one["threads"], two["threads"]) == (1, 2)
    assert one["max_u"] > 0.1 and one["iterations"] >= 3
    assert one == {**two, "threads": 1}, f"1 thread: {one}\n2 threads: {two}"
