"""A design's refusal by ``tabletcad build``, as the tests of the toolmakers' trials check it."""

from __future__ import annotations

import re
from pathlib import Path

from tabletcad.cli import main

#: the one line a refusal prints
ONE_LINE = re.compile(r"^error: (\S+) = (.+) is not allowed: (.+)$")


def build_refused(capsys, tmp_path: Path, design: str) -> tuple[str, str, str]:
    """``(parameter, value, range)`` of the one-line refusal of ``tabletcad build`` of ``design`` (a TOML
    text written to ``tmp_path/d.toml``): exit status 2, one line, nothing written beside the design."""
    src = tmp_path / "d.toml"
    src.write_text(design, encoding="utf-8")
    assert main(["build", str(src), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    m = ONE_LINE.match(err[0])
    assert m, err[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.toml"]
    return m.group(1), m.group(2), m.group(3)
