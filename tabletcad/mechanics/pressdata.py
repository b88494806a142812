"""Press data: force and punch-position records of a compaction run, with metadata.

A record is a delimited text file (comma, semicolon or tab separated, sniffed;
decimal commas with ``;``/tab; UTF-8 with or without BOM, UTF-16, Windows-1252;
``#`` comment lines allowed) with a header row.  Columns are recognised by
name, case-insensitively and ignoring their unit:

* force: a header containing ``force`` or ``load`` (``Upper Punch Force``);
* punch displacement: ``displacement``, ``disp``, ``position``, ``distance``,
  ``travel`` or ``stroke``;
* tablet thickness / punch gap: ``thickness``, ``height`` or ``gap``;
* time, optional: ``time``.

Units come from the header — ``Force (kN)``, ``Force [daN]``, ``Time [ms]``,
``Displacement (µm)``, ``force_N`` — and are converted to N, mm and s
(:mod:`tabletcad.mechanics.units`); a header without a unit means N, mm or s,
an unknown unit is refused.  Two columns that could play one role (upper and
lower punch force) are refused unless ``columns=`` (the CLI's
``--force-column``...) chooses one; ``units=`` (``--force-unit``...) overrides
a header's unit.

Either a displacement or a thickness column is required.  Every other numeric
column is kept, unconverted, in :attr:`PressData.extra` (the thesis sample
carries its printed thickness, relative density, pressure and Heckel columns
that way).

The metadata (:class:`PressMetadata`) give the compact mass (mg), the true
density (mg/mm³), the die diameter (mm) or punch face area (mm²) and an
optional :class:`MachineCompliance`.  They can come from keyword arguments, a
TOML file (keys below) or both (keywords win)::

    mass_mg = 300.0
    true_density = 1.3          # mg/mm³
    diameter = 10.0             # mm  (or face_area = 78.54, mm²)
    displacement_sign = "auto"  # or -1 / +1
    displacement_zero = 0.0     # mm
    [compliance]
    slope = 2e-5                # mm/N
    offset = 0.0267             # mm
    # or: compensation_line = [2e-5, -0.0267]   (see MachineCompliance)
    # or: force = [...], deflection = [...]     (calibration table)

Punch gap from displacement: ``gap = displacement_zero + sign * displacement``.
With ``displacement_sign = "auto"`` the sign is -1 when every reading is <= 0
(readings are the negative distance between the punch faces, as in the
thesis's Appendix B) and +1 otherwise (readings are the gap itself).  Data
recorded as punch *travel* need an explicit ``displacement_zero`` (the gap at
zero travel) and ``displacement_sign = -1``.  Whatever the sign, the gap must
close while the force rises through the loading branch; one that grows there
(punch travel read as the gap by "auto", or a sign given the wrong way round)
is refused, naming ``displacement_sign`` and ``displacement_zero``: neither is
ever guessed.

Corrected thickness (mm): ``thickness = gap + compliance.deflection(F)``.
"""

from __future__ import annotations

import csv
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from tabletcad.errors import MISSING, DesignError, check_finite, check_range
from tabletcad.tolerance import DEFAULT
from tabletcad.mechanics.units import DIMENSIONS, header_unit, strip_unit, unit_factor
from tabletcad.tolerance import (MAX_COMPLIANCE_MM_PER_N, MAX_PRESSURE_MPA, MAX_TRUE_DENSITY_MG_MM3,
                                 MIN_TRUE_DENSITY_MG_MM3)
from tabletcad.mechanics.validity import DataWarning, warn

__all__ = [
    "MachineCompliance",
    "PressData",
    "PressMetadata",
    "check_compliance_table",
    "metadata_beside",
    "read_metadata",
    "read_press_data",
]


@dataclass(frozen=True)
class MachineCompliance:
    """Elastic deflection of press frame and punches as a function of force.

    The deflection ``δ(F)`` (mm) is *added* to the measured punch gap to obtain
    the true compact thickness: under load the tooling shortens, so the
    position transducer over-states how far the punches have closed.

    Either a line ``δ = slope·F + offset`` or a calibration table (force in N,
    deflection in mm, interpolated linearly and extrapolated along the end
    segments).

    Attributes
    ----------
    slope : float
        mm/N (line form).
    offset : float
        mm (line form).
    table_force, table_deflection : tuple of float
        Calibration table (table form); empty for the line form.
    """

    slope: float = 0.0
    offset: float = 0.0
    table_force: tuple[float, ...] = ()
    table_deflection: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        check_range("compliance slope", self.slope, 0.0, MAX_COMPLIANCE_MM_PER_N, "mm/N")
        check_range("compliance offset", self.offset, -DEFAULT.max_length, DEFAULT.max_length, "mm")
        if self.table_force or self.table_deflection:
            check_compliance_table(self.table_force, self.table_deflection)

    @classmethod
    def from_compensation_line(cls, slope: float, intercept: float) -> MachineCompliance:
        """Compliance from a compensation-test line ``y = slope·x + intercept`` as printed.

        The thesis's Appendix B prints ``y = 0.00002x - 0.0267``; its thickness
        column equals ``-displacement + 0.00002·F + 0.0267`` to within the
        printed rounding (checked on all 243 rows), i.e. the line is evaluated in
        the machine's sign convention (compression negative) and subtracted.  In
        the convention of this class that is ``δ(F) = slope·F - intercept``.
        """
        return cls(slope=float(slope), offset=-float(intercept))

    @property
    def is_table(self) -> bool:
        return bool(self.table_force)

    def deflection(self, force: np.ndarray | float) -> np.ndarray:
        """Deflection (mm) at ``force`` (N)."""
        F = np.asarray(force, dtype=float)
        if not self.is_table:
            return self.slope * F + self.offset
        f = np.asarray(self.table_force)
        d = np.asarray(self.table_deflection)
        out = np.interp(F, f, d)
        lo_slope = (d[1] - d[0]) / (f[1] - f[0])
        hi_slope = (d[-1] - d[-2]) / (f[-1] - f[-2])
        out = np.where(F < f[0], d[0] + lo_slope * (F - f[0]), out)
        out = np.where(F > f[-1], d[-1] + hi_slope * (F - f[-1]), out)
        return out

    def to_dict(self) -> dict[str, Any]:
        if self.is_table:
            return {"force": list(self.table_force), "deflection": list(self.table_deflection)}
        return {"slope": self.slope, "offset": self.offset}


