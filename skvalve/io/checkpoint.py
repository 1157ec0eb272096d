"""Checkpoints of a solve: every converged load step written atomically, and resumed to the same result.

A :class:`Checkpoint` is a solver callback. After each converged step it writes
``<folder>/step_<k>.npz`` holding the load factor, the solution vector and the committed state of
every stateful term (:meth:`skvalve.fem.Problem.state`, e.g. warm-started RVEs), under a temporary
name then renamed, so an interrupted run leaves only whole files. :func:`latest` finds the last
one and :func:`resume` restores the terms and returns ``(t0, u0)`` for
:func:`skvalve.fem.solve`::

    checkpoint = Checkpoint("run/")
    t0, u0 = resume(problem, "run/")                 # (0.0, None) when there is nothing to resume
    solve(problem, steps, t0=t0, u0=u0, callbacks=[checkpoint])
"""

from __future__ import annotations

import re
import zipfile
from pathlib import Path

import numpy as np

from ..fem.problem import Problem
from ..fem.solvers.newton import StepEvent
from .files import replace_atomically

__all__ = ["Checkpoint", "latest", "resume"]

_NAME = re.compile(r"^step_(\d{5})\.npz$")


class Checkpoint:
    """Solver callback writing ``step_<k>.npz`` (load factor, solution, term states) per converged step.

    Parameters
    ----------
    folder : created if missing; steps already there from an earlier run are kept.
    every : write every ``every``-th step (the last converged step is always the newest file).
    """

    def __init__(self, folder, every: int = 1) -> None:
        if isinstance(every, bool) or not isinstance(every, int) or every < 1:
            raise ValueError(f"every must be a positive integer; got {every!r}")
        self.folder = Path(folder)
        if self.folder.exists() and not self.folder.is_dir():
            raise ValueError(f"checkpoint folder {self.folder} exists and is not a folder")
        self.folder.mkdir(parents=True, exist_ok=True)
        self.every = every
        self._offset = _last_index(self.folder)

    def __call__(self, event: StepEvent) -> None:
        if event.step == 0 or event.step % self.every:
            return
        index = self._offset + event.step
        path = self.folder / f"step_{index:05d}.npz"
        arrays = {f"term/{key}": value for key, value in event.problem.state().items()}
        replace_atomically(path, lambda p: np.savez(p, load_factor=np.float64(event.load_factor), u=event.u, **arrays))


def _last_index(folder: Path) -> int:
    indices = [int(m.group(1)) for p in folder.iterdir() if (m := _NAME.match(p.name))] if folder.is_dir() else []
    return max(indices, default=0)


def latest(folder) -> Path | None:
    """The newest checkpoint file in ``folder``, or None."""
    folder = Path(folder)
    index = _last_index(folder)
    return folder / f"step_{index:05d}.npz" if index else None


def resume(problem: Problem, folder) -> tuple[float, np.ndarray | None]:
    """Restore the newest checkpoint's term states into ``problem``; ``(t0, u0)`` for ``solve``.

    Returns ``(0.0, None)`` when the folder holds no checkpoint. A damaged file raises ``ValueError``
    naming it.
    """
    path = latest(folder)
    if path is None:
        return 0.0, None
    try:
        with np.load(path, allow_pickle=False) as data:
            t0, u0 = float(data["load_factor"]), np.array(data["u"])
            states = {key[len("term/"):]: np.array(data[key]) for key in data.files if key.startswith("term/")}
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as err:
        raise ValueError(f"checkpoint {path} is damaged ({type(err).__name__}: {err}); delete it to resume "
                         "from the one before") from err
    if u0.shape != (problem.space.n_dofs,):
        raise ValueError(f"checkpoint {path} holds {u0.size} dofs; the problem has {problem.space.n_dofs}")
    problem.restore(states)
    return t0, u0
