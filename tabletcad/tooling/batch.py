"""Scripting API: tooling for a range of tablet sizes in one call (with a tqdm progress bar),
in this process or on a Dask cluster (:mod:`tabletcad.parallel`).

>>> from tabletcad.tooling import tooling_batch, ToolingSpec
>>> rows = tooling_batch("thesis.shallow_convex_round",
...                      [dict(diameter=d, thickness=0.3 * d, band=0.2 * d) for d in (6, 8, 10)],
...                      ToolingSpec(clearance_mm=0.02), out_dir="tools")   # doctest: +SKIP
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any, Iterable

from tabletcad.families import FAMILIES
from tabletcad.families import family as lookup_family
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
                  drawing: bool = True, workers: int = 0, scheduler: str | None = None, client=None) -> list[dict]:
    """Tooling for every parameter set in ``sizes`` of ``family``; one summary row per size.

    Files go to ``out_dir/<family>_<k>/`` when ``out_dir`` is given, with ``batch.json`` naming each
    folder's parameters and summary row.  The batch owns ``out_dir`` as a build owns its folder
    (:mod:`tabletcad.io.outputs`): everything is written at once when every size is made, the folders of
    an earlier, larger batch are removed, and a file it would replace that no batch wrote there, or that
    was edited since, is refused (:class:`~tabletcad.errors.DesignError`) before any size is made.
    Rows hold the parameters,
    tablet and punch volumes, the quadrature check, the largest OCC/manifold3d disagreement and
    the seconds spent (total and in OCC Booleans).

    Runs on :func:`tabletcad.parallel.map_tasks`: in this process by
    default (``workers=0``), on a local Dask cluster of ``workers`` processes, on the cluster of
    ``scheduler`` (an address) or of an open ``client``.  Workers receive the parameters and
    return the rows and the files' bytes, which are written here.
    """
    from tabletcad.parallel import map_tasks

    if isinstance(spec, dict):
        spec = parse_tooling(spec)
    family = lookup_family(family, parameter="family").name
    sizes = [dict(p) for p in sizes]
    if out_dir is not None:  # a folder's files of someone else's, or edited, refused before any size is made
        from tabletcad.io.outputs import check_replaceable
        from tabletcad.tooling.stage import tooling_outputs

        names = tooling_outputs(spec if spec is not None else ToolingSpec()) if drawing else ["assembly.step"]
        check_replaceable(out_dir, ["batch.json"] + [f"{family}_{k:03d}/{n}" for k in range(len(sizes)) for n in names])

    # every size is made before any file is written: a size refused half-way (a tablet too large for its
    # die) had left the folders of the sizes before it
    results = map_tasks(_tooling_task, sizes, kwargs=dict(family=family, spec=spec, check=check,
                                                          interference_check=interference_check, drawing=drawing,
                                                          files=out_dir is not None),
                        client=client, scheduler=scheduler, workers=None if client or scheduler else workers,
                        progress=progress, desc=f"tooling {family}")
    rows = [r["row"] for r in results]
    if out_dir is not None:  # all at once, as a build publishes (an earlier batch's other sizes go)
        import json

        from tabletcad.io.outputs import publish, staging_folder

        with staging_folder(out_dir) as staging:
            for k, res in enumerate(results):
                d = staging / f"{family}_{k:03d}"
                d.mkdir()
                for name, data in res["files"].items():
                    (d / name).write_bytes(data)
            index = [dict(folder=f"{family}_{k:03d}", family=family, **row) for k, row in enumerate(rows)]
            (staging / "batch.json").write_text(json.dumps(index, indent=1, default=float) + "\n", encoding="utf-8")
            publish(staging, out_dir)
    return rows


def _tooling_task(params: dict, *, family: str, spec: ToolingSpec | None, check: bool, interference_check: bool,
                  drawing: bool, files: bool) -> dict:
    """One size of :func:`tooling_batch` on a worker: its summary row and (optionally) its files as bytes."""
    import tempfile

    from tabletcad.tooling.stage import write_tooling
    from tabletcad.tooling.toolset import make_tooling

    t0 = time.perf_counter()
    tablet = FAMILIES[family].build(**params)  # the catalogue name (tooling_batch resolved it)
    ts = make_tooling(tablet, spec, check=check, interference_check=interference_check)
    data: dict[str, bytes] = {}
    if files:
        with tempfile.TemporaryDirectory(prefix="tabletcad-tooling-") as tmp:
            data = {p.name: p.read_bytes() for p in write_tooling(ts, Path(tmp), drawing=drawing)}
    r = ts.report
    row = dict(
        params=dict(params), tablet_volume_mm3=r["tablet"]["volume_mm3"],
        upper_punch_volume_mm3=r["upper_punch"]["volume_mm3"],
        upper_punch_rel_diff_vs_quadrature=r["upper_punch"]["volume_rel_diff_vs_quadrature"],
        boolean_max_rel_diff=r["boolean_max_rel_diff_occ_vs_manifold3d"],
        interference_mm3=r.get("interference_mm3"), max_gap_mm=r.get("max_gap_mm"),
        seconds=time.perf_counter() - t0, occ_boolean_seconds=r["seconds"]["occ_booleans"], files=list(data),
    )
    return dict(row=row, files=data)
