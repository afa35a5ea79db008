"""Shared by the robotalk Python tests (ctest runs them: python/tests/CMakeLists.txt).

The environment says where things are: PYTHONPATH the build tree's package,
ROBOTALK_SERVER / ROBOTALK_KEYGEN / ROBOTALK_LOGPLAY / ROBOTALK_FK_REFERENCE the
programs, ROBOTALK_MODELS the project's models, ROBOTALK_SHARED_ROBOTS the
real robots (tests needing them skip where the folder is absent), and
ROBOTALK_NETNS=1 that the tests run inside a private network namespace
(scripts/netns_run.sh): only then do they start servers.
"""

from __future__ import annotations

import os
import subprocess
import time
from pathlib import Path
from typing import Iterator, List, Optional

import pytest

MODELS = Path(os.environ.get("ROBOTALK_MODELS", Path(__file__).resolve().parents[2] / "models"))
SHARED = Path(os.environ.get("ROBOTALK_SHARED_ROBOTS", Path(__file__).resolve().parents[3] / "shared" / "robots"))


def shared_robot(name: str) -> Path:
    path = SHARED / name
    if not path.exists():
        pytest.skip(f"{path} is absent (../shared/robots beside the checkout)")
    return path


def program(var: str) -> str:
    path = os.environ.get(var)
    if not path:
        pytest.skip(f"${var} is not set (run through ctest)")
    return path


def url_of(port: int) -> str:
    return f"udpm://239.255.76.67:{port}?ttl=0"


class Server:
    """A robotalk-server with the kinematic Pioneer (and the iiwa14 where the
    shared robots are), stopped by stop() or at the end of the test session."""

    def __init__(self, port: int, state_dir: Path, extra: Optional[List[str]] = None) -> None:
        if os.environ.get("ROBOTALK_NETNS") != "1":
            pytest.skip("not inside a private network namespace (ctest runs these through scripts/netns_run.sh)")
        self.port = port
        self.url = url_of(port)
        self.state_dir = state_dir
        self.extra = extra or []
        self.log_path = state_dir / f"server-{port}.log"
        self.proc: Optional[subprocess.Popen[bytes]] = None
        self.start()

    def start(self) -> None:
        robots = ["--robot", f"pioneer=kinematic:{MODELS / 'pioneer2dx_pantilt.urdf'}"]
        iiwa = SHARED / "iiwa14.urdf"
        if iiwa.exists():
            robots += ["--robot", f"iiwa=kinematic:{iiwa}"]
        self._starts = getattr(self, "_starts", 0) + 1
        expected = self._starts * (2 if (SHARED / "iiwa14.urdf").exists() else 1)
        log = open(self.log_path, "ab")
        self.proc = subprocess.Popen(
            [program("ROBOTALK_SERVER"), *robots, "--url", self.url, "--duration", "120",
             "--state-dir", str(self.state_dir), *self.extra],
            stderr=log, stdout=subprocess.DEVNULL,
        )
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError(f"robotalk-server exited: {self.log_path.read_text()}")
            if self.log_path.read_text().count("serving robot") >= expected:
                return
            time.sleep(0.05)
        raise RuntimeError(f"robotalk-server did not start: {self.log_path.read_text()}")

    def stop(self) -> None:
        if self.proc and self.proc.poll() is None:
            self.proc.terminate()
            self.proc.wait(10)

    def log(self) -> str:
        return self.log_path.read_text()


@pytest.fixture(scope="session")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    s = Server(7951, tmp_path_factory.mktemp("server"))
    yield s
    s.stop()
