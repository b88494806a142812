"""The sweep engine: design dictionaries in, report scalars and file bytes out, on Dask.

Work crosses process boundaries only as plain data: a task receives a design
*dictionary* (the parsed TOML) and returns a dict of report scalars and, when
asked, the bytes of the files it wrote.  No OpenCascade object is pickled; a
worker builds its tablet and solids itself.  Nothing assumes a shared
filesystem: files come back to the client, or go to a storage URL (fsspec)
written by the worker.

The tasks run on :func:`tabletcad.parallel.map_tasks` (re-exported here with
:func:`~tabletcad.parallel.open_client`): in this process, on a local cluster of
worker processes, or on an existing cluster.
"""

from __future__ import annotations

import tempfile
import threading
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from tabletcad.errors import DesignError
from tabletcad.parallel import CONNECT_TIMEOUT_S, map_tasks, open_client
from tabletcad.pipeline.report import flatten_report
from tabletcad.sweep.spec import OUTPUTS

__all__ = ["evaluate_design", "sweep_task", "failed_design", "map_tasks", "open_client", "flatten_report", "CONNECT_TIMEOUT_S", "error_message"]

def error_message(exc: BaseException) -> str:
    """The one-line message of a failed design (a DesignError's own line, else ``Type: first line``)."""
    msg = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
    if isinstance(exc, DesignError):
        return msg
    return f"{type(exc).__name__}: {msg}" if msg else type(exc).__name__


def _files_of(folder: Path, names: Sequence[str]) -> dict[str, bytes]:
    return {n: (folder / n).read_bytes() for n in names if (folder / n).is_file()}


def _store_files(store: str, sub: str, files: dict[str, bytes]) -> list[str]:
    import fsspec

    fs, root = fsspec.core.url_to_fs(store)
    folder = f"{root.rstrip('/')}/{sub}"
    fs.makedirs(folder, exist_ok=True)
    for name, data in files.items():
        fs.pipe_file(f"{folder}/{name}", data)
    return sorted(files)


def evaluate_design(design: dict[str, Any], outputs: Sequence[str] = ("report",), *, name: str = "sweep",
                    store: str | None = None, folder: str = "", tmp_root: str | None = None) -> dict[str, Any]:
    """See :func:`_evaluate_design`; the warnings the design gives (a punch tip without a land, an old family
    name) are its row's ``warnings`` (each once, ``"; "`` between), not lines on the terminal.

    Python's warning state is one per process, so the designs of one worker process run one at a time
    (:data:`_WARNINGS_HELD`; a worker of several threads, which the GIL held by OpenCascade and the
    quadrature leaves little to gain from, would otherwise put one design's warnings in another's row).
    Only tabletcad's own categories (``UserWarning``, ``FutureWarning``) are shown every time; the
    filters of other categories stand (a ``-W error`` or the test suite's errors on RuntimeWarning)."""
    with _WARNINGS_HELD, warnings.catch_warnings(record=True) as caught:
        for category in (UserWarning, FutureWarning):
            warnings.filterwarnings("always", category=category)
        res = _evaluate_design(design, outputs, name=name, store=store, folder=folder, tmp_root=tmp_root)
    res["warnings"] = "; ".join(dict.fromkeys(" ".join(str(w.message).split()) for w in caught))
    return res


#: held while a design's warnings are recorded (see :func:`evaluate_design`)
_WARNINGS_HELD = threading.Lock()


def _evaluate_design(design: dict[str, Any], outputs: Sequence[str] = ("report",), *, name: str = "sweep",
                     store: str | None = None, folder: str = "", tmp_root: str | None = None) -> dict[str, Any]:
    """Build one design from its dictionary and return its results as plain data; never raises.

    Returns ``dict(values=..., status="ok"|"error", error=..., files=...)`` (and ``warnings``, from
    :func:`evaluate_design`):
    ``values`` holds every scalar of the report (:func:`flatten_report`) — the
    geometry report of :func:`tabletcad.pipeline.report.geometry_report`, which is the
    ``report.json`` of ``tabletcad build``; with file or tooling outputs the report of
    :func:`tabletcad.pipeline.build.build_tablet` itself (a failed tooling check is then a failed design,
    as in ``tabletcad build``).  ``files`` maps file names to
    bytes (empty when ``store`` is given: the worker then writes them to
    ``store/folder/`` through fsspec).  ``tmp_root``: the folder the build's files are made in (a local
    sweep's own, which it removes however it ends: a worker ended by a Ctrl-C cannot), else the
    system's temporary folder.
    """
    try:
        from tabletcad.pipeline.design import Design

        spec = Design.from_dict(design, default_name=name)
        tablet = spec.build()
        if spec.tooling_spec is not None:  # refused as report and build refuse it, whatever the outputs
            from tabletcad.tooling.stage import check_tooling

            check_tooling(tablet, spec.tooling_spec)
        files: dict[str, bytes] = {}
        wanted = [f for o in outputs if o not in ("report", "tooling") for f in OUTPUTS[o]]
        if tmp_root is not None and not Path(tmp_root).is_dir():  # (a remote worker: its own temporary folder)
            tmp_root = None
        with tempfile.TemporaryDirectory(prefix="tabletcad-sweep-", dir=tmp_root) as tmp:
            if wanted or "tooling" in outputs:
                from tabletcad.pipeline.build import build_tablet

                # the build's own steps, as `tabletcad build` runs them: with the "tooling" output the
                # design's [tooling] table (the defaults without one) is built from the CAD step's solid;
                # without it the tablet's files are the plain tablet and [tooling] is not built
                tooling = None
                if "tooling" in outputs:
                    from tabletcad.tooling.spec import ToolingSpec
                    from tabletcad.tooling.stage import tooling_outputs

                    tooling = spec.tooling_spec or ToolingSpec()
                    wanted += tooling_outputs(tooling)  # (the PDF drawing and complete punches' had been left out)
                # (the picture only when the png output asks for it: most of such a build's CPU time)
                report = build_tablet(tablet, Path(tmp) / "build", tooling=tooling, options=spec.report_options,
                                      cad=True, progress=False, picture="tablet.png" in wanted)
                files.update(_files_of(Path(tmp) / "build", wanted))
            else:  # the report of `tabletcad build`, without its files
                from tabletcad.pipeline.build import cad_available, fe_breaking_force_section
                from tabletcad.pipeline.report import geometry_report

                report = geometry_report(tablet, spec.report_options)
                if spec.report_options is not None and spec.report_options.fe_breaking_force:
                    report["fe_breaking_force"] = fe_breaking_force_section(tablet, spec.report_options,
                                                                            spec.tooling_spec, cad_available())
        if store is not None and files:
            _store_files(store, folder, files)
            files = {}
        return dict(values=flatten_report(report), status="ok", error="", files=files)
    except Exception as exc:  # a failing design is a row, never the end of the sweep
        return failed_design(exc)


def failed_design(exc: BaseException) -> dict[str, Any]:
    """The result of a design that failed with ``exc`` (in the worker, or by losing its worker)."""
    return dict(values={}, status="error", error=error_message(exc), files={}, warnings="")


def sweep_task(item: tuple[dict[str, Any], str], **kw: Any) -> dict[str, Any]:
    """:func:`evaluate_design` of ``item = (design, design_hash)``; files go to the folder named by the hash."""
    design, key = item
    return evaluate_design(design, folder=key, **kw)
