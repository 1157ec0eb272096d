"""The trust region's records (:func:`skvalve.fem.solvers.trust_region.trust_region`): its options, its controller
between steps (what a resumed run needs), what a callback sees after each step, and the result."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..problem import Problem

__all__ = ["TrustRegionControl", "TrustRegionOptions", "TrustRegionResult", "TrustRegionStep"]


@dataclass
class TrustRegionOptions:
    r"""Controls of :func:`trust_region` (units of the problem).

    Attributes
    ----------
    radius, max_radius, min_radius : float
        The first, largest and smallest trust-region radius :math:`\Delta`: the most any node may move in one step.
        Below ``min_radius`` the solver gives up.
    max_strain_increment : float or None
        Largest change of a watched edge's tensile stretch :math:`\max(\ell/L, 1)` in one step (the step is scaled
        down to it; ``None``: off).
    shift, min_shift, max_shift : float
        The first shift :math:`\alpha` (relative to the tangent's diagonal), the value below which it becomes 0, and
        the value above which the solver gives up.
    project : bool
        Project each element block of the symmetric terms (solids, trusses), and an extra sparse matrix (contact),
        onto its positive semidefinite part in :math:`H` (the model :math:`m` of the steps that are not Newton's):
        the term's own projection where it gives one (an IPC barrier's, stencil by stencil), else each connected
        block's (:func:`~skvalve.fem.solvers.trust_steps.step_matrix`).
    project_terms : tuple of str
        Names of terms (``Term.name``) whose element blocks are projected even when ``project`` is off: e.g. the
        chordae of a valve, whose compressed struts (an input truss carries its law in compression) give the
        tangent a negative lateral stiffness :math:`-N/\ell` per strut that an unprojected step matrix must
        out-shift, shortening every other mode's step with it, while the leaflets keep the soft curvature that
        projection would drop; or the IPC contact (the valve's settle stage), whose stencils projected one by one
        keep a coapting patch's sliding directions soft.
    shift_terms : tuple of str
        Names of terms whose indefinite element blocks (for a sparse matrix such as contact's: connected blocks) are
        shifted by the smallest multiple of the identity that makes each semidefinite (:func:`shift_psd`): a local
        Levenberg shift where one term's negative curvature (e.g. a contact pair near a free edge) would otherwise set
        the global shift that damps every soft mode of the structure. For the IPC barrier a shifted patch stiffens
        its sliding too: on the 1.0 diseased valve's held load, 5.5e-3 after 25 settle steps against 7.8e-8 after
        34 with the stencils projected (``project_terms``).
    eta : float
        Accept a step when :math:`\rho = \Delta\Pi/m \ge \eta`.
    local_shift, local_decay : float
        A rejected step's energy change splits over the nodes (each node's share of the work integral); the fewest
        nodes that carry 90 % of its rise get a shift of their own, at least ``local_shift`` and ten times their last
        one (a local Levenberg-Marquardt term :math:`s_i D_i` added to :math:`H + \alpha D`; the equilibrium does not
        depend on it), and the radius is cut only to 0.7 of the step; after each accepted step the local shifts fall
        by ``local_decay`` (below ``min_shift``: zero). ``local_shift`` 0: off (every rejection halves the radius).
    newton_below, newton_decrease, newton_backtracks : float, float, int
        Below the relative residual ``newton_below`` (0: never) a step is first tried as Newton's with the full
        tangent, scaled into ``max_radius``, and kept when the residual norm falls below ``newton_decrease`` times its
        value (module docstring). Where it does not, the try backtracks along the same direction: the fraction
        :math:`a` = 1/2, 1/4, ... (at most ``newton_backtracks`` halvings) is kept when the norm falls below
        :math:`1 - a\,(1 - \text{newton\_decrease})` of its value (a sufficient decrease proportional to the
        fraction). Newton's direction lowers the residual norm for any regular tangent, symmetric or not, so a short
        enough fraction always does; a follower pressure on an open surface has no potential, and the energy steps can
        circle its equilibrium (released energy each step, the residual not falling). A failed try is rewound and not
        repeated until the residual has halved or ten steps have passed.
    fit_radius : int
        A step longer than the radius is shortened by raising the shift :math:`\alpha` (at most this many
        refactorisations, :func:`fitted_shift`) before what is left is scaled down; 0: scaled at once. Scaling keeps
        the direction, which soft modes dominate (a slack chord's branch point, a free leaflet edge: Newton's step
        moves them millimetres), so a step held to the radius corrects the stiff part of the residual only by the same
        small fraction; the shifted step (Levenberg-Marquardt, Moré 1978) solves the stiff part and moves along the
        soft modes only as far as the radius allows.
    shift_scaling : str
        :math:`D` of the shift :math:`\alpha D`: ``"diagonal"``, the tangent's diagonal (Marquardt's scaling), or
        ``"uniform"``, its median times the identity (Levenberg's, the scaling of the trust region itself, which bounds
        nodal motions in length units). Under a diagonal shift every mode is damped in proportion to its own
        stiffness, so a shift that an indefinite or very soft direction needs shortens the stiff part of the step by
        as much; under a uniform one only the modes softer than :math:`\alpha D` are damped.
    rtol, atol : float
        Converged when :math:`\lVert R_f\rVert \le \max(\text{atol}, \text{rtol}\,f_\text{ref})`.
    reference : float or None
        :math:`f_\text{ref}` of the relative residual (``rtol``, ``newton_below``): a force the caller knows better
        (e.g. a valve's end load) than the default, the reactions' and loads' norm.
    max_steps : int
        The most accepted steps.
    stall_fraction, stall_window : float, int
        With ``stall_fraction`` > 0 the relaxation returns unconverged, with ``stalled`` set, once the energy drop
        averaged over the last ``stall_window`` accepted steps is below ``stall_fraction`` of its average over all of
        them (scale-free: the same test for any valve or load). It ends a stage of a staged relaxation (trust-region
        runs one after the other, each from the state the one before ended at), e.g. projected steps that carry a
        structure a long way down its energy and no longer do once it is there.
    solver : str or None
        Sparse backend (:func:`skvalve.fem.solvers.linsolve.solver_name`); PARDISO reports the inertia, SuperLU does not
        (then :math:`\alpha` rises only when a step is not a descent direction of the model).
    """

    radius: float = 0.25
    max_radius: float = 2.0
    min_radius: float = 1e-6
    max_strain_increment: float | None = 0.2
    shift: float = 1e-3
    min_shift: float = 1e-8
    max_shift: float = 1e8
    project: bool = True
    project_terms: tuple[str, ...] = ()
    shift_terms: tuple[str, ...] = ()
    eta: float = 0.01
    local_shift: float = 0.1
    local_decay: float = 0.5
    newton_below: float = 0.0
    newton_decrease: float = 0.5
    newton_backtracks: int = 5
    fit_radius: int = 0
    shift_scaling: str = "diagonal"
    rtol: float = 1e-6
    atol: float = 0.0
    reference: float | None = None
    max_steps: int = 500
    stall_fraction: float = 0.0
    stall_window: int = 20
    solver: str | None = None

    def __post_init__(self) -> None:
        for name in ("radius", "max_radius", "min_radius", "shift", "min_shift", "max_shift", "rtol"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise ValueError(f"TrustRegionOptions.{name} must be a positive finite number; got {value!r}")
        if not self.min_radius <= self.radius <= self.max_radius:
            raise ValueError("TrustRegionOptions: need min_radius <= radius <= max_radius; got "
                             f"{self.min_radius!r}, {self.radius!r}, {self.max_radius!r}")
        if not self.min_shift < self.max_shift:
            raise ValueError(f"TrustRegionOptions: need min_shift < max_shift; got {self.min_shift!r}, "
                             f"{self.max_shift!r}")
        if not (math.isfinite(self.local_shift) and self.local_shift >= 0.0) or not 0.0 < self.local_decay <= 1.0:
            raise ValueError("TrustRegionOptions: need local_shift >= 0 and 0 < local_decay <= 1; got "
                             f"{self.local_shift!r}, {self.local_decay!r}")
        if not (math.isfinite(self.newton_below) and self.newton_below >= 0.0) or not 0.0 < self.newton_decrease < 1.0:
            raise ValueError("TrustRegionOptions: need newton_below >= 0 and 0 < newton_decrease < 1; got "
                             f"{self.newton_below!r}, {self.newton_decrease!r}")
        if not (isinstance(self.newton_backtracks, int) and self.newton_backtracks >= 0):
            raise ValueError(f"TrustRegionOptions.newton_backtracks must be an integer >= 0; got "
                             f"{self.newton_backtracks!r}")
        if self.shift_scaling not in ("diagonal", "uniform"):
            raise ValueError(f"TrustRegionOptions.shift_scaling must be 'diagonal' or 'uniform'; got "
                             f"{self.shift_scaling!r}")
        if not (isinstance(self.fit_radius, int) and self.fit_radius >= 0):
            raise ValueError(f"TrustRegionOptions.fit_radius must be an integer >= 0; got {self.fit_radius!r}")
        if not 0.0 < self.eta < 0.25:
            raise ValueError(f"TrustRegionOptions.eta must lie in (0, 0.25); got {self.eta!r}")
        if self.max_strain_increment is not None and not (math.isfinite(self.max_strain_increment)
                                                          and self.max_strain_increment > 0):
            raise ValueError("TrustRegionOptions.max_strain_increment must be None or positive; "
                             f"got {self.max_strain_increment!r}")
        if self.reference is not None and not (math.isfinite(self.reference) and self.reference > 0):
            raise ValueError(f"TrustRegionOptions.reference must be None or a positive force; got {self.reference!r}")
        if not (math.isfinite(self.atol) and self.atol >= 0):
            raise ValueError(f"TrustRegionOptions.atol must be finite and >= 0; got {self.atol!r}")
        if not (isinstance(self.max_steps, int) and self.max_steps > 0):
            raise ValueError(f"TrustRegionOptions.max_steps must be a positive integer; got {self.max_steps!r}")
        if not (0.0 <= self.stall_fraction < 1.0) or not (isinstance(self.stall_window, int) and self.stall_window > 1):
            raise ValueError("TrustRegionOptions: need 0 <= stall_fraction < 1 and an integer stall_window > 1; got "
                             f"{self.stall_fraction!r}, {self.stall_window!r}")


@dataclass
class TrustRegionControl:
    """The controller between two steps: all a run resumed from an accepted step needs to repeat the uninterrupted one
    (pass it as ``control`` to :func:`trust_region`; each :class:`TrustRegionStep` carries a copy).

    ``steps`` accepted steps and ``attempts`` tried ones so far, the radius, the shift and the last positive shift
    (``fallback``), the local shifts (one per dof), when a failed Newton try may be repeated, and the accepted steps'
    energy changes (the stall test)."""

    radius: float
    shift: float
    fallback: float
    local: np.ndarray
    steps: int = 0
    attempts: int = 0
    retry_below: float = math.inf
    retry_after: int = 0
    energy_changes: list[float] = field(default_factory=list)

    @classmethod
    def start(cls, options: TrustRegionOptions, n_dofs: int) -> TrustRegionControl:
        """The controller of a fresh run: the options' first radius and shift, no local shifts."""
        return cls(options.radius, options.shift, options.shift, np.zeros(n_dofs))

    def copy(self) -> TrustRegionControl:
        return replace(self, local=self.local.copy(), energy_changes=list(self.energy_changes))


@dataclass
class TrustRegionStep:
    """What a callback receives after each accepted step (the fields a pseudo-transient callback reads, too)."""

    problem: Problem
    step: int
    load_factor: float
    u: np.ndarray
    residual_norm: float
    relative_residual: float
    energy_change: float
    ratio: float
    shift: float
    radius: float
    control: TrustRegionControl | None = None  # the controller after this step (resume from it)
    largest: float = math.nan  # the step's largest nodal motion


@dataclass
class TrustRegionResult:
    """The accepted steps (residual norms, energy changes, ratios, shifts, largest nodal motions) and the last state.

    ``newton_tries``: full-tangent Newton steps tried below ``newton_below`` (``newton_steps`` counts the kept ones, and
    those of the trust region itself); ``negative_eigenvalues``: of :math:`K_s` at the converged state (PARDISO's
    inertia; None where not measured). A kept Newton try's energy change is the trapezoidal work of the residual."""

    u: np.ndarray
    load_factor: float
    residuals: list[float] = field(default_factory=list)
    energy_changes: list[float] = field(default_factory=list)
    ratios: list[float] = field(default_factory=list)
    shifts: list[float] = field(default_factory=list)
    largest_increments: list[float] = field(default_factory=list)
    newton_steps: int = 0
    newton_tries: int = 0
    rejected: int = 0
    factorizations: int = 0
    radius_fits: int = 0
    converged: bool = False
    stalled: bool = False
    relative_residual: float = math.inf
    negative_eigenvalues: int | None = None
    timings: dict[str, float] = field(default_factory=lambda: {"assembly": 0.0, "solve": 0.0})
