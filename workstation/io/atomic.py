"""Atomic writes: write a temporary file beside the target, then rename over it."""

from __future__ import annotations

import io
import os
import re
import shutil
import stat
import tempfile
from pathlib import Path
from typing import NoReturn

from workstation.errors import InputError as OutputError  # names the file and what is wrong with it


def atomic_write_bytes(path: str | Path, data: bytes, backup: bool = False) -> Path | None:
    """Write ``data`` to ``path`` atomically; with ``backup`` keep the old file as ``path.bak``.

    Returns the backup path when one was made.
    """
    path = _target(path)
    if backup:
        check_outputs((), backups=(path,))
    try:
        tmp = _write_temp(path, data)
    except BaseException as e:  # a full disk names the file it was writing (issue #67 item 4)
        _reraise(e, path)
    try:
        return _commit(tmp, path, backup)
    except BaseException as e:
        _drop(tmp)
        _reraise(e, path)


def atomic_write_set(files: dict[Path, bytes], backup: tuple[Path, ...] = ()) -> None:
    """Write several files that belong together (a run's outputs) so that they appear together
    or not at all: each is written and synced to a temporary file beside it first, and only
    when every one is whole are they renamed into place — a rename takes no space, so a full
    disk stops the writes, never the renames, and the previous files stay as they were.
    ``backup``: the files whose previous version is kept as ``.bak``. These are outputs, not
    files a person edits: a symbolic link in their place is replaced, never written through."""
    temps: dict[Path, str] = {}
    keep = {_target(b, follow=False) for b in backup}
    try:
        for path, data in files.items():
            path = _target(path, follow=False)
            try:
                temps[path] = _write_temp(path, data)
            except BaseException as e:
                _reraise(e, path)
        for path, tmp in temps.items():
            _commit(tmp, path, path in keep)
    finally:
        for tmp in temps.values():
            _drop(tmp)


def check_outputs(paths, backups=()) -> None:
    """Refuse, before anything is written, an output path that is not a regular file or
    nothing, and a backup place (``<name>.bak`` of each of ``backups``) that is not either
    (issue #67 item 5: a command wrote its first file, then stopped at the second; a folder
    named like the backup was reported as a temporary file)."""
    for p in paths:
        if _exists_not_file(Path(p)):
            raise OutputError(p, "is not a regular file (a device, a folder, a pipe or a socket): "
                              "give the path of a file to write")  # fmt: skip
    for p in backups:  # (a backup is made only of a file there)
        bak = Path(p).with_name(Path(p).name + ".bak")
        if Path(p).is_file() and _exists_not_file(bak):
            raise OutputError(bak, f"is not a regular file: the previous {Path(p).name} is kept "
                              "there as a backup when it is written again — move it away")  # fmt: skip


def outside(folder: str | Path, paths) -> Path | None:
    """The first of ``paths`` that leads out of ``folder`` once symbolic links are followed
    (None when all stay inside): an output folder must not be steered elsewhere by a link
    planted in it (issue #33)."""
    root = Path(folder).resolve()
    for p in paths:
        if not Path(p).resolve().is_relative_to(root):
            return Path(p)
    return None


def safe_name(text: str, limit: int = 100) -> str:
    """``text`` as one plain file name: letters, digits, '.', '_' and '-' kept, anything else
    '_', no leading dot, at most ``limit`` characters (a name from the data — an AP's BSSID —
    can then never name another folder)."""
    name = re.sub(r"[^A-Za-z0-9._-]", "_", str(text)).lstrip(".")[:limit]
    return name or "_"


def _target(path: str | Path, follow: bool = True) -> Path:
    """The file to write: through a link to the file it points at (``follow``; else the link
    itself is replaced). Anything but a regular file or nothing is refused (issue #55: as root,
    ``-o /dev/null`` replaced the device with a file, and backing up /dev/zero filled a disk)."""
    path = Path(path)
    if follow and path.is_symlink():  # save through a link to the file it points at, keep it
        path = path.resolve()
    if not (follow is False and path.is_symlink()) and _exists_not_file(path):
        raise OutputError(
            path, "is not a regular file (a device, a folder, a pipe or a socket): give the path "
            "of a file to write"
        )  # fmt: skip
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


