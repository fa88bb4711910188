"""The machine as one typed spec (``machine``), read from YAML with overrides by path (``load``), and the one
grammar of quantities in files and options (``quantity``)."""

from stewart_drake.spec.load import apply_overrides, load_machine, machine_yaml
from stewart_drake.spec.machine import (
    ActuatorSpec,
    ControllerSpec,
    FirmwareFormat,
    Gains,
    Machine,
    PayloadSpec,
    RunSpec,
    SensorSpec,
)
from stewart_drake.spec.quantity import Quantity, parse_number, parse_quantity

__all__ = [
    "ActuatorSpec",
    "ControllerSpec",
    "FirmwareFormat",
    "Gains",
    "Machine",
    "PayloadSpec",
    "Quantity",
    "RunSpec",
    "SensorSpec",
    "apply_overrides",
    "load_machine",
    "machine_yaml",
    "parse_number",
    "parse_quantity",
]
