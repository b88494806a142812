"""Sweep results: ``results.csv``, its resume journal, the DataFrame and the plots.

Columns, in order: each varied key named exactly as in the sweep file, every
scalar of the report (dotted names for nested sections, e.g.
``design_report.weight_mg``; in the order the report gives them, new ones
appended as they first appear), then ``status`` (``ok`` or ``error``),
``error`` (the one-line message) and ``design_hash`` (the key
``--resume`` uses: :func:`tabletcad.sweep.spec.design_hash` of the design
dictionary).  One row per design, in the sweep's order.

While a sweep runs, each finished design is appended to
``results.partial.jsonl`` beside ``results.csv``; an interrupted sweep resumes
from both, and the journal is removed once ``results.csv`` is complete.
Floats are written with ``repr`` and read back by Python's ``float``, so
values survive the file exactly.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from tabletcad.errors import DesignError

__all__ = ["RESULTS_CSV", "JOURNAL", "TAIL_COLUMNS", "results_frame", "write_results", "read_results",
           "read_done", "append_journal", "plot_results", "parse_cell"]

RESULTS_CSV = "results.csv"
JOURNAL = "results.partial.jsonl"
TAIL_COLUMNS = ("warnings", "status", "error", "design_hash")
#: the tail columns a results.csv must have (one written before rows had ``warnings`` is read with them empty)
_REQUIRED_TAIL = ("status", "error", "design_hash")


def results_frame(keys: Sequence[str], rows: Iterable[dict[str, Any]]):
    """A DataFrame of ``rows`` with the columns in the documented order.

    A column of whole numbers (a count: faces, triangles) that some row leaves empty (a design that
    failed) is pandas' nullable ``Int64``, so that it is written as the report has it (``9``, not the
    ``9.0`` a float column with NaN would give)."""
    import pandas as pd

    rows = list(rows)
    cols: dict[str, None] = dict.fromkeys(keys)
    for r in rows:
        for k in r:
            if k not in cols and k not in TAIL_COLUMNS:
                cols[k] = None
    cols.update(dict.fromkeys(TAIL_COLUMNS))
    df = pd.DataFrame.from_records(rows, columns=list(cols))
    for c in cols:
        vals = [r.get(c) for r in rows]
        given = [v for v in vals if v is not None]
        if given and len(given) < len(vals) and all(isinstance(v, int) and not isinstance(v, bool) for v in given):
            df[c] = pd.array(vals, dtype="Int64")
    return df


def write_results(df, path: str | Path) -> Path:
    """Write ``df`` as CSV atomically (floats by ``repr``)."""
    from tabletcad.io.atomic import atomic_write_text

    return atomic_write_text(path, df.to_csv(index=False, lineterminator="\n"))


def read_results(path: str | Path):
    """Read a ``results.csv`` back, every value exactly as written.

    Cells (except the text columns ``warnings``, ``status``, ``error`` and ``design_hash``, which are text,
    ``warnings`` and ``error`` ``""`` when empty as a run gives them) are parsed by Python itself (``int``,
    then ``float`` — exact for ``repr`` output —, ``True``/``False``, else text; an empty cell is None),
    so the columns have ``object`` dtype.
    """
    import pandas as pd

    try:
        df = pd.read_csv(path, dtype=str, keep_default_na=False)
    except (ValueError, pd.errors.ParserError) as exc:
        raise DesignError("results file", str(path), f"must be a results.csv written by tabletcad sweep ({exc})") from None
    missing = [c for c in _REQUIRED_TAIL if c not in df.columns]
    if missing:
        raise DesignError("results file", str(path), f"has no {', '.join(missing)} column; it was not written by tabletcad sweep")
    if "warnings" not in df.columns:
        df.insert(len(df.columns) - len(_REQUIRED_TAIL), "warnings", "")

    def cell(c: str, v: str) -> Any:
        if c in ("warnings", "error"):
            return v
        return (v or None) if c in TAIL_COLUMNS else parse_cell(v)

    cols = {c: pd.Series([cell(c, v) for v in df[c]], dtype=object)
            for c in df.columns}  # the text columns stay text (a hash of digits too)
    return pd.DataFrame(cols, columns=df.columns)


def parse_cell(text: str) -> Any:
    """The value of one CSV cell as :func:`write_results` wrote it."""
    if text == "":
        return None
    if text in ("True", "False"):
        return text == "True"
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def append_journal(path: Path, row: dict[str, Any]) -> None:
    """Append one finished design to the journal (one JSON object per line, flushed)."""
    with open(path, "a", encoding="utf-8") as fh:
        fh.write(json.dumps(row) + "\n")
        fh.flush()


def read_done(out_dir: Path) -> dict[str, dict[str, Any]]:
    """Finished designs of an earlier run of the sweep in ``out_dir``, keyed by design hash."""
    done: dict[str, dict[str, Any]] = {}
    csv = out_dir / RESULTS_CSV
    if csv.is_file():
        df = read_results(csv)
        for r in df.to_dict(orient="records"):
            done[str(r["design_hash"])] = r
    journal = out_dir / JOURNAL
    if journal.is_file():
        lines = journal.read_bytes().decode("utf-8", errors="replace").splitlines()
        for k, line in enumerate(lines):
            try:
                r = json.loads(line)
            except json.JSONDecodeError:
                if k == len(lines) - 1 and k > 0:  # the last line of an interrupted run may be cut short
                    continue
                r = None
            if not (isinstance(r, dict) and "design_hash" in r):  # not a sweep's journal: never ours to delete
                raise DesignError("--out", str(out_dir), f"holds a {JOURNAL} that no sweep wrote (line {k + 1}); "
                                  "move it or write into another folder")
            done[str(r["design_hash"])] = r
    return done


def plot_names(outputs: Sequence[str]) -> list[str]:
    """The file names of :func:`plot_results`'s plots of ``outputs``."""
    return [f"plot_{_safe(o)}.png" for o in outputs]


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name)


