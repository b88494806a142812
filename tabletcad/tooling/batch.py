"""Scripting API: tooling for a range of tablet sizes in one call (with a tqdm progress bar).

>>> from tabletcad.tooling import tooling_batch, ToolingSpec
>>> rows = tooling_batch("shallow_convex_round",
...                      [dict(diameter=d, thickness=0.3 * d, band=0.2 * d) for d in (6, 8, 10)],
...                      ToolingSpec(clearance_mm=0.02), out_dir="tools")   # doctest: +SKIP
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any, Iterable

from tabletcad.shapes import FAMILIES, _load_plugins
from tabletcad.tooling.spec import ToolingSpec, parse_tooling

__all__ = ["tooling_batch", "tooling_for"]


def tooling_for(tablet, spec: ToolingSpec | dict | None = None, out_dir=None, **kw: Any):
    """:func:`~tabletcad.tooling.toolset.make_tooling` (``spec`` may be a ``[tooling]``-style dict),
    writing the STEP files and drawing into ``out_dir`` when given."""
    from tabletcad.tooling.toolset import make_tooling

    if isinstance(spec, dict):
        spec = parse_tooling(spec)
    ts = make_tooling(tablet, spec, **kw)
    if out_dir is not None:
        from tabletcad.tooling.stage import write_tooling

        Path(out_dir).mkdir(parents=True, exist_ok=True)
        ts.report["files"] = [p.name for p in write_tooling(ts, Path(out_dir))]
    return ts


def tooling_batch(family: str, sizes: Iterable[dict], spec: ToolingSpec | dict | None = None, *, out_dir=None,
                  progress: bool = True, check: bool = True, interference_check: bool = False,
                  drawing: bool = True) -> list[dict]:
    """Tooling for every parameter set in ``sizes`` of ``family``; one summary row per size.

    Files go to ``out_dir/<family>_<k>/`` when ``out_dir`` is given.  Rows hold the parameters,
    tablet and punch volumes, the quadrature check, the largest OCC/manifold3d disagreement and
    the seconds spent (total and in OCC Booleans).
    """
    from tqdm import tqdm

    from tabletcad.tooling.stage import write_tooling
    from tabletcad.tooling.toolset import make_tooling

    _load_plugins()
    if isinstance(spec, dict):
        spec = parse_tooling(spec)
    fam = FAMILIES[family]
    sizes = list(sizes)
    rows = []
    for k, params in enumerate(tqdm(sizes, desc=f"tooling {family}", unit="size", disable=not progress)):
        t0 = time.perf_counter()
        tablet = fam.build(**params)
        ts = make_tooling(tablet, spec, check=check, interference_check=interference_check)
        files = []
        if out_dir is not None:
            d = Path(out_dir) / f"{family}_{k:03d}"
            d.mkdir(parents=True, exist_ok=True)
            files = [p.name for p in write_tooling(ts, d, drawing=drawing)]
        r = ts.report
        rows.append(dict(
            params=dict(params), tablet_volume_mm3=r["tablet"]["volume_mm3"],
            upper_punch_volume_mm3=r["upper_punch"]["volume_mm3"],
            upper_punch_rel_diff_vs_quadrature=r["upper_punch"]["volume_rel_diff_vs_quadrature"],
            boolean_max_rel_diff=r["boolean_max_rel_diff_occ_vs_manifold3d"],
            interference_mm3=r.get("interference_mm3"), max_gap_mm=r.get("max_gap_mm"),
            seconds=time.perf_counter() - t0, occ_boolean_seconds=r["seconds"]["occ_booleans"], files=files,
        ))
    return rows
