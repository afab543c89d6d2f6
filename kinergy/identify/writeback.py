"""From the full method's regression unknowns back to a Robot (:mod:`kinergy.identify.full`).

A robot file stores masses, centres of mass and inertias, not base parameters. The links are
written, in this order of preference:

1. the standard parameters closest to the model's that reproduce the identified base parameters
   exactly (:func:`~kinergy.identify.physical.standard_from_base`);
2. when one of those links is not physical (:func:`~kinergy.identify.physical.link_consistency`)
   or a rotor inertia is negative, the least-squares fit constrained to physical links and
   non-negative rotor inertias (:func:`~kinergy.identify.constrained.physical_fit`);
3. the model's data for a link still not physical.

Rotor inertias give ``motor_inertia = J - reducer_inertia`` (UR5e eq 9, Table IV; below the
reducer inertia, the reducer inertia gives way so the written ``J_m + J_r`` is the identified
one); friction levels replace the joints' friction parameters.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from kinergy.dynamics.regressor import BaseParameters, inertial_parameters, parameter_names
from kinergy.errors import KinergyError
from kinergy.friction.registry import get_model, with_linear_parameters
from kinergy.identify.columns import Columns, Stacked
from kinergy.identify.constrained import physical_fit
from kinergy.identify.physical import (
    inertia_vector,
    link_consistency,
    link_from_standard,
    parameter_scale,
    standard_from_base,
)
from kinergy.identify.regression import Solved
from kinergy.model.robot import Drive, Friction, Joint, Link, Robot, Source

__all__ = ["CLOSEST", "CONSTRAINED", "WriteBack", "write_back"]

Array = NDArray[np.float64]

#: how the links were written: the closest standard parameters, or the constrained fit
CLOSEST = "closest"
CONSTRAINED = "physically consistent least squares"

_REF = "kinergy identify (full base-parameter regression, nursing eqs 15-16, UR5e eq 2)"


@dataclass(frozen=True, eq=False)
class WriteBack:
    """The identified robot and how it was written.

    Attributes
    ----------
    robot : Robot
    x : ndarray, shape (p,)
        The regression unknowns it was written from (the constrained fit's when used).
    method : str
        :data:`CLOSEST` or :data:`CONSTRAINED`.
    chi2 : float or None
        The constrained fit's chi^2 increase; None when it was not used.
    links_not_physical_closest : tuple of int
        Links (1-based) whose closest standard parameters are not physical.
    links_physical : tuple of bool
        Per link, whether the robot's link is the identified one (else the model's).
    standard_parameters : dict
        The written standard parameters by name (kg, kg m, kg m^2).
    warnings : tuple of str
    """

    robot: Robot
    x: Array
    method: str
    chi2: float | None
    links_not_physical_closest: tuple[int, ...]
    links_physical: tuple[bool, ...]
    standard_parameters: dict[str, float]
    warnings: tuple[str, ...]


@dataclass(frozen=True, eq=False)
class _Links:
    """The standard parameters of the links (the payload's share taken out of the last, (p,)),
    the unknowns they go with, how, the chi^2 increase of the constrained fit, and the links
    flagged."""

    links: Array
    x: Array
    method: str
    chi2: float | None
    flagged: dict[int, str]


def _links(
    robot: Robot,
    base: BaseParameters,
    problem: Solved,
    cols: Columns,
    merged_rotor: dict[int, Array],
    warnings: list[str],
) -> _Links:
    """Steps 1 and 2 of the module docstring (warnings appended for the constrained fit)."""
    n_link, x = cols.n_link, problem.x
    pi0 = inertial_parameters(robot)
    payload = pi0 - inertial_parameters(robot, include_payload=False)  # the last link's part
    scale = parameter_scale(robot)
    pi = standard_from_base(base, x[:n_link], pi0, scale=scale)
    flagged = {j: p for j, p in enumerate(link_consistency(pi - payload)) if p is not None}
    negative = [m for m in range(robot.n) if x[n_link + m] < 0.0]
    if not (flagged or negative):
        return _Links(pi - payload, x, CLOSEST, None, flagged)
    refit = physical_fit(problem, base, cols, pi0, scale, payload, merged_rotor)
    if refit is None:
        return _Links(pi - payload, x, CLOSEST, None, flagged)
    instead = (
        "the returned robot takes its links, rotor inertias and friction from the "
        f"least-squares fit constrained to physical links and non-negative rotor "
        f"inertias (chi^2 up by {refit.chi2:.3g}; fit['physical_fit'], while "
        "fit['base_parameters'] and fit['regression'] are the unconstrained fit)"
    )
    for j, p in flagged.items():
        warnings.append(f"link {j + 1} ({robot.joints[j].name}): {p}; {instead}")
    for m in negative:
        warnings.append(
            f"joint {m + 1} ({robot.joints[m].name}): identified rotor inertia "
            f"{x[n_link + m]:.3g} kg m^2 is negative; {instead}"
        )
    return _Links(refit.pi - payload, refit.x, CONSTRAINED, refit.chi2, flagged)


def _with_links(
    robot: Robot, links: Array, warnings: list[str]
) -> tuple[list[Joint], Array, list[bool]]:
    """Step 3: the joints with the links ``links`` (payload excluded, (p,)) where physical, the
    model's elsewhere (with a warning); the standard parameters written (p,); and per link
    whether it is the identified one."""
    links = links.copy()
    model = inertial_parameters(robot, include_payload=False)
    joints: list[Joint] = []
    physical: list[bool] = []
    for j, (joint, problem) in enumerate(zip(robot.joints, link_consistency(links), strict=True)):
        link = joint.link
        if problem is None:
            mass, c, i_c = link_from_standard(links[10 * j : 10 * j + 10])
            try:
                link = Link(mass=mass, com=c, inertia=inertia_vector(i_c))
            except KinergyError as err:
                problem = str(err)
        if problem is not None:
            warnings.append(
                f"link {j + 1} ({joint.name}): {problem}; kept the model's mass, centre of mass "
                "and inertia for this link, so the returned robot's torques differ from the "
                "identified base parameters' (fit['regression'] is the identified fit, "
                "fit['torque'], fit['current'] and fit['joint_torque'] the returned robot's)"
            )
            links[10 * j : 10 * j + 10] = model[10 * j : 10 * j + 10]
        joints.append(dataclasses.replace(joint, link=link))
        physical.append(problem is None)
    return joints, links, physical


def _with_rotor(m: int, joint: Joint, rotor: float, warnings: list[str]) -> Drive:
    """``joint``'s drive with rotor inertia ``rotor`` = J_m + J_r (kg m^2, motor side)."""
    drive = joint.drive
    if rotor >= drive.reducer_inertia:
        return dataclasses.replace(drive, motor_inertia=rotor - drive.reducer_inertia)
    # motor inertia clipped at 0; the reducer inertia gives way too, so the written J_m + J_r is
    # the identified one (arms with link-side torque sensors see about 0)
    reducer = max(rotor, 0.0)
    warnings.append(
        f"joint {m + 1} ({joint.name}): identified rotor inertia {rotor:.3g} kg m^2 is "
        + ("not positive" if rotor <= 0.0 else "below the model's reducer inertia")
        + f" ({drive.reducer_inertia:.3g}): motor inertia set to 0 and reducer inertia "
        f"to {reducer:.3g} kg m^2"
    )
    return dataclasses.replace(drive, motor_inertia=0.0, reducer_inertia=reducer)


def _with_friction(
    m: int, joint: Joint, friction: tuple[str, dict[str, float]], values: Array, warnings: list[str]
) -> Drive:
    """``joint``'s drive with friction ``(model, parameters)`` at the levels ``values`` (motor
    side)."""
    model, params = friction
    for name, value in zip(get_model(model).linear, values, strict=True):
        if value < 0.0 and name != "gamma1":
            warnings.append(
                f"joint {m + 1} ({joint.name}): friction {name} = {value:.3g} is negative"
            )
    new = with_linear_parameters(model, params, values)
    return dataclasses.replace(joint.drive, friction=Friction(model, new))


def _sources(robot: Robot, method: str, physical: list[bool], commanded: bool) -> dict[str, Source]:
    """The robot's sources with the identified groups marked."""
    sources: dict[str, Source] = dict(robot.sources)
    kept_links = [str(j + 1) for j, ok in enumerate(physical) if not ok]
    note = (
        f"; link(s) {', '.join(kept_links)} kept from the model (not physical)"
        if kept_links
        else ""
    )
    for group in ("mass", "com", "inertia"):
        sources[group] = Source("identified", _REF + f" ({method})" + note)
    sources["drive_inertia"] = Source("identified", _REF)
    if not commanded:
        sources["friction"] = Source("identified", _REF)
    return sources


def write_back(
    robot: Robot,
    base: BaseParameters,
    problem: Solved,
    stacked: Stacked,
    commanded: bool,
    merged_rotor: dict[int, Array],
) -> WriteBack:
    """The identified robot from the solved regression ``problem`` of ``stacked`` (module
    docstring).

    ``commanded``: a fit against ``target_moment``, which keeps the model's friction;
    ``merged_rotor`` gives each merged rotor inertia's column in link base columns (motor ->
    (b,)), which the constrained fit may move.
    """
    warnings: list[str] = []
    cols = stacked.cols
    n_link = cols.n_link
    written = _links(robot, base, problem, cols, merged_rotor, warnings)
    link_joints, links, physical = _with_links(robot, written.links, warnings)
    final = []
    for m, joint in enumerate(link_joints):
        joint = dataclasses.replace(
            joint, drive=_with_rotor(m, joint, float(written.x[n_link + m]), warnings)
        )
        if not commanded:
            friction = (stacked.models[m], stacked.params[m])
            values = cols.friction(written.x, m)
            joint = dataclasses.replace(
                joint, drive=_with_friction(m, joint, friction, values, warnings)
            )
        final.append(joint)
    robot_out = dataclasses.replace(
        robot.with_joints(final), sources=_sources(robot, written.method, physical, commanded)
    )
    return WriteBack(
        robot=robot_out,
        x=written.x,
        method=written.method,
        chi2=written.chi2,
        links_not_physical_closest=tuple(sorted(j + 1 for j in written.flagged)),
        links_physical=tuple(physical),
        standard_parameters=dict(zip(parameter_names(robot), links.tolist(), strict=True)),
        warnings=tuple(warnings),
    )
