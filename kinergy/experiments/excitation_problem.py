"""Excitation design problem: Fourier-series trajectories to optimise for identifying the base
parameters.

A finite Fourier series per joint (nursing eq 22) is shaped so that the stacked regressor of the
identification is as well conditioned as the robot's limits allow (nursing section 4.2, eq 23,
Tables 5-6). An :class:`ExcitationProblem` puts together

- the parametrisation (:mod:`kinergy.experiments.excitation_series`): zero speed and acceleration
  at the start pose and at every period boundary for any value of the unknowns;
- the criterion (:mod:`kinergy.experiments.excitation_regression`): the condition number or
  D-optimality of the column-scaled regression matrix of the full identification, with its
  gradient;
- the limits (:mod:`kinergy.experiments.excitation_limits`): joint range, speed, acceleration and
  a floor, as constraints with exact Jacobians and as a final check at every ``dt`` sample.

:func:`excitation_problem` builds it; :func:`kinergy.experiments.excitation_design.
design_excitation` solves it.

References: nursing eqs 22-23 and Tables 5-6; J. Swevers, C. Ganseman, D. B. Tukel, J. de
Schutter, H. Van Brussel, "Optimal robot excitation and identification", IEEE T-RA 13(5), 1997;
M. Gautier, W. Khalil, "Exciting trajectories for the identification of base inertial
parameters of robots", IJRR 11(4), 1992.

Examples
--------
>>> import kinergy
>>> from kinergy.experiments.excitation_design import design_excitation
>>> from kinergy.experiments.excitation_limits import excitation_limits
>>> ur5e = kinergy.load_robot("ur5e")
>>> limits = excitation_limits(ur5e, floor=0.1)  # every frame from the elbow on 10 cm up
>>> problem = excitation_problem(ur5e, limits=limits, harmonics=3, samples=60)
>>> best = design_excitation(problem, starts=1, maxiter=20)
>>> bool(best.margins["speed"] >= 0 and best.margins["floor"] >= 0)
True
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from kinergy import checks
from kinergy.arrays import Array
from kinergy.errors import KinergyError
from kinergy.experiments.excitation_limits import (
    ExcitationLimits,
    constraints,
    constraints_jacobian,
    excitation_limits,
    fit_into_limits,
)
from kinergy.experiments.excitation_regression import (
    Criterion,
    ExcitationRegression,
    criterion,
    excitation_regression,
    scaled_condition,
)
from kinergy.experiments.excitation_series import (
    FourierParametrisation,
    SeriesGrid,
    sample_times,
)
from kinergy.model.robot import Robot
from kinergy.trajectory.fourier import fourier_motion
from kinergy.trajectory.motion import CONTROLLER_DT, Motion

__all__ = ["ExcitationProblem", "excitation_problem"]


@dataclass(frozen=True, eq=False)
class ExcitationProblem:
    """An excitation design problem: the parametrisation, limits and criterion (module docstring).

    Built by :func:`excitation_problem`; its methods are the callables the optimiser uses. The
    unknowns ``z`` (``(2L - 2) * n``) are ``Z`` (2L - 2, n) flattened row by row, and the
    coefficients of joint ``i`` are ``[a_i; b_i] = E Z[:, i]``.

    Attributes
    ----------
    robot : Robot
    series : FourierParametrisation
        Harmonics ``L``, period ``T`` (s) and start pose.
    limits : ExcitationLimits
    criterion : Criterion
    regression : ExcitationRegression
        The columns of the regression matrix ``W``.
    grid : SeriesGrid
        One period's grid the criterion is evaluated on (``samples`` points).
    constraint_grid : SeriesGrid
        The grid the constraints are evaluated on (twice as fine).
    sample_grid : SeriesGrid
        Every ``dt`` sample of one period: the final check.
    dt : float
        Sample time of the motion and of the final check, s.
    """

    robot: Robot
    series: FourierParametrisation
    limits: ExcitationLimits
    criterion: Criterion
    regression: ExcitationRegression = field(repr=False)
    grid: SeriesGrid = field(repr=False)
    constraint_grid: SeriesGrid = field(repr=False)
    sample_grid: SeriesGrid = field(repr=False)
    dt: float
    _last: dict[bytes, float] = field(default_factory=dict, init=False, repr=False)

    @property
    def period(self) -> float:
        """``T``, s."""
        return self.series.period

    @property
    def base_frequency(self) -> float:
        """``w_f = 2 pi / T``, rad/s."""
        return self.series.base_frequency

    @property
    def size(self) -> int:
        """Number of unknowns, ``(2L - 2) n``."""
        return self.series.free * self.robot.n

    @property
    def columns(self) -> int:
        """Columns of ``W``: link base parameters plus the independent drive columns."""
        return self.regression.size

    # -- coefficients and states ------------------------------------------------------------

    def coefficients(self, z: ArrayLike) -> tuple[Array, Array, Array]:
        """``q0`` (n,), ``a`` and ``b`` (n, L) of nursing eq 22 for unknowns ``z``."""
        return self.series.coefficients(z)

    def states(self, z: ArrayLike) -> tuple[Array, Array, Array]:
        """``q``, ``qd``, ``qdd`` on the grid ``t``, (samples, n) each."""
        return self.grid.states(self.limits.start, self.series.unknowns(z))

    def motion(self, z: ArrayLike) -> Motion:
        """One period of the excitation sampled every ``dt`` (:func:`fourier_motion`)."""
        q0, a, b = self.coefficients(z)
        return fourier_motion(q0, a, b, base_frequency=self.base_frequency, dt=self.dt)

    # -- criterion --------------------------------------------------------------------------

    def objective(self, z: ArrayLike) -> tuple[float, Array]:
        """The criterion (log condition number or ``-log det``) and its gradient, shape (size,)."""
        zz = self.series.unknowns(z)
        value, sens, cond = self.regression.criterion_gradient(*self.states(zz), self.criterion)
        self._last.clear()
        self._last[zz.tobytes()] = cond
        grad = sum(basis.T @ s for basis, s in zip(self.grid.bases, sens, strict=True))
        return value, np.asarray(grad).reshape(-1)

    def condition(self, z: ArrayLike, *, exact: bool = True) -> float:
        """Condition number of the column-scaled ``W`` on the grid: from its singular values, or
        (``exact=False``, for progress reports) from the eigenvalues of ``W_s^T W_s``."""
        if not exact:
            zz = self.series.unknowns(z)
            if zz.tobytes() in self._last:  # the optimiser has just evaluated it
                return self._last[zz.tobytes()]
            return criterion(self._w_flat(zz), Criterion.COND)[2]
        return scaled_condition(self._w_flat(z))[0]

    def d_criterion(self, z: ArrayLike) -> float:
        """``-log det(W_s^T W_s)`` on the grid (SVD)."""
        return scaled_condition(self._w_flat(z))[1]

    def _w_flat(self, z: ArrayLike) -> Array:
        return self.regression.flat(*self.states(z))

    # -- constraints ------------------------------------------------------------------------

    def constraints(self, z: ArrayLike) -> Array:
        """Inequality constraints, ``>= 0`` when met (limits 1 % tightened; see
        :func:`kinergy.experiments.excitation_limits.constraints`)."""
        zz = self.series.unknowns(z)
        return constraints(self.robot, self.limits.tightened(), self.constraint_grid, zz)

    def constraints_jacobian(self, z: ArrayLike) -> Array:
        """Jacobian of :meth:`constraints`, shape (constraints, size)."""
        zz = self.series.unknowns(z)
        return constraints_jacobian(self.robot, self.limits.tightened(), self.constraint_grid, zz)

    # -- checks and feasible draws ----------------------------------------------------------

    def margins(self, z: ArrayLike) -> dict[str, float]:
        """Smallest distance to each limit over every ``dt`` sample of one period (>= 0: met;
        :meth:`ExcitationLimits.check`)."""
        return self.limits.check(self.robot, self.motion(z))

    def fit_into_limits(self, z: ArrayLike, *, safety: float = 1.0 - 1e-9) -> Array:
        """``s z`` with the largest ``s <= 1`` that meets every limit at every ``dt`` sample, times
        ``safety`` when it had to shrink (:func:`kinergy.experiments.excitation_limits.
        fit_into_limits`)."""
        grids = (self.constraint_grid, self.sample_grid)
        zz = fit_into_limits(self.robot, self.limits, grids, self.series.unknowns(z), safety=safety)
        return zz.reshape(-1)

    def random_start(self, rng: np.random.Generator) -> Array:
        """A random feasible ``z``: standard normal unknowns (iid normal coefficients projected on
        the boundary conditions), scaled to 99.9 % of the largest factor that meets every limit at
        every ``dt`` sample, so each draw uses the whole room the limits give."""
        zz = rng.standard_normal(self.size)
        return self.fit_into_limits(1e6 * zz, safety=0.999)  # from far outside: limits set the size


def _check_options(harmonics: int, period: float, dt: float, samples: int) -> None:
    """The scalar options: integers, positive times, enough grid points."""
    if isinstance(harmonics, bool) or not isinstance(harmonics, int | np.integer):
        raise KinergyError(f"harmonics must be an integer, got {harmonics!r}")
    if harmonics < 2:
        raise KinergyError(
            f"harmonics must be >= 2, got {harmonics}: with zero speed and acceleration at both "
            "ends a single harmonic cannot move"
        )
    period = checks.number(period, "period", gt=0.0)
    if not (np.isfinite(dt) and 0 < dt < period):
        raise KinergyError(f"dt must be in (0, period), got {dt}")
    if isinstance(samples, bool) or not isinstance(samples, int | np.integer):
        raise KinergyError(f"samples must be an integer, got {samples!r}")
    if samples < 4 * harmonics:
        raise KinergyError(
            f"samples must be >= 4 * harmonics = {4 * harmonics} per period, got {samples}"
        )


def _grids(
    series: FourierParametrisation, samples: int, dt: float
) -> tuple[SeriesGrid, SeriesGrid, SeriesGrid]:
    """The criterion's grid (``samples`` points of a period), the constraints' (twice as many)
    and every ``dt`` sample."""
    period = series.period
    t = np.arange(samples, dtype=float) * (period / samples)
    t_c = np.arange(2 * samples, dtype=float) * (period / (2 * samples))
    return series.grid(t), series.grid(t_c), series.grid(sample_times(period, dt))


def excitation_problem(
    robot: Robot,
    *,
    limits: ExcitationLimits | None = None,
    harmonics: int = 5,
    period: float = 10.0,
    criterion: Criterion | str = Criterion.COND,
    include_drives: bool = True,
    samples: int = 200,
    dt: float = CONTROLLER_DT,
) -> ExcitationProblem:
    """Build an excitation design problem (module docstring).

    Parameters
    ----------
    robot : Robot
    limits : ExcitationLimits, optional
        Start pose, joint ranges, speeds, accelerations and floor
        (:func:`~kinergy.experiments.excitation_limits.excitation_limits`); default that
        function's defaults: UR's home pose on a 6-joint arm, +-90 deg about it, the robot's
        speeds, 5 cm above the base plane.
    harmonics : int
        ``L`` of nursing eq 22, >= 2.
    period : float
        ``T = 2 pi / w_f``, s.
    criterion : Criterion or its value
        Condition number or D-optimality of the column-scaled regression matrix.
    include_drives : bool
        Add the rotor-inertia and friction columns to the regression matrix.
    samples : int
        Grid points per period for the criterion (the constraints use twice as many).
    dt : float
        Sample time of the motion and the final check, s (the controller's 0.002).

    Raises
    ------
    KinergyError
        Bad options, limits of another robot.
    """
    _check_options(harmonics, period, dt, samples)
    kind = checks.choice(criterion, Criterion, "criterion")
    limits = excitation_limits(robot) if limits is None else limits
    if limits.start.shape != (robot.n,):
        raise KinergyError(f"limits for {limits.start.size} joints, {robot.name} has {robot.n}")
    regression = excitation_regression(robot, include_drives=include_drives)
    if samples * robot.n < 2 * regression.size:
        raise KinergyError(
            f"samples: {samples} grid points x {robot.n} joints is too few for {regression.size} "
            f"parameters (need at least {-(-2 * regression.size // robot.n)})"
        )
    series = FourierParametrisation(int(harmonics), float(period), limits.start)
    grid, constraint_grid, sample_grid = _grids(series, samples, dt)
    return ExcitationProblem(
        robot=robot,
        series=series,
        limits=limits,
        criterion=kind,
        regression=regression,
        grid=grid,
        constraint_grid=constraint_grid,
        sample_grid=sample_grid,
        dt=float(dt),
    )
