"""``tabletcad build``: every output of a design, written all-or-nothing into a folder.

Outputs are produced in a staging folder beside the target and moved into
place only when all of them succeeded, so a failure leaves no partial file;
the folder then holds exactly this build's files besides any files tabletcad
did not write (:mod:`tabletcad.io.outputs`).
The CAD outputs (STEP, STL, GLB, tooling) are added when the CAD layer
(:mod:`tabletcad.cad`) can be imported.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Callable

from tabletcad.errors import reraise_interrupt
from tabletcad.design import load_design
from tabletcad.io.outputs import STAGING_MARKER, publish, staging_folder
from tabletcad.plot import plot_tablet
from tabletcad.report import geometry_report, to_json
from tabletcad.tablet import Tablet

__all__ = ["build_design", "build_tablet", "register_stage"]

# Extra stages: (name, callable (tablet, design_path, out, report) -> None, check or None), run in order.
# A stage's check (tablet, design_path) -> None validates its input and raises DesignError before
# any stage builds geometry.
_STAGES: list[tuple[str, Callable[..., None]]] = []
_CHECKS: dict[str, Callable[..., None]] = {}


def register_stage(name: str, func: Callable[..., None], check: Callable[..., None] | None = None) -> None:
    """Add an output stage (used by the CAD layer and tooling) run after the core outputs.

    ``check(tablet=..., design_path=...)``, if given, runs before any stage builds anything:
    bad input of the stage is refused before the (slow) geometry.
    """
    if name not in [n for n, _ in _STAGES]:
        _STAGES.append((name, func))
    if check is not None:
        _CHECKS[name] = check


def _load_optional_stages() -> None:
    try:
        import tabletcad.cad.stage  # noqa: F401  (registers its stages)
    except ImportError as exc:  # the CAD layer is optional
        reraise_interrupt(exc)  # ... but a Ctrl-C during its import is not its absence
        if os.environ.get("TABLETCAD_REQUIRE_CAD"):
            raise
        _ = exc


def build_tablet(tablet: Tablet, out_dir: str | Path, *, design_path: str | Path | None = None, progress: bool = True) -> dict[str, Any]:
    """Write ``report.json``, ``tablet.png`` and the CAD files of ``tablet`` into ``out_dir``.

    Returns the report; ``report["outputs"]`` names the files this build wrote.
    Nothing in ``out_dir`` changes if any stage fails.  The folder is owned by
    the build (:mod:`tabletcad.io.outputs`): files of an earlier build that
    this one does not write are removed, files tabletcad did not write are kept.
    """
    out_dir = Path(out_dir)
    _load_optional_stages()
    stages = list(_STAGES)
    for name, _ in stages:  # every stage's input is checked before any geometry is built
        if name in _CHECKS:
            _CHECKS[name](tablet=tablet, design_path=design_path)
    with staging_folder(out_dir) as staging:
        report = geometry_report(tablet)
        try:
            from tqdm import tqdm

            it = tqdm(stages, desc="build", unit="stage", disable=not progress or not stages, leave=False)
        except ImportError:  # pragma: no cover
            it = stages
        for name, func in it:
            func(tablet=tablet, design_path=design_path, out=staging, report=report)
        plot_tablet(tablet, staging / "tablet.png")
        names = sorted(p.name for p in staging.iterdir() if p.name != STAGING_MARKER) + ["report.json"]
        report["outputs"] = sorted(names)
        (staging / "report.json").write_text(to_json(report), encoding="utf-8")
        publish(staging, out_dir)
        return report


def build_design(design: str | Path, out_dir: str | Path, *, progress: bool = True) -> dict[str, Any]:
    """Load a design file and :func:`build_tablet` it."""
    tablet = load_design(design)
    return build_tablet(tablet, out_dir, design_path=design, progress=progress)
