"""stewart-drake: model and verify Stewart platforms and their fixed-point controllers with Drake.

The public API is this package's top: ``import stewart_drake as sd``, then ``sd.load_platform``, ``sd.ik``,
``sd.fk``, ``sd.simulate``, ... (``__all__`` lists every public name; ``tests/api_snapshot.txt`` records their
signatures and ``CHANGELOG.md`` every change to them). Units are SI (metres, radians, seconds, newtons) and
poses are ``(..., 6)`` ``[px, py, pz, a, b, g]`` in the platform's Euler convention (``utn`` unless an argument
says otherwise). Everything below the top (``stewart_drake.core``, ``stewart_drake.drake``, ...) is internal
and may move between releases.

``import stewart_drake`` is light: the names are loaded when first used (module ``__getattr__``), so that the
numpy functions (``ik``, ``fk``, ``inverse_dynamics``, ``stiffness``, ...) work where pydrake is not installed and
only ``simulate``, ``montecarlo``, ``firmware.check``, ``report``, ``inspect_model`` and ``viewer_readout`` import
Drake.
"""

# First, before any other import: Ctrl-C from the first moment (``system.interrupts``): the command line, while
# it starts, ends at once with one line and status 130; a worker process it started ignores it.
from stewart_drake.system import interrupts  # isort: skip

interrupts.at_import()

import importlib  # noqa: E402
import sys  # noqa: E402
import types  # noqa: E402
import typing  # noqa: E402

# The same names as _PUBLIC, for type checkers and the docs (at run time each is loaded on first use).
if typing.TYPE_CHECKING:
    from stewart_drake.api import firmware
    from stewart_drake.api.calibration import CalibrateResult, PlanMeasurementsResult, calibrate, plan_measurements
    from stewart_drake.api.cross_check import CrossCheck, cross_check
    from stewart_drake.api.cueing import CueResult, cue
    from stewart_drake.api.design import ModesResult, StiffnessResult, modes, stiffness
    from stewart_drake.api.drawing import plot_platform
    from stewart_drake.api.dsp import DspIKResult, dsp_ik
    from stewart_drake.api.dynamics import DynamicsResult, inverse_dynamics
    from stewart_drake.api.kinematics import FKResult, FKSolution, IKResult, fk, ik
    from stewart_drake.api.leg import LegFKResult, LegIKResult, leg_fk, leg_ik
    from stewart_drake.api.model import ModelInspection, inspect_model
    from stewart_drake.api.platform import load_platform, presets
    from stewart_drake.api.reach import WorkspaceResult, workspace
    from stewart_drake.api.response import LoopResponse, loop_response
    from stewart_drake.api.servo import ServoResult, servo
    from stewart_drake.api.simulation import SimulationResult, simulate
    from stewart_drake.api.sizing import SizingResult, size
    from stewart_drake.api.tune import TuneResult, tune
    from stewart_drake.api.viewer import ViewerReadout, viewer_readout
    from stewart_drake.control.cueing.drive import Drive, load_drive
    from stewart_drake.control.cueing.generators import ship_drive
    from stewart_drake.core.geometry import Platform
    from stewart_drake.core.realtime_fk import RealtimeFK, RealtimeResult
    from stewart_drake.core.trajectory import Trajectory
    from stewart_drake.errors import PhysicalLimitError, StewartError, UsageError
    from stewart_drake.montecarlo.api import MonteCarloResult, montecarlo
    from stewart_drake.montecarlo.measurements_api import MeasurementsResult, simulate_measurements
    from stewart_drake.report.api import ReportResult, report
    from stewart_drake.spec import Machine, load_machine
    from stewart_drake.synthesis.api import OptimizeResult, WorkspaceProof, load_requirements, optimize, prove_workspace

__version__ = "0.4.1"


