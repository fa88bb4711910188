"""The machine spec: typed fields checked on construction (errors name the spec path), loaded from YAML
with the file's line numbers, overrides by path in the quantity grammar, and a YAML round trip."""

from __future__ import annotations

import dataclasses

import pytest
import yaml

from stewart_drake.control.gains import ControllerConfig
from stewart_drake.core.geometry import load_preset, preset_path
from stewart_drake.errors import MachineError, QuantityError
from stewart_drake.spec import ControllerSpec, FirmwareFormat, Machine, PayloadSpec, load_machine
from stewart_drake.spec.machine import FIELDS
from tests._own_platform import NEWCOMER_PLATFORM

PLATFORM = NEWCOMER_PLATFORM
SECTIONS = """\
payload: {mass: 150kg, position: [0, 0, 50mm]}
controller:
  period: 0.5ms
  latency: computation
firmware: {word_bits: 24, length_lsb: 30um, trig: exact}
sensors: {resolution: 10um}
motions: [rotating]
"""


def write(tmp_path, text, name="machine.yaml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_the_default_format_is_the_controllers():
    # the one home of the format: its defaults are the loop's (the DSP's 16-bit words, 1 mm, tfr16)
    assert FirmwareFormat().qformat() == ControllerConfig().ik_format
    assert FirmwareFormat().convention == ControllerConfig().convention


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (lambda: ControllerSpec(period=-1), "controller.period must be > 0 s, got -1"),
        (
            lambda: ControllerSpec(latency="late"),
            "controller.latency must be one of sample, computation, none, got late",
        ),
        (lambda: FirmwareFormat(word_bits=40), "firmware.word_bits must be an integer 8..31, got 40"),
        (
            lambda: FirmwareFormat(word_bits=24),
            "firmware.word_bits must be 16 with trig tfr16 (use trig exact), got 24",
        ),
        (lambda: FirmwareFormat(length_lsb=0.0), "firmware.length_lsb must be > 0 m, got 0"),
        (
            lambda: PayloadSpec(mass=1.0, position=(0, 0, -0.1)),
            "payload.position must be at z >= 0 (on the plate), got [0.0, 0.0, -0.1]",
        ),
    ],
)
def test_fields_are_checked_on_construction(build, message):
    with pytest.raises(MachineError) as e:
        build()
    assert str(e.value) == message


def test_a_plain_platform_file_is_a_machine(tmp_path):
    m = load_machine(write(tmp_path, PLATFORM))
    assert m.controller == ControllerSpec() and m.firmware == FirmwareFormat() and m.motions == ("seed",)
    assert m.platform.mass == 60.0 and m.loaded_platform is m.platform
    assert load_machine(preset_path("utn-dynamic")).platform.name == "utn-dynamic"
    assert load_machine("utn-dynamic").platform_source == "utn-dynamic"


def test_sections_are_read_in_the_quantity_grammar(tmp_path):
    m = load_machine(write(tmp_path, PLATFORM + SECTIONS))
    assert m.controller.period == 0.0005 and m.controller.latency == "computation"
    assert m.firmware == FirmwareFormat(24, 0.00003, "exact", "utn")
    assert m.sensors.resolution == 1e-05
    assert m.motions == ("rotating",)
    # the payload is the plant's and the design's: 60 kg plate + 150 kg at 50 mm above the plate frame
    assert m.loaded_platform.mass == 210.0
    assert m.loaded_platform.com[2] == pytest.approx(0.05, rel=1e-12)  # both masses' centres at z = 50 mm


def test_the_platform_under_platform_as_a_preset_or_inline(tmp_path):
    m = load_machine(write(tmp_path, "platform: utn-dynamic\ncontroller: {period: 2ms}\n"))
    assert m.platform.name == "utn-dynamic" and m.controller.period == 0.002
    inline = "platform:\n" + "".join("  " + line + "\n" for line in PLATFORM.splitlines())
    assert load_machine(write(tmp_path, inline, "inline.yaml")).platform.name == "newcomer-6dof-sim"


def test_errors_name_the_file_line_and_path(tmp_path):
    p = write(tmp_path, PLATFORM + "controller:\n  period: -1ms\n")
    with pytest.raises(MachineError, match=rf"^{p}:13: controller.period must be > 0 s, got -1ms$"):
        load_machine(p)
    p = write(tmp_path, PLATFORM + "controller:\n  perod: 1ms\n", "typo.yaml")
    with pytest.raises(MachineError, match=rf"^{p}:13: unknown key 'controller.perod' \(did you mean 'period'\?\)$"):
        load_machine(p)
    p = write(tmp_path, PLATFORM + "firmwre: {word_bits: 16}\n", "top.yaml")
    with pytest.raises(MachineError, match=rf"^{p}:12: unknown key 'firmwre' \(did you mean 'firmware'\?\)$"):
        load_machine(p)
    p = write(tmp_path, PLATFORM + "firmware: {length_lsb: 30 parsecs}\n", "unit.yaml")
    with pytest.raises(QuantityError, match=rf"^{p}:12: firmware.length_lsb: cannot read '30 parsecs'"):
        load_machine(p)


