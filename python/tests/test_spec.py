"""The motion specification from Python, in-process: load_urdf, RobotModel,
Kinematics against the C++ figures (fk_reference, the same Kinematics run
from C++), plus the package's own shape: stubs, help(), reprs, text forms."""

from __future__ import annotations

import pydoc
import re
import subprocess
import warnings
from pathlib import Path
from typing import Dict, List, Tuple

import numpy as np
import pytest

import robotalk
from robotalk import _robotalk
from conftest import MODELS, program, shared_robot

SHARED_ROBOTS = ["iiwa14.urdf", "ur5.urdf", "atlas.urdf", "pr2.urdf", "romeo.urdf", "pioneer_lx_ptu_jaco2.urdf"]


def test_pioneer_model_by_name_and_index() -> None:
    model = robotalk.load_urdf(MODELS / "pioneer2dx_pantilt.urdf")
    assert repr(model) == "<RobotModel 'pioneer2dx_pantilt': 7 links, 6 joints, 4 dofs, 1 control frames>"
    pan = model.joint("pan")
    assert model.joint(model.joint_index("pan")).name == "pan" and pan.num_dofs == 1
    assert model.find_joint("nek") is None and model.find_link(model.links[0].name) == 0
    assert model.dof_offset("pan") == 2 and model.parent_joint(model.links[0].name) == -1
    assert model.frame(0).name == "camera" and model.frame("camera").pose.shape == (7,)
    assert model.roots[0].base == "differential"
    assert pan.dofs[0].type == "revolute" and pan.dofs[0].upper == pytest.approx(2.775)
    with pytest.raises(robotalk.LookupError, match="robot 'pioneer2dx_pantilt' has no joint named 'nek'"):
        model.joint("nek")
    with pytest.raises(LookupError, match="no link with index 99"):
        model.link(99)
    merged = robotalk.load_urdf(MODELS / "pioneer2dx_pantilt.urdf", merge_massless_chains=True)
    assert merged.find_joint("pan+tilt") is not None


def test_urdf_errors_and_warnings(tmp_path: Path) -> None:
    with pytest.raises(robotalk.UrdfError, match="missing.urdf"):
        robotalk.load_urdf(tmp_path / "missing.urdf")
    with pytest.raises(robotalk.UrdfError):
        robotalk.parse_urdf("<robot name='x'><link name='a'/><joint name='j' type='fixed'>"
                            "<parent link='a'/><child link='b'/></joint></robot>")
    lx = shared_robot("pioneer_lx_ptu_jaco2.urdf")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robotalk.load_urdf(lx)
    assert any("ptu_pan" in str(w.message) and w.category is robotalk.RobotalkWarning for w in caught)
    with pytest.raises(robotalk.UrdfError, match="ptu_pan"):
        robotalk.load_urdf(lx, strict=True)


def reference(urdf: Path, q: np.ndarray) -> Tuple[Dict[str, np.ndarray], np.ndarray, np.ndarray]:
    out = subprocess.run([program("ROBOTALK_FK_REFERENCE"), str(urdf), *[repr(float(x)) for x in q]],
                         check=True, capture_output=True, text=True).stdout
    poses: Dict[str, np.ndarray] = {}
    jacobian = com = np.zeros(0)
    for line in out.splitlines():
        words = line.split()
        if words[0] == "link":
            poses[words[1]] = np.array([float(x) for x in words[2:]]).reshape(4, 4)
        elif words[0] == "jacobian":
            jacobian = np.array([float(x) for x in words[2:]]).reshape(6, int(words[1]))
        elif words[0] == "com":
            com = np.array([float(x) for x in words[1:]])
    return poses, jacobian, com


def posture(model: robotalk.RobotModel) -> np.ndarray:
    """A posture inside every limit: 0.3 rad (or m) per dof, clipped."""
    q: List[float] = []
    for joint in model.joints:
        for k, dof in enumerate(joint.dofs):
            q.append(float(np.clip(0.3 * (k + 1) * (-1) ** len(q), dof.lower, dof.upper)))
    return np.array(q)


