"""The FreeCADs the FreeCAD tests run under: Debian's 0.20 and trixie's 1.0 (in a chroot).

``FREECADS`` lists both, each with the command that runs its ``FreeCADCmd`` (and its GUI
under Xvfb): the system's ``freecadcmd`` (0.20), and ``.ci/freecad1 run freecadcmd`` for
the Debian trixie root that ``.ci/freecad1 build`` (called from ``.ci/setup``) keeps in
``/var/cache/tabletcad/freecad-trixie``.  ``params()`` gives one ``pytest.param`` per
version; a missing one is a skip, which ``conftest.py`` turns into a failure in CI.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FREECAD1 = ROOT / ".ci" / "freecad1"


def clean_env() -> dict[str, str]:
    """The environment without the project's virtual environment (FreeCAD uses its own Python)."""
    env = dict(os.environ)
    venv = env.pop("VIRTUAL_ENV", None)
    for k in ("PYTHONPATH", "PYTHONHOME", "MPLBACKEND"):
        env.pop(k, None)
    drop = {str(Path(sys.prefix) / "bin")}
    if venv:
        drop.add(str(Path(venv) / "bin"))
    env["PATH"] = os.pathsep.join(p for p in env.get("PATH", "").split(os.pathsep) if p and p not in drop)
    return env


def _which(*names: str) -> str | None:
    path = clean_env()["PATH"]
    for n in names:
        exe = shutil.which(n, path=path)
        if exe:
            return exe
    return None


@dataclass(frozen=True)
class FreeCADInstall:
    """One FreeCAD: ``cmd`` runs its FreeCADCmd, ``gui`` its GUI (``None``: not available)."""

    version: str
    cmd: tuple[str, ...] | None
    gui: tuple[str, ...] | None
    missing: str = ""

    @property
    def id(self) -> str:
        return f"fc{self.version}"


def _system() -> FreeCADInstall:
    cmd = _which("freecadcmd", "FreeCADCmd")
    gui = _which("freecad", "FreeCAD")
    return FreeCADInstall(
        "0.20",
        (cmd,) if cmd else None,
        (gui,) if gui else None,
        "" if cmd else "freecadcmd not installed (Debian: freecad-python3; .ci/setup)",
    )


def _chroot() -> FreeCADInstall:
    root = Path(os.environ.get("TABLETCAD_FREECAD1_ROOT", "/var/cache/tabletcad/freecad-trixie"))
    ok = (root / "usr/bin/freecadcmd").is_symlink() and (root / ".tabletcad-stamp").is_file()
    why = ""
    if not ok:
        why = f"FreeCAD 1.0 root {root} not built (.ci/freecad1 build)"
    elif os.geteuid() != 0 and shutil.which("sudo") is None:
        ok, why = False, "FreeCAD 1.0 root needs root (chroot)"
    run = (str(FREECAD1), "run")
    return FreeCADInstall(
        "1.0",
        run + ("freecadcmd",) if ok else None,
        run + ("freecad",) if ok else None,  # X display: the host's Xvfb (its socket is in /tmp)
        why,
    )


FREECADS = (_system(), _chroot())


def params(gui: bool = False) -> list:
    """One ``pytest.param`` per FreeCAD (id ``fc0.20`` / ``fc1.0``), skipped when missing."""
    out = []
    for fc in FREECADS:
        have = fc.gui if gui else fc.cmd
        marks = () if have else (pytest.mark.skip(reason=fc.missing or f"FreeCAD {fc.version} GUI missing"),)
        out.append(pytest.param(fc, id=fc.id, marks=marks))
    return out


def version_of(fc: FreeCADInstall) -> str:
    """``major.minor.patch`` as FreeCAD itself reports it."""
    proc = subprocess.run(
        [*fc.cmd, "-c", "import FreeCAD; print('FCVERSION=' + '.'.join(FreeCAD.Version()[:3]))"],
        env=clean_env(),
        capture_output=True,
        text=True,
        timeout=120,
    )
    return next((ln.split("=", 1)[1] for ln in proc.stdout.splitlines() if ln.startswith("FCVERSION=")), "?")
