"""A progress bar for FE² solves (a solver callback): load steps, Newton iterations, RVE throughput."""

from __future__ import annotations

from tqdm.auto import tqdm

from .material import RVEMaterial

__all__ = ["FE2Progress"]


class FE2Progress:
    """tqdm bar advanced at every converged step, showing load factor, Newton iterations and RVE solves/s.

    Parameters
    ----------
    material : the RVE material (its ``solves`` and ``solve_seconds`` counters give the throughput).
    total : expected number of converged steps (None if unknown).
    disable : no output (tests, quiet runs).
    """

    def __init__(self, material: RVEMaterial, total: int | None = None, disable: bool = False,
                 desc: str = "FE2 steps") -> None:
        self.material = material
        self.steps = 0  # converged steps seen
        self.iterations = 0  # Newton iterations of the solve so far
        self.bar = tqdm(total=total, disable=disable, desc=desc, leave=False)

    def __call__(self, event) -> None:
        if event.step == 0:
            return
        rate = self.material.solves / self.material.solve_seconds if self.material.solve_seconds > 0 else 0.0
        self.steps += 1
        self.iterations = event.result.iterations
        self.bar.update(1)
        self.bar.set_postfix(t=f"{event.load_factor:.3g}", newton=self.iterations,
                             rve_per_s=f"{rate:.0f}")

    def close(self) -> None:
        self.bar.close()
