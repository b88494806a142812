"""Derived compaction curves of a press record: pressure, density, porosity, Heckel term.

Definitions (thesis eqs 2.2-2.3; units mm, N, MPa, mg):

* pressure ``P = F / A`` (MPa), ``A`` the punch face area (mm²);
* relative density (solid fraction) ``D = m / (ρ_true · A · h)``, ``h`` the
  compliance-corrected thickness (mm), ``m`` in mg, ``ρ_true`` in mg/mm³;
* porosity ``ε = 1 - D``; Heckel term ``ln(1 / (1 - D))``.

Loading and unloading branches
------------------------------
The loading branch runs from the first row to the row of maximum compression,
found as follows: scan the rows in order; the loading branch ends at the last
row carrying the running force maximum before the force first falls below it by
more than ``drop`` (default 2 %) of the record's largest force (a load cell's
noise is a fraction of its range: a baseline's 0.5 N then 0.3 N before the
punches meet the powder is not the end of loading).  If the force never falls that
far, the branch ends at the last row of the global force maximum.  The
unloading branch follows it as long as the force keeps falling; if the force
rises again by more than ``drop`` of the peak above its running minimum the
record is *reloaded* (the thesis's Appendix B does this twice) and the rows
from there on are excluded from both branches.  The result lists every range
used so reports can state it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tabletcad.errors import DesignError
from tabletcad.mechanics.branches import Branches, split_branches
from tabletcad.mechanics.pressdata import PressData
from tabletcad.mechanics.validity import DataWarning, warn

__all__ = ["Branches", "CompactionCurves", "compaction_curves", "relative_density", "split_branches"]


#: The least relative density a press record must reach under load: no powder bed is that loose (it starts
#: near 0.3).  A mass typed in grams (0.3 for 300 mg) gave 0.0006 and Py = 3.6e5 MPa, exit 0.
MIN_PEAK_RELATIVE_DENSITY = 0.05


def check_peak_relative_density(D) -> None:
    """Refuse relative densities (under load) whose largest is below :data:`MIN_PEAK_RELATIVE_DENSITY`:
    a mass in grams, a density or a diameter in the wrong unit, or a displacement in µm read as mm."""
    D = np.asarray(D, dtype=float)
    D = D[np.isfinite(D)]
    if D.size and float(np.max(D)) < MIN_PEAK_RELATIVE_DENSITY:
        raise DesignError("relative_density", f"at most {float(np.max(D)):.3g}",
                          f"must reach {MIN_PEAK_RELATIVE_DENSITY:g} under load (a powder bed starts near 0.3, a "
                          "compact reaches 0.7-1): check the mass (mg, not g), the true density (mg/mm³), the die "
                          "diameter (mm) and the displacement's unit")


def relative_density(thickness, mass_mg: float, true_density: float, area: float) -> np.ndarray:
    """Relative density ``D = m / (ρ_true A h)`` (eq 2.3), dimensionless.

    Parameters
    ----------
    thickness : array_like
        Compact thickness, mm.
    mass_mg : float
        mg.
    true_density : float
        mg/mm³.
    area : float
        Punch face area, mm².
    """
    return float(mass_mg) / (float(true_density) * float(area) * np.asarray(thickness, dtype=float))


@dataclass(frozen=True)
class CompactionCurves:
    """Derived curves of one press record (arrays over all rows).

    Attributes
    ----------
    pressure : ndarray
        MPa.
    thickness : ndarray
        Compliance-corrected thickness, mm.
    relative_density : ndarray
        Solid fraction, dimensionless.
    porosity : ndarray
        ``1 - relative_density``.
    heckel : ndarray
        ``ln(1/(1 - D))``; NaN where ``D >= 1``.
    branches : Branches
    line_numbers : ndarray of int
        Source-file line of each row.
    elastic_recovery : float or None
        In-die elastic recovery ``(h_end - h_min) / h_min`` (fraction) over the
        unloading branch, or ``None`` when the unloading branch does not reach
        ``recovery_force_fraction`` of the peak force (then ``recovery_note``
        says why).
    recovery_note : str
    """

    pressure: np.ndarray
    thickness: np.ndarray
    relative_density: np.ndarray
    porosity: np.ndarray
    heckel: np.ndarray
    branches: Branches
    line_numbers: np.ndarray
    elastic_recovery: float | None
    recovery_note: str

    @property
    def loading(self) -> slice:
        return self.branches.loading_slice

    def describe_rows(self) -> str:
        """One line naming the rows (source-file lines) used for each branch."""
        b = self.branches
        ln = self.line_numbers
        s = f"loading rows {b.loading[0] + 1}-{b.loading[1]} (file lines {ln[b.loading[0]]}-{ln[b.loading[1] - 1]})"
        if b.unloading[1] > b.unloading[0]:
            s += f"; unloading rows {b.unloading[0] + 1}-{b.unloading[1]}"
        if b.reloading_from is not None:
            s += f"; rows {b.reloading_from + 1}-{ln.size} reload the compact and are not used"
        return s


def _check_thickness(h: np.ndarray, lines: np.ndarray | None) -> None:
    """Refuse a compact thickness (mm, after the compliance correction) beyond the size limit
    (``Tolerances.max_length``), named by its line: a displacement of -1e300 mm had been taken as a bed
    1e300 mm thick (exit 0, the row's relative density 3e-301)."""
    from tabletcad.tolerance import DEFAULT

    bad = np.flatnonzero(h > DEFAULT.max_length)
    if bad.size:
        i = int(bad[0])
        row = f"line {int(lines[i])}" if lines is not None else f"row {i + 1}"
        raise DesignError(f"{row} thickness", float(h[i]), f"must be <= {DEFAULT.max_length:g} mm (size limit, "
                          "Tolerances.max_length): check the position column's unit, displacement_sign and "
                          "displacement_zero", "mm")


def compaction_curves(
    data: PressData, *, drop: float = 0.02, recovery_force_fraction: float = 0.1
) -> CompactionCurves:
    """Compute pressure, thickness, relative density, porosity and Heckel term.

    Parameters
    ----------
    data : PressData
    drop : float
        Branch-splitting threshold, see :func:`split_branches`.
    recovery_force_fraction : float
        The unloading branch must end below this fraction of the peak force for
        the in-die elastic recovery to be reported.
    """
    meta = data.metadata
    P = data.force / meta.area
    h = np.asarray(data.thickness, dtype=float)
    _check_thickness(h, data.line_numbers)
    D = relative_density(h, meta.mass_mg, meta.true_density, meta.area)
    branches = split_branches(data.force, drop=drop)
    check_peak_relative_density(D[slice(*branches.loading)])
    over = D >= 1.0
    with np.errstate(divide="ignore", invalid="ignore"):
        H = np.where(over, np.nan, -np.log1p(-np.where(over, 0.0, D)))
    lo, hi = branches.loading
    n_over = int(over[lo:hi].sum())
    if n_over:
        warn(
            DataWarning,
            f"{n_over} loading row(s) have relative density >= 1 (check the mass, the true density, the die "
            "diameter or face area (mm, mm²), the compliance); their Heckel term is undefined",
        )
    ulo, uhi = branches.unloading
    if uhi - ulo < 1:
        er, note = None, "no unloading branch"
    else:
        h_min = float(h[branches.peak])
        f_end = float(data.force[uhi - 1])
        ratio = f_end / float(data.force[branches.peak])
        if ratio > recovery_force_fraction:
            er = None
            note = f"unloading stops at {100 * ratio:.0f} % of the peak force"
            if branches.reloading_from is not None:
                note += " before the compact is reloaded"
        else:
            er = (float(h[uhi - 1]) - h_min) / h_min
            note = ""
    lines = data.line_numbers if data.line_numbers is not None else np.arange(1, P.size + 1)
    return CompactionCurves(
        pressure=P, thickness=h, relative_density=D, porosity=1.0 - D, heckel=H,
        branches=branches, line_numbers=lines, elastic_recovery=er, recovery_note=note,
    )
