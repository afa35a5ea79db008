"""The state stream in Python: an iterator, and a callback run by a Python thread.

The C++ client calls its state-stream callback on its ReadDaemon thread, the
thread that also files replies and retransmits. Calling Python there would
make the daemon wait for the GIL and for the callback. So the daemon only
copies each sample into a bounded queue (``_StateQueue``, C++, no GIL), and
this module drains it: ``for sample in stream`` takes them on the caller's
thread; ``callback=`` runs them on a Python thread of its own. When the
consumer falls behind, the oldest samples are dropped and counted
(``StateStream.dropped``): a slow callback sees the newest state, never a
stalled client.
"""

from __future__ import annotations

import threading
from types import TracebackType
from typing import TYPE_CHECKING, Callable, Iterator, Optional, Type

from ._robotalk import StateSample, _StateQueue

if TYPE_CHECKING:
    from . import RobotClient


class ClosesOnExit:
    """A context manager whose block's end calls ``self.close()``."""

    def close(self) -> None:
        raise NotImplementedError

    def __exit__(
        self,
        exc_type: Optional[Type[BaseException]],
        exc: Optional[BaseException],
        tb: Optional[TracebackType],
    ) -> None:
        self.close()


class StateStream(ClosesOnExit):
    """A running state stream (``RobotClient.state_stream()``).

    Iterate it (``for sample in stream``: blocks until the next sample, ends
    when the stream is closed), or give ``callback`` to have each sample
    passed to it on a thread of its own. A context manager: leaving the
    ``with`` block closes it. An exception raised by the callback ends the
    stream and is raised again by ``close()``.
    """

    def __init__(
        self,
        client: "RobotClient",
        queue: _StateQueue,
        period: float,
        callback: Optional[Callable[[StateSample], object]] = None,
    ) -> None:
        self._client = client
        self._queue = queue
        #: The period the server streams at (s): the shortest any client asked for.
        self.period = period
        self._callback = callback
        self._error: Optional[BaseException] = None
        self._thread: Optional[threading.Thread] = None
        if callback is not None:
            self._thread = threading.Thread(
                target=self._run, name=f"robotalk-state-{client.robot}", daemon=True
            )
            self._thread.start()

    def _run(self) -> None:
        assert self._callback is not None
        while True:
            sample = self._queue.get(0.1)
            if sample is None:
                if self._queue.closed:
                    return
                continue
            try:
                self._callback(sample)
            except BaseException as e:  # noqa: B902 - kept for close()
                self._error = e
                self._queue.close()
                return

    def get(self, timeout: Optional[float] = None) -> Optional[StateSample]:
        """The next sample, waiting at most ``timeout`` s (None: until one comes);
        None when none came or the stream is closed."""
        return self._queue.get(timeout)

    def __iter__(self) -> Iterator[StateSample]:
        while True:
            sample = self._queue.get(None)
            if sample is None:
                return
            yield sample

    @property
    def dropped(self) -> int:
        """Samples dropped because the consumer fell behind (queue full)."""
        return self._queue.dropped

    @property
    def received(self) -> int:
        """Samples received from the server."""
        return self._queue.received

    @property
    def closed(self) -> bool:
        return self._queue.closed

    def close(self) -> None:
        """Cancels this client's stream request and ends iteration and the callback
        thread; raises the callback's exception, if it raised one."""
        if not self._queue.closed:
            self._queue.close()
            if self._client._stream is self and not self._client.closed:
                self._client._stop_state_stream()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join()
        if self._client._stream is self:
            self._client._stream = None
        error, self._error = self._error, None
        if error is not None:
            raise error

    def __enter__(self) -> "StateStream":
        return self

    def __repr__(self) -> str:
        state = "closed" if self.closed else "running"
        mode = "callback" if self._callback is not None else "iterator"
        return (
            f"<StateStream of '{self._client.robot}' every {self.period * 1e3:g} ms, {mode}, "
            f"{state}, {self.received} received, {self.dropped} dropped>"
        )
