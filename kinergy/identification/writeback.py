"""From the full method's regression unknowns back to a Robot (:mod:`kinergy.identification.full`).

A robot file stores masses, centres of mass and inertias, not base parameters. The links are
written, in this order of preference:

1. the standard parameters closest to the model's that reproduce the identified base parameters
   exactly (:func:`~kinergy.identification.physical.standard_from_base`);
2. when one of those links is not physical (:func:`~kinergy.identification.physical.link_consistency`)
   or a rotor inertia, friction level or torque constant is outside its bounds, the
   least-squares fit constrained to physical values
   (:func:`~kinergy.identification.constrained.physical_fit`, a convex problem); when the
   unconstrained fit is physical it is that problem's solution already;
3. the model's data for a link still not physical.

Rotor inertias give ``motor_inertia = J - reducer_inertia`` (UR5e eq 9, Table IV; below the
reducer inertia, the reducer inertia gives way so the written ``J_m + J_r`` is the identified
one); friction levels replace the joints' friction parameters.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from kinergy.arrays import Array
from kinergy.dynamics.regressor import BaseParameters, inertial_parameters, parameter_names
from kinergy.errors import KinergyError
from kinergy.friction.model import FrictionModel
from kinergy.identification.columns import Columns, Regression
from kinergy.identification.constrained import ConstrainedFit, bounds, physical_fit
from kinergy.identification.physical import (
    inertia_vector,
    link_consistency,
    link_from_standard,
    parameter_scale,
    standard_from_base,
)
from kinergy.identification.regression import Solved
from kinergy.identification.result import AT_BOUND, IDENTIFIED, KEPT, Flag
from kinergy.messages import Messages
from kinergy.model.robot import Drive, Friction, Joint, Link, Robot, Source

__all__ = ["CLOSEST", "CONSTRAINED", "WriteBack", "write_back"]


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
    active : tuple of str
        The constraints the constrained fit sits on.
    solver : str or None
        The constrained fit's solver.
    flags : tuple of Flag
        Per column of the regression: ``identified``, ``kept from prior`` or ``at bound``.
    links_not_physical_closest : tuple of int
        Links (1-based) whose closest standard parameters are not physical.
    links_physical : tuple of bool
        Per link, whether the robot's link is the identified one (else the model's).
    standard_parameters : dict
        The written standard parameters by name (kg, kg m, kg m^2).
    said : Messages
        What writing the robot did (notes) and what may be wrong with it (warnings).
    """

    robot: Robot
    x: Array
    method: str
    chi2: float | None
    active: tuple[str, ...]
    solver: str | None
    flags: tuple[Flag, ...]
    links_not_physical_closest: tuple[int, ...]
    links_physical: tuple[bool, ...]
    standard_parameters: dict[str, float]
    said: Messages


@dataclass(frozen=True, eq=False)
class _Links:
    """The standard parameters of the links (the payload's share taken out of the last, (p,)),
    the unknowns they go with, how, the constrained fit (None when not used), and the links
    flagged."""

    links: Array
    x: Array
    method: str
    refit: ConstrainedFit | None
    flagged: dict[int, str]


def _out_of_bounds(cols: Columns, x: Array, lo: Array, hi: Array) -> dict[int, str]:
    """Non-link columns of ``x`` outside their bounds (index -> phrase)."""
    out = {}
    for k, (value, low, high) in enumerate(zip(x[cols.n_link :], lo, hi, strict=True)):
        if not low <= value <= high:
            col = cols.n_link + k
            out[col] = f"{cols.names[col]} = {value:.3g} is outside [{low:.3g}, {high:.3g}]"
    return out


