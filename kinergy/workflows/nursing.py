"""The nursing doc's identification end to end on the digital twin (nursing sections 4.1-4.2).

``kinergy nursing`` runs :func:`nursing_study`:

1. for every joint, the constant-speed back-and-forth friction runs
   (:func:`kinergy.experiments.friction_runs.back_and_forth_motion`), simulated by the twin
   (:func:`kinergy.twin.simulate`) with its current noise (the twin's default
   :class:`~kinergy.twin.TwinSettings`) or without; currents to joint torques by eq 21 and
   the robot's coupling; friction as the odd part (eq 20); Makkar's model (eq 13) fitted by
   particle swarm optimisation and by least squares, next to the twin's own curve (the robot
   file's motor-side Makkar converted to the joint side, ``gamma1, gamma4 * k n``, rates ``* n``,
   ``gamma6 * k n^2``; k = 2 motors of n = 3060 on the nursing arm) and the doc's Table 4 and
   R^2 (0.927 pitch, 0.931 rotation);
2. the excitation of Table 6 (eq 22), ten 10 s periods on the twin, then the nursing method
   (:func:`kinergy.identification.nursing.identify_nursing`): currents filtered at 15 Hz and averaged
   over the periods (eq 24), joint torques less the identified friction and drive inertia
   (eq 25), ridge regression of the minimal parameter set on a 70/30 split in time, and the
   per-joint RMSE on the 30 % (eq 26) next to the doc's Table 8.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from kinergy.checks import integer
from kinergy.drives.coupled import joint_kind, joint_side_makkar, joint_torques_from_current
from kinergy.errors import KinergyError
from kinergy.experiments.friction_runs import back_and_forth_motion
from kinergy.experiments.nursing_doc import DOC_FRICTION_R2, DOC_TABLE4, DOC_TABLE8
from kinergy.experiments.nursing_excitation import table6_motion
from kinergy.friction.makkar import makkar
from kinergy.identification.friction_points import FrictionPoints, friction_points
from kinergy.identification.makkar_fit import MakkarFit, fit_makkar_lsq, fit_makkar_pso
from kinergy.identification.nursing import MotorFrictionFit, NursingFit, identify_nursing
from kinergy.identification.options import MakkarMethod
from kinergy.jsonable import to_jsonable
from kinergy.logs.prepare import IdentData, prepare
from kinergy.model.robot import Robot
from kinergy.trajectory.motion import Motion
from kinergy.twin import TwinSettings, simulate
from kinergy.workflows.twin import MAX_SEED

__all__ = [
    "DocFriction",
    "FitComparison",
    "FrictionStudy",
    "NursingStudy",
    "NursingStudyOptions",
    "RidgeStudy",
    "StudyTimings",
    "nursing_study",
]

Progress = Callable[[str], None]


@dataclass(frozen=True)
class FitComparison:
    """A Makkar fit (joint side) of one joint's runs: ``gamma`` (6,), R^2 against the level
    means (``r2``) and every sample's odd part (``r2_samples``); against the twin's own curve
    (None without one): the largest relative parameter error and the R^2 of the curves."""

    gamma: tuple[float, ...]
    r2: float
    r2_samples: float
    max_rel_error: float | None
    curve_r2_vs_twin: float | None


@dataclass(frozen=True)
class DocFriction:
    """The doc's Table 4 curve (joint side) and the R^2 it reports for this kind of joint."""

    gamma: tuple[float, ...]
    r2: float


@dataclass(frozen=True)
class FrictionStudy:
    """One joint's friction runs: its ``kind``, the speed ``levels`` and their range (rad/s), the
    axis' ``tilt`` from vertical (rad), the largest even part (N m), the ``pso`` and ``lsq``
    fits, the ``twin``'s joint-side curve and the ``doc``'s (None where there is none)."""

    joint: int
    name: str
    kind: str
    levels: int
    speed_range: tuple[float, float]
    tilt: float
    error_max: float
    pso: FitComparison
    lsq: FitComparison
    twin: tuple[float, ...] | None
    doc: DocFriction | None


