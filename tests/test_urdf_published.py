"""URDFs as their makers publish them: meshes, materials, ``<gazebo>``, ``<ros2_control>``, the
transmissions of ROS 1, ros2_control and Drake, franka_description's extra ``<dynamics>``
attributes, a differential transmission kinergy does not read.

- Oracle: Pinocchio reads the same file; the rigid-body torques agree to 1e-9 (the meshes and
  the rest change nothing).
- The drives are what the file says, referred to the motor: each joint's gear ratio from its
  transmission (ROS 1 ``mechanicalReduction`` in the actuator, ros2_control
  ``mechanical_reduction`` in the joint, Drake's ``drake:gear_ratio``), the rotor inertia Drake
  gives as the motor inertia, ``<dynamics damping friction>`` as ``viscous = damping / n^2``,
  ``coulomb = friction / |n|``; a transmission of two joints is named in a note.
- A URDF installed with a package (MuJoCo's test data) reads as published, or is refused in one
  line naming why.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from clicase import run_case
from conftest import random_state

import kinergy
from kinergy.model.urdf import import_urdf

pin = pytest.importorskip("pinocchio")

MESH = (
    '<visual><origin xyz="0 0 0" rpy="0 0 0"/><geometry><mesh filename="package://arm_description/'
    'meshes/visual/{0}.dae"/></geometry><material name="grey"><color rgba="0.5 0.5 0.5 1"/>'
    '</material></visual><collision><geometry><mesh filename="package://arm_description/meshes/'
    'collision/{0}.stl" scale="0.001 0.001 0.001"/></geometry></collision>'
)


def _link(name: str, mass: float, com: str, inertia: str) -> str:
    return (
        f'<link name="{name}">{MESH.format(name)}<inertial><origin xyz="{com}" rpy="0.1 -0.2 0.3"/>'
        f'<mass value="{mass}"/><inertia {inertia}/></inertial></link>'
    )


def _joint(name: str, parent: str, child: str, xyz: str, rpy: str, axis: str, dynamics: str) -> str:
    return (
        f'<joint name="{name}" type="revolute"><origin xyz="{xyz}" rpy="{rpy}"/>'
        f'<parent link="{parent}"/><child link="{child}"/><axis xyz="{axis}"/>'
        f'<limit lower="-2.8" upper="2.8" effort="87" velocity="2.175"/>{dynamics}'
        '<safety_controller k_position="100.0" k_velocity="40.0" soft_lower_limit="-2.7" '
        'soft_upper_limit="2.7"/></joint>'
    )


INERTIA = 'ixx="0.05" ixy="0.001" ixz="-0.002" iyy="0.04" iyz="0.0005" izz="0.03"'


def published_arm() -> str:
    """A 4-joint arm written the way published descriptions are (module docstring)."""
    links = [
        '<link name="world"/>',
        _link("base_link", 4.0, "0 0 0.05", INERTIA),
        _link("link1", 3.0, "0 -0.03 0.1", INERTIA),
        _link("link2", 2.5, "0.1 0 0.02", INERTIA),
        _link("link3", 2.0, "0 0.05 0", INERTIA),
        _link("link4", 1.0, "0 0 0.03", INERTIA),
        '<link name="hand"><inertial><origin xyz="0 0 0.04"/><mass value="0.7"/>'
        '<inertia ixx="0.002" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.001"/></inertial></link>',
        '<link name="finger_left"/>',
        '<link name="finger_right"/>',
    ]
    franka = (
        '<dynamics D="1" K="7000" damping="0.003" friction="0.2" mu_coulomb="0" mu_viscous="16"/>'
    )
    joints = [
        '<joint name="world_joint" type="fixed"><parent link="world"/><child link="base_link"/>'
        '<origin xyz="0 0 0.02" rpy="0 0 0"/></joint>',
        _joint("joint1", "base_link", "link1", "0 0 0.333", "0 0 0", "0 0 1", franka),
        _joint("joint2", "link1", "link2", "0 0 0", "-1.5707963267948966 0 0", "0 0 1", franka),
        _joint("joint3", "link2", "link3", "0 -0.316 0", "1.5707963267948966 0 0", "0 0 1", ""),
        _joint("joint4", "link3", "link4", "0.0825 0 0", "1.5707963267948966 0 0", "0 0 -1", ""),
        '<joint name="hand_joint" type="fixed"><parent link="link4"/><child link="hand"/>'
        '<origin xyz="0 0 0.107" rpy="0 0 -0.785"/></joint>',
        '<joint name="finger_left_joint" type="prismatic"><parent link="hand"/>'
        '<child link="finger_left"/><axis xyz="0 1 0"/>'
        '<limit lower="0" upper="0.04" effort="20" velocity="0.2"/></joint>',
        '<joint name="finger_right_joint" type="prismatic"><parent link="hand"/>'
        '<child link="finger_right"/><axis xyz="0 -1 0"/>'
        '<limit lower="0" upper="0.04" effort="20" velocity="0.2"/>'
        '<mimic joint="finger_left_joint"/></joint>',
    ]
    transmissions = [
        # ROS 1: the reduction in the actuator; Drake's rotor inertia beside it
        '<transmission name="trans1"><type>transmission_interface/SimpleTransmission</type>'
        '<joint name="joint1"><hardwareInterface>hardware_interface/EffortJointInterface'
        '</hardwareInterface></joint><actuator name="motor1"><mechanicalReduction>160'
        '</mechanicalReduction><drake:rotor_inertia value="3.3e-5"/></actuator></transmission>',
        # Drake: drake:gear_ratio (mechanicalReduction ignored, as Drake does)
        '<transmission name="trans2"><type>transmission_interface/SimpleTransmission</type>'
        '<joint name="joint2"/><actuator name="motor2"><mechanicalReduction>1'
        '</mechanicalReduction><drake:gear_ratio value="-120"/>'
        "<drake:rotor_inertia>2.5e-5</drake:rotor_inertia></actuator></transmission>",
        # a differential transmission of the fingers: not read, named in a note
        '<transmission name="fingers"><type>transmission_interface/DifferentialTransmission'
        '</type><joint name="finger_left_joint"/><joint name="finger_right_joint"/>'
        '<actuator name="a1"/><actuator name="a2"/></transmission>',
    ]
    ros2_control = (
        '<ros2_control name="ArmSystem" type="system"><hardware><plugin>arm_hardware/ArmSystem'
        '</plugin><param name="ip">192.168.0.2</param></hardware><joint name="joint3">'
        '<command_interface name="effort"/><state_interface name="position"/></joint>'
        '<transmission name="trans3"><plugin>transmission_interface/SimpleTransmission</plugin>'
        '<actuator name="motor3" role="actuator1"/><joint name="joint3" role="joint1">'
        "<mechanical_reduction>100.0</mechanical_reduction><offset>0.0</offset></joint>"
        "</transmission></ros2_control>"
    )
    gazebo = (
        '<gazebo reference="link1"><material>Gazebo/Grey</material></gazebo>'
        '<gazebo><plugin name="gazebo_ros2_control" filename="libgazebo_ros2_control.so">'
        "<parameters>controllers.yaml</parameters></plugin></gazebo>"
    )
    return (
        '<?xml version="1.0"?>\n<robot name="published_arm" '
        'xmlns:xacro="http://www.ros.org/wiki/xacro" xmlns:drake="http://drake.mit.edu">'
        '<material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>'
        + "".join(links + joints + transmissions)
        + ros2_control
        + gazebo
        + "</robot>\n"
    )


def test_a_published_urdf_gives_its_geometry_and_drives(tmp_path: Path) -> None:
    path = tmp_path / "arm.urdf"
    path.write_text(published_arm(), encoding="utf-8")
    result = import_urdf(path, tip="hand")
    robot = result.robot
    assert not result.restored and robot.joint_names == ["joint1", "joint2", "joint3", "joint4"]
    # transmissions: ROS 1, Drake, ros2_control; none for joint4
    assert [j.drive.gear_ratio for j in robot.joints] == [160.0, -120.0, 100.0, 1.0]
    assert [j.drive.motor_inertia for j in robot.joints] == [3.3e-5, 2.5e-5, 0.0, 0.0]
    assert robot.sources["drive_inertia"].status == "published"
    # franka-style <dynamics>: damping and friction referred to the motor, the rest not read
    for joint, gear in zip(robot.joints[:2], (160.0, -120.0), strict=True):
        assert joint.drive.friction.name == "viscous_coulomb"
        assert joint.drive.friction.params["viscous"] == pytest.approx(0.003 / gear**2, rel=1e-15)
        assert joint.drive.friction.params["coulomb"] == pytest.approx(0.2 / abs(gear), rel=1e-15)
    assert [j.drive.friction.name for j in robot.joints[2:]] == ["none", "none"]
    assert any(
        "'fingers' (transmission_interface/DifferentialTransmission" in n for n in result.notes
    )
    assert "gear ratios from <transmission>, rotor inertias from <transmission> and friction" in (
        result.drives
    )
    # the rigid body, meshes and all, as Pinocchio reads the same file (the fingers locked)
    model = pin.buildModelFromUrdf(str(path))
    locked = [model.getJointId(n) for n in ("finger_left_joint", "finger_right_joint")]
    reduced = pin.buildReducedModel(model, locked, pin.neutral(model))
    data = reduced.createData()
    q, qd, qdd = random_state(robot, 20, seed=9)
    expected = np.array([pin.rnea(reduced, data, *s) for s in zip(q, qd, qdd, strict=True)])
    got = kinergy.rnea(robot, q, qd, qdd)
    assert np.max(np.abs(got - expected)) < 1e-9 * np.max(np.abs(expected))


def test_the_command_reads_it_and_says_what_it_left(tmp_path: Path) -> None:
    (tmp_path / "arm.urdf").write_text(published_arm(), encoding="utf-8")
    outcome = run_case(
        ["robot", "import-urdf", "arm.urdf", "--tip", "hand", "--out", "arm.toml"],
        tmp_path,
        outputs=["arm.toml"],
        refuse=False,
    )
    assert "wrote arm.toml: published_arm, 4 joints (mdh)" in outcome.out
    assert "kinergy: note: arm.urdf: transmission 'fingers'" in outcome.err
    assert kinergy.load_robot(tmp_path / "arm.toml").joints[0].drive.gear_ratio == 160.0


def test_two_transmissions_of_one_joint_must_agree(tmp_path: Path) -> None:
    text = published_arm().replace(
        "</robot>",
        '<transmission name="again"><type>SimpleTransmission</type><joint name="joint1"/>'
        "<actuator><mechanicalReduction>100</mechanicalReduction></actuator></transmission>"
        "</robot>",
    )
    (tmp_path / "arm.urdf").write_text(text, encoding="utf-8")
    with pytest.raises(kinergy.KinergyError, match="joint 'joint1' has two transmissions"):
        import_urdf(tmp_path / "arm.urdf", tip="hand")


def test_a_urdf_installed_with_a_package_reads_or_is_refused_in_one_line() -> None:
    mujoco = pytest.importorskip("mujoco")
    path = Path(mujoco.__file__).parent / "testdata" / "model.urdf"
    if not path.exists():
        pytest.skip("mujoco ships no test URDF")
    with pytest.raises(kinergy.KinergyError) as err:  # one link, no joint: not an arm
        import_urdf(path)
    assert str(err.value).startswith(f"{path}: ") and "\n" not in str(err.value)
