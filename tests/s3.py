"""A real S3-compatible server for the tests (moto's), on 127.0.0.1, and the environment that
points boto/s3fs at it — the same variables a surveyor sets for a real store."""

from __future__ import annotations

import logging
from collections.abc import Iterator
from contextlib import contextmanager

import pytest


def need_store(*more: str) -> None:
    """Skip the module unless what talking to a store takes is installed (and ``more``)."""
    for name in ("s3fs", "upath", "moto.server", *more):
        pytest.importorskip(name)


@contextmanager
def local_s3() -> Iterator[dict[str, str]]:
    """Start the server, set ``AWS_*`` (endpoint, dummy keys) for this process, yield them
    (for processes the test starts), and undo it all."""
    import s3fs
    from moto.server import ThreadedMotoServer

    logging.getLogger("werkzeug").setLevel(logging.ERROR)  # moto's access log
    srv = ThreadedMotoServer(ip_address="127.0.0.1", port=0)
    srv.start()
    host, port = srv.get_host_and_port()
    env = {"AWS_ACCESS_KEY_ID": "testing", "AWS_SECRET_ACCESS_KEY": "testing",
           "AWS_DEFAULT_REGION": "us-east-1", "AWS_ENDPOINT_URL": f"http://{host}:{port}"}  # fmt: skip
    try:
        with pytest.MonkeyPatch.context() as mp:
            for k, v in env.items():
                mp.setenv(k, v)
            mp.delenv("AWS_PROFILE", raising=False)
            s3fs.S3FileSystem.clear_instance_cache()
            try:
                yield env
            finally:
                s3fs.S3FileSystem.clear_instance_cache()
    finally:
        srv.stop()


def without_credentials(mp: pytest.MonkeyPatch) -> None:
    """No key anywhere boto looks (environment, files, the machine's metadata service)."""
    import s3fs

    for k in ("AWS_ACCESS_KEY_ID", "AWS_SECRET_ACCESS_KEY"):
        mp.delenv(k, raising=False)
    mp.setenv("AWS_SHARED_CREDENTIALS_FILE", "/nonexistent")
    mp.setenv("AWS_CONFIG_FILE", "/nonexistent")
    mp.setenv("AWS_EC2_METADATA_DISABLED", "true")
    s3fs.S3FileSystem.clear_instance_cache()


@contextmanager
def checking_s3() -> Iterator[str]:
    """A second server, its own process, that checks every request's key (moto's IAM check from
    the first request on): the endpoint URL; any key given to it is a wrong one."""
    import os
    import socket
    import subprocess
    import sys
    import time

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    proc = subprocess.Popen([sys.executable, "-m", "moto.server", "-H", "127.0.0.1", "-p",
                             str(port)], env={**os.environ, "INITIAL_NO_AUTH_ACTION_COUNT": "0"},
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)  # fmt: skip
    try:
        for _ in range(300):
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                time.sleep(0.1)
        yield f"http://127.0.0.1:{port}"
    finally:
        proc.terminate()
        proc.wait(30)
