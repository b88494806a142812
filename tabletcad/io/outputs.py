"""Output folders that a build owns: staging, publishing and the build manifest.

A build writes everything into a staging folder and, when every output succeeded,
moves the files into place with :func:`publish`.  The staging folder lies on the
output folder's own file system, so that every move is a rename: inside the output
folder (``<name>/.tabletcad-staging.<random>``) when it exists (a mount point, a
link to another disk, a folder in a parent the user cannot write), else beside it
(``.<name>.<random>``, where the output folder will be made).  The output folder then holds a manifest,
``.tabletcad-build.json``, naming every file of that build with its SHA-256.
The next build into the same folder removes the files of the earlier build
that it does not write itself, but only those listed by the earlier manifest
*and unchanged since* (same hash): files that tabletcad did not write, or that
someone edited after the build, are never touched, and a build that would write a
file of the same name as one of them is refused (:class:`~tabletcad.errors.DesignError`
for ``--out``) before anything in the folder changes.

A staging folder carries a marker (``.tabletcad-staging.json``: process id,
host, start time).  :func:`staging_folder` removes the current staging folder
on any exception, on Ctrl-C and on SIGTERM; a build killed outright (SIGKILL,
power loss) leaves its staging folder, and the next build into the same
folder removes it once the process named in its marker is gone (or, on
another host, once it is older than :data:`STALE_AFTER_S`).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shutil
import socket
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

from tabletcad.errors import DesignError
from tabletcad.io.atomic import atomic_write_text
from tabletcad.io.signals import sigterm_raises, signals_deferred

__all__ = ["MANIFEST", "OPTIMISE_MANIFEST", "STAGING_MARKER", "STALE_AFTER_S", "staging_folder", "publish", "read_manifest",
           "clean_stale_staging", "file_sha256", "check_replaceable"]

MANIFEST = ".tabletcad-build.json"
#: the manifest of ``tabletcad optimise``'s folder: a command owns the files of its own manifest only, so a
#: build into an optimisation's folder never takes its results (optimum.toml, report.json) for its own
OPTIMISE_MANIFEST = ".tabletcad-optimise.json"
#: the files an FE command wrote into its ``--out`` folder (``tabletcad fe diametral/punch``)
FE_MANIFEST = ".tabletcad-fe.json"

#: Output folders that :func:`publish` completed in this process.  The command line reads it: a
#: Ctrl-C that reaches a build after its outputs are in place is too late to undo it, and the
#: command reports the finished build rather than "interrupted" beside a full folder.
published: list[Path] = []
#: Staging folders open in this process (:func:`staging_folder`): a publish into one of them (an optimisation's
#: build of its optimum, put in place inside the optimisation's staging folder) is not a finished output.
_open_staging: list[Path] = []
STAGING_MARKER = ".tabletcad-staging.json"
#: a staging folder of another host (its process cannot be asked) is stale after this many seconds
STALE_AFTER_S = 24 * 3600.0


def file_sha256(path: Path) -> str:
    """Hex SHA-256 of a file's bytes."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def read_manifest(out_dir: str | os.PathLike[str], manifest: str = MANIFEST) -> dict[str, str]:
    """``{relative file name: sha256}`` of the build recorded in ``out_dir`` (empty if none or unreadable)."""
    try:
        data = json.loads((Path(out_dir) / manifest).read_text(encoding="utf-8"))
        files = data["files"]
        return {str(k): str(v) for k, v in files.items()} if isinstance(files, dict) else {}
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return {}


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    except (OSError, OverflowError, ValueError):
        return False
    return True


