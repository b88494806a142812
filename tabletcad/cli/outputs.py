"""Output files of the commands: checked before anything is computed, written all or none."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

import click

from tabletcad.errors import DesignError

__all__ = ["check_output", "check_out_folder", "out_folder", "staged"]


def check_output(option: str, path: Path | None, suffixes: tuple[str, ...] = (".png", ".svg", ".pdf")) -> None:
    """Refuse, before anything is computed, an output file that could not be written."""
    if path is None:
        return
    if path.suffix.lower() not in suffixes:
        allowed = suffixes[0] if len(suffixes) == 1 else ", ".join(suffixes[:-1]) + f" or {suffixes[-1]}"
        raise DesignError(option, str(path), f"must end in {allowed}")
    if path.is_dir():
        raise DesignError(option, str(path), "is a folder; give a file name")
    from tabletcad.io.outputs import FE_MANIFEST, MANIFEST, OPTIMISE_MANIFEST, read_manifest

    records = (MANIFEST, FE_MANIFEST, OPTIMISE_MANIFEST)
    if path.name in records:  # overwritten, the folder's next run refuses its own files
        raise DesignError(option, str(path), "must not be the record of the files a tabletcad run owns in a folder "
                          "(give another name)")
    for record in records:  # a file a build, FE or optimise run owns there
        if path.name in read_manifest(path.parent, record):
            raise DesignError(option, str(path), f"is a file the tabletcad run in {path.parent} owns (its next run "
                              "would refuse it as edited): give another name or folder")
    _check_writable_from(option, path, path.absolute().parent)


def _check_writable_from(option: str, path: Path, start: Path) -> None:
    """Refuse ``path`` unless the nearest existing folder at or above ``start`` is a writable folder."""
    folder = start
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if not folder.is_dir():
        raise DesignError(option, str(path), f"cannot be created: {folder} is a file, not a folder")
    if not os.access(folder, os.W_OK | os.X_OK) or not _takes_files(folder):
        raise DesignError(option, str(path), f"cannot be written: folder {folder} is not writable")


def _takes_files(folder: Path) -> bool:
    """Whether a file can be made in ``folder``: a nameless temporary one is made and removed at once
    (``os.access`` says yes to root in /sys and /proc, where writing fails after the work is done)."""
    try:
        with tempfile.TemporaryFile(dir=folder, prefix=".tabletcad-probe-"):
            pass
    except OSError:
        return False
    return True


def check_out_folder(option: str, raw: str | os.PathLike[str]) -> Path:
    """The output folder ``raw`` as a path, or :class:`DesignError` for ``option`` before anything is
    computed: an empty name (an unset shell variable would build into the current folder), an
    existing file, or a folder that cannot be made or written."""
    if not str(raw).strip():
        raise DesignError(option, str(raw), "must name a folder (give . for the current one)")
    path = Path(raw)
    if path.exists() and not path.is_dir():
        raise DesignError(option, str(path), "must be a folder (a file of that name exists)")
    _check_writable_from(option, path, path.absolute())
    return path


def out_folder(option: str = "--out") -> click.ParamType:
    """click type of an output folder option: :func:`check_out_folder` on the text as given."""

    class OutFolder(click.ParamType):
        name = "folder"

        def convert(self, value, param, ctx):  # noqa: ARG002
            return value if isinstance(value, Path) else check_out_folder(option, value)

    return OutFolder()


@contextlib.contextmanager
def staged(**targets: Path | None) -> Iterator[dict[str, Path]]:
    """Temporary files standing for the outputs ``targets``; all are moved into place only if the body succeeds.

    The body writes each output to ``staged[name]`` (same suffix as its
    target).  If it raises, no target is touched; if moving one fails, the
    targets already moved that did not exist before are removed again.
    """
    from tabletcad.io import atomic_write_bytes

    with tempfile.TemporaryDirectory(prefix="tabletcad-") as tmp:
        staged = {k: Path(tmp) / f"{k}{p.suffix}" for k, p in targets.items() if p is not None}
        yield staged
        created: list[Path] = []
        k = None
        try:
            for k, src in staged.items():
                dst = targets[k]
                existed = dst.exists()
                atomic_write_bytes(dst, src.read_bytes())
                if not existed:
                    created.append(dst)
        except BaseException as exc:
            for dst in created:
                dst.unlink(missing_ok=True)
            if isinstance(exc, OSError) and k is not None:  # (/proc/x.json): named as the option, not a temporary
                raise DesignError({"json": "--json-file"}.get(k, f"--{k}"), str(targets[k]),
                                  f"cannot be written: {(exc.strerror or str(exc)).lower()}") from None
            raise