def check_compliance_table(force: Sequence[float], deflection: Sequence[float]) -> None:
    """Refuse a force-deflection calibration table no press has, naming the entry at fault.

    A table is the ``[compliance]`` keys ``force`` (N) and ``deflection`` (mm) of a metadata file, or
    :class:`MachineCompliance`'s ``table_force`` and ``table_deflection``.  It needs at least two pairs
    (an empty one would be no correction at all: the lactose record's K moves by 15 %), forces strictly
    increasing, deflections within ±1000 mm, and every step between neighbouring rows within
    0-:data:`~tabletcad.tolerance.MAX_COMPLIANCE_MM_PER_N` mm/N, as the line form's slope: a frame
    shortens more under more force, by about 2e-5 mm/N (a falling deflection gave K = 0.01103 instead
    of 0.008557 1/MPa; a table typed in kN is 1000 times too steep).

    Parameters
    ----------
    force : sequence of float
        N, one per row.
    deflection : sequence of float
        mm, one per row.

    Raises
    ------
    DesignError
        ``compliance.table`` (lengths or count), or the entry ``compliance.force[i]`` or
        ``compliance.deflection[i]`` (0-based, as the file's list) at fault.
    """
    if len(force) != len(deflection):
        raise DesignError("compliance table", f"{len(force)} forces, {len(deflection)} deflections",
                          "force and deflection lists must have the same length")
    f = np.asarray(force, dtype=float)
    d = np.asarray(deflection, dtype=float)
    if f.size < 2 or not np.all(np.isfinite(f)) or not np.all(np.isfinite(d)):
        raise DesignError("compliance table", f.size, "needs >= 2 finite (force, deflection) pairs")
    for i in range(1, f.size):
        if not f[i] > f[i - 1]:
            raise DesignError(f"compliance force {i}", float(f[i]), f"must be > compliance.force[{i - 1}] = "
                              f"{f[i - 1]:.6g} N (the forces strictly increasing)", "N")
    for i, x in enumerate(d):
        check_range(f"compliance deflection {i}", float(x), -DEFAULT.max_length, DEFAULT.max_length, "mm")
    step = np.diff(d) / np.diff(f)
    bad = np.flatnonzero((step < 0.0) | (step > MAX_COMPLIANCE_MM_PER_N))
    if bad.size:
        k = int(bad[0])
        raise DesignError(f"compliance deflection {k + 1}", float(d[k + 1]),
                          f"its step from {d[k]:.6g} mm at {f[k]:.6g} N to {d[k + 1]:.6g} mm at {f[k + 1]:.6g} N is "
                          f"{step[k]:.4g} mm/N; a step must be >= 0 and <= {MAX_COMPLIANCE_MM_PER_N:g} mm/N (a press "
                          "frame shortens under force, about 2e-5 mm/N): forces in N, deflections in mm", "mm")


@dataclass(frozen=True)
class PressMetadata:
    """What a press record needs besides its columns.

    Attributes
    ----------
    mass_mg : float
        Compact mass, mg.
    true_density : float
        True (skeletal) density of the powder, mg/mm³ (numerically g/cm³).
    diameter : float or None
        Die diameter, mm (flat round punches).
    face_area : float or None
        Punch face area, mm² (for a shaped punch); give it or ``diameter``, not both.
    compliance : MachineCompliance or None
        Machine deflection correction; ``None`` means none.
    displacement_sign : int or "auto"
        See the module docstring.
    displacement_zero : float
        mm; see the module docstring.
    """

    mass_mg: float
    true_density: float
    diameter: float | None = None
    face_area: float | None = None
    compliance: MachineCompliance | None = None
    displacement_sign: int | str = "auto"
    displacement_zero: float = 0.0
    notes: str = ""

    def __post_init__(self) -> None:
        # generous physical limits: a compact of up to 1 kg, any solid's density, a die up to 1 m
        check_range("mass_mg", self.mass_mg, 0.0, 1e6, "mg", lo_open=True)
        check_range("true_density", self.true_density, MIN_TRUE_DENSITY_MG_MM3, MAX_TRUE_DENSITY_MG_MM3, "mg/mm³")
        if self.diameter is None and self.face_area is None:
            raise DesignError("diameter", MISSING, "give the die diameter (mm) or the punch face area (mm²)", "mm")
        if self.diameter is not None and self.face_area is not None:
            raise DesignError("face_area", self.face_area, "give diameter or face_area, not both (the punch face "
                              "area is one quantity)", "mm²")
        if self.diameter is not None:
            check_range("diameter", self.diameter, 0.0, DEFAULT.max_length, "mm", lo_open=True)
        if self.face_area is not None:
            check_range("face_area", self.face_area, 0.0, 1e6, "mm²", lo_open=True)
        if not isinstance(self.notes, str):
            raise DesignError("notes", self.notes, "must be text")
        if self.displacement_sign not in ("auto", 1, -1):
            raise DesignError("displacement_sign", self.displacement_sign, "must be 'auto', 1 or -1")
        check_finite("displacement_zero", self.displacement_zero, "mm")

    @property
    def area(self) -> float:
        """Punch face area, mm²."""
        if self.face_area is not None:
            return float(self.face_area)
        return math.pi * float(self.diameter) ** 2 / 4.0

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"mass_mg": self.mass_mg, "true_density": self.true_density}
        if self.diameter is not None:
            out["diameter"] = self.diameter
        if self.face_area is not None:
            out["face_area"] = self.face_area
        if self.compliance is not None:
            out["compliance"] = self.compliance.to_dict()
        return out


