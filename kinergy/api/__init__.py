"""The Python API, the one front door: every command parses its flags into the typed options
these functions take, calls one of them, and formats the result it returns.

Options are frozen dataclasses checked on construction (a value out of range, or a name that is
not one of an option's, is one :class:`~kinergy.errors.KinergyError` line naming the option as
its flag), so the command line and Python refuse the same value with the same message:
:class:`LogReading` (how every command reads its logs: ``--columns``, ``--repair``,
``--cutoff``, ``--accept``, ``--topic``, ``--effort``, ``--payload``, ``--from``/``--to``:
the payload given replaces the one the log's controller logged, which is used otherwise, and
the model's; the window is seconds on the log's own time axis; :meth:`LogReading.parse` takes
them as the flags give them), :class:`IdentifyOptions`, :class:`EnergyOptions`,
:class:`SimulateOptions`, :class:`FleetOptions`, :class:`StreamOptions`,
:class:`RecordOptions`, ...

Each function returns the typed result the command prints; its ``to_dict()`` is the command's
``--json`` without the ``kinergy`` record of the command line (version, command, options) and
with the same ``inputs`` (each input log by content, with its checks), ``notes`` and
``warnings``.

=====================================  ======================================================
``read_log(path, reading, robot)``     a log read whole (through the plausibility checks when
                                       a robot is given)
``convert(log, out, to, robot)``       ``kinergy convert``: a log as a ROS 2 bag or a CSV,
                                       :class:`Converted`
``identify(logs, robot, options)``     ``kinergy identify``: :class:`IdentificationResult`
``identify_payload(logs, robot)``      ``kinergy identify --payload-only``: :class:`PayloadRun`
``validate(model, logs)``              ``kinergy validate``: :class:`ValidationReport`
``energy(model, log_or_motion)``       ``kinergy energy``: :class:`LogEnergy` of a log or motion
                                       file, :class:`EnergyReport` of a :class:`Motion`
``report(model, ...)``                 ``kinergy report``: :class:`StudyReport`
``simulate(robot, trajectory)``        ``kinergy simulate``: the twin's :class:`Simulation`
``optimize_program(model, prog)``      ``kinergy optimize``: a URScript program's or a task's
                                       energy-optimal version at the same cycle time
``place(robot, program, grid)``        ``kinergy place``: :class:`PlaceRun`
``record(address, out)``               ``kinergy record``: :class:`Recording`
``monitor(address, robot)``            ``kinergy monitor``: :class:`MonitorRun`
``fleet_energy(logs, manifest, out)``  ``kinergy fleet energy``: :class:`FleetResult`
``excite(robot, options)``             ``kinergy excite``: :class:`ExciteRun`
``nursing_study(robot, options)``      ``kinergy nursing``: :class:`NursingStudy`
``demo(out)``                          ``kinergy demo``: :class:`DemoRun`
``robot_list()``                       ``kinergy robot list``
``robot_show(robot)``                  ``kinergy robot show``
``import_calibration(robot, file)``    ``kinergy robot import-calibration``
``export_robot(model, format, out)``   ``kinergy robot export``
``import_urdf(urdf, out)``             ``kinergy robot import-urdf``
=====================================  ======================================================

Names are imported on first use (PEP 562), so a command loads only what it calls.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

#: public name -> module that defines it
_API = {
    # functions, one per command
    "read_log": "kinergy.api.logs",
    "convert": "kinergy.api.logs",
    "identify": "kinergy.api.logs",
    "identify_payload": "kinergy.api.logs",
    "validate": "kinergy.api.logs",
    "energy": "kinergy.api.logs",
    "report": "kinergy.api.logs",
    "simulate": "kinergy.api.twin",
    "excite": "kinergy.api.twin",
    "nursing_study": "kinergy.api.twin",
    "demo": "kinergy.api.twin",
    "optimize_program": "kinergy.api.optimize",
    "place": "kinergy.api.optimize",
    "MAX_POINTS": "kinergy.api.optimize",
    "PLOT_POINTS": "kinergy.api.optimize",
    "record": "kinergy.api.live",
    "monitor": "kinergy.api.live",
    "fleet_energy": "kinergy.api.live",
    "robot_list": "kinergy.api.robots",
    "robot_show": "kinergy.api.robots",
    "import_calibration": "kinergy.api.robots",
    "export_robot": "kinergy.api.robots",
    "import_urdf": "kinergy.api.robots",
    # the options they take
    "LogReading": "kinergy.logs.reading",
    "LogKind": "kinergy.workflows.convert",
    "IdentifyOptions": "kinergy.identification.options",
    "Method": "kinergy.identification.options",
    "Target": "kinergy.identification.options",
    "Solver": "kinergy.identification.options",
    "EnergyOptions": "kinergy.workflows.energy",
    "MotionSource": "kinergy.trajectory.motion",
    "Mismatch": "kinergy.twin",
    "SimulateOptions": "kinergy.workflows.twin",
    "FleetOptions": "kinergy.workflows.fleet",
    "ProgramOptions": "kinergy.optimize.options",
    "Configurations": "kinergy.optimize.options",
    "ToolSymmetry": "kinergy.optimize.options",
    "ViaPoints": "kinergy.optimize.options",
    "PlacementGrid": "kinergy.optimize.placement",
    "Range": "kinergy.optimize.placement",
    "ExportFormat": "kinergy.workflows.robots",
    "ExciteOptions": "kinergy.workflows.excite",
    "FloorFrames": "kinergy.workflows.excite",
    "NursingStudyOptions": "kinergy.workflows.nursing",
    "StreamOptions": "kinergy.live.stream",
    "RecordOptions": "kinergy.live.stream",
    # the results they return
    "IdentificationResult": "kinergy.identification.result",
    "Converted": "kinergy.workflows.convert",
    "PayloadRun": "kinergy.workflows.identify",
    "ValidationReport": "kinergy.identification.validation",
    "LogEnergy": "kinergy.workflows.energy",
    "EnergyReport": "kinergy.accounting.energy",
    "StudyReport": "kinergy.workflows.study",
    "Simulation": "kinergy.workflows.twin",
    "OptimizeRun": "kinergy.workflows.optimize",
    "Recording": "kinergy.live.recorder",
    "MonitorRun": "kinergy.workflows.monitor",
    "CycleEnergy": "kinergy.live.monitor",
    "FleetResult": "kinergy.fleet.summary",
    "ExciteRun": "kinergy.workflows.excite",
    "NursingStudy": "kinergy.workflows.nursing",
    "DemoRun": "kinergy.workflows.demo",
    "PlaceRun": "kinergy.workflows.place",
    "LibraryRobot": "kinergy.workflows.robots",
    "RobotFile": "kinergy.workflows.robots",
    "UrdfImport": "kinergy.model.urdf",
    "CalibrationImport": "kinergy.workflows.calibration",
    "Export": "kinergy.model.export",
}

__all__ = [
    "MAX_POINTS",
    "PLOT_POINTS",
    "CalibrationImport",
    "Configurations",
    "Converted",
    "CycleEnergy",
    "DemoRun",
    "EnergyOptions",
    "EnergyReport",
    "ExciteOptions",
    "ExciteRun",
    "Export",
    "ExportFormat",
    "FleetOptions",
    "FleetResult",
    "FloorFrames",
    "IdentificationResult",
    "IdentifyOptions",
    "LibraryRobot",
    "LogEnergy",
    "LogKind",
    "LogReading",
    "Method",
    "Mismatch",
    "MonitorRun",
    "MotionSource",
    "NursingStudy",
    "NursingStudyOptions",
    "OptimizeRun",
    "PayloadRun",
    "PlaceRun",
    "PlacementGrid",
    "ProgramOptions",
    "Range",
    "RecordOptions",
    "Recording",
    "RobotFile",
    "SimulateOptions",
    "Simulation",
    "Solver",
    "StreamOptions",
    "StudyReport",
    "Target",
    "ToolSymmetry",
    "UrdfImport",
    "ValidationReport",
    "ViaPoints",
    "convert",
    "demo",
    "energy",
    "excite",
    "export_robot",
    "fleet_energy",
    "identify",
    "identify_payload",
    "import_calibration",
    "import_urdf",
    "monitor",
    "nursing_study",
    "optimize_program",
    "place",
    "read_log",
    "record",
    "report",
    "robot_list",
    "robot_show",
    "simulate",
    "validate",
]

if TYPE_CHECKING:  # pragma: no cover - for type checkers and IDEs only
    from kinergy.accounting.energy import EnergyReport
    from kinergy.api.live import fleet_energy, monitor, record
    from kinergy.api.logs import (
        convert,
        energy,
        identify,
        identify_payload,
        read_log,
        report,
        validate,
    )
    from kinergy.api.optimize import MAX_POINTS, PLOT_POINTS, optimize_program, place
    from kinergy.api.robots import (
        export_robot,
        import_calibration,
        import_urdf,
        robot_list,
        robot_show,
    )
    from kinergy.api.twin import demo, excite, nursing_study, simulate
    from kinergy.fleet.summary import FleetResult
    from kinergy.identification.options import IdentifyOptions, Method, Solver, Target
    from kinergy.identification.result import IdentificationResult
    from kinergy.identification.validation import ValidationReport
    from kinergy.live.monitor import CycleEnergy
    from kinergy.live.recorder import Recording
    from kinergy.live.stream import RecordOptions, StreamOptions
    from kinergy.logs.reading import LogReading
    from kinergy.model.export import Export
    from kinergy.model.urdf import UrdfImport
    from kinergy.optimize.options import Configurations, ProgramOptions, ToolSymmetry, ViaPoints
    from kinergy.optimize.placement import PlacementGrid, Range
    from kinergy.trajectory.motion import MotionSource
    from kinergy.twin import Mismatch
    from kinergy.workflows.calibration import CalibrationImport
    from kinergy.workflows.convert import Converted, LogKind
    from kinergy.workflows.demo import DemoRun
    from kinergy.workflows.energy import EnergyOptions, LogEnergy
    from kinergy.workflows.excite import ExciteOptions, ExciteRun, FloorFrames
    from kinergy.workflows.fleet import FleetOptions
    from kinergy.workflows.identify import PayloadRun
    from kinergy.workflows.monitor import MonitorRun
    from kinergy.workflows.nursing import NursingStudy, NursingStudyOptions
    from kinergy.workflows.optimize import OptimizeRun
    from kinergy.workflows.place import PlaceRun
    from kinergy.workflows.robots import ExportFormat, LibraryRobot, RobotFile
    from kinergy.workflows.study import StudyReport
    from kinergy.workflows.twin import SimulateOptions, Simulation


def __getattr__(name: str) -> Any:
    """Import a public name's module on first use (PEP 562)."""
    module = _API.get(name)
    if module is None:
        raise AttributeError(f"module 'kinergy.api' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
