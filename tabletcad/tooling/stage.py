"""The tooling stage of ``tabletcad build``: runs when the design file has a ``[tooling]`` table.

Writes ``assembly.step``, ``upper_punch.step``, ``lower_punch.step``,
``die.step``, ``drawing.svg`` and ``drawing.dxf`` into the build's staging
folder and adds the ``tooling`` section to ``report.json`` (``interference_mm3``,
``max_gap_mm`` and the per-method details).  Bad ``[tooling]`` input raises
:class:`~tabletcad.errors.DesignError` before anything is built (the CLI
exits with status 2 and the build writes nothing).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from tabletcad.build import register_stage
from tabletcad.errors import DesignError, GeometryError
from tabletcad.tablet import Tablet

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

__all__ = ["tooling_stage", "read_tooling_table", "write_tooling"]


def read_tooling_table(design_path) -> dict | None:
    """The ``[tooling]`` table of a design file, or None."""
    if design_path is None:
        return None
    data = tomllib.loads(Path(design_path).read_text(encoding="utf-8"))
    return data.get("tooling")


def write_tooling(ts, out: Path, *, drawing: bool = True) -> list[Path]:
    """Write the STEP files (and the drawing) of a :class:`~tabletcad.tooling.toolset.ToolSet`."""
    from tabletcad.tooling.assembly import write_assembly, write_parts

    out = Path(out)
    files = [write_assembly(ts.parts, out / "assembly.step", name=f"{ts.tablet.name}_tooling",
                            offsets={"upper_punch": ts.lift_mm})]
    files += write_parts(ts.parts, out)
    if drawing:
        from tabletcad.tooling.drawing import write_drawing

        files += write_drawing(ts, out)
    return files


def tooling_stage(*, tablet: Tablet, out: Path, report: dict[str, Any], design_path=None) -> None:
    table = read_tooling_table(design_path)
    if table is None:
        return
    from tabletcad.tooling.spec import parse_tooling
    from tabletcad.tooling.toolset import make_tooling

    spec = parse_tooling(table)
    t = tablet.trim
    if t.u != (0.0, 1.0) or not t.full_v or t.w[0] > 0:
        raise DesignError("[tooling]", tablet.name, "tooling needs a whole solid tablet (no [trim], no ring)")
    ts = make_tooling(tablet, spec)
    res = ts.report
    if res.get("interference_mm3", 0.0) > 1e-6 or not res["interference"]["gap_within_clearance"]:
        raise GeometryError(
            f"{tablet.name}: tooling check failed: overlap {res['interference_mm3']:.3g} mm^3, largest gap "
            f"{res['max_gap_mm']:.4g} mm (clearance {spec.clearance_mm} mm)", ts)
    files = write_tooling(ts, Path(out))
    res["files"] = sorted(p.name for p in files)
    report["tooling"] = res


register_stage("tooling", tooling_stage)