@dataclass(frozen=True)
class RidgeStudy:
    """The ridge regression of the links against the doc's Table 8: per joint (``joints``)
    ``rmse_test``, ``rmse_train`` (N m), ``r2_test``, ``torque_std_test`` (N m) and ``table8``;
    ``alpha``, ``intercept`` (N m), the number of base ``parameters``, the training share
    ``split``, the excitation's ``period`` (s) and the current filter's ``cutoff`` (Hz)."""

    joints: tuple[str, ...]
    rmse_test: tuple[float, ...]
    rmse_train: tuple[float, ...]
    r2_test: tuple[float, ...]
    torque_std_test: tuple[float, ...]
    table8: tuple[float, ...]
    alpha: float
    intercept: float
    parameters: int
    split: float
    period: float | None
    cutoff: float | None


@dataclass(frozen=True)
class StudyTimings:
    """Wall time of each stage, s."""

    friction: float
    excitation: float
    identify: float


@dataclass(frozen=True)
class NursingStudy:
    """What :func:`nursing_study` found (``kinergy nursing --json``)."""

    robot: str
    noise: bool
    seed: int
    friction: tuple[FrictionStudy, ...]
    ridge: RidgeStudy
    friction_motors: tuple[MotorFrictionFit, ...]
    excitation_notes: tuple[str, ...]
    warnings: tuple[str, ...]
    timings: StudyTimings

    def to_dict(self) -> dict[str, Any]:
        """``kinergy nursing --json`` (without where the command came from)."""
        out: dict[str, Any] = to_jsonable(self)
        return out


@dataclass(frozen=True)
class NursingStudyOptions:
    """How :func:`nursing_study` runs the twin, checked on construction.

    Attributes
    ----------
    noise : bool
        The twin's default lag and noise (``TwinSettings(seed=...)``) or none.
    seed : int
        Seed of the twin's noise (log k uses ``seed + k``) and of the swarm, 0 to
        :data:`~kinergy.workflows.twin.MAX_SEED`.
    """

    noise: bool = True
    seed: int = 0

    def __post_init__(self) -> None:
        object.__setattr__(self, "noise", bool(self.noise))
        object.__setattr__(self, "seed", integer(self.seed, "--seed", ge=0, le=MAX_SEED))


def _twin_log(robot: Robot, name: str, motion: Motion, settings: TwinSettings) -> IdentData:
    return prepare(simulate(robot, motion, settings, name=name), robot.n)


def _fit_comparison(mf: MakkarFit, pts: FrictionPoints, truth: np.ndarray | None) -> FitComparison:
    """``mf`` against the samples' odd part and the twin's curve ``truth`` (6,) if known."""
    rel, curve = None, None
    if truth is not None:
        rel = float(np.max(np.abs(mf.gamma / truth - 1.0)))
        curve = mf.r2_against(pts.speeds, makkar(truth, pts.speeds))
    return FitComparison(
        gamma=tuple(mf.gamma.tolist()),
        r2=mf.r2,
        r2_samples=mf.r2_against(pts.sample_speeds, pts.sample_friction),
        max_rel_error=rel,
        curve_r2_vs_twin=curve,
    )


