"""Law parameters given as strings, None, booleans or arrays fail at construction, naming the parameter.

Before, ``NeoHookean("2.0", 1)`` built and failed later inside ``cauchy`` (issue 12 item 6).
"""

import numpy as np
import pytest

from skvalve.materials import BimodularNeoHookean, IncompressibleNeoHookean, LeeSacks, NeoHookean, Ogden
from skvalve.materials.base import VolumetricEnergy, check_scalar
from skvalve.materials.neo_hookean import lame_from_shear_poisson

BAD = ["2.0", None, True, np.array([1.0, 2.0]), [1.0], b"1"]

CASES = {
    "NeoHookean.mu": lambda v: NeoHookean(v, 1.0),
    "NeoHookean.lmbda": lambda v: NeoHookean(1.0, v),
    "from_shear_poisson.G": lambda v: NeoHookean.from_shear_poisson(v, 0.3),
    "from_shear_poisson.nu": lambda v: NeoHookean.from_shear_poisson(1.0, v),
    "IncompressibleNeoHookean.mu": lambda v: IncompressibleNeoHookean(v),
    "LeeSacks.c0": lambda v: LeeSacks(v, 0.1, 1.0),
    "LeeSacks.c1": lambda v: LeeSacks(1.0, v, 1.0),
    "LeeSacks.c2": lambda v: LeeSacks(1.0, 0.1, v),
    "LeeSacks.D": lambda v: LeeSacks(1.0, 0.1, 1.0, v),
    "BimodularNeoHookean.mu_tension": lambda v: BimodularNeoHookean(v, 1.0, [1, 0, 0]),
    "BimodularNeoHookean.mu_compression": lambda v: BimodularNeoHookean(1.0, v, [1, 0, 0]),
    "BimodularNeoHookean.smoothing": lambda v: BimodularNeoHookean(1.0, 1.0, [1, 0, 0], smoothing=v),
    "VolumetricEnergy.modulus": lambda v: VolumetricEnergy(v),
}
NAMES = {
    "from_shear_poisson.G": "G",
    "from_shear_poisson.nu": "nu",
}


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("bad", BAD, ids=["str", "None", "bool", "array", "list", "bytes"])
def test_scalar_parameters_reject_non_numbers(case, bad):
    name = NAMES.get(case, case.split(".")[1])
    if case == "LeeSacks.D" and bad is None:
        assert LeeSacks(1.0, 0.1, 1.0, None).incompressible  # None means "incompressible" here
        return
    with pytest.raises(TypeError, match=f"parameter {name} must be a real number"):
        CASES[case](bad)


@pytest.mark.parametrize("bad", ["2.0", None, ["1.0"], [1.0, None]])
def test_ogden_sequences_reject_non_numbers(bad):
    with pytest.raises(TypeError, match="parameter mu"):
        Ogden(bad, (2.0,) if not isinstance(bad, list) or len(bad) == 1 else (2.0, 3.0))
    with pytest.raises(TypeError, match="parameter alpha"):
        Ogden((1.0,) if not isinstance(bad, list) or len(bad) == 1 else (1.0, 1.0), bad)


def test_numbers_of_every_kind_are_still_accepted():
    assert check_scalar("x", np.float32(2.5)) == 2.5 and check_scalar("x", np.int64(3)) == 3.0
    assert check_scalar("x", np.array(1.5)) == 1.5  # a 0-d array is a number
    assert NeoHookean(2, 1).mu == 2
    assert lame_from_shear_poisson(np.float64(1.0), 0.25) == (1.0, 1.0)
    F = np.eye(3)[:, :, None] * 1.1
    assert np.all(np.isfinite(NeoHookean(2.0, 1.0).cauchy(F)))
