"""Design-space sweeps: many tablets from one sweep file, on a local or remote Dask cluster.

>>> from tabletcad.sweep import run_sweep
>>> df = run_sweep("samples/sweep/concave_round_grid.toml", "out/sweep", workers=2)  # doctest: +SKIP

Modules: :mod:`~tabletcad.sweep.spec` (the sweep file and its sampling),
:mod:`~tabletcad.sweep.engine` (one design in, plain data out, run on
:mod:`tabletcad.parallel`), :mod:`~tabletcad.sweep.results`
(``results.csv``, resume journal, plots) and :mod:`~tabletcad.sweep.run`
(:func:`run_sweep`).  Needs the ``sweep`` extra (``dask[distributed]``, pandas).
"""

from __future__ import annotations

from tabletcad.sweep.run import run_sweep
from tabletcad.sweep.spec import SweepSpec, design_hash, load_sweep, parse_sweep

__all__ = ["run_sweep", "SweepSpec", "load_sweep", "parse_sweep", "design_hash"]