def _exists_not_file(path: Path) -> bool:
    try:
        st = os.stat(path)
    except (FileNotFoundError, NotADirectoryError):
        return False
    return not stat.S_ISREG(st.st_mode)


def _write_temp(path: Path, data: bytes) -> str:
    """``data`` in a synced temporary file beside ``path`` with the mode ``path`` will have."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        # mkstemp makes the file private (0600): keep the original's mode, else the umask's
        os.chmod(tmp, path.stat().st_mode & 0o7777 if path.exists() else _default_mode())
    except BaseException:
        _drop(tmp)
        raise
    return tmp


def _commit(tmp: str, path: Path, backup: bool) -> Path | None:
    """Rename ``tmp`` over ``path``, first copying the old file to ``path.bak`` when asked."""
    bak = None
    # only a regular file is backed up (a link replaced in place may point at a device: its
    # copy would never end), and never more than it holds
    if backup and path.is_file() and not _exists_not_file(path):
        # the backup is itself written aside and renamed: a kill mid-copy leaves the old
        # .bak (or none), never a half file
        bak = path.with_name(path.name + ".bak")
        fd2, tmp_bak = tempfile.mkstemp(prefix=f".{bak.name}.", suffix=".tmp", dir=path.parent)
        os.close(fd2)
        try:
            shutil.copy2(path, tmp_bak)
            os.replace(tmp_bak, bak)
        finally:
            _drop(tmp_bak)
    os.replace(tmp, path)
    return bak


def _drop(tmp: str) -> None:
    if os.path.exists(tmp):
        os.unlink(tmp)


def _reraise(e: BaseException, path: Path) -> NoReturn:
    """Raise ``e`` again; an OSError naming no file (a full disk) names ``path``."""
    if isinstance(e, OSError) and e.filename is None:
        raise OSError(e.errno, f"{e.strerror or e} (while writing it)", str(path)) from e
    raise e


def _default_mode() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def save_figure(fig, path: str | Path, **kw) -> None:
    """A matplotlib figure saved as PNG atomically: drawn in memory, then written whole (a full
    disk left a 0-byte PNG: issue #67 item 4)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", **kw)
    atomic_write_bytes(path, buf.getvalue())


def atomic_write_text(path: str | Path, text: str, backup: bool = False) -> Path | None:
    return atomic_write_bytes(path, text.encode("utf-8"), backup=backup)


def atomic_replace_dir(build, target: str | Path) -> Path:
    """Build a folder with ``build(tmpdir)`` then swap it in place of ``target``."""
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.", dir=target.parent))
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o777 & ~umask)  # mkdtemp makes it private; a saved folder is not
    try:
        build(tmp)
        old = None
        if target.exists():
            old = target.with_name(f".{target.name}.old")
            if old.exists():
                shutil.rmtree(old)
            os.replace(target, old)
        os.replace(tmp, target)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return target


_TMP_FILE = re.compile(r"^\..+\.[A-Za-z0-9_]{8}\.tmp$")  # mkstemp(prefix=".name.", suffix=".tmp")
_TMP_DIR = re.compile(r"^\.(.+)\.[A-Za-z0-9_]{8}$")  # mkdtemp(prefix=".name.")


def sweep_leftovers(
    folder: str | Path, names=None, recursive: bool = False, own: bool = False
) -> list[Path]:
    """Remove what a killed save left behind in ``folder``: our temporary files
    (``.NAME.XXXXXXXX.tmp``, only for ``names`` when given) and half-built folders
    (``.NAME.XXXXXXXX`` beside a ``NAME`` they were to replace; any such, in a folder that is
    all ``own``: a campaign's output). Returns what was removed."""
    folder = Path(folder)
    if not folder.is_dir():
        return []
    removed = []
    it = folder.rglob(".*") if recursive else folder.glob(".*")
    for p in list(it):
        try:
            if p.is_file() and not p.is_symlink() and _TMP_FILE.match(p.name):
                if names is None or any(p.name.startswith(f".{n}.") for n in names):
                    p.unlink()
                    removed.append(p)
            elif p.is_dir() and not p.is_symlink() and names is None:
                m = _TMP_DIR.match(p.name)
                if m and (own or (p.parent / m.group(1)).exists()):
                    shutil.rmtree(p, ignore_errors=True)
                    removed.append(p)
        except OSError:
            continue  # gone meanwhile, or not ours to remove
    return removed
