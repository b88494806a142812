"""Loading and unloading branches of a press record: which rows are loading, unloading and reloading.

The rule is :mod:`tabletcad.mechanics.compaction`'s (see its module docstring); it lives apart so that the
press-data reader (:mod:`tabletcad.mechanics.pressdata`, which checks that the punch gap closes over the
loading branch) and the compaction curves (which read the reader's data) share it without importing each other.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tabletcad.errors import DesignError, check_range

__all__ = ["Branches", "split_branches"]


@dataclass(frozen=True)
class Branches:
    """Row ranges (0-based, ``stop`` exclusive) of the loading and unloading branches.

    Attributes
    ----------
    loading : (int, int)
        Rows of the loading branch, start to maximum compression inclusive.
    unloading : (int, int)
        Rows of the unloading branch; empty (``start == stop``) if none.
    peak : int
        Row of maximum compression (last row of ``loading``).
    reloading_from : int or None
        First row of a renewed loading after the unloading branch, excluded.
    """

    loading: tuple[int, int]
    unloading: tuple[int, int]
    peak: int
    reloading_from: int | None

    @property
    def loading_slice(self) -> slice:
        return slice(*self.loading)

    @property
    def unloading_slice(self) -> slice:
        return slice(*self.unloading)


def split_branches(force, drop: float = 0.02, *, quantity: str = "force", unit: str = "N") -> Branches:
    """Split a force series into loading and unloading branches (see module docstring).

    Parameters
    ----------
    force : array_like
        Force per row, N, in recording order.
    drop : float
        Fraction of the record's peak force that counts as a real fall or rise
        (filters transducer noise, which is a fraction of the load cell's range, not of the force
        reached so far); 0 < drop < 1.
    quantity, unit : str
        What the series is and its unit, for a refusal's words: ``"pressure"``, ``"MPa"`` when a
        table of pressures (``tabletcad kawakita``, ``walker``) is split.

    Raises
    ------
    DesignError
        If there is no loading branch (fewer than 3 rows up to the peak or a
        non-positive peak force).
    """
    F = np.asarray(force, dtype=float)
    check_range("drop", drop, 0.0, 1.0, lo_open=True, hi_open=True)
    n = F.size
    if n < 3:
        raise DesignError("data", f"{n} row" + ("" if n == 1 else "s"), "need at least 3 rows with a loading branch")
    # noise is measured against the record's largest force, not the running one: a press export's rows before the
    # punches meet the powder (0.5 N then 0.3 N ahead of a 4.8 kN record) had ended the loading branch at row 1
    scale = float(np.max(F))
    if F[0] < 0.0 and (scale <= 0.0 or -F[0] > drop * scale):  # a tensile force, not a baseline's noise
        raise DesignError(f"row 1 {quantity}", float(F[0]),
                          f"has no loading branch: compression {quantity}s must be > 0", unit)
    runmax = np.maximum.accumulate(F)
    fall = np.flatnonzero(runmax - F > drop * scale)
    end = int(fall[0]) if fall.size else n
    seg = F[:end]
    peak = int(np.flatnonzero(seg == seg.max())[-1])
    if peak < 2 or F[peak] <= 0.0 or F[peak] <= F[0]:
        raise DesignError("data", f"peak {quantity} at row {peak + 1}",
                          f"has no loading branch ({quantity} must rise over >= 3 rows)")
    reload_from = None
    stop = peak + 1
    if fall.size:
        runmin = F[peak]
        stop = n
        for i in range(peak + 1, n):
            runmin = min(runmin, F[i])
            if F[i] > runmin + drop * F[peak]:
                reload_from = i
                hits = np.flatnonzero(F[peak + 1 : i] == runmin)
                stop = int(hits[-1]) + peak + 2 if hits.size else peak + 1
                break
    return Branches(loading=(0, peak + 1), unloading=(peak + 1, stop), peak=peak, reloading_from=reload_from)
