"""robotalk.RobotClient against a real robotalk-server (kinematic Pioneer and
iiwa14) in a private network namespace: connect, describe, every command's
signals, blocking and non-blocking calls, queries, errors."""

from __future__ import annotations

import subprocess
import time

import numpy as np
import pytest

import robotalk
from conftest import MODELS, SHARED, Server, program


@pytest.fixture()
def robot(server: Server):  # type: ignore[no-untyped-def]
    with robotalk.connect("pioneer", server.url) as r:
        r.reset_panic()
        yield r


def test_robots_lists_what_the_server_announces(server: Server) -> None:
    found = {r.name: r for r in robotalk.robots(server.url, listen=1.2)}
    assert found["pioneer"].total_dofs == 4
    assert found["pioneer"].driver == "kinematic"
    assert found["pioneer"].base_type == "differential"
    assert "'pioneer'" in repr(found["pioneer"])


def test_robots_warns_of_a_flood_of_names_it_does_not_list(server: Server) -> None:
    forger = subprocess.Popen([program("ROBOTALK_FORGE"), server.url, "announce-names", "flood", "1100", "4"])
    try:
        with pytest.warns(robotalk.RobotalkWarning, match=r"listing the first 1024 robots heard; [1-9]"):
            listed = robotalk.robots(server.url, listen=1.5)
    finally:
        forger.wait(timeout=10)
    assert len(listed) == 1024


def test_connects_and_describes_the_robot(robot: robotalk.RobotClient) -> None:
    assert robot.connected and robot.robot == "pioneer"
    model = robot.model
    assert model.num_dofs == 4
    assert model.dof_names == ["left_wheel_joint", "right_wheel_joint", "pan", "tilt"]
    assert [f.name for f in model.frames] == ["camera"]
    assert model == robotalk.load_urdf(robotalk_models("pioneer2dx_pantilt.urdf"), robot_name="pioneer")
    assert "of robot 'pioneer' (4 dofs)" in repr(robot)
    assert robot.clock_round_trip > 0
    assert abs(robot.server_now() - robot.query("CLOCK").exec_time) < 1.0


def robotalk_models(name: str) -> str:
    return str(MODELS / name)


def settle(robot: robotalk.RobotClient, joint: str, value: float) -> float:
    """Waits (at most 3 s) until `joint` reaches `value`: a set-point is answered
    at once, the kinematic driver then moves at the joint's velocity limit."""
    deadline = time.monotonic() + 3
    while True:
        q = float(robot.joint_state(joint).positions[0])
        if abs(q - value) < 1e-6 or time.monotonic() > deadline:
            return q
        time.sleep(0.02)


def test_every_command_answers_its_signal(robot: robotalk.RobotClient) -> None:
    assert robot.goto(0.3, 0.0, 0.0).signal == "SUCCESS"
    assert robot.set_joint("pan", [0.3]).signal == "SUCCESS"
    clamped = robot.set_joint("pan", [99.0])
    assert clamped.signal == "MODIFIED" and "clamped to the upper limit" in clamped.message
    unknown = robot.set_joint("nek", [0.3])
    assert unknown.signal == "ERROR" and unknown.message == "JOINT_SETPOINT: robot 'pioneer' has no joint named 'nek'"
    assert robot.set_joint("pan", [0.1, 0.2]).signal == "ERROR"
    assert robot.joint_speed("left_wheel_joint", [0.2]).signal == "SUCCESS"
    assert robot.joint_force("pan", [0.3]).signal == "NA"
    assert robot.frame_setpoint("camera", [0.3, 0, 0.39, 1, 0, 0, 0]).signal in ("SUCCESS", "MODIFIED")
    assert robot.set_speed(0.1, 0.0).signal == "SUCCESS"
    assert robot.stop().signal == "SUCCESS"
    assert robot.execute(robotalk.Command.parse("goto 0 0 0")).signal == "SUCCESS"
    # A GOTO interrupted by STOP, and one refused while another runs.
    first = robot.goto(2.0, 0.0, 0.0, wait=False)
    time.sleep(0.2)
    assert robot.goto(0.0, 1.0, 0.0).signal == "BUSY"
    assert robot.stop().signal == "SUCCESS"
    assert first.wait(5).signal == "INTERRUPTED"
    assert robot.goto(0.0, 0.0, 0.0).succeeded


