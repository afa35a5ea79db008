"""RoboTalk from Python: drive robots, read their descriptions, read session logs.

Bindings of RoboTalk's C++ client (keyed mode, exactly-once delivery, clock
sync and the four command modes come with it), its motion specification and
its log reader. See docs/python.md.

    import robotalk
    with robotalk.connect("pioneer") as robot:
        r = robot.goto(1.0, 0.0, 0.0)        # blocks until the reply; r.signal == "SUCCESS"
        print(robot.base_pose())             # numpy [x, y, theta, v, omega]

    model = robotalk.load_urdf("iiwa14.urdf")
    kin = robotalk.Kinematics(model)
    kin.update(q)                            # numpy, model.num_dofs values
    kin.link_pose("iiwa_link_7")             # 4x4 numpy

Times are seconds (float) or datetime.timedelta; a command's ``start`` is a
time on the server clock (``robot.server_now() + 0.5``). Errors are
``RobotalkError`` and its subclasses, with the C++ messages.
"""

from __future__ import annotations

import os
import warnings
from datetime import timedelta
from typing import Callable, Iterable, List, NamedTuple, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

from ._robotalk import (
    AnnouncedRobot,
    ClientError,
    Command,
    ControlFrame,
    Dof,
    Joint,
    Kinematics,
    Link,
    LogError,
    LookupError,
    ModelError,
    PanicRefusedError,
    PendingReply,
    ProtocolError,
    Reply,
    RobotalkError,
    RobotModel,
    RootLink,
    SequenceResult,
    SignalError,
    StateSample,
    TimedCommand,
    TimeoutError,
    TransportError,
    UnknownOutcomeError,
    UrdfError,
    UsageError,
    _RobotClient,
    command_status_kind,
    extract,
    format_sequence,
    log_info,
    log_states,
    parse_sequence,
)
from ._robotalk import _load_urdf, _parse_urdf, _robots
from ._stream import ClosesOnExit, StateStream

__version__ = "0.1.0"

__all__ = [
    "AnnouncedRobot", "ClientError", "Command", "ControlFrame", "Dof", "Joint", "JointState",
    "Kinematics", "Link", "LogError", "LookupError", "ModelError", "PanicRefusedError",
    "PendingReply", "ProtocolError", "Reply", "RobotClient", "RobotModel", "RobotalkError",
    "RobotalkWarning", "RootLink", "SIGNALS", "SequenceResult", "SignalError", "StateSample",
    "StateStream", "TimedCommand", "TimeoutError", "TransportError", "UnknownOutcomeError",
    "UrdfError", "UsageError", "connect", "extract", "format_sequence", "load_urdf",
    "command_status_kind", "log_info", "log_states", "parse_sequence", "parse_urdf", "robots",
]

#: The seven return signals, as Reply.signal names them.
SIGNALS = ("SUCCESS", "MODIFIED", "NA", "BUSY", "INTERRUPTED", "ERROR", "PANIC")

Seconds = Union[float, timedelta]
FloatArray = npt.NDArray[np.float64]


class RobotalkWarning(UserWarning):
    """A defect load_urdf() repaired (the message names the element)."""


class JointState(NamedTuple):
    """JOINT_STATE: positions, velocities and efforts, one per dof (numpy)."""

    positions: FloatArray
    velocities: FloatArray
    efforts: FloatArray


def load_urdf(
    path: Union[str, "os.PathLike[str]"],
    *,
    strict: bool = False,
    merge_massless_chains: bool = False,
    robot_name: str = "",
) -> RobotModel:
    """Reads and imports a URDF file (with RoboTalk's <robotalk> extension block).

    Each repaired defect is a RobotalkWarning ("joint 'ptu_pan': lower limit
    2.775 > upper -2.775; swapped"); ``strict=True`` refuses them instead.
    ``merge_massless_chains`` makes e.g. a pan-tilt unit one 2-dof joint
    "pan+tilt". Raises UrdfError naming the file and what is wrong.
    """
    model, found = _load_urdf(os.fspath(path), strict, merge_massless_chains, robot_name)
    for w in found:
        warnings.warn(w, RobotalkWarning, stacklevel=2)
    return model


def parse_urdf(
    xml: str, *, strict: bool = False, merge_massless_chains: bool = False, robot_name: str = ""
) -> RobotModel:
    """load_urdf() from the XML text."""
    model, found = _parse_urdf(xml, strict, merge_massless_chains, robot_name)
    for w in found:
        warnings.warn(w, RobotalkWarning, stacklevel=2)
    return model


def robots(url: Optional[str] = None, listen: Seconds = 1.5) -> List[AnnouncedRobot]:
    """The robots the servers on ``url`` announce, heard for ``listen`` s (servers
    announce once a second), sorted by name: at most 1024, the first heard. A
    RobotalkWarning says how many announcements named robots beyond those (more
    names than a LAN has robots: someone may be flooding ROBOTALK/ANNOUNCE)."""
    listed, unlisted = _robots(url, listen)
    if unlisted:
        warnings.warn(f"listing the first {len(listed)} robots heard; {unlisted} announcements named others: "
                      "more names than a LAN has robots, someone may be flooding ROBOTALK/ANNOUNCE",
                      RobotalkWarning, stacklevel=2)
    return listed