@dataclass(frozen=True)
class PressData:
    """One compaction record.

    Attributes
    ----------
    force : ndarray
        Upper-punch force, N.
    gap : ndarray
        Measured punch gap before compliance correction, mm.
    thickness : ndarray
        Compact thickness after compliance correction, mm.
    time : ndarray or None
        s, when the file had a time column.
    displacement : ndarray or None
        Raw displacement readings, mm, when the file had them.
    metadata : PressMetadata
    extra : dict of str to ndarray
        Other numeric columns, keyed by their header.
    line_numbers : ndarray of int
        1-based line number in the source file of every kept row.
    dropped_rows : int
        Rows dropped because a required value was missing.
    source : str
        File name, or ``"<arrays>"``.
    """

    force: np.ndarray
    gap: np.ndarray
    thickness: np.ndarray
    metadata: PressMetadata
    time: np.ndarray | None = None
    displacement: np.ndarray | None = None
    extra: Mapping[str, np.ndarray] = field(default_factory=dict)
    line_numbers: np.ndarray | None = None
    dropped_rows: int = 0
    source: str = "<arrays>"

    def __len__(self) -> int:
        return int(self.force.size)

    @classmethod
    def from_arrays(
        cls,
        force,
        *,
        metadata: PressMetadata,
        displacement=None,
        thickness=None,
        time=None,
    ) -> PressData:
        """Build a record from arrays (force in N, displacement or thickness in mm)."""
        F = np.asarray(force, dtype=float).ravel()
        if (displacement is None) == (thickness is None):
            raise DesignError("columns", "displacement/thickness", "give exactly one of displacement or thickness")
        pos = np.asarray(displacement if thickness is None else thickness, dtype=float).ravel()
        if pos.size != F.size:
            raise DesignError("columns", f"{F.size} forces, {pos.size} positions", "must have equal length")
        t = None if time is None else np.asarray(time, dtype=float).ravel()
        if t is not None and t.size != F.size:
            raise DesignError("time", f"{t.size} values", f"must have {F.size} values")
        for name, arr, unit in (("force", F, "N"), ("position", pos, "mm")):
            bad = ~np.isfinite(arr)
            if bad.any():
                raise DesignError(name, float(arr[bad][0]), "must be finite numbers", unit)
        return _assemble(F, pos, thickness is not None, t, metadata, {}, np.arange(1, F.size + 1), 0, "<arrays>")


def _check_gap_closes(F: np.ndarray, gap: np.ndarray, sign: int, meta: PressMetadata, lines: np.ndarray,
                      column: str) -> None:
    """Refuse a punch gap, read from displacements with ``sign``, that does not close while the force rises.

    Through the loading branch (:func:`tabletcad.mechanics.compaction.split_branches`) the punches
    close on the powder: the gap (mm) at the peak force is smaller than at the branch's first row.
    A gap that grows there is a column read the wrong way round, e.g. punch travel taken as the gap
    itself by ``displacement_sign = "auto"`` (a new user's record gave K = -0.000329 1/MPa and
    Py = -3040 MPa with only a warning).  A record without a loading branch is left to the
    curves' own refusal.

    Parameters
    ----------
    F : ndarray
        Force per row, N.
    gap : ndarray
        Punch gap per row, mm, ``displacement_zero + sign * displacement``.
    sign : int
        The sign used, +1 or -1 (``meta.displacement_sign`` resolved).
    meta : PressMetadata
        The record's metadata (``displacement_sign`` as given, ``displacement_zero``).
    lines : ndarray of int
        The rows' 1-based line numbers in the file.
    column : str
        The displacement column's header, for the message.

    Raises
    ------
    DesignError
        ``displacement_sign``, naming ``displacement_zero`` too, when the gap does not close.
    """
    from tabletcad.mechanics.branches import split_branches

    try:
        first, end = split_branches(F).loading
    except DesignError:
        return
    peak = end - 1
    if gap[peak] < gap[first]:
        return
    how = ("'auto' read the readings as the gap itself (some are > 0; it takes -1 only when every reading "
           "is <= 0, as the thesis's Appendix B)" if sign == 1 else "'auto' read the readings as minus the gap "
           "(every one is <= 0)") if meta.displacement_sign == "auto" else f"{sign:+d} as given"
    raise DesignError(
        "displacement_sign", meta.displacement_sign,
        f"makes the punch gap {meta.displacement_zero:g} {'+' if sign > 0 else '-'} {column!r} grow from "
        f"{gap[first]:.4g} mm to {gap[peak]:.4g} mm while the force rises to its peak {F[peak]:.4g} N "
        f"(file lines {int(lines[first])}-{int(lines[peak])}), where the punches close on the powder: {how}. "
        "A column of punch travel needs displacement_sign = -1 and displacement_zero = the gap at zero travel "
        "(mm) in the metadata file; tabletcad does not guess them")