# public name -> (module that defines it, its name there). The module is imported on first use of the name:
# the Drake-backed names import pydrake at their module top, and the numpy names must work without it.
_PUBLIC = {
    "StewartError": ("stewart_drake.errors", "StewartError"),
    "UsageError": ("stewart_drake.errors", "UsageError"),
    "PhysicalLimitError": ("stewart_drake.errors", "PhysicalLimitError"),
    "Platform": ("stewart_drake.core.geometry", "Platform"),
    "load_platform": ("stewart_drake.api.platform", "load_platform"),
    "load_machine": ("stewart_drake.spec.load", "load_machine"),
    "Machine": ("stewart_drake.spec.machine", "Machine"),
    "presets": ("stewart_drake.api.platform", "presets"),
    "Trajectory": ("stewart_drake.core.trajectory", "Trajectory"),
    "ik": ("stewart_drake.api.kinematics", "ik"),
    "IKResult": ("stewart_drake.api.kinematics", "IKResult"),
    "fk": ("stewart_drake.api.kinematics", "fk"),
    "FKResult": ("stewart_drake.api.kinematics", "FKResult"),
    "FKSolution": ("stewart_drake.api.kinematics", "FKSolution"),
    "RealtimeFK": ("stewart_drake.core.realtime_fk", "RealtimeFK"),
    "RealtimeResult": ("stewart_drake.core.realtime_fk", "RealtimeResult"),
    "inverse_dynamics": ("stewart_drake.api.dynamics", "inverse_dynamics"),
    "DynamicsResult": ("stewart_drake.api.dynamics", "DynamicsResult"),
    "stiffness": ("stewart_drake.api.design", "stiffness"),
    "StiffnessResult": ("stewart_drake.api.design", "StiffnessResult"),
    "modes": ("stewart_drake.api.design", "modes"),
    "ModesResult": ("stewart_drake.api.design", "ModesResult"),
    "size": ("stewart_drake.api.sizing", "size"),
    "SizingResult": ("stewart_drake.api.sizing", "SizingResult"),
    "workspace": ("stewart_drake.api.reach", "workspace"),
    "WorkspaceResult": ("stewart_drake.api.reach", "WorkspaceResult"),
    "simulate": ("stewart_drake.api.simulation", "simulate"),
    "loop_response": ("stewart_drake.api.response", "loop_response"),
    "LoopResponse": ("stewart_drake.api.response", "LoopResponse"),
    "tune": ("stewart_drake.api.tune", "tune"),
    "TuneResult": ("stewart_drake.api.tune", "TuneResult"),
    "SimulationResult": ("stewart_drake.api.simulation", "SimulationResult"),
    "montecarlo": ("stewart_drake.montecarlo.api", "montecarlo"),
    "MonteCarloResult": ("stewart_drake.montecarlo.api", "MonteCarloResult"),
    "firmware": ("stewart_drake.api.firmware", None),
    "report": ("stewart_drake.report.api", "report"),
    "ReportResult": ("stewart_drake.report.api", "ReportResult"),
    "calibrate": ("stewart_drake.api.calibration", "calibrate"),
    "CalibrateResult": ("stewart_drake.api.calibration", "CalibrateResult"),
    "plan_measurements": ("stewart_drake.api.calibration", "plan_measurements"),
    "PlanMeasurementsResult": ("stewart_drake.api.calibration", "PlanMeasurementsResult"),
    "simulate_measurements": ("stewart_drake.montecarlo.measurements_api", "simulate_measurements"),
    "MeasurementsResult": ("stewart_drake.montecarlo.measurements_api", "MeasurementsResult"),
    "load_requirements": ("stewart_drake.synthesis.api", "load_requirements"),
    "optimize": ("stewart_drake.synthesis.api", "optimize"),
    "OptimizeResult": ("stewart_drake.synthesis.api", "OptimizeResult"),
    "prove_workspace": ("stewart_drake.synthesis.api", "prove_workspace"),
    "WorkspaceProof": ("stewart_drake.synthesis.api", "WorkspaceProof"),
    "dsp_ik": ("stewart_drake.api.dsp", "dsp_ik"),
    "DspIKResult": ("stewart_drake.api.dsp", "DspIKResult"),
    "servo": ("stewart_drake.api.servo", "servo"),
    "ServoResult": ("stewart_drake.api.servo", "ServoResult"),
    "leg_fk": ("stewart_drake.api.leg", "leg_fk"),
    "LegFKResult": ("stewart_drake.api.leg", "LegFKResult"),
    "leg_ik": ("stewart_drake.api.leg", "leg_ik"),
    "LegIKResult": ("stewart_drake.api.leg", "LegIKResult"),
    "inspect_model": ("stewart_drake.api.model", "inspect_model"),
    "cross_check": ("stewart_drake.api.cross_check", "cross_check"),
    "cue": ("stewart_drake.api.cueing", "cue"),
    "CueResult": ("stewart_drake.api.cueing", "CueResult"),
    "Drive": ("stewart_drake.control.cueing.drive", "Drive"),
    "load_drive": ("stewart_drake.control.cueing.drive", "load_drive"),
    "ship_drive": ("stewart_drake.control.cueing.generators", "ship_drive"),
    "CrossCheck": ("stewart_drake.api.cross_check", "CrossCheck"),
    "ModelInspection": ("stewart_drake.api.model", "ModelInspection"),
    "viewer_readout": ("stewart_drake.api.viewer", "viewer_readout"),
    "ViewerReadout": ("stewart_drake.api.viewer", "ViewerReadout"),
    "plot_platform": ("stewart_drake.api.drawing", "plot_platform"),
}