def _friction_study(
    robot: Robot, j: int, settings: TwinSettings, seed: int
) -> tuple[IdentData, FrictionStudy]:
    """Joint ``j``'s runs on the twin, the log and both Makkar fits next to the twin and doc."""
    joint = robot.joints[j]
    run = back_and_forth_motion(robot, j)
    data = _twin_log(robot, f"twin:friction-{joint.name}", run.motion, settings)
    assert data.current is not None
    tau = joint_torques_from_current(robot, data.current)
    pts = friction_points(data.q[:, j], tau[:, j], run.speeds, run.forward, run.backward, joint=j)
    truth = joint_side_makkar(robot, j)
    kind = joint_kind(robot, j)
    doc = None
    if kind in DOC_TABLE4:
        doc = DocFriction(DOC_TABLE4[kind], DOC_FRICTION_R2[kind])
    study = FrictionStudy(
        joint=j + 1,
        name=joint.name,
        kind=kind,
        levels=int(pts.speeds.size),
        speed_range=(float(pts.speeds.min()), float(pts.speeds.max())),
        tilt=run.tilt,
        error_max=float(np.max(np.abs(pts.error))),
        pso=_fit_comparison(fit_makkar_pso(pts.speeds, pts.friction, rng=seed), pts, truth),
        lsq=_fit_comparison(fit_makkar_lsq(pts.speeds, pts.friction), pts, truth),
        twin=None if truth is None else tuple(truth.tolist()),
        doc=doc,
    )
    return data, study


def _ridge_study(robot: Robot, fit: NursingFit) -> RidgeStudy:
    """The identification's ridge regression next to Table 8."""
    ridge = fit.ridge
    assert ridge is not None and fit.base_parameters
    return RidgeStudy(
        joints=tuple(robot.joint_names),
        rmse_test=ridge.rmse_test,
        rmse_train=ridge.rmse_train,
        r2_test=ridge.r2_test,
        torque_std_test=ridge.torque_std_test,
        table8=DOC_TABLE8,
        alpha=ridge.alpha,
        intercept=ridge.intercept,
        parameters=len(fit.base_parameters),
        split=ridge.split,
        period=ridge.logs[0].period,
        cutoff=ridge.logs[0].cutoff,
    )


def nursing_study(
    robot: Robot,
    options: NursingStudyOptions | None = None,
    *,
    progress: Progress | None = None,
) -> NursingStudy:
    """Run the nursing doc's identification on ``robot``'s twin (module docstring).

    Parameters
    ----------
    robot : Robot
        The twin's model (6 joints, for Table 6's excitation).
    options : NursingStudyOptions, optional
        Noise and seed (default: the twin's noise, seed 0).
    progress : callable, optional
        Called with a line of text at each stage.

    Returns
    -------
    NursingStudy
    """
    options = options or NursingStudyOptions()
    noise, seed = options.noise, options.seed
    say = progress or (lambda _msg: None)
    if robot.n != 6:
        raise KinergyError(
            f"the nursing study runs Table 6's excitation: 6 joints, {robot.name} has {robot.n}"
        )

    def settings(k: int) -> TwinSettings:
        return TwinSettings(seed=seed + k) if noise else TwinSettings.exact()

    t0 = time.perf_counter()
    datas, friction = [], []
    for j, joint in enumerate(robot.joints):
        say(f"friction runs of joint {j + 1} ({joint.name}) on the twin")
        data, study = _friction_study(robot, j, settings(j), seed)
        datas.append(data)
        friction.append(study)
    t1 = time.perf_counter()
    say("Table 6 excitation, 10 periods, on the twin")
    motion, _, notes = table6_motion(robot, periods=10)
    datas.append(_twin_log(robot, "twin:excitation-table6", motion, settings(robot.n)))
    t2 = time.perf_counter()
    say("identifying (nursing method: Makkar friction per motor, ridge on the minimal set)")
    result = identify_nursing(robot, datas, fit=MakkarMethod.LSQ, seed=seed)
    t3 = time.perf_counter()
    assert isinstance(result.fit, NursingFit)
    return NursingStudy(
        robot=robot.name,
        noise=noise,
        seed=seed,
        friction=tuple(friction),
        ridge=_ridge_study(robot, result.fit),
        friction_motors=result.fit.friction_motors,
        excitation_notes=tuple(notes),
        warnings=tuple(result.warnings),
        timings=StudyTimings(friction=t1 - t0, excitation=t2 - t1, identify=t3 - t2),
    )