def _check_forces(F: np.ndarray, area: float, lines: np.ndarray, force_column: str) -> None:
    """Refuse a force no press makes, beyond ``MAX_PRESSURE_MPA`` on the punch face either way, named by
    its line and column (a load cell's small negative readings are read).

    A force of 1e300 N had been refused as the fit's window or as a thickness, or, in a row after the
    loading branch, had moved the branch and given K = 0.046 1/MPa with a warning only, exit 0.

    Parameters
    ----------
    F : ndarray
        Force per row, N (converted from the file's unit).
    area : float
        Punch face area, mm².
    lines : ndarray of int
        The rows' 1-based line numbers in the file.
    force_column : str
        The force column's header.
    """
    f_max = MAX_PRESSURE_MPA * area
    bad = np.flatnonzero(np.abs(F) > f_max)
    if bad.size:
        i = int(bad[0])
        raise DesignError(f"line {int(lines[i])} {force_column!r}", float(F[i]),
                          f"must be within ±{f_max:.4g} N ({MAX_PRESSURE_MPA:g} MPa on the {area:.4g} mm² punch face: "
                          "check the column's unit and the die diameter or face area)", "N")


def _assemble(F, pos, is_thickness, t, meta, extra, lines, dropped, source, column="displacement",
              force_column="force") -> PressData:
    if F.size == 0:
        raise DesignError("data", source, "has no complete rows")
    _check_forces(F, meta.area, lines, force_column)
    if is_thickness:
        gap = pos.copy()
        disp = None
    else:
        disp = pos
        sign = meta.displacement_sign
        if sign == "auto":
            sign = -1 if np.all(disp <= 0.0) else 1
        gap = meta.displacement_zero + sign * disp
        _check_gap_closes(F, gap, sign, meta, lines, column)
    comp = meta.compliance
    if comp is not None and comp.is_table and np.any(np.isfinite(F)):
        f_hi, f_lo = float(np.nanmax(F)), float(np.nanmin(F))
        span = comp.table_force[-1] - comp.table_force[0]
        if f_hi > comp.table_force[-1] + 0.1 * span or f_lo < comp.table_force[0] - 0.1 * span:
            warn(DataWarning, f"the compliance table covers {comp.table_force[0]:g}-{comp.table_force[-1]:g} N and "
                              f"the record {f_lo:.4g}-{f_hi:.4g} N: the deflection beyond it is extrapolated along "
                              "the table's end segments (calibrate over the record's forces)")
    thickness = gap if comp is None else gap + comp.deflection(F)
    if np.any(thickness <= 0.0):
        i = int(np.flatnonzero(thickness <= 0.0)[0])
        raise DesignError(
            f"line {int(lines[i])} thickness", float(thickness[i]),
            "must be > 0; check displacement_sign/displacement_zero", "mm",
        )
    for arr in (F, gap, thickness):
        arr.setflags(write=False)
    return PressData(
        force=F, gap=gap, thickness=thickness, metadata=meta, time=t, displacement=disp,
        extra=extra, line_numbers=lines, dropped_rows=dropped, source=source,
    )


_ROLE_PATTERNS = (
    ("force", re.compile(r"force|load")),
    ("thickness", re.compile(r"thickness|height|gap")),
    ("displacement", re.compile(r"displacement|disp\b|disp\.|position|distance|travel|stroke")),
    ("time", re.compile(r"^time|\btime\b")),
)
#: column roles: the keys of ``columns=`` and ``units=`` (the CLI's ``--<role>-column``)
ROLES = ("force", "displacement", "thickness", "time")


def _role(header: str) -> str | None:
    h = strip_unit(header).lower()
    for role, pat in _ROLE_PATTERNS:
        if pat.search(h):
            return role
    return None


def decode_text(raw: bytes) -> str:
    """UTF-8 (with or without BOM), UTF-16 (with or without BOM), else Windows-1252 (µ as the byte 0xB5)."""
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        return raw.decode("utf-16")
    head = raw[:4096]
    if head.count(0) > len(head) // 4:  # UTF-16 without BOM: every other byte of ASCII text is 0
        return raw.decode("utf-16-le" if head[1::2].count(0) > head[0::2].count(0) else "utf-16-be", errors="replace")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        return raw.decode("cp1252", errors="replace")


def _sniff_delimiter(lines: list[str]) -> str:
    """The delimiter (tab, ``;`` or ``,``) splitting the header and the first rows into equally many cells."""
    sample = lines[: min(len(lines), 20)]
    for d in ("\t", ";", ","):
        counts = {len(next(csv.reader([ln], delimiter=d))) for ln in sample}
        if len(counts) == 1 and counts.pop() > 1:
            return d
    head = sample[0]
    return "\t" if "\t" in head else ";" if head.count(";") > head.count(",") else ","


_COMMENT_OR_BLANK = re.compile(r"(?:^|\n)[ \t]*(?:#|\n|$)")


