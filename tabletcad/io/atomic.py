"""Atomic file writing: write to a temporary file beside the target, then rename.

A reader never sees a half-written file, and a failure leaves no file behind.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

__all__ = ["atomic_path", "atomic_write_bytes", "atomic_write_text"]


@contextlib.contextmanager
def atomic_path(target: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path in the target's folder; rename it onto ``target`` on success.

    The temporary file keeps the target's suffix so that writers which choose a
    format by suffix (meshio, OCC exporters) behave the same.  If the body
    raises, the temporary file is removed and ``target`` is left untouched.  A ``target`` that
    is a folder, or whose folder cannot be made or take files, is a
    :class:`~tabletcad.errors.DesignError` naming it, before anything is written.
    """
    target = Path(target)
    if target.is_dir():  # the rename would fail after the work with an error naming the temporary file
        from tabletcad.errors import DesignError

        raise DesignError("path", str(target), "is a folder: give the file's name (its suffix chooses the format)")
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{target.stem}.", suffix=target.suffix, dir=target.parent)
    except OSError as exc:  # (a file where a folder is needed, /proc): the target named, not the temporary file
        from tabletcad.errors import DesignError

        why = "a file of that name is in the way" if isinstance(exc, (FileExistsError, NotADirectoryError)) else \
            (exc.strerror or type(exc).__name__).lower()
        raise DesignError("path", str(target), f"cannot be written in {target.parent}: {why}") from None
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        try:
            yield tmp_path
        except OSError as exc:
            if exc.errno is None or exc.filename not in (None, str(tmp_path)):
                raise
            # a write into the temporary file refused by the system (no space left on device) names no file:
            # the target it stands for is named (the command line had said "output")
            raise OSError(exc.errno, exc.strerror, str(target)) from exc
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp_path, 0o666 & ~umask)  # mkstemp creates 0600; give the file normal permissions
        os.replace(tmp_path, target)
    finally:
        if tmp_path.exists():
            tmp_path.unlink()


def atomic_write_bytes(target: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to ``target`` atomically and return the target path."""
    with atomic_path(target) as tmp:
        tmp.write_bytes(data)
    return Path(target)


def atomic_write_text(target: str | os.PathLike[str], text: str) -> Path:
    """Write ``text`` (UTF-8) to ``target`` atomically and return the target path."""
    return atomic_write_bytes(target, text.encode("utf-8"))
