"""Export a robot to a Pinocchio model (optional: needs the ``pin`` package).

Pinocchio is the independent oracle of kinergy's tests and benchmark, and a way for users to take
a kinergy model (say, one identified from logs) into Pinocchio-based tools.
"""

from __future__ import annotations

from typing import Any

from kinergy.dynamics.chain import link_inertials, make_chain
from kinergy.errors import KinergyError
from kinergy.model.robot import Robot

__all__ = ["to_pinocchio"]


def to_pinocchio(robot: Robot, *, include_payload: bool = True) -> Any:
    """A ``pinocchio.Model`` with the same kinematics, link inertials and gravity as ``robot``.

    Joint i of the Pinocchio model is a revolute-z joint whose frame is ``F_{i-1} · P_i · Rz(q_i)``
    (see :mod:`kinergy.dynamics.chain`); link i's inertia is carried into it through ``C_i``. The
    payload, when present, is merged into the last body. A frame named ``flange`` is added.
    """
    try:
        import pinocchio as pin
    except ImportError:
        raise KinergyError(
            "exporting to Pinocchio needs the 'pin' package (pip install pin)"
        ) from None
    chain = make_chain(robot)
    body = link_inertials(robot, include_payload=include_payload)
    model = pin.Model()
    model.name = robot.name
    parent = 0
    previous = robot.base
    for i, joint in enumerate(robot.joints):
        placement = previous @ chain.pre[i]
        jid = model.addJoint(
            parent, pin.JointModelRZ(), pin.SE3(placement[:3, :3], placement[:3, 3]), joint.name
        )
        post = chain.post[i]
        inertia = pin.Inertia(float(body.mass[i]), body.com[i], body.inertia_com[i])
        model.appendBodyToJoint(
            jid, pin.SE3(post[:3, :3], post[:3, 3]).act(inertia), pin.SE3.Identity()
        )
        parent = jid
        previous = post
    flange = chain.post[-1] @ robot.flange
    model.addFrame(
        pin.Frame("flange", parent, pin.SE3(flange[:3, :3], flange[:3, 3]), pin.FrameType.OP_FRAME)
    )
    model.gravity.linear = robot.gravity
    return model