def _read_table(text: str, source: str) -> tuple[list[str], list[int], list[Sequence[str]], str]:
    """Header, 1-based line numbers of the data rows, the cells column by column, and the delimiter."""
    all_lines = text.splitlines()
    first = next((i for i, ln in enumerate(all_lines) if ln.strip() and not ln.lstrip().startswith("#")), None)
    if first is None:
        raise DesignError("data", source, "is empty")
    delim = _sniff_delimiter([ln for ln in all_lines[first: first + 40] if ln.strip() and not ln.lstrip().startswith("#")])
    header = [h.strip() for h in next(csv.reader([all_lines[first]], delimiter=delim))]
    ncol = len(header)
    body = "\n".join(all_lines[first + 1:])
    if body and '"' not in text and _COMMENT_OR_BLANK.search(body) is None:
        # fast path for long records: no quotes, comments or blank lines; every row checked to hold ncol cells
        codes = np.frombuffer(body.encode("utf-8"), dtype=np.uint8)
        ends = np.append(np.flatnonzero(codes == 10), codes.size)
        seps = np.searchsorted(np.flatnonzero(codes == ord(delim)), ends)
        if np.all(np.diff(seps, prepend=0) == ncol - 1):
            flat = body.replace("\n", delim).split(delim)
            numbers = list(range(first + 2, first + 2 + ends.size))
            return header, numbers, [flat[j::ncol] for j in range(ncol)], delim
    numbered = [(i + 1, ln) for i, ln in enumerate(all_lines[first + 1:], start=first + 1)
                if ln.strip() and not ln.lstrip().startswith("#")]
    rows = list(csv.reader([ln for _, ln in numbered], delimiter=delim))
    for k, cells in enumerate(rows):
        if len(cells) != ncol:
            if len(cells) > ncol and any(c.strip() for c in cells[ncol:]):
                hint = (" (a number with a decimal comma in a comma-separated file splits in two: separate the "
                        "columns with ; or tabs)") if delim == "," and "," in numbered[k][1] else ""
                raise DesignError(f"line {numbered[k][0]}", len(cells), f"has more cells than the {ncol} headers{hint}")
            rows[k] = (cells + [""] * ncol)[:ncol]
    columns = [list(col) for col in zip(*rows)] if rows else [[] for _ in header]
    return header, [i for i, _ in numbered], columns, delim


#: the unit a table column is read in when its header names none, by the column's dimension
TABLE_UNITS = {"pressure": "MPa", "length": "mm", "fraction": "", "force": "N", "time": "s"}


def read_columns(path: str | Path, columns: Mapping[str, tuple[str, str]]) -> dict[str, np.ndarray]:
    """Numeric columns of a table of tablets or compacts (kawakita, walker, profiles), read as a press
    record is: the delimiter sniffed (``,``, ``;``, tab), decimal commas with ``;`` or tab, UTF-8 (BOM),
    UTF-16 or Windows-1252, ``#`` comments and blank lines skipped, and each column's unit taken from
    its header and converted (``Pressure (kPa)``, ``thickness_um``, ``Solid fraction (%)``).

    ``columns`` maps a key to ``(header, dimension)``: the header is found case-insensitively, as
    written or by its name without the unit, spaces, underscores and hyphens alike (``pressure_MPa``
    finds ``Pressure (kPa)``, ``solid_fraction`` finds ``Solid fraction (%)``); the
    dimension (``"pressure"``, ``"length"``, ``"fraction"``) gives the units a header may state and the
    unit taken when it states none (:data:`TABLE_UNITS`: MPa, mm, a fraction).  Returns the columns in
    MPa, mm or as fractions, and ``_lines`` (each row's line number in the file).

    Raises
    ------
    DesignError
        No such column, a unit of another dimension or an unknown one, a cell that is not a number
        (named by the file's line and the column).
    """
    path = Path(path)
    header, line_numbers, by_column, delim = _read_table(decode_text(path.read_bytes()), path.name)
    if not line_numbers:
        raise DesignError("DATA", str(path), "must hold a header row and at least one row of numbers")
    names = [h.lower() for h in header]
    decimal_comma = delim != "," and any("," in c for col in by_column for c in col[:50])
    out: dict[str, np.ndarray] = {}
    def word(text: str) -> str:  # "Solid fraction", "solid_fraction" and "solid-fraction" are one name
        return re.sub(r"[\s_\-]+", "_", strip_unit(text).strip().lower())

    bare = [word(h) for h in header]
    for key, (name, dimension) in columns.items():
        want = name.strip().lower()
        if want in names:  # the header as written, else the one header of that name in any unit
            j = names.index(want)
        elif bare.count(word(name)) == 1:
            j = bare.index(word(name))
        else:
            raise DesignError("column", name, f"must be one of the header's columns of {path.name} (or its name "
                              f"without the unit): {', '.join(header)}")
        unit = header_unit(header[j])
        factor, exponent = (1.0, 0) if unit is None else _column_unit(
            header[j], unit, dimension, f"; or no unit in the header for {TABLE_UNITS[dimension] or 'a fraction'}")
        col = _parse_column(by_column[j], exponent, decimal_comma)
        if isinstance(col, np.ndarray) and not np.all(np.isfinite(col)):
            col = int(np.flatnonzero(~np.isfinite(col))[0])  # a missing value: every row is one tablet
        if not isinstance(col, np.ndarray):
            raise DesignError(f"{path.name!r} line {line_numbers[col]} {header[j]!r}", by_column[j][col].strip() or MISSING,
                              "must be a number")
        out[key] = col * factor if exponent is None else col
    out["_lines"] = np.asarray(line_numbers)
    return out


def _column_unit(header: str, unit: str, dimension: str, hint: str) -> tuple[float, int | None]:
    """:func:`unit_factor` of a header's unit, a refusal naming the column as written (``column = 'Force (Kn)'``,
    not an escaped token)."""
    try:
        return unit_factor(unit, dimension, "column", hint)
    except DesignError as exc:
        raise DesignError("column", header, f"states the unit {unit!r}, which {exc.allowed}") from None