def _links(
    robot: Robot,
    base: BaseParameters,
    problem: Solved,
    reg: Regression,
    merged_rotor: dict[int, Array],
    said: Messages,
) -> _Links:
    """Steps 1 and 2 of the module docstring (what the constrained fit did, said)."""
    cols = reg.cols
    n_link, x = cols.n_link, problem.x
    pi0 = inertial_parameters(robot)
    payload = pi0 - inertial_parameters(robot, include_payload=False)  # the last link's part
    scale = parameter_scale(robot)
    pi = standard_from_base(base, x[:n_link], pi0, scale=scale)
    flagged = {j: p for j, p in enumerate(link_consistency(pi - payload)) if p is not None}
    outside = _out_of_bounds(cols, x, *bounds(cols, reg.models))
    if not (flagged or outside):
        return _Links(pi - payload, x, CLOSEST, None, flagged)
    names = robot.joint_names
    refit = physical_fit(problem, base, cols, reg.models, pi0, scale, payload, names, merged_rotor)
    if refit is None:
        for col, phrase in outside.items():  # never written: the model's value instead
            said.warn(f"{phrase}: kept the model's value (the constrained fit failed)")
            x = x.copy()
            x[col] = cols.prior[col]
        return _Links(pi - payload, x, CLOSEST, None, flagged)
    for j, p in flagged.items():
        said.note(f"link {j + 1} ({robot.joints[j].name}): {p}")
    for phrase in outside.values():
        said.note(phrase)
    said.note(
        f"for the {len(flagged) + len(outside)} finding(s) above, the returned robot is the "
        "least-squares fit constrained to physical links, rotor inertias and friction (chi² up "
        f"by {refit.chi2:.3g}; fit['physical_fit'], while fit['base_parameters'] and "
        "fit['regression'] are the unconstrained fit)"
    )
    return _Links(refit.pi - payload, refit.x, CONSTRAINED, refit, flagged)


def _with_links(
    robot: Robot, links: Array, said: Messages
) -> tuple[list[Joint], Array, list[bool]]:
    """Step 3: the joints with the links ``links`` (payload excluded, (p,)) where physical, the
    model's elsewhere (with a warning); the standard parameters written (p,); and per link
    whether it is the identified one."""
    links = links.copy()
    model = inertial_parameters(robot, include_payload=False)
    joints: list[Joint] = []
    physical: list[bool] = []
    kept: list[str] = []
    for j, (joint, problem) in enumerate(zip(robot.joints, link_consistency(links), strict=True)):
        link = joint.link
        if problem is None:
            mass, c, i_c = link_from_standard(links[10 * j : 10 * j + 10])
            try:
                link = Link(mass=mass, com=c, inertia=inertia_vector(i_c))
            except KinergyError as err:
                problem = str(err)
        if problem is not None:
            said.warn(f"link {j + 1} ({joint.name}): {problem}")
            kept.append(str(j + 1))
            links[10 * j : 10 * j + 10] = model[10 * j : 10 * j + 10]
        joints.append(dataclasses.replace(joint, link=link))
        physical.append(problem is None)
    if kept:
        said.warn(
            f"kept the model's mass, centre of mass and inertia for link(s) {', '.join(kept)}, "
            "so the returned robot's torques differ from the identified base parameters' "
            "(fit['regression'] is the identified fit, fit['torque'], fit['current'] and "
            "fit['joint_torque'] the returned robot's)"
        )
    return joints, links, physical


def _with_rotor(m: int, joint: Joint, rotor: float, low: list[str]) -> Drive:
    """``joint``'s drive with rotor inertia ``rotor`` = J_m + J_r (kg m^2, motor side); where it
    is below the model's reducer inertia, ``low`` receives the joint and both values."""
    drive = joint.drive
    if rotor >= drive.reducer_inertia:
        return dataclasses.replace(drive, motor_inertia=rotor - drive.reducer_inertia)
    # motor inertia clipped at 0; the reducer inertia gives way too, so the written J_m + J_r is
    # the identified one (arms with link-side torque sensors see about 0)
    reducer = max(rotor, 0.0)
    low.append(f"joint {m + 1} ({joint.name}) {rotor:.3g} (reducer {drive.reducer_inertia:.3g})")
    return dataclasses.replace(drive, motor_inertia=0.0, reducer_inertia=reducer)


