"""Every code block of the README runs, so none of them can silently rot.

* ```` ```sh ```` blocks: each line is a command (a trailing ``# comment`` is dropped) run
  with the project's ``.venv/bin`` first on ``PATH``, in a fresh folder that holds a
  ``samples`` link to the repository's samples; every command must exit 0.
* Transcript blocks (no language, lines starting with ``$ ``): each command runs the same
  way, and every line the README shows under it must appear among the lines it printed
  (white space folded; ``...`` in a shown line stands for anything, e.g. a time; in a line
  that ends ``# numbers within P %`` each number may differ by P %: an FE figure on gmsh's mesh),
  so the figures quoted in the README are the figures the command
  prints today.
* ```` ```python ```` blocks run as scripts in such a folder.
* ```` ```toml ```` blocks must parse.

Two commands are not run from here: ``make test`` is this very suite, and ``make demo``
runs its set-up then ``tabletcad build`` of the demo sample, which
``test_make_demo_builds_the_sample`` runs as the Makefile does.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.cad  # the README describes (and runs) the full install: CAD, FE, Dask, FreeCAD

try:
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib

REPO = Path(__file__).resolve().parent.parent
README = REPO / "README.md"
NOT_RUN_HERE = {"make test"}


def _blocks() -> list[tuple[int, str, str]]:
    """``(line, language, text)`` of every fenced block of the README."""
    out, lang, start, buf = [], None, 0, []
    for i, line in enumerate(README.read_text(encoding="utf-8").splitlines(), start=1):
        if line.startswith("```"):
            if lang is None:
                lang, start, buf = line[3:].strip(), i, []
            else:
                out.append((start, lang, "\n".join(buf)))
                lang = None
        elif lang is not None:
            buf.append(line)
    assert lang is None, f"README: block at line {start} is not closed"
    return out


BLOCKS = _blocks()


def _fold(s: str) -> str:
    return " ".join(s.split())


def _strip_comment(cmd: str) -> str:
    return re.sub(r"(^|\s+)#.*$", "", cmd).strip()


_NUMBER = r"[-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?"
_WITHIN = re.compile(r"\s+#\s*numbers within (\d+(?:\.\d+)?) %\s*$")


def _pattern(shown: str) -> re.Pattern:
    """A README output line as a pattern: white space folded, ``...`` stands for anything; in a
    line marked ``# numbers within P %`` every number is a number (compared by :func:`_matches`)."""
    m = _WITHIN.search(shown)
    if m:
        shown = shown[: m.start()]
    parts = []
    for part in _fold(shown).split("..."):
        if m:
            pieces = re.split(f"({_NUMBER})", part)
            parts.append("".join(f"({_NUMBER})" if k % 2 else re.escape(x) for k, x in enumerate(pieces)))
        else:
            parts.append(re.escape(part))
    return re.compile(".*".join(parts))


def _matches(shown: str, printed: str) -> bool:
    """``printed`` is the README's ``shown`` line; a line marked ``# numbers within P %`` (a figure
    that moves with a library's release, e.g. an FE result on gmsh's mesh) matches when every number
    printed lies within P % of the one shown."""
    found = _pattern(shown).fullmatch(printed)
    m = _WITHIN.search(shown)
    if not found or not m:
        return bool(found)
    want = re.findall(_NUMBER, _fold(shown[: m.start()]).replace("...", " "))
    tol = float(m.group(1)) / 100.0
    return all(abs(float(g) - float(w)) <= tol * abs(float(w)) for g, w in zip(found.groups(), want))


def _workdir(tmp_path: Path) -> Path:
    (tmp_path / "samples").symlink_to(REPO / "samples")
    (tmp_path / ".venv").symlink_to(Path(sys.executable).parent.parent)
    return tmp_path


def _env(home: Path) -> dict[str, str]:
    """The environment of a README command: the venv's commands first, a throw-away HOME
    (``make freecad-workbench`` installs into the user's FreeCAD folder)."""
    env = dict(os.environ)
    home.mkdir(exist_ok=True)
    env["HOME"] = str(home)
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    env.setdefault("MPLBACKEND", "Agg")
    return env


def _run(cmd: str, cwd: Path) -> subprocess.CompletedProcess:
    if cmd.startswith("make "):
        cmd = f"make -C {shlex.quote(str(REPO))} {cmd[5:]}"
    return subprocess.run(cmd, shell=True, cwd=cwd, env=_env(cwd / ".home"), capture_output=True, text=True, timeout=900)


def _ids(kind: str) -> list:
    return [pytest.param(text, id=f"line{line}") for line, lang, text in BLOCKS if lang == kind]


def _transcripts() -> list:
    return [
        pytest.param(text, id=f"line{line}")
        for line, lang, text in BLOCKS
        if lang == "" and any(ln.startswith("$ ") for ln in text.splitlines())
    ]


@pytest.mark.parametrize("text", _ids("sh"))
def test_shell_block_runs(text: str, tmp_path: Path) -> None:
    cwd = _workdir(tmp_path)
    for line in text.splitlines():
        cmd = _strip_comment(line.strip()) if line.strip() else ""
        if not cmd or cmd in NOT_RUN_HERE or cmd == "make demo":
            continue
        r = _run(cmd, cwd)
        assert r.returncode == 0, f"{cmd!r} exited {r.returncode}:\n{r.stdout[-2000:]}\n{r.stderr[-2000:]}"