def _parse_column(cells: Sequence[str], exponent: int | None, decimal_comma: bool) -> np.ndarray | int:
    """A column of cells as floats (``exponent`` as in :func:`_to_float`, missing values NaN).

    Returns the row index of the first cell that is not a number instead.
    """
    try:  # fast path: every cell a plain number
        if decimal_comma:
            cells = "\n".join(cells).replace(",", ".").split("\n")
        if exponent and not any(("e" in c or "E" in c) for c in cells):
            cells = [c.strip() + f"e{exponent}" for c in cells]
        elif exponent:
            raise ValueError
        return np.array(cells, dtype=float)
    except ValueError:
        pass
    out = np.full(len(cells), np.nan)
    for k, cell in enumerate(cells):
        cell = cell.strip()
        if cell.lower() in _MISSING:
            continue
        try:
            out[k] = _to_float(cell, exponent, decimal_comma)
        except ValueError:
            return k
    return out


_MISSING = {"", "na", "nan", "n/a", "null", "none", "-"}
_NUMBER = re.compile(r"^([+-]?(?:\d+\.?\d*|\.\d+))(?:[eE]([+-]?\d+))?$")


def _to_float(cell: str, exponent: int | None, decimal_comma: bool) -> float:
    """``cell`` as a float; with ``exponent`` k the value of ``cell`` x 10^k, rounded once.

    Raises ValueError when ``cell`` is not a number.
    """
    if decimal_comma:
        cell = cell.replace(",", ".")
    if not exponent:
        return float(cell)
    m = _NUMBER.match(cell)
    if m is None:
        raise ValueError(cell)
    return float(f"{m.group(1)}e{int(m.group(2) or 0) + exponent}")


def _pick(role: str, header: list[str], found: list[int], chosen: str | None) -> int | None:
    """The column index for ``role``: the one named by its option, the only one found, or refuse."""
    option = f"--{role}-column"
    if chosen is not None:
        names = [h.lower() for h in header]
        key = str(chosen).strip().lower()
        if names.count(key) > 1:  # (the first of them had been taken)
            numbers = ", ".join(str(j + 1) for j, n in enumerate(names) if n == key)
            raise DesignError(option, str(chosen), f"names {names.count(key)} columns (numbers {numbers}): give "
                              "the column's number")
        if key in names:
            return names.index(key)
        if key.isdigit() and 1 <= int(key) <= len(header):
            return int(key) - 1
        raise DesignError(option, str(chosen), f"must be one of the headers {header} or a column number 1-{len(header)}")
    if len(found) > 1:
        names = [header[j] for j in found]
        raise DesignError(f"{role} column", names, f"is ambiguous; choose one with {option}")
    return found[0] if found else None


