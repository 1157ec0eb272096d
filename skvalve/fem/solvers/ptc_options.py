"""Controls of pseudo-transient continuation (:func:`skvalve.fem.solvers.ptc.pseudo_transient`): one options class, its
every field documented and validated."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

__all__ = ["PseudoTransientOptions"]


@dataclass
class PseudoTransientOptions:
    r"""Controls of :func:`pseudo_transient` (units of the problem).

    Attributes
    ----------
    damping : float
        :math:`c`, the coefficient of :math:`M/\Delta\tau` (force per volume per length per unit pseudo-time).
    stiffness_damping : float or callable
        :math:`\beta`, a damping :math:`\beta\,|\mathrm{diag}\,K_{ff}|/\Delta\tau` proportional to the tangent's
        diagonal (Rayleigh's stiffness-proportional part): it damps most where the material is stiffest, which is where
        an element driven far into an exponential law loses stability. Zero: off; a callable: a function of the load
        factor.
    held_stiffness_damping : float or None
        :math:`\beta` once the load is held at ``end`` (``None``: ``stiffness_damping`` throughout). The
        stiffness-proportional part damps a soft mode (a leaflet's bending, whose eigenvalue is far below its nodes'
        diagonal stiffness) far more than a stiff one, so at the held load, where nothing is left to overshoot
        into an exponential law along a moving load, it holds the soft modes back most; the trust regions and the
        local damping still catch the steps that overshoot.
    first_step, min_step : float
        The first :math:`\Delta\tau`, and the smallest before giving up.
    max_load_step : float
        The largest :math:`\Delta\tau` while the load factor still moves (the load path's resolution).
    growth : float
        The largest SER growth of :math:`\Delta\tau` per step once the load is held.
    held_growth : float
        The smallest growth of :math:`\Delta\tau` per accepted step once the load is held (1: pure SER). SER alone
        keeps :math:`\Delta\tau` where a residual that does not fall (a slow, damped mode of a soft structure) leaves
        it; a growth on every accepted step fades the damping anyway, the trust regions and local damping catching the
        steps that then overshoot.
    load_growth : float
        The growth of :math:`\Delta\tau` per accepted step while the load moves (back towards ``max_load_step``
        after a cut; a gentle value wastes fewer rejected steps on a path whose trust regions bind).
    fill : float or None
        Grow :math:`\Delta\tau` no further than to fill this fraction of the trust regions (``max_increment``,
        ``max_strain_increment``), predicted from the share of them the last accepted step used (a step that
        follows the load or a damped flow is about proportional to :math:`\Delta\tau`): the next
        :math:`\Delta\tau` is at most :math:`\Delta\tau\,\text{fill}/\text{used}`, so a path whose trust
        regions bind stops proposing steps that break them (each rejection costs a factorisation). ``None``: off.
    max_increment : float or None
        Trust region: the largest nodal displacement change in one step (length); ``None``: off.
    max_strain_increment : float or None
        Trust region on the ``edges`` given to :func:`pseudo_transient`: the largest change of an edge's tensile
        stretch :math:`\max(\ell/L, 1)` in one step (``None``: off; slack cables and shortening edges move freely).
        Exponential laws (collagenous leaflets, chordae) need it: a linearised step taken from the flat toe of such a
        law into its steep part overshoots by orders of magnitude, however small the nodal displacement.
    blow_up : float
        Reject a step whose residual exceeds this multiple of the reference (the larger of the residual before the
        step and the linearised one with the new prescribed values).
    accept_jumps_below : float
        A step shorter than this is accepted even when its residual grows past ``blow_up`` (the trust regions and the
        inversion test still apply): a growth that no shorter step removes is a discontinuity of the problem (a
        contact pair that enters at a finite overlap), not an overshoot, and the steps after it resolve it.
    local_damping, max_local_damping, local_decay : float
        When nodes break a trust region, or carry most of a residual that grew past ``blow_up``, their whole damping
        (mass and stiffness-proportional parts) is multiplied by ``local_damping`` (at most ``max_local_damping``
        times in all) and the step is retried only a little shorter, instead of cutting the pseudo-time step for the
        whole problem by the factor the worst node needs (a local pseudo-time step, the implicit analogue of an
        explicit code's selective mass scaling; the equilibrium does not depend on the damping); after each accepted
        step the factors fall by ``local_decay`` towards 1. 1: off.
    rtol, atol : float
        Converged, once the load is at ``end``, when the free residual is at most the larger of ``atol`` and
        ``rtol`` times the larger of the reactions' and the external forces' norms.
    max_steps : int
        The most accepted pseudo-steps.
    stall_steps : int
        Give up (``ConvergenceError``, the best held state kept) when, with the load held at ``end``, the residual
        has not fallen below half its value of ``stall_steps`` steps before (0: never).
    solver : str or None
        Sparse backend (:func:`skvalve.fem.solvers.linsolve.solver_name`).
    """

    damping: float = 1e-4
    stiffness_damping: float | Callable[[float], float] = 0.0
    held_stiffness_damping: float | None = None
    first_step: float = 1e-3
    min_step: float = 1e-9
    max_load_step: float = 0.01
    growth: float = 2.0
    held_growth: float = 1.0
    load_growth: float = 1.25
    fill: float | None = None
    max_increment: float | None = 0.5
    max_strain_increment: float | None = 0.05
    blow_up: float = 10.0
    accept_jumps_below: float = 1e-6
    local_damping: float = 1.0
    max_local_damping: float = 1e4
    local_decay: float = 0.5
    rtol: float = 1e-6
    atol: float = 0.0
    max_steps: int = 5000
    stall_steps: int = 200
    solver: str | None = None

    def __post_init__(self) -> None:
        positive = ("damping", "first_step", "min_step", "max_load_step", "growth", "held_growth", "load_growth",
                    "blow_up", "rtol",
                    "local_damping", "max_local_damping")
        if not (math.isfinite(self.accept_jumps_below) and self.accept_jumps_below >= 0):
            raise ValueError("PseudoTransientOptions.accept_jumps_below must be finite and >= 0; "
                             f"got {self.accept_jumps_below!r}")
        for name in positive:
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise ValueError(f"PseudoTransientOptions.{name} must be a positive finite number; got {value!r}")
        if self.max_increment is not None and not (math.isfinite(self.max_increment) and self.max_increment > 0):
            raise ValueError("PseudoTransientOptions.max_increment must be None or positive; "
                             f"got {self.max_increment!r}")
        if self.max_strain_increment is not None and not (math.isfinite(self.max_strain_increment)
                                                          and self.max_strain_increment > 0):
            raise ValueError("PseudoTransientOptions.max_strain_increment must be None or positive; "
                             f"got {self.max_strain_increment!r}")
        if not callable(self.stiffness_damping) and not (math.isfinite(self.stiffness_damping)
                                                         and self.stiffness_damping >= 0):
            raise ValueError("PseudoTransientOptions.stiffness_damping must be finite and >= 0; "
                             f"got {self.stiffness_damping!r}")
        if self.held_stiffness_damping is not None and not (math.isfinite(self.held_stiffness_damping)
                                                            and self.held_stiffness_damping >= 0):
            raise ValueError("PseudoTransientOptions.held_stiffness_damping must be None or finite and >= 0; "
                             f"got {self.held_stiffness_damping!r}")
        if self.fill is not None and not (isinstance(self.fill, int | float) and 0.0 < self.fill <= 1.0):
            raise ValueError(f"PseudoTransientOptions.fill must be None or lie in (0, 1]; got {self.fill!r}")
        if not (math.isfinite(self.atol) and self.atol >= 0):
            raise ValueError(f"PseudoTransientOptions.atol must be finite and >= 0; got {self.atol!r}")
        if not 0.0 < self.local_decay <= 1.0:
            raise ValueError(f"PseudoTransientOptions.local_decay must lie in (0, 1]; got {self.local_decay!r}")
        if min(self.growth, self.load_growth, self.held_growth) < 1.0 or self.held_growth > self.growth:
            raise ValueError("PseudoTransientOptions: need 1 <= held_growth <= growth and load_growth >= 1; got "
                             f"growth={self.growth!r}, held_growth={self.held_growth!r}, "
                             f"load_growth={self.load_growth!r}")