def test_overrides_by_path():
    m = load_machine("utn-dynamic", ["controller.period=0.5ms", "firmware.length_lsb=30um", "firmware.trig=exact"])
    assert (m.controller.period, m.firmware.length_lsb, m.firmware.trig) == (0.0005, 0.00003, "exact")
    assert load_machine(m, {"controller.feedforward": "false"}).controller.feedforward is False
    with pytest.raises(MachineError, match=r"^controller.period must be > 0 s, got -1$"):
        load_machine("utn-dynamic", ["controller.period=-1"])
    with pytest.raises(MachineError, match=r"^unknown key 'controller.perod' \(did you mean 'controller.period'\?\)$"):
        load_machine("utn-dynamic", ["controller.perod=1ms"])
    with pytest.raises(MachineError, match=r"is not PATH=VALUE"):
        load_machine("utn-dynamic", ["controller.period"])


def test_yaml_round_trip(tmp_path):
    m = load_machine(write(tmp_path, PLATFORM + SECTIONS))
    back = load_machine(yaml.safe_load(m.to_yaml()))
    assert back.to_yaml() == m.to_yaml()
    for name in ("controller", "firmware", "sensors", "actuators", "payload", "run", "motions"):
        assert getattr(back, name) == getattr(m, name)
    assert back.loaded_platform.mass == m.loaded_platform.mass


def test_a_machine_is_frozen():
    m = Machine(load_preset("utn-dynamic"))
    with pytest.raises(dataclasses.FrozenInstanceError):
        m.controller = ControllerSpec()


def test_the_machine_template_holds_every_section_at_its_default(tmp_path, capsys):
    from stewart_drake.cli import main

    assert main(["init", "--machine-template"]) == 0
    path = write(tmp_path, capsys.readouterr().out, "template.yaml")
    m = load_machine(path)
    default = Machine(m.platform)
    for name in ("actuators", "sensors", "controller", "firmware", "payload", "run", "motions"):
        assert getattr(m, name) == getattr(default, name), name
    text = path.read_text()
    # every overridable path is written in the template, so that it shows the user every field
    for path in FIELDS:
        section, field = path.split(".")
        assert f"\n{section}:" in text and f"\n  {field}:" in text, path


def test_a_mapping_may_hold_a_platform_object():
    p = load_preset("utn-dynamic")
    m = load_machine({"platform": p, "controller": {"period": "2ms"}, "firmware": {"length_lsb": "0.5mm"}})
    assert m.platform is p and m.controller.period == 0.002 and m.firmware.length_lsb == 0.0005
    assert load_machine({"platform": p}).platform is p
    with pytest.raises(MachineError, match=r"unknown key 'controler' \(did you mean 'controller'\?\)"):
        load_machine({"platform": p, "controler": {"period": "2ms"}})


def test_every_section_field_has_a_path_in_the_grammar():
    from stewart_drake.spec.machine import SECTIONS

    paths = {f"{name}.{f.name}" for name, tp in SECTIONS.items() for f in dataclasses.fields(tp)}
    assert paths == set(FIELDS)


def test_a_machine_takes_a_platform_object():
    with pytest.raises(
        MachineError, match=r"^platform must be a Platform \(load_machine reads names and files\), got str$"
    ):
        Machine("utn-dynamic")


@pytest.mark.parametrize(
    ("tail", "message"),
    [
        ("[a, b]: 1\n", ":12: a key must be a name, got a list"),
        ("motions: [circle]\n", ":12: motions item 1: 'circle' is not seed, rotating, a .csv file or a .stw script"),
        ("requirements: {a: 1}\n", ":12: requirements must be a file path or null, got a mapping"),
        ("controller: {period: null}\n", ":12: controller.period: cannot read 'null' as a number"),
        ("controller: {gains: {kp: 1}}\n", ":12: controller.gains must be design, tune or {kp, ki, kd, kv}, got"),
        ("run: {fit: maybe}\n", ":12: run.fit: 'maybe' is not one of true, false"),
        ("controller: [1, 2]\n", ":12: controller must be a mapping of key: value, got a list"),
    ],
)
def test_a_bad_machine_file_is_one_line_naming_file_line_and_path(tmp_path, tail, message):
    p = write(tmp_path, PLATFORM + tail)
    with pytest.raises((MachineError, QuantityError)) as e:
        load_machine(p)
    assert str(e.value).startswith(f"{p}{message}"), str(e.value)


def test_a_sections_overrides_are_checked_together():
    # 24-bit words need the exact trig: given together, in either order, they are one valid format
    for words in (["firmware.word_bits=24", "firmware.trig=exact"], ["firmware.trig=exact", "firmware.word_bits=24"]):
        assert load_machine("utn-dynamic", words).firmware == FirmwareFormat(24, 1e-3, "exact", "utn")
    with pytest.raises(
        MachineError, match=r"^firmware.word_bits must be 16 with trig tfr16 \(use trig exact\), got 24$"
    ):
        load_machine("utn-dynamic", ["firmware.word_bits=24"])


def test_a_format_that_cannot_hold_the_stroke_is_refused():
    """16-bit words at 20 µm hold 32767 × 20 µm = 0.655 m, less than utn-dynamic's 0.95 m stroke end: a loop's
    set-point word would clamp (the loop ran 75 mm below its reference without a word); 30 µm holds 0.983 m.
    The machine itself may hold such a format (a certificate finds the clamp); a closed loop refuses it
    (``tests/cli/test_simulate_machine.py``)."""
    from stewart_drake.errors import MachineError
    from stewart_drake.spec import load_machine

    fine = load_machine("utn-dynamic", ["firmware.length_lsb=20um"])
    with pytest.raises(MachineError, match=r"holds lengths up to 0\.65534 m, less than the stroke's end 0\.95 m"):
        fine.check_loop_format()
    load_machine("utn-dynamic", ["firmware.length_lsb=30um"]).check_loop_format()