def read_press_data(
    path: str | Path,
    meta: str | Path | Mapping[str, Any] | PressMetadata | None = None,
    *,
    columns: Mapping[str, str | None] | None = None,
    units: Mapping[str, str | None] | None = None,
    **overrides: Any,
) -> PressData:
    """Read a press record from a delimited text file (CSV, ``;``-separated, TSV).

    The delimiter is sniffed (the one that splits the header and the first
    rows into equally many cells); with ``;`` or tab separators decimal commas
    (``0,0000``) are read.  A UTF-8 BOM, UTF-16 with BOM and Windows-1252
    (``µ`` as one byte) are decoded; ``#`` lines are comments.

    Columns get their role from their header (module docstring; also
    ``upper punch force``, ``punch distance``, ``travel``, ``stroke``), their
    unit from the header (:func:`tabletcad.mechanics.units.header_unit`:
    ``Force (kN)``, ``Time [ms]``, ``displacement_mm``) and are converted to
    N, mm and s; a header without a unit is taken as N, mm or s.

    Parameters
    ----------
    path : path
        The data file.
    meta : path, mapping, PressMetadata or None
        Metadata: a TOML file, a mapping with the TOML keys, a ready
        :class:`PressMetadata`, or ``None`` to use the TOML file with the same
        stem beside ``path`` if there is one.
    columns : mapping of role to header, optional
        Chooses the column of a role (``force``, ``displacement``,
        ``thickness``, ``time``) by header (case-insensitive) or 1-based
        number; needed when two columns could play a role (upper and lower
        punch force).  Choosing ``thickness`` makes it the position column.
    units : mapping of role to unit, optional
        Overrides the header's unit of a role (``force``: N, kN...;
        ``displacement`` — also used for a thickness column — mm, µm...;
        ``time``: s, ms...; see :data:`tabletcad.mechanics.units.UNITS`).
    **overrides
        Metadata keys (``mass_mg``, ``true_density``, ``diameter``,
        ``face_area``, ``compliance``, ``displacement_sign``,
        ``displacement_zero``) that override the file; ``None`` values are
        ignored.  ``compliance`` may be a :class:`MachineCompliance` or a
        ``(slope, offset)`` pair.

    Returns
    -------
    PressData

    Raises
    ------
    DesignError
        Missing or ambiguous columns, an unknown unit, non-numeric cells, or
        invalid metadata.  Rows with a missing force or position are dropped
        with a :class:`DataWarning` stating how many.
    """
    path = Path(path)
    columns = {k: v for k, v in (columns or {}).items() if v is not None}
    units = {k: v for k, v in (units or {}).items() if v is not None}
    for k in list(columns) + list(units):
        if k not in ROLES:
            raise DesignError("column role", k, f"must be one of {', '.join(ROLES)}")
    # options first: a bad option is reported before the file is read
    option_units = {
        role: unit_factor(u, DIMENSIONS[role], f"--{'displacement' if role == 'thickness' else role}-unit")
        for role, u in units.items()
    }
    header, line_numbers, by_column, delim = _read_table(decode_text(path.read_bytes()), path.name)
    found: dict[str, list[int]] = {r: [] for r in ROLES}
    for j, h in enumerate(header):
        r = _role(h)
        if r is not None:
            found[r].append(j)
    roles: dict[str, int] = {}
    for r in ROLES:  # columns chosen by option first; a chosen column plays no other role
        if r in columns:
            j = _pick(r, header, [], columns[r])
            if j in roles.values():
                other = next(k for k, v in roles.items() if v == j)
                raise DesignError(f"--{r}-column", columns[r], f"is already the {other} column")
            roles[r] = j
    for r in ROLES:
        if r not in columns:
            j = _pick(r, header, [k for k in found[r] if k not in roles.values()], None)
            if j is not None:
                roles[r] = j
    if "force" not in roles:
        raise DesignError("columns", header, "need a force column (header containing 'force' or 'load')")
    if "thickness" in columns:
        pos_role = "thickness"
    elif "displacement" in roles:
        pos_role = "displacement"  # a printed thickness column beside it stays in `extra`
    elif "thickness" in roles:
        pos_role = "thickness"
    else:
        raise DesignError("columns", header, "need a displacement or thickness column")
    for r in option_units:  # a unit for a column the record does not have would be ignored without a word
        role = r if r != "displacement" else pos_role
        if role not in roles:
            shown = ", ".join(header[:8]) + (", ..." if len(header) > 8 else "")
            raise DesignError(f"--{r}-unit", units[r], f"is for a {r} column, which {path.name} has none of "
                              f"(columns: {shown})")
    factors: dict[int, tuple[float, int | None]] = {}
    for r in ("force", pos_role, "time"):
        if r not in roles:
            continue
        j = roles[r]
        unit_role = "displacement" if r == "thickness" else r
        if unit_role in option_units or r in option_units:
            factors[j] = option_units.get(r, option_units.get(unit_role))
            continue
        u = header_unit(header[j])
        if u is None and r != "time":  # never guessed: a record in kN read as N gave a Py of 0.1 MPa
            example = {"force": "'Force [kN]', 'force_N'", "displacement": "'Displacement [mm]', 'position_um'",
                       "thickness": "'Thickness [mm]', 'gap_um'"}[r]
            raise DesignError("column", header[j], f"states no unit for its {r}: write it in the header "
                              f"({example}) or give --{unit_role}-unit (tabletcad does not guess one)")
        factors[j] = (1.0, 0) if u is None else _column_unit(header[j], u, DIMENSIONS[r], f"; or give --{unit_role}-unit")
    used = {roles["force"], roles[pos_role]} | ({roles["time"]} if "time" in roles else set())
    nrow = len(line_numbers)
    decimal_comma = delim != "," and any("," in c for col in by_column for c in col[:50])
    values = np.full((nrow, len(header)), np.nan)
    numeric_cols = []
    for j in range(len(header)):
        col = _parse_column(by_column[j], factors.get(j, (1.0, 0))[1], decimal_comma)
        if isinstance(col, np.ndarray):
            values[:, j] = col
            numeric_cols.append(j)
        elif j in used:
            raise DesignError(f"line {line_numbers[col]} {header[j]!r}", by_column[j][col].strip(), "must be a number")
        # else: a non-numeric optional column is ignored entirely
        by_column[j] = []  # free the text as soon as it is read
    for j, (factor, exponent) in factors.items():
        if exponent is None:
            values[:, j] *= factor
    need = [roles["force"], roles[pos_role]]
    for j in need:  # an infinite reading (inf, 1e400) is no missing value: it had been dropped as one
        inf = np.flatnonzero(np.isinf(values[:, j]))
        if inf.size:
            k = int(inf[0])
            unit = "N" if j == roles["force"] else "mm"
            raise DesignError(f"line {line_numbers[k]} {header[j]!r}", float(values[k, j]),
                              f"must be a finite number (infinite as read, in {unit}); leave a missing value's "
                              "cell empty", unit)
    keep = np.all(np.isfinite(values[:, need]), axis=1)
    dropped = int((~keep).sum())
    if dropped:
        warn(DataWarning, f"{path.name}: dropped {dropped} row(s) with a missing force or position value")
    values = values[keep]
    lines = np.asarray(line_numbers, dtype=int)[keep]
    t = values[:, roles["time"]] if "time" in roles else None
    if t is not None and not np.all(np.isfinite(t)):
        warn(DataWarning, f"{path.name}: time column has missing values; time ignored")
        t = None
    extra = {
        header[j]: values[:, j].copy() for j in numeric_cols if j not in used and np.any(np.isfinite(values[:, j]))
    }
    metadata = _resolve_metadata(path, meta, overrides)
    return _assemble(
        values[:, roles["force"]].copy(), values[:, roles[pos_role]].copy(), pos_role == "thickness",
        t, metadata, extra, lines, dropped, path.name, header[roles[pos_role]], header[roles["force"]],
    )


def metadata_beside(path: str | Path) -> Path | None:
    """The metadata TOML with the same stem next to ``path``, if it exists."""
    cand = Path(path).with_suffix(".toml")
    return cand if cand.is_file() else None


