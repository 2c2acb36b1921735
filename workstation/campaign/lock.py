"""One campaign run at a time writes to an output folder or prefix (issue #54 item 3): two
runs into one ``--out`` would interleave their walks' files and each other's ``state.json``.

The run takes ``campaign.lock`` before it writes anything: created only if absent — on disk with
``O_EXCL``, in a store with a conditional PUT (``If-None-Match: *``; a store that ignores it
is caught by reading the lock back). The lock says who holds it (host, process, start, a random
token) and when that run last wrote a result (``beat``). A second run refuses, naming the
holder; a lock left by a run that was killed is taken over: on this machine when its process is
gone, from elsewhere when it has not written for ``STALE_S``. Workers of a run write their
files only while their run's token is the lock's (:func:`still_holds`): a worker of a killed
run that finishes late writes nothing over the run that took over.
"""

from __future__ import annotations

import json
import os
import secrets
import socket
import time

from workstation.errors import InputError
from workstation.io.store import get_bytes, is_remote, put_text, remove, store_errors

NAME = "campaign.lock"
STALE_S = 900.0  # a holder elsewhere that wrote nothing this long is gone
BEAT_S = 60.0  # how often a running campaign says it is alive (at most)


class CampaignLock:
    """``with CampaignLock(out, say):`` — held for the run, released at its end."""

    def __init__(self, out, say=print) -> None:
        self.out, self.say, self.path = out, say, out / NAME
        self.token = secrets.token_hex(8)
        self.last_beat = 0.0

    def _record(self) -> dict:
        return {"host": socket.gethostname(), "pid": os.getpid(), "token": self.token,
                "started": time.time(), "beat": time.time()}  # fmt: skip

    def __enter__(self) -> CampaignLock:
        for _ in range(3):
            if self._create():
                self.last_beat = time.monotonic()
                return self
            held = self._held()
            if held is None:
                continue  # released between our try and our look: try again
            if not _gone(held):
                raise InputError(
                    self.path,
                    f"another campaign run is writing here (host {held.get('host')}, process "
                    f"{held.get('pid')}, last result {_ago(held)} ago): wait for it, or give "
                    f"another --out; if that run is gone, delete {self.path}",
                )
            self.say(f"taking over {self.path}: the run that held it (host {held.get('host')}, "
                     f"process {held.get('pid')}) is gone; it resumes where that run stopped — "
                     "walks it finished in its last second run again (what is done is written "
                     "down once a second)")  # fmt: skip
            remove(self.path)
        raise InputError(self.path, "could not take the campaign's lock (another run keeps taking it)")

    def __exit__(self, *_exc) -> None:
        held = self._held()
        if held is not None and held.get("token") == self.token:
            remove(self.path)

    def beat(self) -> None:
        """Say the run is alive (rewrites the lock at most every ``BEAT_S``)."""
        if time.monotonic() - self.last_beat < BEAT_S:
            return
        self.last_beat = time.monotonic()
        held = self._held()
        if held is not None and held.get("token") == self.token:
            put_text(self.path, json.dumps({**held, "beat": time.time()}))

    def _create(self) -> bool:
        data = json.dumps(self._record())
        if not is_remote(self.path):
            self.path.parent.mkdir(parents=True, exist_ok=True)
            try:
                fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
            except FileExistsError:
                return False
            with os.fdopen(fd, "w") as f:
                f.write(data)
            return True
        with store_errors(self.path):
            try:
                self.path.fs.pipe_file(self.path.path, data.encode(), IfNoneMatch="*")
            except FileExistsError:
                return False
        held = self._held()  # a store that ignores the condition: whose is it now?
        return held is not None and held.get("token") == self.token

    def _held(self) -> dict | None:
        return _read_lock(self.out)


def _read_lock(out) -> dict | None:
    """The lock's record, None when there is none ({} when it cannot be read as one). At most
    64 kB of it is read; on disk a lock that is no regular file (a link planted to a device)
    is refused, never read."""
    p = out / NAME
    with store_errors(p):
        try:
            if is_remote(p):  # one ranged GET (a worker asks before each walk's writes)
                text = get_bytes(p, limit=(1 << 16) + 1)
                if text is None:
                    return None
                if len(text) > 1 << 16:
                    return {}  # no lock of ours: no holder can be named
            else:
                if p.is_symlink() or (p.exists() and not p.is_file()):
                    raise InputError(p, "is not a regular file: our lock is never read or "
                                     "written through it; remove it, or give another --out")  # fmt: skip
                with open(p, "rb") as f:
                    text = f.read(1 << 16)
        except FileNotFoundError:
            return None
    try:
        held = json.loads(text)
    except (ValueError, UnicodeDecodeError):
        return {}  # half-written by a crash on disk: no holder can be named
    return held if isinstance(held, dict) else {}


def still_holds(out, token: str) -> bool:
    """The run with ``token`` still holds ``out``'s lock (a worker asks before it writes)."""
    held = _read_lock(out)
    return held is not None and held.get("token") == token


def _gone(held: dict) -> bool:
    if not held:
        return True
    if held.get("host") == socket.gethostname() and isinstance(held.get("pid"), int):
        try:
            os.kill(held["pid"], 0)
        except ProcessLookupError:
            return True
        except PermissionError:
            return False
        return False
    return time.time() - float(held.get("beat") or 0) > STALE_S


def _ago(held: dict) -> str:
    s = max(0.0, time.time() - float(held.get("beat") or 0))
    return f"{s:.0f} s" if s < 120 else f"{s / 60:.0f} min"
