"""``tabletcad build``: every output of a design, written all-or-nothing into a folder.

Outputs are produced in a staging folder beside the target and moved into
place only when all of them succeeded, so a failure leaves no partial file.
The CAD outputs (STEP, STL, GLB, tooling) are added when the CAD layer
(:mod:`tabletcad.cad`) can be imported.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path
from typing import Any, Callable

from tabletcad.design import load_design
from tabletcad.plot import plot_tablet
from tabletcad.report import geometry_report, to_json
from tabletcad.tablet import Tablet

__all__ = ["build_design", "build_tablet", "register_stage"]

# Extra stages: callables (tablet, design_path, staging_dir, report) -> None, run in order.
_STAGES: list[tuple[str, Callable[..., None]]] = []


def register_stage(name: str, func: Callable[..., None]) -> None:
    """Add an output stage (used by the CAD layer and tooling) run after the core outputs."""
    if name not in [n for n, _ in _STAGES]:
        _STAGES.append((name, func))


def _load_optional_stages() -> None:
    try:
        import tabletcad.cad.stage  # noqa: F401  (registers its stages)
    except ImportError as exc:  # the CAD layer is optional
        if os.environ.get("TABLETCAD_REQUIRE_CAD"):
            raise
        _ = exc


def build_tablet(tablet: Tablet, out_dir: str | Path, *, design_path: str | Path | None = None, progress: bool = True) -> dict[str, Any]:
    """Write ``report.json``, ``tablet.png`` and the CAD files of ``tablet`` into ``out_dir``.

    Returns the report.  Nothing is left in ``out_dir`` if any stage fails.
    """
    out_dir = Path(out_dir)
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.", dir=out_dir.parent))
    try:
        report = geometry_report(tablet)
        _load_optional_stages()
        stages = list(_STAGES)
        try:
            from tqdm import tqdm

            it = tqdm(stages, desc="build", unit="stage", disable=not progress or not stages, leave=False)
        except ImportError:  # pragma: no cover
            it = stages
        for name, func in it:
            func(tablet=tablet, design_path=design_path, out=staging, report=report)
        plot_tablet(tablet, staging / "tablet.png")
        (staging / "report.json").write_text(to_json(report), encoding="utf-8")
        out_dir.mkdir(parents=True, exist_ok=True)
        umask = os.umask(0)
        os.umask(umask)
        for f in sorted(staging.iterdir()):
            os.chmod(f, 0o666 & ~umask)
            os.replace(f, out_dir / f.name)
        return report
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def build_design(design: str | Path, out_dir: str | Path, *, progress: bool = True) -> dict[str, Any]:
    """Load a design file and :func:`build_tablet` it."""
    tablet = load_design(design)
    return build_tablet(tablet, out_dir, design_path=design, progress=progress)