def test_a_fixed_base_answers_na_and_a_data_query_raises_signal_error(server: Server) -> None:
    if not (SHARED / "iiwa14.urdf").exists():
        pytest.skip("no ../shared/robots/iiwa14.urdf")
    with robotalk.connect("iiwa", server.url) as arm:
        assert arm.goto(1, 0, 0).signal == "NA"
        assert arm.set_speed(0.1, 0).signal == "NA"
        with pytest.raises(robotalk.SignalError) as e:
            arm.link_poses("nek")
        assert e.value.reply.signal == "ERROR"
        assert str(e.value) == "LINK_POSES 'nek': ERROR: " + e.value.reply.message
        assert arm.set_joint("iiwa_joint_1", [0.5]).signal == "SUCCESS"
        assert settle(arm, "iiwa_joint_1", 0.5) == pytest.approx(0.5, abs=1e-6)


def test_non_blocking_calls_return_a_future_like_reply(robot: robotalk.RobotClient) -> None:
    start = robot.server_now() + 0.3
    pending = robot.set_joint("tilt", [-0.2], start=start, wait=False)
    assert not pending.done() and pending.poll() is None and "pending" in repr(pending)
    assert pending.wait_for(0.01) is None
    reply = pending.result(timeout=5)
    assert reply.signal == "SUCCESS" and pending.done() and pending.poll() is not None
    assert reply.exec_time >= start - 1e-3  # never early
    with pytest.raises(robotalk.RobotalkError, match="negative"):
        pending.wait(-1)
    batch = robot.send_batch([robotalk.Command("JOINT_SETPOINT", "pan", [0.1]), robotalk.Command("STOP")])
    assert [p.wait(5).signal for p in batch] == ["SUCCESS", "SUCCESS"]
    query = robot.query("BASE_POSE", wait=False)
    assert len(query.wait(5).values) == 5


def test_command_status_kind_tells_a_waiting_command_from_one_that_ended(robot: robotalk.RobotClient) -> None:
    ended = robot.set_joint("pan", [0.1])
    assert robotalk.command_status_kind(robot.command_status(ended.id), ended.id) == "ENDED"
    waiting = robot.set_joint("tilt", [-0.1], start=robot.server_now() + 30, wait=False)
    status = robot.command_status(waiting.id)
    assert status.signal == "BUSY" and robotalk.command_status_kind(status, waiting.id) == "NOT_ENDED"
    never = waiting.id + 1000
    status = robot.command_status(never)
    assert status.signal == "NA" and robotalk.command_status_kind(status, never) == "NOT_RECEIVED"
    robot.stop()


def test_queries_return_numpy_arrays(robot: robotalk.RobotClient) -> None:
    robot.set_joint("pan", [0.25])
    settle(robot, "pan", 0.25)
    pose = robot.base_pose()
    assert isinstance(pose, np.ndarray) and pose.shape == (5,)
    state = robot.joint_state()
    assert state.positions.shape == (4,) and state.positions[2] == pytest.approx(0.25, abs=1e-6)
    assert robot.joint_state("pan").positions.tolist() == pytest.approx([0.25], abs=1e-6)
    assert robot.link_poses().shape == (7, 7)
    assert robot.frame_poses("camera").shape == (1, 7)
    with pytest.raises(robotalk.SignalError, match="has no"):
        robot.joint_state("nek")


def test_errors_are_the_cpp_hierarchy_with_its_messages(server: Server) -> None:
    client = robotalk.RobotClient(server.url, connect_timeout=0.5)
    with pytest.raises(robotalk.ClientError, match=r"RobotClient::Execute: not connected|not connected"):
        client.goto(1, 0, 0)
    with pytest.raises(robotalk.TimeoutError) as e:
        client.connect("nobody")
    assert "robot 'nobody'" in str(e.value)
    assert isinstance(e.value, TimeoutError)  # the builtin too
    with pytest.raises(robotalk.ClientError, match="invalid robot name"):
        client.connect("a b")
    client.close()
    with pytest.raises(robotalk.ClientError, match="RobotClient.goto: the client is closed"):
        client.goto(1, 0, 0)
    assert repr(client) == "<RobotClient closed>"
    with pytest.raises(robotalk.UsageError, match="unknown command type 'gogo'"):
        robotalk.Command("gogo")
    with pytest.raises(robotalk.UsageError, match="value 0 is nan"):
        robotalk.Command("goto", values=[float("nan"), 0, 0])


