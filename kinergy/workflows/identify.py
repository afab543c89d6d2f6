"""``kinergy identify``: a model (or a payload) from logs, written as a robot file."""

from __future__ import annotations

import datetime
import os
from collections.abc import Sequence

from kinergy.errors import KinergyError
from kinergy.identify.full import identify_full
from kinergy.identify.nursing import identify_nursing
from kinergy.identify.payload import PayloadEstimate, identify_payload
from kinergy.identify.preprocess import IdentData
from kinergy.identify.result import IdentificationResult
from kinergy.identify.sanity import check_signals
from kinergy.identify.sequential import identify_sequential
from kinergy.model import Payload, Robot, save_robot

__all__ = ["METHODS", "MIN_SECONDS", "identify_model", "identify_payload_model"]

#: identification methods by the name ``--method`` takes
METHODS = ("sequential", "full", "nursing")
#: s: the shortest logs (all together) an identification accepts
MIN_SECONDS = 1.0


def _header(what: str, logs: Sequence[str | os.PathLike[str]]) -> str:
    from kinergy import __version__

    stamp = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    return f"kinergy {__version__}: {what} from {', '.join(os.fspath(p) for p in logs)} on {stamp}"


def identify_model(
    robot: Robot,
    datas: Sequence[IdentData],
    out: str | os.PathLike[str],
    *,
    method: str = "sequential",
    friction: str | None = None,
    target: str = "auto",
    solver: str = "ols",
    ridge: float = 0.0,
) -> IdentificationResult:
    """Identify ``robot`` from prepared logs by ``method`` and write the model to ``out``.

    Raises
    ------
    KinergyError
        Logs spanning less than :data:`MIN_SECONDS` together, or with signals no robot logs
        (:func:`~kinergy.identify.sanity.check_signals`); nothing is written.
    """
    check_signals(datas)
    seconds = sum(float(d.t[-1] - d.t[0]) for d in datas)
    if seconds < MIN_SECONDS:
        raise KinergyError(
            f"the logs span {seconds:.2f} s: identification needs at least {MIN_SECONDS:g} s of "
            "motion (a few periods of every joint's excitation)"
        )
    if method == "sequential":
        result = identify_sequential(robot, list(datas), friction=friction)
    elif method == "nursing":
        result = identify_nursing(robot, list(datas))
    else:
        result = identify_full(
            robot, list(datas), target=target, solver=solver, ridge=ridge, friction=friction
        )
    what = f"{robot.name} identified ({result.method} method)"
    save_robot(result.robot, out, header=_header(what, [d.path for d in datas]))
    return result


def identify_payload_model(
    robot: Robot, datas: Sequence[IdentData], out: str | os.PathLike[str]
) -> tuple[Payload, PayloadEstimate]:
    """Identify the payload of ``robot`` (the model without it) and write the model with it."""
    check_signals(datas)
    payload, report = identify_payload(robot, list(datas))
    what = f"{robot.name} with the payload identified"
    save_robot(robot.with_payload(payload), out, header=_header(what, [d.path for d in datas]))
    return payload, report