def _with_friction(
    m: int,
    joint: Joint,
    friction: tuple[FrictionModel, dict[str, float]],
    values: Array,
    said: Messages,
) -> Drive:
    """``joint``'s drive with friction ``(model, parameters)`` at the levels ``values`` (motor
    side)."""
    model, params = friction
    for name, value in zip(model.linear, values, strict=True):
        if value < 0.0 and name != "gamma1":
            said.warn(f"joint {m + 1} ({joint.name}): friction {name} = {value:.3g} is negative")
    new = model.with_values(params, values)
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


def _flags(cols: Columns, problem: Solved, written: _Links) -> tuple[Flag, ...]:
    """Each column's flag: at a bound of the constrained fit, kept from the prior (a column the
    logs cannot tell apart, or one the fit could not make physical), else identified."""
    at_bound = set(written.refit.at_bound) if written.refit is not None else set()
    dropped = set(problem.dropped.tolist())
    out = []
    for k in range(cols.prior.size):
        if k in at_bound:
            out.append(AT_BOUND)
        elif k in dropped or (
            k >= cols.n_link and written.x[k] != problem.x[k] and written.refit is None
        ):
            out.append(KEPT)
        else:
            out.append(IDENTIFIED)
    return tuple(out)


def _with_drive(
    m: int,
    joint: Joint,
    reg: Regression,
    x: Array,
    commanded: bool,
    said: Messages,
    low: list[str],
) -> Joint:
    """``joint`` with motor ``m``'s rotor inertia (one below the reducer's into ``low``),
    friction (not ``commanded``) and, against measured torques, joint ``m``'s torque sensor
    offset from the unknowns ``x``."""
    cols = reg.cols
    drive = _with_rotor(m, joint, float(x[cols.n_link + m]), low)
    joint = dataclasses.replace(joint, drive=drive)
    if not commanded:
        friction = (reg.models[m], reg.params[m])
        drive = _with_friction(m, joint, friction, cols.friction(x, m), said)
        joint = dataclasses.replace(joint, drive=drive)
    if cols.offset_at is not None:  # against measured torques: joint m's sensor offset
        sensor = dataclasses.replace(joint.torque_sensor, offset=float(x[cols.offset_at + m]))
        joint = dataclasses.replace(joint, torque_sensor=sensor)
    return joint


def write_back(
    robot: Robot,
    base: BaseParameters,
    problem: Solved,
    reg: Regression,
    commanded: bool,
    merged_rotor: dict[int, Array],
) -> WriteBack:
    """The identified robot from the solved regression ``problem`` of ``reg`` (module
    docstring). ``commanded``: a fit against ``target_moment``, which keeps the model's
    friction; ``merged_rotor`` gives each merged rotor inertia's column in link base columns
    (motor -> (b,)), which the constrained fit may move."""
    said = Messages()
    cols = reg.cols
    written = _links(robot, base, problem, reg, merged_rotor, said)
    link_joints, links, physical = _with_links(robot, written.links, said)
    low: list[str] = []
    final = [
        _with_drive(m, joint, reg, written.x, commanded, said, low)
        for m, joint in enumerate(link_joints)
    ]
    if low:
        said.note(
            "identified rotor inertia J_m + J_r below the model's reducer inertia, kg m² (arms "
            "with link-side torque sensors see about 0): motor inertia set to 0 and reducer "
            f"inertia to the identified value: {', '.join(low)}"
        )
    sources = _sources(robot, written.method, physical, commanded)
    refit = written.refit
    return WriteBack(
        robot=dataclasses.replace(robot.with_joints(final), sources=sources),
        x=written.x,
        method=written.method,
        chi2=refit.chi2 if refit is not None else None,
        active=refit.active if refit is not None else (),
        solver=refit.solver if refit is not None else None,
        flags=_flags(cols, problem, written),
        links_not_physical_closest=tuple(sorted(j + 1 for j in written.flagged)),
        links_physical=tuple(physical),
        standard_parameters=dict(zip(parameter_names(robot), links.tolist(), strict=True)),
        said=said,
    )