# Bytes that are not UTF-8 (two that never are, a truncated 3-byte sequence),
# as a forger (or a server echoing a target) may put them in a reply, and
# how they reach Python: backslash-escaped, never as UnicodeDecodeError.
NOT_UTF8 = [(b"\xff\xfe", r"\xff\xfe"), (b"pa\xe2\x82", r"pa\xe2\x82")]


def test_a_reply_message_not_utf8_reaches_python_escaped(robot: robotalk.RobotClient) -> None:
    for target, shown in NOT_UTF8:
        # The server echoes the target's bytes in its message: a reply's text from the wire.
        reply = robot.set_joint(target, [0.1])  # type: ignore[arg-type]
        assert reply.signal == "ERROR"
        assert reply.message == f"JOINT_SETPOINT: robot 'pioneer' has no joint named '{shown}'"
        assert f"'{reply.message}'" in repr(reply)
        pending = robot.set_joint(target, [0.1], wait=False)  # type: ignore[arg-type]
        assert f"JOINT_SETPOINT '{shown}'" in repr(pending)
        assert pending.wait(5).message == reply.message
        # A query whose data was asked for: SignalError, its text built from the reply's.
        with pytest.raises(robotalk.SignalError) as e:
            robot.joint_state(target)  # type: ignore[arg-type]
        assert str(e.value) == f"JOINT_STATE '{shown}': ERROR: " + e.value.reply.message
        assert shown in e.value.reply.message


def test_a_signal_errors_text_shows_a_servers_control_characters_escaped(robot: robotalk.RobotClient) -> None:
    # Review 14: the server echoes the target in its message (a reply's text
    # from the wire, anyone's in open mode); SignalError's text, which a
    # traceback prints, shows its control characters as \xNN; the reply it
    # carries keeps them (it was the raw text: ESC, BEL, CR, a line break).
    target = "pan\x1b[2J\a\r\n  robotalk: forged\x7f\u009b"
    with pytest.raises(robotalk.SignalError) as e:
        robot.joint_state(target)
    assert not any(ord(c) < 0x20 or 0x7F <= ord(c) <= 0x9F for c in str(e.value)), repr(str(e.value))
    assert r"pan\x1b[2J\x07\x0d\x0a  robotalk: forged\x7f\xc2\x9b" in str(e.value)
    assert target in e.value.reply.message
    # The reply's repr (an interactive session prints it) escapes them too.
    assert not any(ord(c) < 0x20 or 0x7F <= ord(c) <= 0x9F for c in repr(e.value.reply)), repr(e.value.reply)


def test_an_error_naming_bytes_not_utf8_shows_them_escaped(server: Server) -> None:
    # A RobotalkError's text holding such bytes: the class and the text, escaped
    # (it was a UnicodeDecodeError, or the class with its text lost).
    client = robotalk.RobotClient(server.url, connect_timeout=0.3)
    try:
        for name, shown in NOT_UTF8:
            with pytest.raises(robotalk.ClientError) as e:
                client.connect(name)  # type: ignore[arg-type]
            assert f"'{shown}'" in str(e.value)
    finally:
        client.close()


def test_panic_from_one_client_is_seen_by_another(server: Server) -> None:
    with robotalk.connect("pioneer", server.url) as a, robotalk.connect("pioneer", server.url) as b:
        a.panic()
        refused = b.goto(0.5, 0, 0)
        assert refused.signal == "PANIC"
        assert b.set_joint("pan", [0.1]).signal == "PANIC"
        assert robotalk.robots(server.url, listen=1.2)[-1].panic
        assert a.reset_panic().signal == "SUCCESS"
        assert b.set_joint("pan", [0.1]).signal == "SUCCESS"
