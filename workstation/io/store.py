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

import argparse
import atexit
import hashlib
import re
import shutil
import tempfile
from collections.abc import Callable
from functools import lru_cache
from pathlib import Path
from typing import Any, TypeVar

from workstation.errors import InputError, Unreadable
from workstation.io.atomic import atomic_write_bytes
from workstation.io.yamlio import load_yaml

T = TypeVar("T")
_URL = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*://")


def is_url(p: object) -> bool:
    """A URL of a store (``file://`` is a local path)."""
    return isinstance(p, str) and bool(_URL.match(p)) and not p.lower().startswith("file://")


def path_or_url(text: str) -> str | Path:
    """The argparse type of an input that may live in a store: a URL stays as typed (a
    ``Path`` would fold its ``//``), anything else is a path."""
    return text if is_url(text) else Path(text.removeprefix("file://"))


def read_via_local(src: object, read: Callable[[Path], T]) -> T:
    """``read(path)`` of ``src``: a local path as it is; a URL's object (or every object under
    the prefix) copied into a temporary folder first, removed after. An :class:`InputError`
    from ``read`` names the URL, not the copy."""
    if not is_remote(src):
        return read(Path(str(src)))
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


def output_path(text: str) -> str | Path:
    """The argparse type of an output a command can write to a store (:func:`write_via_local`):
    a URL stays as typed (``Path`` folded ``s3://b/k`` into a local folder ``s3:/b/k``)."""
    return path_or_url(text)


LOCAL_ONLY = "this output is written only on this machine"


def local_output(text: str) -> Path:
    """The argparse type of an output written only on this machine: a store's URL refused in
    one line (exit 2), never folded into a local folder named ``s3:``."""
    if is_url(text):
        raise argparse.ArgumentTypeError(
            f"{text}: {LOCAL_ONLY} — write it here and copy it up (run --out, merge -o, quality "
            "--out and campaign run --out write to a store)"
        )
    return Path(text.removeprefix("file://"))


def write_via_local(dest: object, write: Callable[[Path], T]) -> T:
    """``write(path)`` for an output at ``dest``: a local path as it is; for a store's URL the
    output (a file or a folder, and any file written beside it) is made in a temporary folder
    first and each file then put at the same place under the URL's parent — one object each,
    the previous one kept as ``.bak`` where the command keeps one (a file it writes with a
    backup: the object is copied first). Nothing is written under the working folder."""
    if not is_remote(dest):
        return write(Path(str(dest)))
    url = str(dest).rstrip("/")
    parent, name = url.rsplit("/", 1)
    tmp = Path(tempfile.mkdtemp(prefix="workstation-out-"))
    try:
        got = write(tmp / name)
        for f in sorted(q for q in tmp.rglob("*") if q.is_file() and not q.name.endswith(".bak")):
            target = place(f"{parent}/{f.relative_to(tmp).as_posix()}", cached=False)
            put_bytes(target, f.read_bytes(), backup=(f.with_name(f.name + ".bak")).exists()
                      or _exists(target))  # fmt: skip
        return got
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _exists(p) -> bool:
    with store_errors(p):
        return bool(p.fs.exists(p.path))


def is_remote(p: object) -> bool:
    """``p`` (a path, a :func:`place` or a string) lives in a store, not on this machine."""
    return not isinstance(p, Path) and is_url(str(p))


def place(p: object, cached: bool = True) -> Any:
    """A local path as :class:`Path`, a URL as universal_pathlib's ``UPath`` — the same few
    operations on both (``/``, ``name``, ``is_file``, ``read_text``, ``iterdir``, ``glob``).
    ``cached=False`` for a place others write to while we read (a campaign's output: its
    workers): every question goes to the store, never to a listing made before."""
    if not is_remote(p):
        return Path(str(p).removeprefix("file://")) if not isinstance(p, Path) else p
    if not isinstance(p, str):
        return p
    try:
        from upath import UPath
    except ImportError:
        raise InputError(p, _words(ImportError("universal_pathlib is not installed"))) from None
    return UPath(p, use_listings_cache=False) if not cached else UPath(p)


def put_bytes(p, data: bytes, backup: bool = False):
    """Write a whole file: on disk atomically (a temporary file renamed over it), in a store as
    one object (a PUT is all or nothing: no half object is ever seen). ``backup``: the previous
    file or object is kept as ``NAME.bak`` first; returns where (None when there was none)."""
    if not is_remote(p):
        return atomic_write_bytes(p, data, backup=backup)
    with store_errors(p):
        bak = None
        if backup and p.fs.exists(p.path):
            bak = p.with_name(p.name + ".bak")
            p.fs.copy(p.path, bak.path)
        p.write_bytes(data)
        return bak


def put_text(p, text: str, backup: bool = False):
    return put_bytes(p, text.encode(), backup)


def get_bytes(p, limit: int | None = None) -> bytes | None:
    """A whole file's bytes, None when there is none — in a store one GET, never a HEAD before
    it (issue #66: a campaign in a bucket took 2 × as long as on disk, at ~10 ms a request).
    ``limit``: at most that many bytes are read (a ranged GET)."""
    if not is_remote(p):
        try:
            with open(p, "rb") as f:
                return f.read() if limit is None else f.read(limit)
        except (FileNotFoundError, IsADirectoryError):  # no file there, as is_file() says
            return None
    with store_errors(p):
        try:
            return _cat(p.fs, p.path, limit)
        except FileNotFoundError:
            return None


def _cat(fs, path: str, limit: int | None = None) -> bytes:
    """One GET: s3fs asks an object's size first (a HEAD) unless told to read it in one piece."""
    one = {"max_concurrency": 1} if hasattr(fs, "max_concurrency") else {}
    return fs.cat_file(path, start=None if limit is None else 0, end=limit, **one)


