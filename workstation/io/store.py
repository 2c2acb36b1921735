"""Inputs that live in object storage (issue #54): an fsspec URL (``s3://bucket/key``,
``gs://…``, ``memory://…``) wherever a command reads a radio map — a file, or a campaign's
merged map of one building (the prefix ``radiomap/building=NAME``) — read as the same bytes on
disk would be: the object (every object under the prefix) is copied into a temporary folder,
read there by the file's own reader, and the folder removed; an error names the URL.

Credentials and the endpoint come from the usual places — ``AWS_ACCESS_KEY_ID``,
``AWS_SECRET_ACCESS_KEY``, ``AWS_ENDPOINT_URL`` (an S3-compatible server), ``~/.aws``, fsspec's
own configuration — and are never written anywhere: an error says what was refused, not with
which key. ``s3://`` needs s3fs (``pip install -e .[store]``).
"""

from __future__ import annotations

import re
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

from workstation.errors import InputError

T = TypeVar("T")
_URL = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*://")


def is_url(p: object) -> bool:
    """A URL of a store (``file://`` is a local path)."""
    return isinstance(p, str) and bool(_URL.match(p)) and not p.lower().startswith("file://")


def path_or_url(text: str) -> str | Path:
    """The argparse type of an input that may live in a store: a URL stays as typed (a
    ``Path`` would fold its ``//``), anything else is a path."""
    return text if is_url(text) else Path(text.removeprefix("file://"))


def read_via_local(src: str | Path, read: Callable[[Path], T]) -> T:
    """``read(path)`` of ``src``: a local path as it is; a URL's object (or every object under
    the prefix) copied into a temporary folder first, removed after. An :class:`InputError`
    from ``read`` names the URL, not the copy."""
    if not is_url(src):
        return read(Path(src))
    url = str(src)
    tmp = Path(tempfile.mkdtemp(prefix="workstation-store-"))
    try:
        local = _fetch(url, tmp)
        try:
            return read(local)
        except InputError as e:
            where = e.path or ""
            if where.startswith(str(local)):
                where = url + where[len(str(local)) :]
            raise InputError(where or url, e.reason, e.line) from None
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _fetch(url: str, tmp: Path) -> Path:
    """The object or prefix at ``url`` copied under ``tmp``, keeping its last name."""
    try:
        import fsspec

        fs, root = fsspec.core.url_to_fs(url)
        root = root.rstrip("/")
        dest = tmp / (root.rsplit("/", 1)[-1] or "object")
        if fs.isfile(root):
            fs.get(root, str(dest))
        elif fs.isdir(root):
            fs.get(root + "/", str(dest), recursive=True)
        else:
            raise FileNotFoundError(url)
        return dest
    except InputError:
        raise
    except Exception as e:  # noqa: BLE001 - every store's failure, said in one line
        raise InputError(url, _words(e)) from None


def _words(e: Exception) -> str:
    """What a store's failure means to a surveyor (never the credentials themselves)."""
    if isinstance(e, ImportError) or "Protocol not known" in str(e):
        return f"no way to read this URL here ({e}); for s3:// install s3fs: pip install -e .[store]"
    if isinstance(e, FileNotFoundError):
        return "no such object, prefix or bucket"
    if isinstance(e, PermissionError):
        return ("access denied: check the credentials (AWS_ACCESS_KEY_ID / "
                "AWS_SECRET_ACCESS_KEY, ~/.aws) and what they may read")  # fmt: skip
    name = type(e).__name__
    if "Credentials" in name or "InvalidAccessKeyId" in str(e) or "SignatureDoesNotMatch" in str(e):
        return "the store refused the credentials (AWS_ACCESS_KEY_ID / AWS_SECRET_ACCESS_KEY, ~/.aws)"
    if "Connect" in name or isinstance(e, (ConnectionError, TimeoutError)):
        return f"cannot reach the store ({name}): check AWS_ENDPOINT_URL and the network"
    first = str(e).strip().splitlines()[0] if str(e).strip() else ""
    return f"cannot read it: {name}{': ' + first[:200] if first else ''}"
