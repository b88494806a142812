"""``tabletcad sweep SWEEP.toml --out DIR``: a design-space sweep on Dask (see :mod:`tabletcad.sweep`)."""

from __future__ import annotations

from pathlib import Path

import click

from tabletcad.cli.outputs import out_folder
from tabletcad.errors import DesignError

__all__ = ["COMMANDS"]


def _require_sweep() -> None:
    """The sweep extra (Dask ``distributed``, pandas), or the one-line error naming it."""
    try:
        import distributed  # noqa: F401
        import pandas  # noqa: F401
    except ImportError as exc:
        raise DesignError("tabletcad sweep", exc.name, "needs the sweep extra: pip install 'tabletcad[sweep]'") from None


@click.command("sweep")
@click.argument("sweep_file", metavar="SWEEP.toml", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--out", "out_dir", required=True, type=out_folder(),
              help="Output folder: results.csv, files of file outputs, plots.")
@click.option("--workers", type=int, default=None, help="Worker processes of a local Dask cluster (default: one per CPU).")
@click.option("--scheduler", default=None, help="Address of an existing Dask scheduler (tcp://host:port).")
@click.option("--resume", is_flag=True, help="Skip designs already in OUT/results.csv (keyed by a hash of the design).")
@click.option("--plot", "plots", multiple=True, metavar="COLUMN", help="Plot this report column against the varied keys (repeatable).")
@click.option("--store", default=None, help="Folder or fsspec URL the workers write file outputs to.")
@click.option("--connect-timeout", type=float, default=None, help="Seconds to wait for --scheduler (default 10).")
@click.option("--quiet", is_flag=True, help="No progress bar.")
def sweep_cmd(sweep_file: Path, out_dir: Path, workers, scheduler, resume: bool, plots, store, connect_timeout,
              quiet: bool) -> None:
    """Build every design of SWEEP.toml and write OUT/results.csv (one row per design)."""
    _require_sweep()
    from tabletcad.sweep import run_sweep
    from tabletcad.sweep.engine import CONNECT_TIMEOUT_S

    if workers is not None and scheduler is not None:
        raise DesignError("--workers", workers, "give either --workers or --scheduler, not both")
    if workers is not None and workers < 1:
        raise DesignError("--workers", workers, "must be an integer >= 1")  # (and at most 4 per CPU: run_sweep)
    if connect_timeout is not None and not 0 < connect_timeout <= 3600:  # (inf reached Dask as "infs")
        raise DesignError("--connect-timeout", connect_timeout, "must be > 0 and <= 3600", "s")
    df = run_sweep(sweep_file, out_dir, workers=workers, scheduler=scheduler, resume=resume, progress=not quiet,
                   store=store, plot=tuple(plots), connect_timeout=connect_timeout or CONNECT_TIMEOUT_S)
    n_err = int((df["status"] != "ok").sum())
    click.echo(f"{len(df)} design{'' if len(df) == 1 else 's'} ({len(df) - n_err} ok, {n_err} failed) -> {out_dir / 'results.csv'}")


COMMANDS = [sweep_cmd]