def local_building(url) -> Path:
    """A building file in a store, with the plan images it names, copied into a temporary
    folder as they lie beside it (its images are relative to it): the local building file.
    The folder stays for the process's life (a plan is read again when it is drawn); copied
    once a process."""
    return _local_building(str(url))


@lru_cache(maxsize=8)
def _local_building(url: str) -> Path:
    src = place(url)
    tmp = Path(tempfile.mkdtemp(prefix="workstation-building-"))
    atexit.register(shutil.rmtree, tmp, True)
    local = tmp / src.name
    with store_errors(src):
        local.write_bytes(src.read_bytes())
    data = load_yaml(local, "building file")
    floors = data.get("floors") if isinstance(data, dict) else None
    for e in (floors.values() if isinstance(floors, dict) else []):
        image = e.get("image") if isinstance(e, dict) else None
        if not isinstance(image, str) or is_url(image) or Path(image).is_absolute():
            continue  # refused or read as they are by the building's own loader
        dest = (tmp / image).resolve()
        if not dest.is_relative_to(tmp.resolve()):
            continue  # out of the folder: the loader says so
        dest.parent.mkdir(parents=True, exist_ok=True)
        with store_errors(src.parent / image):
            dest.write_bytes((src.parent / image).read_bytes())
    return local


def remove(p, recursive: bool = False) -> None:
    """Remove a file (``recursive``: a folder or prefix) if it is there."""
    if not is_remote(p):
        if recursive:
            shutil.rmtree(p, ignore_errors=True)
        else:
            Path(p).unlink(missing_ok=True)
        return
    with store_errors(p):
        if p.fs.exists(p.path):
            p.fs.rm(p.path, recursive=recursive)


def etag(p) -> str:
    """What a store says of an object's content without reading it: its ETag and size (a
    folder's: those of the files in it), "missing" when absent — a changed object has
    another, whatever its time stamp."""
    with store_errors(p):
        fs, root = p.fs, p.path
        try:
            info = fs.info(root)  # one request for an object
        except FileNotFoundError:
            return "missing"
        infos = [info] if info.get("type") != "directory" else [
            i for i in fs.ls(root, detail=True) if i.get("type") == "file"
        ]  # fmt: skip
    return ";".join(_tag(i) for i in sorted(infos, key=lambda i: i["name"]))


def listed(folder) -> dict[str, str] | None:
    """Every object under a store's ``folder`` with what :func:`etag` says of it, by its path
    below the folder — a few requests for a thousand objects (one listing page each), where
    asking each object was one request apiece (issue #66); None on disk (ask the files)."""
    if not is_remote(folder):
        return None
    with store_errors(folder):
        try:
            found = folder.fs.find(folder.path, detail=True)
        except FileNotFoundError:
            return {}
    root = folder.path.rstrip("/") + "/"
    return {name[len(root):]: _tag(info) for name, info in found.items()
            if name.startswith(root) and info.get("type") == "file"}  # fmt: skip


def _tag(info: dict) -> str:
    return (f"{info['name'].rsplit('/', 1)[-1]}:{info.get('ETag') or info.get('etag') or ''}:"
            f"{info.get('size')}")


class store_errors:
    """``with store_errors(url):`` — any failure of the store inside becomes one
    :class:`InputError` naming the URL and saying what it means (:func:`_words`)."""

    def __init__(self, where: object) -> None:
        self.where = str(where)

    def __enter__(self) -> None:
        return None

    def __exit__(self, kind, e, _tb) -> None:
        if e is None or isinstance(e, InputError) or not _of_store(e) or not is_url(self.where):
            return  # a bug stays a bug (its traceback), Ctrl+C stays Ctrl+C
        raise InputError(self.where, _words(e)) from None


def _of_store(e: BaseException) -> bool:
    """A failure of the store or of reaching it (s3fs says most as an OSError), not ours."""
    mod = type(e).__module__.split(".")[0]
    return isinstance(e, (OSError, ImportError)) or mod in {"botocore", "aiobotocore", "s3fs",
                                                           "fsspec", "aiohttp"}  # fmt: skip


def _fetch(url: str, tmp: Path) -> Path:
    """The object or prefix at ``url`` copied under ``tmp``, keeping its last name."""
    try:
        import fsspec

        fs, root = fsspec.core.url_to_fs(url)
        root = root.rstrip("/")
        dest = tmp / _local_name(root.rsplit("/", 1)[-1] or "object")
        try:  # an object: one GET (a HEAD to ask first cost each campaign walk a request)
            data = _cat(fs, root)
        except (FileNotFoundError, IsADirectoryError):
            data = None
        if data is not None:
            dest.write_bytes(data)
        elif fs.isdir(root):
            fs.get(root + "/", str(dest), recursive=True)
        else:
            raise FileNotFoundError(url)
        return dest
    except InputError:
        raise
    except Exception as e:  # noqa: BLE001 - every store's failure, said in one line
        raise Unreadable(url, _words(e)) from None


NAME_MAX = 255  # bytes of one file name on the usual file systems (an object's key may be longer)


def _local_name(name: str) -> str:
    """An object's last name as a local file name: as it is, or — past ``NAME_MAX`` bytes (issue
    #67 item 6: Errno 36, "File name too long") — a digest of it with its suffixes (.txt.gz:
    the reader goes by them)."""
    if len(name.encode()) <= NAME_MAX:
        return name
    suffix = "".join(Path(name).suffixes[-2:])[-40:]
    return hashlib.sha1(name.encode()).hexdigest()[:20] + suffix


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