def plot_column_error(name: str, columns: Sequence[str], keys: Sequence[str]) -> DesignError:
    """The refusal of ``--plot name``, listing the report ``columns`` that can be plotted (not the
    varied ``keys``, not the status columns)."""
    allowed = [c for c in columns if c not in keys and c not in TAIL_COLUMNS]
    return DesignError("--plot", name, "must be a report column of results.csv: " + ", ".join(allowed))


def plot_results(df, keys: Sequence[str], outputs: Sequence[str], out_dir: str | Path) -> list[Path]:
    """``plot_<output>.png``: each chosen output against each varied key (designs with status ok).

    Uses a Matplotlib :class:`~matplotlib.figure.Figure` with the Agg canvas;
    the global backend is left alone.  An output that is not a column of the
    results is a :class:`DesignError`.
    """
    import numpy as np
    import pandas as pd
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from tabletcad.io.figures import save_figure

    ok = df[df["status"] == "ok"]
    numeric = [c for c in df.columns if c not in keys and c not in TAIL_COLUMNS
               and pd.to_numeric(ok[c], errors="coerce").notna().any()]
    for o in outputs:
        if o in df.columns and o not in keys and o not in TAIL_COLUMNS and o not in numeric:
            # a column known before the run (the first design's report has the name) but no number in any
            # design that built (a tip rating without a compaction force): not "not a column"
            raise DesignError("--plot", o, f"must be a report column with a number in some design: every one of the "
                              f"{len(ok)} designs that built leaves it empty in results.csv (the input it needs is "
                              "not in the sweep's design)")
        if o not in numeric:
            raise plot_column_error(o, numeric, keys)
    paths = []
    for o in outputs:
        y = pd.to_numeric(ok[o], errors="coerce")
        fig = Figure(figsize=(4.0 * len(keys), 3.4), layout="constrained")
        FigureCanvasAgg(fig)
        axes = fig.subplots(1, len(keys), squeeze=False)[0]
        for ax, k in zip(axes, keys):
            x = pd.to_numeric(ok[k], errors="coerce")
            if x.isna().any():  # categorical axis (e.g. families): positions with labels
                cats = list(dict.fromkeys(ok[k].astype(str)))
                x = ok[k].astype(str).map({c: i for i, c in enumerate(cats)})
                ax.set_xticks(range(len(cats)), cats, rotation=30)
            ax.scatter(np.asarray(x, float), np.asarray(y, float), s=14)
            ax.set_xlabel(k)
            ax.set_ylabel(o)
            ax.grid(alpha=0.3)
        fig.suptitle(f"{o}: {len(ok)} designs")
        path = Path(out_dir) / plot_names([o])[0]
        # written atomically (whole or not at all: a plot cut short is no plot of the sweep's), with the mark
        # by which a resumed run knows the plot for its own
        save_figure(fig, path, fmt="png", dpi=110, metadata={"Software": PLOT_SOFTWARE})
        paths.append(path)
    return paths


#: the PNG ``Software`` text a sweep's plots carry: a resumed run replaces a plot file only when it is one
PLOT_SOFTWARE = "tabletcad sweep"


def is_sweep_plot(path: str | Path) -> bool:
    """Whether ``path`` is a plot a sweep wrote (a PNG whose ``Software`` text is :data:`PLOT_SOFTWARE`), not a file
    of the user's under that name (``--resume --plot`` had replaced the user's own ``plot_volume_mm3.png``)."""
    from PIL import Image

    try:
        with Image.open(path) as im:
            return im.format == "PNG" and getattr(im, "text", {}).get("Software") == PLOT_SOFTWARE
    except Exception:  # noqa: BLE001 - not an image, unreadable: not the sweep's
        return False
