"""A build owns its output folder: manifest, rebuilds, foreign files, staging folders of killed builds.

The publishing rules, tested on plain files (no CAD).  Real ``tabletcad build`` runs
(rebuilds, cut-aways, killed builds) are in ``test_build_outputs_cad.py``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tabletcad.io.outputs import MANIFEST, STAGING_MARKER, file_sha256, publish, read_manifest, staging_folder

ROOT = Path(__file__).resolve().parents[1]


# ----------------------------------------------------------------------------- publishing rules
def _stage(parent: Path, out: Path, files: dict[str, str]) -> list[str]:
    with staging_folder(out) as st:
        for name, text in files.items():
            (st / name).parent.mkdir(parents=True, exist_ok=True)
            (st / name).write_text(text)
        names = publish(st, out)
    return names


def test_rebuild_removes_only_unchanged_files_of_the_earlier_build(tmp_path):
    out = tmp_path / "out"
    assert _stage(tmp_path, out, {"a.step": "A", "b.stl": "B", "c.png": "C", "sub/d.svg": "D"}) == [
        "a.step", "b.stl", "c.png", "sub/d.svg"]
    manifest = read_manifest(out)
    assert manifest["b.stl"] == file_sha256(out / "b.stl")
    (out / "mine.txt").write_text("not tabletcad's")  # a file tabletcad did not write
    (out / "c.png").write_text("edited after the build")  # a build file someone changed
    names = _stage(tmp_path, out, {"a.step": "A2", "report.json": "{}"})
    assert names == ["a.step", "report.json"]
    left = sorted(p.relative_to(out).as_posix() for p in out.rglob("*"))
    # b.stl and sub/d.svg (unchanged, not rebuilt) are gone, with the folder sub/ the build made
    assert left == [MANIFEST, "a.step", "c.png", "mine.txt", "report.json"]
    assert (out / "a.step").read_text() == "A2" and (out / "c.png").read_text() == "edited after the build"
    assert sorted(read_manifest(out)) == ["a.step", "report.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no staging folder left


def test_an_output_folder_on_its_own_file_system_is_built_into(tmp_path, monkeypatch):
    """An existing output folder that is a mount point (or a link to another disk): renames across
    its boundary fail (EXDEV, simulated here for every ``os.replace``), so the build stages inside it.
    A rebuild, a foreign file kept, no staging folder left inside or beside it."""
    import errno

    out = tmp_path / "out"
    out.mkdir()
    (out / "mine.txt").write_text("the user's")
    real = os.replace

    def replace(src, dst):
        inside = [out in Path(x).parents for x in (src, dst)]
        if inside[0] != inside[1]:
            raise OSError(errno.EXDEV, "Invalid cross-device link", str(src), None, str(dst))
        return real(src, dst)

    monkeypatch.setattr(os, "replace", replace)
    assert _stage(tmp_path, out, {"a.step": "A", "sub/b.svg": "B"}) == ["a.step", "sub/b.svg"]
    assert _stage(tmp_path, out, {"a.step": "A2"}) == ["a.step"]
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*")) == [MANIFEST, "a.step", "mine.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_a_killed_builds_staging_folder_inside_the_output_folder_is_cleaned(tmp_path):
    from tabletcad.io.outputs import INNER_PREFIX

    out = tmp_path / "out"
    _stage(tmp_path, out, {"a.step": "A"})
    child = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    dead = out / f"{INNER_PREFIX}dead"
    dead.mkdir()
    import socket

    (dead / STAGING_MARKER).write_text(json.dumps(dict(pid=int(child.stdout), host=socket.gethostname(),
                                                       started=time.time())))
    (out / ".tabletcad-staging.notours").mkdir()  # no marker: left alone
    assert _stage(tmp_path, out, {"a.step": "A2"}) == ["a.step"]
    assert not dead.exists() and (out / ".tabletcad-staging.notours").is_dir()


def test_build_into_a_link_to_another_file_system(tmp_path):
    """``tabletcad build --out LINK`` where LINK points at a folder on another file system than its
    own parent (/dev/shm, a tmpfs, when the machine has one apart from the tests' folder; else the
    link's target is a folder beside it, still a link to follow)."""
    import shutil
    import uuid

    shm = Path("/dev/shm")
    other = shm.is_dir() and os.access(shm, os.W_OK) and os.stat(shm).st_dev != os.stat(tmp_path).st_dev
    target = (shm if other else tmp_path) / f"tabletcad-test-{uuid.uuid4().hex}"
    target.mkdir()
    try:
        link = tmp_path / "link"
        link.symlink_to(target, target_is_directory=True)
        design = ROOT / "samples" / "flat_faced_round.toml"
        env = {**os.environ, "PYTHONPATH": str(ROOT)}
        for _ in range(2):  # a first build and a rebuild
            p = subprocess.run([sys.executable, "-m", "tabletcad", "build", str(design), "--out", str(link), "--quiet"],
                               capture_output=True, text=True, env=env, timeout=300)
            assert p.returncode == 0, p.stderr
        names = sorted(q.name for q in target.iterdir())
        assert "report.json" in names and MANIFEST in names
        assert not any(n.startswith(".tabletcad-staging.") for n in names)
        assert sorted(q.name for q in tmp_path.iterdir()) == ["link"] + ([] if other else [target.name])
    finally:
        shutil.rmtree(target, ignore_errors=True)


def test_a_build_never_replaces_a_file_it_did_not_write(tmp_path):
    """A file of a name the build writes that no build wrote there (or that was edited since the
    build that did) is refused before anything in the folder changes; an unchanged one is replaced."""
    from tabletcad.errors import DesignError

    out = tmp_path / "out"
    _stage(tmp_path, out, {"a.step": "A", "b.stl": "B"})
    (out / "mine.step").write_text("the user's own")
    (out / "b.stl").write_text("edited after the build")
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    for clash in ({"mine.step": "M"}, {"b.stl": "B2"}, {"a.step": "A2", "mine.step": "M"}):
        with pytest.raises(DesignError) as exc:
            _stage(tmp_path, out, clash)
        assert exc.value.parameter == "--out" and ("mine.step" in str(exc.value) or "b.stl" in str(exc.value))
        assert {p.name: p.read_bytes() for p in out.iterdir()} == before
        assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no staging folder left
    assert _stage(tmp_path, out, {"a.step": "A3"}) == ["a.step"]  # unchanged since its build: replaced
    assert (out / "a.step").read_text() == "A3" and (out / "mine.step").read_text() == "the user's own"


def test_cli_build_refuses_a_folder_holding_the_users_file_of_an_output_name(tmp_path):
    """``tabletcad build`` into a folder where the user keeps a file named like an output: exit 2,
    one line naming ``--out``, the file untouched, nothing else written; report.json (which every
    build writes) is refused before any geometry is built."""
    from tabletcad.pipeline.build import cad_available

    sample = ROOT / "samples" / "families" / "flat_face_round.toml"
    cad = cad_available()  # without the CAD extra (the core-only pass) no tablet.step is written
    for name in ("tablet.step", "report.json"):
        out = tmp_path / name.replace(".", "_")
        out.mkdir()
        (out / name).write_text("MY OWN")
        r = subprocess.run([sys.executable, "-m", "tabletcad", "build", str(sample), "--out", str(out)],
                           capture_output=True, text=True, cwd=tmp_path)
        assert (out / name).read_text() == "MY OWN"
        if name == "tablet.step" and not cad:  # nothing of that name written: the build runs beside it
            assert r.returncode == 0, r.stderr
            assert {"report.json", "tablet.png", name} <= {p.name for p in out.iterdir()}
            continue
        assert r.returncode == 2, r.stderr
        lines = r.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: --out = ") and name in lines[0], r.stderr
        assert sorted(p.name for p in out.iterdir()) == [name]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report_json", "tablet_step"]


def test_manifest_cannot_remove_files_outside_the_folder(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    victim = tmp_path / "victim.txt"
    victim.write_text("x")
    (out / MANIFEST).write_text(json.dumps({"files": {"../victim.txt": file_sha256(victim)}}))
    _stage(tmp_path, out, {"a.step": "A"})
    assert victim.read_text() == "x"


def test_unreadable_manifest_removes_nothing(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "old.step").write_text("O")
    (out / MANIFEST).write_text("{ not json")
    _stage(tmp_path, out, {"a.step": "A"})
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "a.step", "old.step"]


def test_staging_folder_is_removed_on_error_and_stale_ones_are_cleaned(tmp_path):
    out = tmp_path / "out"
    with pytest.raises(RuntimeError):
        with staging_folder(out) as st:
            assert (st / STAGING_MARKER).is_file()
            raise RuntimeError("stage failed")
    assert list(tmp_path.iterdir()) == []
    # a staging folder of a process that no longer exists (a finished child's pid)
    child = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    dead = tmp_path / ".out.dead1234"
    dead.mkdir()
    import socket

    (dead / STAGING_MARKER).write_text(json.dumps(dict(pid=int(child.stdout), host=socket.gethostname(), started=time.time())))
    (dead / "tablet.step").write_text("half")
    alive = tmp_path / ".out.alive123"  # a build still running (this very process's parent)
    alive.mkdir()
    (alive / STAGING_MARKER).write_text(json.dumps(dict(pid=os.getppid(), host=socket.gethostname(), started=time.time())))
    foreign = tmp_path / ".out.notours"  # no marker: not a tabletcad staging folder
    foreign.mkdir()
    with staging_folder(out):
        pass
    assert sorted(p.name for p in tmp_path.iterdir()) == [".out.alive123", ".out.notours"]