def read_metadata(source: str | Path | Mapping[str, Any], **overrides: Any) -> PressMetadata:
    """Build :class:`PressMetadata` from a TOML file or mapping plus keyword overrides."""
    if isinstance(source, (str, Path)):
        from tabletcad.io.tomlfile import read_toml_file

        raw = read_toml_file(source, "metadata")
    else:
        raw = dict(source)
    if set(raw) == {"press"}:  # allow a [press] table
        raw = raw["press"]
        if not isinstance(raw, Mapping):
            raise DesignError("press", raw, "must be a table")
    raw = dict(raw)
    unknown = sorted(set(raw) - set(METADATA_KEYS))
    if unknown:  # a misspelled key would silently change the results (an ignored compliance moves K by 15 %)
        raise DesignError(unknown[0], raw[unknown[0]], "is not a metadata key (misspelled?): the keys are "
                          + ", ".join(METADATA_KEYS))
    if overrides.get("diameter") is not None and overrides.get("face_area") is not None:
        raise DesignError("face_area", overrides["face_area"], "give diameter or face_area, not both", "mm²")
    given = overrides.get("diameter") is not None or overrides.get("face_area") is not None
    if not given and raw.get("diameter") is not None and raw.get("face_area") is not None:
        # one would be ignored without a word (an option replaces both)
        raise DesignError("face_area", raw["face_area"], "give diameter or face_area, not both (the punch face "
                          "area is one quantity; or give --diameter or --face-area)", "mm²")
    for k, v in overrides.items():
        if v is not None:
            if k in ("diameter", "face_area"):  # the area given another way replaces the file's, either way
                raw.pop("diameter", None)
                raw.pop("face_area", None)
            raw[k] = v
    compliance = _compliance(raw.get("compliance"))
    missing = [k for k in ("mass_mg", "true_density") if k not in raw]
    if missing:
        raise DesignError(missing[0], MISSING, "is required (metadata file or command-line option)")
    sign = raw.get("displacement_sign", "auto")
    if isinstance(sign, float) and sign in (1.0, -1.0):
        sign = int(sign)
    return PressMetadata(
        mass_mg=raw["mass_mg"],
        true_density=raw["true_density"],
        diameter=raw.get("diameter"),
        face_area=raw.get("face_area"),
        compliance=compliance,
        displacement_sign=sign,
        displacement_zero=check_finite("displacement_zero", raw.get("displacement_zero", 0.0), "mm"),
        notes=raw.get("notes", ""),
    )


#: the keys of a press record's metadata (file or mapping; a ``[press]`` table may hold them)
METADATA_KEYS = ("notes", "mass_mg", "true_density", "diameter", "face_area", "compliance", "displacement_sign",
                 "displacement_zero")
#: the forms of a ``[compliance]`` table: exactly one of them
COMPLIANCE_FORMS = (("compensation_line",), ("force", "deflection"), ("slope", "offset"))


def _numbers(name: str, values: Any, unit: str, n: int | None = None) -> tuple[float, ...]:
    """A list of finite numbers (of length ``n`` if given), else :class:`DesignError`."""
    if not isinstance(values, (list, tuple)) or (n is not None and len(values) != n):
        raise DesignError(name, values, f"must be a list of {n or 'several'} numbers", unit)
    return tuple(check_finite(f"{name} {i}", x, unit) for i, x in enumerate(values))  # named by its index


def _named_line(slope: float, offset: float, names: tuple[str, str], shown: tuple[float, float]) -> MachineCompliance:
    """The compliance line ``slope`` (mm/N), ``offset`` (mm), its refusal named as the file gives it: the
    entries ``names`` with their values ``shown`` (a compensation line's intercept is minus the offset;
    ``compensation_line = [1, 0]`` had been refused as ``compliance.slope``, a key the file did not have)."""
    try:
        return MachineCompliance(slope=slope, offset=offset)
    except DesignError as exc:
        i = {"compliance.slope": 0, "compliance.offset": 1}.get(exc.parameter)
        if i is None:
            raise
        raise DesignError(names[i], shown[i], exc.allowed, exc.unit) from None


def _compliance(comp: Any) -> MachineCompliance | None:
    """The machine compliance of a metadata entry: None, a (slope, offset) pair or a ``[compliance]`` table."""
    if comp is None or isinstance(comp, MachineCompliance):
        return comp
    if isinstance(comp, (tuple, list)):
        slope, offset = _numbers("compliance", comp, "", 2)
        return MachineCompliance(slope=slope, offset=offset)
    if not isinstance(comp, Mapping):
        raise DesignError("compliance", comp, "must be a (slope, offset) pair or a table")
    keys = set(comp)
    form = next((f for f in COMPLIANCE_FORMS if keys and keys <= set(f)), None)
    if form is None or (form != ("slope", "offset") and keys != set(form)):
        allowed = "; ".join(" and ".join(f) for f in COMPLIANCE_FORMS)
        raise DesignError("compliance", ", ".join(sorted(keys)) or "an empty table",
                          f"must hold exactly one form of keys: {allowed}")
    if form == ("compensation_line",):
        s, b = _numbers("compliance compensation_line", comp["compensation_line"], "", 2)
        # MachineCompliance.from_compensation_line's convention (offset = -intercept), named as the file's entries
        return _named_line(s, -b, ("compliance compensation_line 0", "compliance compensation_line 1"), (s, b))
    if form == ("force", "deflection"):
        force = _numbers("compliance force", comp["force"], "N")
        deflection = _numbers("compliance deflection", comp["deflection"], "mm")
        check_compliance_table(force, deflection)  # here too: an empty table is no table, not the zero line
        return MachineCompliance(table_force=force, table_deflection=deflection)
    return MachineCompliance(slope=check_finite("compliance slope", comp.get("slope", 0.0), "mm/N"),
                             offset=check_finite("compliance offset", comp.get("offset", 0.0), "mm"))


def _resolve_metadata(path: Path, meta, overrides: Mapping[str, Any]) -> PressMetadata:
    if isinstance(meta, PressMetadata):
        if any(v is not None for v in overrides.values()):
            base = meta.to_dict() | {
                "compliance": meta.compliance,
                "displacement_sign": meta.displacement_sign,
                "displacement_zero": meta.displacement_zero,
            }
            return read_metadata(base, **overrides)
        return meta
    if meta is None:
        meta = metadata_beside(path)
    if meta is None:
        return read_metadata({}, **overrides)
    return read_metadata(meta, **overrides)