__all__ = [
    "__version__",
    "StewartError",
    "UsageError",
    "PhysicalLimitError",
    "Platform",
    "load_platform",
    "load_machine",
    "Machine",
    "presets",
    "Trajectory",
    "ik",
    "IKResult",
    "fk",
    "FKResult",
    "FKSolution",
    "RealtimeFK",
    "RealtimeResult",
    "inverse_dynamics",
    "DynamicsResult",
    "stiffness",
    "StiffnessResult",
    "modes",
    "ModesResult",
    "size",
    "SizingResult",
    "workspace",
    "WorkspaceResult",
    "simulate",
    "SimulationResult",
    "loop_response",
    "LoopResponse",
    "tune",
    "TuneResult",
    "montecarlo",
    "MonteCarloResult",
    "firmware",
    "report",
    "ReportResult",
    "calibrate",
    "CalibrateResult",
    "plan_measurements",
    "PlanMeasurementsResult",
    "simulate_measurements",
    "MeasurementsResult",
    "load_requirements",
    "optimize",
    "OptimizeResult",
    "prove_workspace",
    "WorkspaceProof",
    "dsp_ik",
    "DspIKResult",
    "servo",
    "ServoResult",
    "leg_fk",
    "LegFKResult",
    "leg_ik",
    "LegIKResult",
    "inspect_model",
    "ModelInspection",
    "cross_check",
    "CrossCheck",
    "cue",
    "CueResult",
    "Drive",
    "load_drive",
    "ship_drive",
    "viewer_readout",
    "ViewerReadout",
    "plot_platform",
]

# Public names that are also the names of internal subpackages (stewart_drake.workspace, .montecarlo, .report,
# .firmware): ``sd.workspace`` is a ``_Shadow``, the public function (or namespace) that also passes attribute
# access on to the subpackage, so that ``from stewart_drake import workspace as ws; ws.Limits`` keeps working.
_SHADOWED = frozenset({"workspace", "montecarlo", "report", "firmware"})


class _Shadow:
    """The public object of a name that is also an internal subpackage. Calling it calls the public function;
    an attribute is the public object's (``firmware.generate``, ``firmware.check``) if it has one, else the
    subpackage's (imported on first use). ``inspect.signature`` and ``help`` see the public object."""

    def __init__(self, public, package: str):
        object.__setattr__(self, "__public__", public)
        object.__setattr__(self, "__package_name__", package)
        for attr in ("__doc__", "__name__", "__qualname__", "__module__"):
            object.__setattr__(self, attr, getattr(public, attr, None))
        if callable(public):
            object.__setattr__(self, "__wrapped__", public)

    def __call__(self, *args, **kwargs):
        return self.__public__(*args, **kwargs)

    def _package(self):
        return importlib.import_module(self.__package_name__)

    def __getattr__(self, name: str):
        try:
            return getattr(self.__public__, name)
        except AttributeError:
            return getattr(self._package(), name)

    def __setattr__(self, name: str, value) -> None:  # a test's monkeypatch reaches the subpackage
        setattr(self._package(), name, value)

    def __delattr__(self, name: str) -> None:
        delattr(self._package(), name)

    def __dir__(self) -> list[str]:
        return sorted(set(dir(self.__public__)) | set(dir(self._package())))

    def __repr__(self) -> str:
        return f"<stewart_drake.{self.__public__.__name__.rsplit('.', 1)[-1]}: {self.__public__!r}>"


def __getattr__(name: str):
    """Load a public name on first use (see ``_PUBLIC``) and keep it."""
    if name not in _PUBLIC:
        raise AttributeError(f"module 'stewart_drake' has no attribute {name!r}")
    module_name, attr = _PUBLIC[name]
    module = importlib.import_module(module_name)
    value = module if attr is None else getattr(module, attr)
    if name in _SHADOWED:
        value = _Shadow(value, f"{__name__}.{name}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


class _Package(types.ModuleType):
    """This package's module type: the import system's binding of a subpackage named like a public name
    (``_SHADOWED``) is not kept, so that ``sd.workspace`` stays the public ``_Shadow`` after
    ``stewart_drake.workspace`` (the package) has been imported."""

    def __setattr__(self, name: str, value) -> None:
        if name in _SHADOWED and isinstance(value, types.ModuleType) and value.__name__ == f"{__name__}.{name}":
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package