class RobotClient(_RobotClient, ClosesOnExit):
    """A client of RoboTalk robots: the C++ RobotClient (docs/client.md) in Python.

    ``RobotClient(url=None, *, key=None, server_key=None, known_servers=None,
    timeout=5.0, connect_timeout=5.0, client_id=0)``: ``url`` is the LCM URL
    (None: $LCM_DEFAULT_URL, else LCM's default); ``key`` a client key file for
    a keyed server (None: $ROBOTALK_KEY if set, else open mode); ``timeout``
    bounds each blocking call. Then ``connect(robot)``; or use
    ``robotalk.connect()``. A context manager: leaving the block closes it.

    Every command takes ``start`` (server-clock seconds; None = now) and
    ``wait``: True (default) blocks until the final Reply, with the GIL
    released and Ctrl-C honoured (a KeyboardInterrupt during a motion command
    sends STOP first); False returns a PendingReply at once. A reply with a
    non-success signal is not an exception: look at ``reply.signal``.
    Thread-safe: any thread may call any method.
    """

    _stream: Optional[StateStream] = None

    def __enter__(self) -> "RobotClient":
        return self

    def close(self) -> None:
        """Ends the state stream and stops the client. Sends nothing: a moving robot
        is stopped by the server's watchdog when a client goes quiet. Idempotent."""
        stream, self._stream = self._stream, None
        super().close()
        if stream is not None:
            stream.close()

    # --- queries returning data -------------------------------------------------

    def base_pose(self) -> FloatArray:
        """BASE_POSE: numpy [x, y, theta, v, omega] (m, m, rad, m/s, rad/s).
        Raises SignalError when the robot answers otherwise (NA: a fixed base)."""
        return self._query_values("BASE_POSE")

    def joint_state(self, joint: str = "") -> JointState:
        """JOINT_STATE of every dof (or of one joint): positions, velocities, efforts."""
        v = self._query_values("JOINT_STATE", joint)
        n = len(v) // 3
        return JointState(v[:n], v[n : 2 * n], v[2 * n :])

    def link_poses(self, link: str = "") -> FloatArray:
        """LINK_POSES: numpy (n, 7), one world pose x y z qw qx qy qz per link (or one)."""
        return self._query_values("LINK_POSES", link).reshape(-1, 7)

    def frame_poses(self, frame: str = "") -> FloatArray:
        """FRAME_POSES: numpy (n, 7), one world pose per control frame (or one)."""
        return self._query_values("FRAME_POSES", frame).reshape(-1, 7)

    # --- sequences and the state stream --------------------------------------------

    def run_sequence(
        self,
        frames: Iterable[Union[TimedCommand, Tuple[Seconds, Command]]],
        mode: str = "delay",
        *,
        delay: Seconds = 1.0,
        paced: bool = True,
        batch: int = 200,
        on_reply: Optional[Callable[[int, Reply], object]] = None,
        on_progress: Optional[Callable[[int, int, float, float], object]] = None,
        wait_until_given_up: bool = False,
        collect_unknown_outcomes: bool = False,
    ) -> SequenceResult:
        """Sends timed frames in ``mode`` ('direct', 'delay' or 'playback') and waits
        for every reply (paper Table I, docs/client.md "Modes").

        ``frames``: TimedCommands or (offset s, Command) pairs. ``delay``: delay
        mode's head start on the synchronised server clock. ``paced``: send each
        frame when its offset comes (a live stream) or all at once. ``on_reply(i,
        reply)`` and ``on_progress(answered, total, elapsed_s, duration_s)`` run on
        a worker thread. Ctrl-C, or an exception in a callback, stops the sequence
        and sends STOP before it is raised. Raises TimeoutError, UnknownOutcomeError.
        """
        timed = [f if isinstance(f, TimedCommand) else TimedCommand(f[0], f[1]) for f in frames]
        return self._run_sequence(
            timed, mode, delay, paced, batch, on_reply, on_progress,
            wait_until_given_up, collect_unknown_outcomes,
        )

    def state_stream(
        self,
        period: Seconds,
        callback: Optional[Callable[[StateSample], object]] = None,
        *,
        queue_size: int = 256,
    ) -> StateStream:
        """Broadcast mode: the robot's state every ``period`` (s) as StateSamples.

        Without ``callback``, iterate the returned StateStream; with it, each
        sample is passed to ``callback`` on a Python thread of the stream's own.
        Either way the C++ ReadDaemon only queues samples (``queue_size`` at most;
        the oldest is dropped when full, counted in ``stream.dropped``), so a slow
        consumer never delays replies. One stream per client: a new call closes
        the previous one. Close it (or leave its ``with`` block) to cancel it.
        """
        if self._stream is not None:
            self._stream.close()
        queue, actual = self._start_state_stream(period, queue_size)
        self._stream = StateStream(self, queue, actual, callback)
        return self._stream

    def __repr__(self) -> str:
        if self.closed:
            return "<RobotClient closed>"
        who = f"client {self.client_id & 0xFFFFFFFFFFFFFFFF:016x}"
        if not self.connected:
            return f"<RobotClient {who}, not connected>"
        return f"<RobotClient {who} of robot '{self.robot}' ({self.model.num_dofs} dofs)>"


def connect(
    robot: str,
    url: Optional[str] = None,
    key: Optional[str] = None,
    *,
    server_key: Optional[str] = None,
    known_servers: Optional[str] = None,
    timeout: Seconds = 5.0,
    connect_timeout: Seconds = 5.0,
) -> RobotClient:
    """A RobotClient connected to ``robot``: ``with robotalk.connect("pioneer") as robot:``.

    ``url``: the LCM URL (None: $LCM_DEFAULT_URL or LCM's default). ``key``: a
    client key file for a keyed server (None: $ROBOTALK_KEY, else open mode).
    Raises TimeoutError when no server offers the robot within connect_timeout.
    """
    client = RobotClient(
        url, key=key, server_key=server_key, known_servers=known_servers,
        timeout=timeout, connect_timeout=connect_timeout,
    )
    try:
        client.connect(robot)
    except BaseException:
        client.close()
        raise
    return client
