"""The native Rerun viewer as a child process bound to 127.0.0.1 (``edit``/``view`` without
``--save``, and the headless viewer the tests and screenshots use)."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

from workstation.errors import WorkstationError


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def spawn_viewer(port: int | None = None, headless: bool = False) -> tuple[subprocess.Popen, str]:
    """Start a native viewer bound to 127.0.0.1; returns (process, gRPC URL)."""
    port = port or free_port()
    exe = Path(sys.executable).with_name("rerun")
    cmd = [str(exe) if exe.exists() else "rerun", "--bind", "127.0.0.1", "--port", str(port)]
    if headless:
        cmd += ["--headless", "--hide-welcome-screen"]
    # its own process group: the `rerun` script starts the real viewer as a child
    proc = subprocess.Popen(
        cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True
    )
    deadline = time.time() + 20
    while time.time() < deadline:
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return proc, f"rerun+http://127.0.0.1:{port}/proxy"
        if proc.poll() is not None:
            break
        time.sleep(0.2)
    stop_viewer(proc)

    raise WorkstationError(
        "the Rerun viewer did not start (no display?): use --save FILE.rrd or --connect URL"
    )


def stop_viewer(proc: subprocess.Popen) -> None:
    """Stop a viewer started by :func:`spawn_viewer`, with the child it started."""
    try:
        os.killpg(proc.pid, signal.SIGTERM)
    except ProcessLookupError:
        return
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