@pytest.mark.parametrize("name", SHARED_ROBOTS)
def test_forward_kinematics_equals_the_cpp_figures(name: str) -> None:
    urdf = shared_robot(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", robotalk.RobotalkWarning)
        model = robotalk.load_urdf(urdf)
    q = posture(model)
    poses, jacobian, com = reference(urdf, q)
    kin = robotalk.Kinematics(model)
    kin.update(q)
    assert set(poses) == {link.name for link in model.links}
    all_poses = kin.link_poses()
    for i, link in enumerate(model.links):
        np.testing.assert_allclose(kin.link_pose(link.name), poses[link.name], rtol=0, atol=1e-12)
        np.testing.assert_array_equal(all_poses[i], kin.link_pose(i))
    last = len(model.links) - 1
    np.testing.assert_allclose(kin.point_jacobian(last), jacobian, rtol=0, atol=1e-12)
    np.testing.assert_allclose(kin.center_of_mass(), com, rtol=0, atol=1e-12)


def test_iiwa14_flange_height_and_jacobian_by_finite_differences() -> None:
    model = robotalk.load_urdf(shared_robot("iiwa14.urdf"))
    kin = robotalk.Kinematics(model)
    kin.update(np.zeros(7))
    # The sum of the link offsets along z: 0.1575 + 0.2025 + 0.2045 + 0.2155 + 0.1845 + 0.2155 + 0.081 + 0.045.
    assert kin.link_pose("iiwa_link_ee")[:3, 3] == pytest.approx([0, 0, 1.306], abs=1e-12)
    q = np.array([0.1, -0.4, 0.3, 1.1, -0.2, 0.5, 0.7])
    kin.update(q)
    ee = model.link_index("iiwa_link_ee")
    j = kin.point_jacobian(ee)
    h = 1e-7
    for k in range(7):
        dq = q.copy()
        dq[k] += h
        kin.update(dq)
        plus = kin.link_pose(ee)[:3, 3].copy()
        dq[k] -= 2 * h
        kin.update(dq)
        minus = kin.link_pose(ee)[:3, 3]
        np.testing.assert_allclose((plus - minus) / (2 * h), j[:3, k], atol=1e-6)
    with pytest.raises(robotalk.RobotalkError, match="q has 3 entries, expected 7"):
        kin.update(np.zeros(3))
    with pytest.raises(robotalk.RobotalkError, match="not a rigid transform"):
        kin.update(np.zeros(7), root_poses=[np.zeros((4, 4))])


def test_commands_and_sequences_in_text() -> None:
    c = robotalk.Command.parse("joint_setpoint pan 0.5")
    assert (c.type, c.target, c.values.tolist(), c.start) == ("JOINT_SETPOINT", "pan", [0.5], None)
    assert repr(robotalk.Command("GOTO", values=[1, 0, 0], start=12.5)) == "<Command goto 1 0 0 at 12.500000 s>"
    frames = robotalk.parse_sequence("0 goto 1 0 0\n0.5 stop\n")
    assert [(f.offset, str(f.command)) for f in frames] == [(0.0, "goto 1 0 0"), (0.5, "stop")]
    assert robotalk.format_sequence(frames).splitlines()[-1] == "0.500000 stop"
    with pytest.raises(robotalk.UsageError, match="<string>:1"):
        robotalk.parse_sequence("0 goto 1\n")
    with pytest.raises(ValueError):  # UsageError is a ValueError too
        robotalk.Command.parse("fly 1 2")


def test_stubs_name_everything_the_module_has() -> None:
    stub = (Path(robotalk.__file__).parent / "_robotalk.pyi").read_text()
    stubbed = set(re.findall(r"^(?:class|def) (\w+)", stub, re.M))
    public = {n for n in dir(_robotalk) if not n.startswith("__")}
    assert public == stubbed, (public - stubbed, stubbed - public)
    for cls in [c for c in vars(_robotalk).values() if isinstance(c, type) and not issubclass(c, BaseException)]:
        members = {m for m in vars(cls) if not m.startswith("__") or m == "__len__"}
        body = stub.split(f"class {cls.__name__}", 1)[1].split("\nclass ", 1)[0]
        missing = {m for m in members if not re.search(rf"def {m}\b|^\s+{m}:", body, re.M)}
        assert not missing, (cls.__name__, missing)


def test_help_is_readable() -> None:
    text = pydoc.render_doc(robotalk.RobotClient, renderer=pydoc.plaintext)
    for words in ("goto(", "GOTO: drive the base", "state_stream(", "KeyboardInterrupt", "wait=True"):
        assert words in text, words
    assert robotalk.Kinematics.__doc__ and "Jacobian" in robotalk.Kinematics.__doc__


def test_a_damaged_log_is_read_with_its_damage_named(tmp_path: Path) -> None:
    """Review9: an event header declaring 2^31 - 1 data bytes crashed the
    interpreter in log_info (LCM's reader); now the damage is named and every
    intact event is read."""
    import struct
    events = [struct.pack(">IqqII", 0xEDA1DA01, n, 1000 * n, 2, 100) + b"CH" + bytes([n]) * 100 for n in range(4)]
    damaged = bytearray(b"".join(events))
    at = 2 * len(events[0]) + 24  # event 2's data length
    damaged[at:at + 4] = b"\x7f\xff\xff\xff"
    log = tmp_path / "damaged.lcmlog"
    log.write_bytes(bytes(damaged))
    info = robotalk.log_info(str(log))
    assert info["events"] == 3 and info["rejections"] == 1
    assert "2147483647 data bytes" in info["rejected"][0] and f"byte {2 * len(events[0])}" in info["rejected"][0]


def test_a_logs_channel_names_come_back_in_printable_ascii(tmp_path: Path) -> None:
    """Review 12: a log's channel names are anyone's bytes. One that is not
    UTF-8 made log_info raise UnicodeDecodeError for the whole log, and one
    with a terminal escape came back raw; now every byte outside printable
    ASCII is written \\xNN and the event still counts."""
    import struct
    events = b""
    for n, channel in enumerate((b"OTHER\xe9", b"OTHER\x1b]0;")):
        events += struct.pack(">IqqII", 0xEDA1DA01, n, 1000 * (n + 1), len(channel), 1) + channel + b"x"
    log = tmp_path / "hostile.lcmlog"
    log.write_bytes(events)
    info = robotalk.log_info(str(log))
    assert info["events"] == 2
    assert sorted(info["channels"]) == ["OTHER\\x1b]0;", "OTHER\\xe9"]


def test_texts_not_utf8_cross_into_python_escaped() -> None:
    # Every std::string the bindings hand to Python is decoded with
    # backslashreplace (python/src/py_text.h): a command's target (as
    # robotalk.extract returns them from a log), its text forms, and an
    # exception's message, never UnicodeDecodeError.
    for raw, shown in ((b"\xff\xfe", r"\xff\xfe"), (b"pa\xe2\x82", r"pa\xe2\x82")):
        c = robotalk.Command("JOINT_SETPOINT", raw, [0.1])  # type: ignore[arg-type]
        assert c.target == shown
        assert str(c).startswith(f"joint_setpoint {shown} 0.1") and shown in repr(c)
        with pytest.raises(robotalk.UsageError) as e:
            robotalk.Command(raw)  # type: ignore[arg-type]
        assert str(e.value).startswith(f"unknown command type '{shown}' (")