@pytest.mark.parametrize("text", _transcripts())
def test_transcript_prints_what_the_readme_shows(text: str, tmp_path: Path) -> None:
    cwd = _workdir(tmp_path)
    cmd, expected = None, []

    def check() -> None:
        r = _run(cmd, cwd)
        refused = any(s.startswith("error: ") for s in expected)
        want = 2 if refused else 0
        assert r.returncode == want, f"{cmd!r} exited {r.returncode}, not {want}:\n{r.stderr[-2000:]}"
        printed = [_fold(s) for s in (r.stderr if refused else r.stdout).splitlines()]
        missing = [s for s in expected if not any(_matches(s, p) for p in printed)]
        assert not missing, f"{cmd!r} no longer prints:\n" + "\n".join(missing) + f"\n--- it printed:\n{r.stdout}"

    for line in text.splitlines():
        if line.startswith("$ "):
            if cmd is not None:
                check()
            cmd, expected = _strip_comment(line[2:]), []
        elif line.strip():
            expected.append(line)
    if cmd is not None:
        check()


@pytest.mark.parametrize("text", _ids("python"))
def test_python_block_runs(text: str, tmp_path: Path) -> None:
    cwd = _workdir(tmp_path)
    script = cwd / "block.py"
    script.write_text(text, encoding="utf-8")
    r = subprocess.run(
        [sys.executable, str(script)], cwd=cwd, env=_env(cwd / ".home"), capture_output=True, text=True, timeout=900
    )
    assert r.returncode == 0, r.stderr[-3000:]


@pytest.mark.parametrize("text", _ids("toml"))
def test_toml_block_parses(text: str) -> None:
    tomllib.loads(text)


@pytest.mark.parametrize("text", _ids("toml"))
def test_toml_block_is_taken_by_its_reader(text: str, tmp_path: Path) -> None:
    """A design, ``[tooling]`` or sweep block copied from the README is what tabletcad takes (the
    ``[tooling]`` example once put ``gap_mm`` under ``[tooling.punch]``, which a design refuses)."""
    data = tomllib.loads(text)
    readers = 0
    if "tablet" in data:
        from tabletcad.pipeline.design import Design

        Design.from_dict(data)
        readers += 1
    if "tooling" in data:
        from tabletcad.tooling.spec import parse_tooling

        spec = parse_tooling(data["tooling"])
        readers += 1
        if "tablet" not in data:  # every check short of the Booleans, on the README's 10 mm concave round (a
            # trial: the example's lower tip of 8 mm, the default, could never clear the 22.22 mm die)
            from tabletcad.pipeline.design import Design
            from tabletcad.tooling.outline import tablet_frame
            from tabletcad.tooling.toolset import check_on_frame

            tablet = Design.from_dict({"tablet": dict(family="concave_round", diameter=10.0, band=2.8, cup_depth=0.9,
                                                      land=0.08)}).build()
            check_on_frame(tablet_frame(tablet), spec)
    if "sweep" in data:
        from tabletcad.sweep.spec import load_sweep

        f = tmp_path / "sweep.toml"
        f.write_text(text, encoding="utf-8")
        load_sweep(f)
        readers += 1
    assert readers, f"a TOML block no reader checks: {text.splitlines()[0]}"
    # a block that names the sample it shows holds that sample's data (the sweep block had an outputs line
    # the file lacks)
    named = re.search(r"#\s*(samples/\S+\.toml)", text.splitlines()[0])
    if named:
        assert data == tomllib.loads((REPO / named.group(1)).read_text(encoding="utf-8")), named.group(1)


def test_every_block_is_checked() -> None:
    """A block in a language the tests above do not read would rot unseen (``text`` marks a
    block that is no command, such as the layout tree)."""
    kinds = {"sh", "python", "toml", "text"}
    for line, lang, text in BLOCKS:
        if lang in kinds:
            continue
        assert lang == "" and any(ln.startswith("$ ") for ln in text.splitlines()), (
            f"README line {line}: a ```{lang} block that no test runs"
        )


def test_make_demo_builds_the_sample(tmp_path: Path) -> None:
    """``make demo`` = set-up (this environment) + ``tabletcad build SAMPLE --out out/demo``."""
    makefile = (REPO / "Makefile").read_text(encoding="utf-8")
    m = re.search(r"^demo: setup\n\t\$\(VENV\)/bin/tabletcad (build \$\(SAMPLE\) --out \S+)$", makefile, re.M)
    assert m, "the Makefile's demo target changed: update this test"
    sample = re.search(r"^SAMPLE \?= (\S+)$", makefile, re.M).group(1)
    r = _run(f"tabletcad build {REPO / sample} --out demo", _workdir(tmp_path))
    assert r.returncode == 0, r.stderr[-2000:]
    names = {p.name for p in (tmp_path / "demo").iterdir()}
    assert {"report.json", "tablet.png", "tablet.step", "tablet.stl", "tablet.glb"} <= names