def _is_stale(folder: Path, now: float) -> bool:
    """A staging folder whose build is over: its process is gone (same host) or it is old."""
    try:
        marker = json.loads((folder / STAGING_MARKER).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False  # not ours (no marker), or being created right now
    if not isinstance(marker, dict):
        return False
    pid, host, started = marker.get("pid"), marker.get("host"), marker.get("started")
    if host == socket.gethostname() and isinstance(pid, int) and pid != os.getpid():
        return not _pid_alive(pid)
    return isinstance(started, (int, float)) and now - started > STALE_AFTER_S


#: prefix of a staging folder inside an existing output folder
INNER_PREFIX = ".tabletcad-staging."


def clean_stale_staging(out_dir: str | os.PathLike[str]) -> list[Path]:
    """Remove staging folders of ``out_dir`` left by killed builds (``.<name>.*`` beside it and
    ``.tabletcad-staging.*`` inside it, each with its marker); return them."""
    out_dir = Path(out_dir)
    removed = []
    now = time.time()
    for folder, pattern in ((out_dir.parent, f".{out_dir.name}.*"), (out_dir, f"{INNER_PREFIX}*")):
        with contextlib.suppress(OSError):
            for p in folder.glob(pattern):
                if p.is_dir() and not p.is_symlink() and _is_stale(p, now):
                    shutil.rmtree(p, ignore_errors=True)
                    removed.append(p)
    return removed


@contextlib.contextmanager
def staging_folder(out_dir: str | os.PathLike[str]) -> Iterator[Path]:
    """A fresh staging folder on ``out_dir``'s file system, removed on exit whatever happens: inside
    ``out_dir`` when it is an existing folder (or a link to one), else beside it.

    Stale staging folders of earlier, killed builds into ``out_dir`` are removed
    first.  SIGTERM and Ctrl-C inside the block remove the folder too.
    """
    out_dir = Path(out_dir)
    inside = out_dir.is_dir()
    with sigterm_raises():
        try:
            if not inside:
                out_dir.parent.mkdir(parents=True, exist_ok=True)
            clean_stale_staging(out_dir)
            staging = Path(tempfile.mkdtemp(prefix=INNER_PREFIX, dir=out_dir) if inside
                           else tempfile.mkdtemp(prefix=f".{out_dir.name}.", dir=out_dir.parent))
        except OSError as exc:  # e.g. a folder of a read-only or virtual file system (/proc)
            raise DesignError("--out", str(out_dir), f"cannot be written: {(exc.strerror or str(exc)).lower()}") from None
        _open_staging.append(staging)
        try:
            marker = dict(pid=os.getpid(), host=socket.gethostname(), started=time.time(), target=out_dir.name)
            (staging / STAGING_MARKER).write_text(json.dumps(marker), encoding="utf-8")
            yield staging
        finally:
            _open_staging.remove(staging)
            shutil.rmtree(staging, ignore_errors=True)


def publish(staging: str | os.PathLike[str], out_dir: str | os.PathLike[str], manifest: str = MANIFEST) -> list[str]:
    """Move the files of ``staging`` into ``out_dir`` and record them in its manifest.

    Files of the earlier build in ``out_dir`` (its manifest) that this build did
    not write are removed if they are unchanged since that build; nothing else
    in ``out_dir`` is touched.  Returns the published names (relative, sorted).

    Raises
    ------
    DesignError
        ``--out``: the folder holds a file of a name this build writes that is not an
        unchanged file of the earlier build (someone else's, or edited); nothing is moved.
    """
    staging, out_dir = Path(staging), Path(out_dir)
    files = sorted(p.relative_to(staging) for p in staging.rglob("*") if p.is_file() and p.name != STAGING_MARKER)
    hashes = {p.as_posix(): file_sha256(staging / p) for p in files}
    earlier = read_manifest(out_dir, manifest)
    check_replaceable(out_dir, [rel.as_posix() for rel in files], earlier, manifest)
    with signals_deferred():  # Ctrl-C or SIGTERM now would leave half a build in out_dir
        _move_in(staging, out_dir, files, hashes, earlier, manifest)
        if not _inside_open_staging(out_dir):  # (a Ctrl-C now finds a finished output only if it is the final one)
            published.append(out_dir)
    return sorted(hashes)


def _inside_open_staging(folder: Path) -> bool:
    """Whether ``folder`` lies in a staging folder this process has open (its outputs are not yet published)."""
    here = os.path.realpath(folder)
    for st in _open_staging:
        root = os.path.realpath(st)
        if here == root or here.startswith(root + os.sep):
            return True
    return False


def check_replaceable(out_dir: str | os.PathLike[str], names, earlier: dict[str, str] | None = None,
                      manifest: str = MANIFEST) -> None:
    """Refuse (:class:`~tabletcad.errors.DesignError` for ``--out``) when ``out_dir`` holds a file of
    one of ``names`` (relative paths a build writes) that a build may not replace: one that no
    tabletcad build wrote there, or one edited since (its hash is not the manifest's)."""
    out_dir = Path(out_dir)
    earlier = read_manifest(out_dir, manifest) if earlier is None else earlier
    theirs = [n for n in names if not _ours(out_dir / n, earlier.get(n))]
    if theirs:  # replacing them would lose what someone else put there
        shown = ", ".join(theirs[:3]) + (f" and {len(theirs) - 3} more" if len(theirs) > 3 else "")
        who = {OPTIMISE_MANIFEST: ("run", "tabletcad optimise run"), FE_MANIFEST: ("run", "tabletcad fe run")}.get(
            manifest, ("build", "tabletcad build"))
        raise DesignError("--out", str(out_dir), f"must not hold files this {who[0]} writes that no earlier "
                          f"{who[1]} wrote there or that were edited since ({shown}): move them or write into another "
                          "folder")


def _ours(path: Path, digest: str | None) -> bool:
    """Whether a build may replace ``path``: nothing is there, or the file an earlier build wrote,
    unchanged since (its manifest's ``digest``)."""
    if not os.path.lexists(path):
        return True
    if digest is None or path.is_symlink() or not path.is_file():
        return False
    try:
        return file_sha256(path) == digest
    except OSError:
        return False


def _move_in(staging: Path, out_dir: Path, files: list[Path], hashes: dict[str, str], earlier: dict[str, str],
             manifest: str = MANIFEST) -> None:
    out_dir.mkdir(parents=True, exist_ok=True)
    umask = os.umask(0)
    os.umask(umask)
    for rel in files:
        src, dst = staging / rel, out_dir / rel
        dst.parent.mkdir(parents=True, exist_ok=True)
        os.chmod(src, 0o666 & ~umask)
        os.replace(src, dst)
    for name, digest in earlier.items():
        if name in hashes:
            continue
        old = out_dir / name
        if ".." in Path(name).parts or Path(name).is_absolute():
            continue  # a manifest never names anything outside the folder
        with contextlib.suppress(OSError):
            if old.is_file() and not old.is_symlink() and file_sha256(old) == digest:
                old.unlink()
                parent = old.parent
                while parent != out_dir and not any(parent.iterdir()):  # folders the old build made
                    parent.rmdir()
                    parent = parent.parent
    atomic_write_text(out_dir / manifest, json.dumps(dict(tool="tabletcad", files=hashes), indent=1) + "\n")
