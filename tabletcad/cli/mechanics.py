"""Mechanics commands: ``heckel``, ``kawakita``, ``walker``, ``profiles``, ``strength``, ``contact``, ``shell``, ``love``.

Units: mm, N, MPa, mg, mg/mm³.  Every command computes everything before it
writes any file, so bad input (reported by ``tabletcad.cli.main`` as one
``error:`` line, exit status 2) leaves nothing behind.  Warnings from the
mechanics code are printed as ``warning:`` lines on stderr and, with
``--json``, listed under ``"warnings"``.
"""

from __future__ import annotations

import contextlib
import math
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import click
import numpy as np

from tabletcad.cli.options import option_names
from tabletcad.cli.outputs import check_output as _check_output
from tabletcad.io.jsontext import json_text
from tabletcad.cli.outputs import staged as _staged
from tabletcad.errors import MISSING, DesignError, check_finite, check_positive, check_range, format_bound
from tabletcad.tolerance import DEFAULT, MAX_MODULUS_MPA, MAX_PRESSURE_MPA, MAX_TENSILE_STRENGTH_MPA

__all__ = ["COMMANDS"]


@contextlib.contextmanager
def _collect() -> Iterator[list[str]]:
    """Collect mechanics warnings (their text) into the list yielded; :func:`_emit` echoes them on stderr
    once the command's outputs are written (a write refused after them, ``--json > /dev/full``, had left
    the warnings and the error line: two lines for one refusal)."""
    from tabletcad.mechanics.validity import MechanicsWarning

    msgs: list[str] = []
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always", MechanicsWarning)
        yield msgs
    for w in rec:
        if issubclass(w.category, MechanicsWarning):
            msgs.append(str(w.message))


def _emit(payload: dict[str, Any], as_json: bool, lines: list[str]) -> None:
    """Print the result (its lines, or ``payload`` as JSON), then the payload's ``warnings`` on stderr.

    The warnings come last: a refused write of standard output (a full disk) is then the command's one
    ``error:`` line, as every refusal is."""
    if as_json:
        click.echo(json_text(payload))
    else:
        for ln in lines:
            click.echo(ln)
    from tabletcad.cli import say_warning

    for m in payload.get("warnings", ()):
        say_warning(m)


#: the metadata's keys (as a metadata file writes them) with their units, for the JSON documents
_METADATA_UNITS = {"true_density": "true_density_mg_mm3", "diameter": "diameter_mm", "face_area": "face_area_mm2",
                   "slope": "slope_mm_per_N", "offset": "offset_mm", "force": "force_N", "deflection": "deflection_mm"}


def _metadata_with_units(meta: dict[str, Any]) -> dict[str, Any]:
    """A record's metadata with its units in its keys (``true_density_mg_mm3``; a JSON document's keys
    carry them, as the metadata file's need not)."""
    return {_METADATA_UNITS.get(k, k): (_metadata_with_units(v) if isinstance(v, dict) else v) for k, v in meta.items()}


def _check_input(name: str, path: Path | None) -> None:
    if path is not None and not path.is_file():
        raise DesignError(name, str(path), "must be a file: it is a folder" if path.is_dir() else
                          "must be a file: it is not one" if path.exists() else "must be an existing file")


_JSON_OPTS = [
    click.option("--json", "as_json", is_flag=True, help="Print the result as JSON on stdout."),
    click.option("--json-file", type=click.Path(path_type=Path), help="Write the result as JSON to this file."),
]


def _with_json(f):
    for opt in reversed(_JSON_OPTS):
        f = opt(f)
    return f


# --------------------------------------------------------------------------- heckel
@click.command("heckel")
@click.argument("data", type=click.Path(path_type=Path))
@click.option("--meta", type=click.Path(path_type=Path),
              help="Metadata TOML (default: DATA's name with .toml, if present).")
@click.option("--mass", type=float, help="Compact mass, mg.")
@click.option("--true-density", type=float, help="True density, mg/mm³.")
@click.option("--diameter", type=float, help="Die diameter, mm.")
@click.option("--face-area", type=float, help="Punch face area, mm² (instead of --diameter).")
@click.option("--compliance", nargs=2, type=float, metavar="SLOPE OFFSET",
              help="Machine deflection δ = SLOPE·F + OFFSET (mm/N, mm) added to the punch gap.")
@click.option("--window", nargs=2, type=float, metavar="LO HI",
              help="Pressure window in MPa; default: the widest run straight within the data's noise.")
@click.option("--force-column", help="Header (or 1-based number) of the force column, e.g. 'Upper Punch Force (kN)'.")
@click.option("--displacement-column", help="Header (or number) of the punch displacement/position column.")
@click.option("--thickness-column", help="Header (or number) of a thickness/gap column to use instead of displacement.")
@click.option("--time-column", help="Header (or number) of the time column.")
@click.option("--force-unit", help="Unit of the force column (N, kN, daN, MN, mN, lbf, kgf); overrides the header.")
@click.option("--displacement-unit", help="Unit of the displacement or thickness column (mm, µm, um, cm, m, in).")
@click.option("--time-unit", help="Unit of the time column (s, ms, µs, min, h).")
@click.option("--plot", "plot_file", type=click.Path(path_type=Path), help="Heckel plot (.png/.svg).")
@_with_json
def heckel_cmd(data: Path, meta: Path | None, mass: float | None, true_density: float | None,
               diameter: float | None, face_area: float | None, compliance: tuple[float, float] | None,
               window: tuple[float, float] | None, force_column: str | None, displacement_column: str | None,
               thickness_column: str | None, time_column: str | None, force_unit: str | None,
               displacement_unit: str | None, time_unit: str | None, plot_file: Path | None, as_json: bool,
               json_file: Path | None) -> None:
    """Heckel analysis (eqs 2.2-2.3) of the loading branch of a press record DATA (CSV/TSV).

    Units are read from the headers ('Force (kN)', 'Time [ms]', ...) and
    converted to N, mm and s; the options override units and choose columns.
    Without --window the window is the widest run of points that is straight
    within the record's own noise (README, "Compaction mechanics").
    """
    from tabletcad.mechanics.compaction import compaction_curves
    from tabletcad.mechanics.heckel import fit_heckel, plot_heckel
    from tabletcad.mechanics.pressdata import MachineCompliance, read_press_data

    _check_input("DATA", data)
    _check_input("--meta", meta)
    if diameter is not None and face_area is not None:  # one would be ignored without a word
        raise DesignError("--face-area", face_area, "give --diameter or --face-area, not both", "mm²")
    _check_output("--plot", plot_file)
    _check_json_file(json_file, plot=plot_file)
    _check_window(window)
    given = {k: o for k, o, v in (("mass_mg", "--mass", mass), ("true_density", "--true-density", true_density),
                                  ("diameter", "--diameter", diameter), ("face_area", "--face-area", face_area),
                                  ("compliance slope", "--compliance", compliance),
                                  ("compliance offset", "--compliance", compliance), ("window", "--window", window))
             if v is not None}  # an option overrides the metadata file's key: named as given
    with _collect() as msgs, option_names(given):
        comp = MachineCompliance(slope=compliance[0], offset=compliance[1]) if compliance else None
        rec = read_press_data(
            data, meta, mass_mg=mass, true_density=true_density, diameter=diameter, face_area=face_area,
            compliance=comp,
            columns={"force": force_column, "displacement": displacement_column, "thickness": thickness_column,
                     "time": time_column},
            units={"force": force_unit, "displacement": displacement_unit, "time": time_unit})
        curves = compaction_curves(rec)
        fit = fit_heckel(curves, window=window)
    payload = fit.to_dict() | {
        "warnings": msgs,
        "data": str(data),
        "rows_dropped": rec.dropped_rows,
        "branches": curves.describe_rows(),
        "loading_rows": [curves.branches.loading[0] + 1, curves.branches.loading[1]],
        "fitted_rows": [fit.rows[0] + 1, fit.rows[-1] + 1] if fit.rows else [],
        "elastic_recovery": curves.elastic_recovery,
        "metadata": _metadata_with_units(rec.metadata.to_dict()),
    }
    lo, hi = fit.window_MPa
    how = fit.method if fit.noise_sd is None else f"auto: widest run linear within the noise σ = {fit.noise_sd:.3g}"
    _finish(payload, as_json, json_file, [
        f"{data.name}: {curves.describe_rows()}",
        f"window {lo:.4g}-{hi:.4g} MPa ({how}), n = {fit.n_points}",
        f"K = {fit.K_per_MPa:.4g} 1/MPa, A = {fit.A:.4g}, Py = {fit.Py_MPa:.4g} MPa, R² = {fit.r2:.4f}",
    ], (plot_file, lambda path: plot_heckel(fit, path, title=f"Heckel plot: {data.name}")))


# --------------------------------------------------------------------------- kawakita, walker, profiles
def _read_table(path: Path, columns: dict[str, tuple[str, str]]) -> dict[str, np.ndarray]:
    """Numeric columns of a table, read as a press record is (:func:`tabletcad.mechanics.pressdata.read_columns`:
    delimiter, decimal commas, encodings and the header's units)."""
    from tabletcad.mechanics.pressdata import read_columns

    return read_columns(path, columns)


def _check_window(window: tuple[float, float] | None) -> None:
    """Refuse a ``--window`` that is not two increasing compaction pressures up to ``MAX_PRESSURE_MPA`` (a
    window to 1e300 MPa had been taken, as love, which simulates its window, refused it)."""
    if window is not None:
        check_range("--window", window[0], 0.0, MAX_PRESSURE_MPA, "MPa")  # pressures: a compact is never pulled
        check_range("--window", window[1], 0.0, MAX_PRESSURE_MPA, "MPa", lo_open=True)
        if not window[0] < window[1]:
            raise DesignError("--window", window, "must be two increasing pressures", "MPa")


def _check_json_file(json_file: Path | None, **others: Path | None) -> None:
    """``--json-file`` ends in .json and is none of the command's other output files."""
    _check_output("--json-file", json_file, (".json",))
    for option, path in others.items():
        if json_file is not None and path is not None and json_file.absolute() == path.absolute():
            raise DesignError("--json-file", str(json_file), f"must differ from --{option}")


def _finish(payload: dict[str, Any], as_json: bool, json_file: Path | None, lines: list[str],
            plot: tuple[Path | None, Any] = (None, None)) -> None:
    """Write ``--json-file`` (and a plot) all-or-nothing with the lines or the JSON printed: the files are
    moved into place once the printing succeeded (``--plot h.png > /dev/full`` had left h.png, exit 2)."""
    plot_file, draw = plot
    with _staged(json=json_file, plot=plot_file) as out:
        if json_file is not None:
            out["json"].write_text(json_text(payload) + "\n", encoding="utf-8")
        if plot_file is not None:
            draw(out["plot"])
        _emit(payload, as_json, lines + ([f"json -> {json_file}"] if json_file and not as_json else [])
              + ([f"plot -> {plot_file}"] if plot_file and not as_json else []))


def _compression_table(data: Path, pressure_column: str, thickness_column: str, h0: float | None,
                       window, json_file: Path | None) -> dict[str, np.ndarray]:
    _check_input("DATA", data)
    _check_output("--json-file", json_file, (".json",))
    _check_window(window)
    if h0 is not None:  # a length within the size limit (1e300 had fitted W = 1.5e-298 % per decade, exit 0)
        check_range("--h0", h0, 0.0, DEFAULT.max_length, "mm", lo_open=True)
    table = _read_table(data, {"P": (pressure_column, "pressure"), "h": (thickness_column, "length")})
    bad = np.flatnonzero(~(table["h"] > 0.0))
    if bad.size:  # a thickness is a length: 0 or less is a misread column or a displacement
        raise DesignError(f"{data.name!r} line {int(table['_lines'][bad[0]])} {thickness_column!r}",
                          float(table["h"][bad[0]]), "must be > 0 (the compact's thickness)", "mm")
    bad = np.flatnonzero(table["P"] < 0.0)
    if bad.size:  # a compact is pressed, never pulled: a negative pressure is a misread column
        raise DesignError(f"{data.name!r} line {int(table['_lines'][bad[0]])} {pressure_column!r}",
                          float(table["P"][bad[0]]), "must be >= 0 (a compaction pressure)", "MPa")
    _refuse_too_large(data, table, pressure_column, thickness_column)
    return table


def _refuse_too_large(data: Path, table: dict[str, np.ndarray], pressure_column: str, thickness_column: str) -> None:
    """Refuse a pressure above ``MAX_PRESSURE_MPA`` or a thickness above ``Tolerances.max_length`` in a
    compression table, named by its file, line and column.

    A pressure of 1e300 MPa had fitted Kawakita's a = inf with R² = nan, and thicknesses of 1e300 mm
    had been fitted as a tablet's, exit 0: no compact has them.

    Parameters
    ----------
    data : Path
        The table's file.
    table : dict of str to ndarray
        Its columns ``P`` (MPa), ``h`` (mm) and ``_lines``.
    pressure_column, thickness_column : str
        The columns' headers as the command line names them.
    """
    _refuse_row(data, table, "P", pressure_column, table["P"] > MAX_PRESSURE_MPA,
                f"must be >= 0 and <= {MAX_PRESSURE_MPA:g} MPa (a compaction pressure)", "MPa")
    _refuse_row(data, table, "h", thickness_column, table["h"] > DEFAULT.max_length,
                f"must be > 0 and <= {DEFAULT.max_length:g} mm (the compact's thickness)", "mm")


def _compression_options(f):
    for opt in reversed([
        click.argument("data", type=click.Path(path_type=Path)),
        click.option("--pressure-column", default="pressure_MPa", show_default=True,
                     help="Header of the compaction pressure column, MPa."),
        click.option("--thickness-column", default="thickness_mm", show_default=True,
                     help="Header of the compact thickness (punch gap) column, mm, loading branch."),
        click.option("--h0", type=float, help="Reference thickness defining V0, mm (default: the first row's)."),
        click.option("--window", nargs=2, type=float, metavar="LO HI", help="Pressure window, MPa (default: all P > 0)."),
    ]):
        f = opt(f)
    return _with_json(f)


def _kawakita_line(fit) -> str:
    return f"a = {fit.a:.4g}, b = {fit.b_per_MPa:.4g} 1/MPa (1/b = {fit.inv_b_MPa:.4g} MPa), R² = {fit.r2:.4f}"


def _walker_line(fit) -> str:
    return f"W = {fit.W_percent_per_decade:.4g} % per decade, c = {fit.intercept_percent:.4g} %, R² = {fit.r2:.4f}"


def _compression_command(name: str, fit_name: str, describe, doc: str):
    """A command fitting ``tabletcad.mechanics.kawakita.<fit_name>`` to a pressure/thickness table."""

    @click.command(name.lower(), help=doc)
    @_compression_options
    def command(data: Path, pressure_column: str, thickness_column: str, h0: float | None,
                window: tuple[float, float] | None, as_json: bool, json_file: Path | None) -> None:
        from tabletcad.mechanics import kawakita

        from tabletcad.mechanics.compaction import split_branches

        t = _compression_table(data, pressure_column, thickness_column, h0, window, json_file)
        # the loading branch only (as heckel): a press record goes on past its peak pressure into
        # unloading and reloading rows, whose thickness follows the elastic recovery instead
        a, b = split_branches(t["P"], quantity="pressure", unit="MPa").loading
        lines = [] if (a, b) == (0, len(t["P"])) else [
            f"{data.name}: loading rows {a + 1}-{b} of {len(t['P'])} used (up to the peak pressure; "
            f"the rows after it unload or reload the compact)"]
        with _collect() as msgs:
            try:
                fit = getattr(kawakita, fit_name)(t["P"][a:b], t["h"][a:b], window=window, h0=h0)
            except DesignError as exc:  # the function's names for the options: as given
                if exc.parameter in ("h0", "window"):
                    raise exc.renamed(f"--{exc.parameter}") from None
                raise
        lo, hi = fit.window_MPa
        _finish(fit.to_dict() | {"data": str(data), "loading_rows": [a + 1, b], "warnings": msgs}, as_json, json_file,
                lines + [f"{name} over {lo:.4g}-{hi:.4g} MPa (n = {fit.n_points}, h0 = {fit.h0:.4g} mm): {describe(fit)}"])

    return command


kawakita_cmd = _compression_command(
    "Kawakita", "fit_kawakita", _kawakita_line,
    "Kawakita fit C = abP/(1+bP), C = (h0 - h)/h0, of a table of pressure (MPa) and thickness (mm).")
walker_cmd = _compression_command(
    "Walker", "fit_walker", _walker_line,
    "Walker fit 100 V/V0 = -W log10 P + c (V/V0 = h/h0) of a table of pressure (MPa) and thickness (mm).")


def _refuse_row(data: Path, table: dict[str, np.ndarray], key: str, column: str, bad: np.ndarray, allowed: str,
               unit: str = "") -> None:
    """Refuse the first row of ``table[key]`` marked ``bad``, named by the file, its line and the column
    (``"prof6.csv".line[3].solid_fraction``, as the kawakita and press-record readers name a cell).

    Parameters
    ----------
    data : Path
        The table's file.
    table : dict of str to ndarray
        Columns as :func:`tabletcad.mechanics.pressdata.read_columns` returns them (``_lines`` among them).
    key : str
        The column's key in ``table``.
    column : str
        The column as the command line names it (its header).
    bad : ndarray of bool
        Rows to refuse.
    allowed, unit : str
        The refusal's range and the value's unit.

    Raises
    ------
    DesignError
        For the first bad row.
    """
    rows = np.flatnonzero(bad)
    if rows.size:
        k = int(rows[0])
        raise DesignError(f"{data.name!r} line {int(table['_lines'][k])} {column!r}", float(table[key][k]), allowed,
                          unit)


@click.command("profiles")
@click.argument("data", type=click.Path(path_type=Path))
@click.option("--pressure-column", default="pressure_MPa", show_default=True, help="Compaction pressure, MPa.")
@click.option("--solid-fraction-column", default="solid_fraction", show_default=True,
              help="Solid fraction (relative density) of the ejected tablet, in (0, 1).")
@click.option("--strength-column", default="tensile_strength_MPa", show_default=True, help="Tensile strength, MPa.")
@click.option("--solid-fraction", "as_solid_fraction", is_flag=True,
              help="Plot and report solid fraction instead of porosity.")
@click.option("--plot", "plot_file", type=click.Path(path_type=Path), help="The three profiles (.png/.svg/.pdf).")
@_with_json
def profiles_cmd(data: Path, pressure_column: str, solid_fraction_column: str, strength_column: str,
                 as_solid_fraction: bool, plot_file: Path | None, as_json: bool, json_file: Path | None) -> None:
    """USP <1062> tabletability, compressibility and compactibility profiles, and the
    Ryshkewitch-Duckworth fit (eq 2.6), of a table of tablets (one row per tablet or pressure)."""
    from tabletcad.mechanics.profiles import (compactibility, compressibility, fit_ryshkewitch_duckworth,
                                              plot_profiles, tabletability)

    _check_input("DATA", data)
    _check_output("--json-file", json_file, (".json",))
    _check_output("--plot", plot_file)
    if json_file is not None and plot_file is not None and json_file.absolute() == plot_file.absolute():
        raise DesignError("--plot", str(plot_file), "must differ from --json-file")
    t = _read_table(data, {"P": (pressure_column, "pressure"), "sf": (solid_fraction_column, "fraction"),
                           "s": (strength_column, "pressure")})
    _refuse_row(data, t, "P", pressure_column, t["P"] < 0.0, "must be >= 0 (a compaction pressure)", "MPa")
    _refuse_row(data, t, "sf", solid_fraction_column, ~((t["sf"] > 0.0) & (t["sf"] < 1.0)),
                "must be > 0 and < 1 (a solid fraction; a percentage needs '%' in its header, as "
                "'Solid fraction (%)')")
    _refuse_row(data, t, "s", strength_column, ~(t["s"] > 0.0), "must be > 0 (a tablet's tensile strength)", "MPa")
    # no compact has these (1e300 MPa of either had been plotted and fitted, exit 0)
    _refuse_row(data, t, "P", pressure_column, t["P"] > MAX_PRESSURE_MPA,
                f"must be >= 0 and <= {MAX_PRESSURE_MPA:g} MPa (a compaction pressure)", "MPa")
    _refuse_row(data, t, "s", strength_column, t["s"] > MAX_TENSILE_STRENGTH_MPA,
                f"must be > 0 and <= {MAX_TENSILE_STRENGTH_MPA:g} MPa (a tablet's tensile strength)", "MPa")
    porosity = not as_solid_fraction
    with _collect() as msgs:
        profs = [tabletability(t["P"], t["s"]), compressibility(t["P"], t["sf"], as_porosity=porosity),
                 compactibility(t["sf"], t["s"], as_porosity=porosity)]
        rd = fit_ryshkewitch_duckworth(t["sf"], t["s"]) if len(t["P"]) >= 3 else None
    payload: dict[str, Any] = {
        "data": str(data),
        "profiles": {p.name: {"x": p.x, "y": p.y, "x_label": p.x_label, "y_label": p.y_label} for p in profs},
        "ryshkewitch_duckworth": None if rd is None else {"sigma0_MPa": rd.sigma0_MPa, "k": rd.k, "r2": rd.r2,
                                                          "n_points": rd.n_points},
        "warnings": msgs,
    }
    tab, comp, _ = profs
    lines = [f"{data.name}: {len(t['P'])} tablets, {tab.x.min():.4g}-{tab.x.max():.4g} MPa",
             f"tabletability: tensile strength {tab.y.min():.4g}-{tab.y.max():.4g} MPa",
             f"compressibility: {'porosity' if porosity else 'solid fraction'} {comp.y.min():.4g}-{comp.y.max():.4g}"]
    if rd is not None:
        lines.append(f"Ryshkewitch-Duckworth (eq 2.6): sigma0 = {rd.sigma0_MPa:.4g} MPa, k = {rd.k:.4g}, "
                     f"R² = {rd.r2:.4f}")
    _finish(payload, as_json, json_file, lines, (plot_file, lambda p: plot_profiles(profs, p)))


# --------------------------------------------------------------------------- strength
_METHODS = ("diametral", "axial", "pitt", "elongated-flat", "elongated-convex", "podczeck", "sphere")
#: the options each method reads (besides --force)
_STRENGTH_OPTIONS = {
    "diametral": ("--diameter", "--thickness"), "axial": ("--diameter",),
    "pitt": ("--diameter", "--thickness", "--band"), "elongated-flat": ("--diameter", "--thickness", "--length"),
    "elongated-convex": ("--diameter", "--thickness", "--band", "--length"),
    "podczeck": ("--diameter", "--thickness", "--band", "--face-radius"),
    "sphere": ("--material", "--E", "--nu", "--radius", "--s-y"),
}


@click.command("strength")
@click.argument("method", type=click.Choice(_METHODS))
@click.option("--force", "F", type=float, required=True, help="Breaking (or yield) force, N.")
@click.option("--diameter", "D", type=float, help="Diameter (width for elongated tablets), mm.")
@click.option("--thickness", "t", type=float, help="Total thickness, mm.")
@click.option("--band", "W", type=float, help="Central cylinder (band) thickness, mm.")
@click.option("--length", "L", type=float, help="Length of an elongated tablet, mm (validity check).")
@click.option("--face-radius", "R", type=float, help="Face radius of curvature, mm (Podczeck validity check).")
@click.option("--material", help="Material from the table (sphere method), e.g. kostrolith.")
@click.option("--E", "E", type=float, help="Young's modulus, MPa (sphere).")
@click.option("--nu", type=float, help="Poisson's ratio (sphere).")
@click.option("--radius", type=float, help="Sphere radius, mm (sphere).")
@click.option("--s-y", "s_y", type=float, help="Micro-yield strength, MPa (sphere).")
@_with_json
def strength_cmd(method: str, F: float, D, t, W, L, R, material, E, nu, radius, s_y, as_json: bool,
                 json_file: Path | None) -> None:
    """Tensile strength (MPa) of a tablet from a breaking test (eqs 2.4-2.11)."""
    from tabletcad.mechanics import strength as st

    _check_json_file(json_file)
    given = {"--diameter": D, "--thickness": t, "--band": W, "--length": L, "--face-radius": R, "--material": material,
             "--E": E, "--nu": nu, "--radius": radius, "--s-y": s_y}
    for option, value in given.items():  # an option the method does not read is a mistake, not a no-op
        if value is not None and option not in _STRENGTH_OPTIONS[method]:
            raise DesignError(option, value, f"is not used by method {method!r}, which takes "
                              f"{', '.join(_STRENGTH_OPTIONS[method])}")

    def need(name: str, v):
        if v is None:
            raise DesignError(name, MISSING, f"is required for method {method!r}")
        return v

    # the formulas name their arguments; here they are options
    names = {"force": "--force", "diameter": "--diameter", "width": "--diameter", "thickness": "--thickness",
             "band thickness": "--band", "length": "--length", "face radius": "--face-radius", "E": "--E",
             "nu": "--nu", "radius": "--radius", "r_s": "--radius", "s_y": "--s-y", "material": "--material"}
    inputs: dict = {}  # the sphere method's inputs and their sources
    said = ""
    with _collect() as msgs, option_names(names):
        if method == "diametral":
            sigma, eq = st.diametral_flat(F, need("--diameter", D), need("--thickness", t)), "2.4"
        elif method == "axial":
            sigma, eq = st.axial_flat(F, need("--diameter", D)), "2.5"
        elif method == "pitt":
            sigma, eq = st.pitt_convex(F, need("--diameter", D), need("--thickness", t), need("--band", W)), "2.7"
        elif method == "elongated-flat":
            sigma, eq = st.pitt_heasley_elongated_flat(F, need("--diameter", D), need("--thickness", t), L), "2.8"
        elif method == "elongated-convex":
            sigma, eq = st.pitt_heasley_elongated_convex(
                F, need("--diameter", D), need("--thickness", t), need("--band", W), L), "2.9"
        elif method == "podczeck":
            sigma, eq = st.podczeck_convex(F, need("--diameter", D), need("--thickness", t), W, R), "Podczeck 2013"
        else:
            # each input from its option, else from --material's table row; the result says which
            source = {k: (o if v is not None else None) for k, o, v in
                      (("E", "--E", E), ("nu", "--nu", nu), ("radius", "--radius", radius), ("s_y", "--s-y", s_y))}
            if material:
                from tabletcad.mechanics.materials import get_material

                m = get_material(material)
                E = m.E if E is None else E
                nu = m.nu if nu is None else nu
                radius = m.radius if radius is None else radius
                s_y = m.s_y if s_y is None else s_y
                source = {k: o or f"material {material}" for k, o in source.items()}
            sigma = st.sphere_hertz(F, need("--E", E), need("--nu", nu), need("--radius", radius), need("--s-y", s_y))
            eq = "2.10-2.11"
            inputs = {"inputs": {"E_MPa": E, "nu": nu, "radius_mm": radius, "s_y_MPa": s_y, "source": source}}
            said = (f" (E {E:g} MPa from {source['E']}, nu {nu:g} from {source['nu']}, radius {radius:g} mm from "
                    f"{source['radius']}, s_y {s_y:g} MPa from {source['s_y']})")
    _finish({"method": method, "equation": eq, "tensile_strength_MPa": sigma, "warnings": msgs, **inputs}, as_json,
            json_file, [f"{method} (eq {eq}): tensile strength = {sigma:.4g} MPa{said}"])


# --------------------------------------------------------------------------- contact
@click.command("contact")
@click.option("--material", default="kostrolith", show_default=True, help="Material key in tabletcad/data/materials.toml.")
@click.option("--force", "forces", type=float, multiple=True, required=True, help="Platen force, N (repeatable).")
@click.option("--radius", type=float, help="Sphere radius, mm (default: the material's).")
@click.option("--plot", "plot_file", type=click.Path(path_type=Path),
              help="Force-displacement plot (.png/.svg).")
@_with_json
def contact_cmd(material: str, forces: tuple[float, ...], radius: float | None, plot_file: Path | None,
                as_json: bool, json_file: Path | None) -> None:
    """Compressed spherical tablet: displacement, height, contact radius, boundary circles (eqs 2.1, 5.19-5.26)."""
    from tabletcad.mechanics import contact as ct
    from tabletcad.mechanics.materials import get_material

    _check_output("--plot", plot_file)
    _check_json_file(json_file, plot=plot_file)
    for f in forces:
        check_finite("--force", f, "N")
    if radius is not None:  # a length, as a design's (1e300 mm had overflowed eq 2.1's cubic: exit 1)
        check_range("--radius", radius, 0.0, DEFAULT.max_length, "mm", lo_open=True)
    with _collect() as msgs, option_names({"material": "--material", "radius": "--radius", "force": "--force"}):
        m = get_material(material)
        results = [ct.compress_sphere(f, m, radius) for f in forces]
        r = results[0].radius
        wy = ct.yield_displacement(m.E, m.nu, r, m.s_y)
        curve = ct.force_displacement_curve(m, max(2.0 * max(x.displacement for x in results), 3 * wy), radius=r)
    payload = {
        "material": m.name, "source": m.cited, "radius_mm": r, "yield_displacement_mm": wy,
        "yield_force_eq2_1_N": curve.force_at_yield_ep, "yield_force_hertz_N": curve.force_at_yield_hertz,
        "results": [x.to_dict() for x in results], "warnings": msgs,
    }
    lines = [(f"{m.name}: r_s = {r:g} mm, yield at ω' = {wy * 1000:.4g} µm "
              f"(F = {curve.force_at_yield_ep:.4g} N by eq 2.1, {curve.force_at_yield_hertz:.4g} N by eq 5.19)")]
    for x in results:
        lines.append(f"F = {x.force:g} N: ω = {x.displacement:.4g} mm, height = {x.height:.4g} mm, "
                     f"r_c = {x.contact_radius:.4g} mm (eq 5.23), sqrt(r_s ω/2) = {x.contact_radius_per_contact:.4g} mm")
    _finish(payload, as_json, json_file, lines, (plot_file, lambda path: ct.plot_force_displacement([curve], path)))


# --------------------------------------------------------------------------- shell
@click.command("shell")
@click.option("--outer", "a", type=float, required=True, help="Outer radius a, mm.")
@click.option("--inner", "b", type=float, required=True, help="Inner radius b, mm.")
@click.option("--E", "E", type=float, required=True, help="Young's modulus, MPa.")
@click.option("--nu", type=float, required=True, help="Poisson's ratio.")
@click.option("--p-ext", type=float, required=True, help="Platen pressure on the loaded region, MPa.")
@click.option("--p-int", type=float, default=0.0, show_default=True, help="Internal pressure, MPa.")
@click.option("--psi", type=float, default=90.0, show_default=True, help="Half-angle of the loaded region, degrees.")
@click.option("--region", type=click.Choice(["equator", "poles"]), default="equator", show_default=True)
@click.option("--terms", type=int, default=400, show_default=True, help="Legendre orders kept.")
@click.option("--csv", "csv_file", type=click.Path(path_type=Path), help="u_r(θ) table on both surfaces.")
@click.option("--plot", "plot_file", type=click.Path(path_type=Path), help="u_r(θ) plot (.png/.svg).")
@_with_json
def shell_cmd(a, b, E, nu, p_ext, p_int, psi, region, terms, csv_file, plot_file, as_json, json_file) -> None:
    """Radial displacement of a thick elastic spherical shell (section 6.2.3) by Legendre series."""
    from tabletcad.mechanics.shell import plot_shell, solve_shell

    _check_output("--csv", csv_file, (".csv",))
    _check_output("--plot", plot_file)
    if csv_file is not None and plot_file is not None and csv_file.absolute() == plot_file.absolute():
        raise DesignError("--plot", str(plot_file), "must differ from --csv")
    _check_json_file(json_file, csv=csv_file, plot=plot_file)
    check_range("--terms", terms, 2, 20000)
    for name, v in (("--outer", a), ("--inner", b)):  # lengths within the size limit (1e300 had run: exit 0)
        check_range(name, v, 0.0, DEFAULT.max_length, "mm", lo_open=True)
    check_range("--E", E, 0.0, MAX_MODULUS_MPA, "MPa", lo_open=True)
    if b >= a:
        raise DesignError("--inner", b, f"must be < --outer = {format_bound(a, upper=True)} mm (inner radius below outer)", "mm")
    check_range("--nu", nu, -1.0, 0.5, lo_open=True, hi_open=True)
    check_range("--p-ext", p_ext, -MAX_PRESSURE_MPA, MAX_PRESSURE_MPA, "MPa")
    check_range("--p-int", p_int, -MAX_PRESSURE_MPA, MAX_PRESSURE_MPA, "MPa")
    check_range("--psi", psi, 0, 90, "deg")
    with _collect() as msgs:
        sol = solve_shell(a, b, E, nu, p_ext=p_ext, p_int=p_int, psi=math.radians(check_range("--psi", psi, 0, 90, "deg")),
                          n_terms=terms, region=region)
        th = np.radians(np.linspace(0.0, 180.0, 181))
        ua = sol.radial_displacement(a, th)
        ub = sol.radial_displacement(b, th)
        half = sol.radial_displacement(a, math.pi / 2, n_terms=terms // 2)
        umax = float(max(np.abs(ua).max(), np.abs(ub).max()))
        if umax > 0.05 * (a - b):
            from tabletcad.mechanics.validity import ValidityWarning, warn

            warn(ValidityWarning, f"displacements up to {umax:.3g} mm exceed 5 % of the wall thickness "
                 f"{a - b:.3g} mm: outside linear (small-strain) elasticity")
    eq = float(ua[90])
    payload = {
        "outer_mm": a, "inner_mm": b, "E_MPa": E, "nu": nu, "p_ext_MPa": p_ext, "p_int_MPa": p_int, "psi_deg": psi,
        "region": region, "terms": terms,
        "u_r_outer_mm": {"at_0_deg": float(ua[0]), "at_45_deg": float(ua[45]), "at_90_deg": eq,
                         "min": float(ua.min()), "max": float(ua.max())},
        "u_r_inner_mm": {"at_0_deg": float(ub[0]), "at_90_deg": float(ub[90]), "min": float(ub.min()),
                         "max": float(ub.max())},
        "thickness_change_at_90deg_mm": eq - float(ub[90]),
        "series_change_at_90deg_mm": eq - float(half),
        "warnings": msgs,
    }
    with _staged(csv=csv_file, plot=plot_file, json=json_file) as out:
        if json_file is not None:
            out["json"].write_text(json_text(payload) + "\n", encoding="utf-8")
        if csv_file is not None:
            rows = ["theta_deg,u_r_outer_mm,u_r_inner_mm"] + [f"{d:g},{x:.10g},{y:.10g}" for d, x, y in
                                                            zip(np.degrees(th), ua, ub)]
            out["csv"].write_text("\n".join(rows) + "\n", encoding="utf-8")
        if plot_file is not None:
            plot_shell(sol, out["plot"])
        _emit(payload, as_json, [  # (before the files are moved into place, as in _finish)
            (f"shell a = {a:g} mm, b = {b:g} mm, E = {E:g} MPa, ν = {nu:g}; p_ext = {p_ext:g} MPa over "
             f"{region} ψ = {psi:g}°, p_int = {p_int:g} MPa; {terms} orders"),
            f"u_r(a): θ=0° {ua[0]:.4g} mm, θ=90° {eq:.4g} mm; u_r(b): θ=0° {ub[0]:.4g} mm, θ=90° {ub[90]:.4g} mm",
            f"series change at θ=90° from {terms // 2} to {terms} orders: {eq - half:.3g} mm",
        ] + [f"{option} -> {path}" for option, path in (("json", json_file), ("csv", csv_file), ("plot", plot_file))
             if path is not None and not as_json])


# --------------------------------------------------------------------------- love
#: love's model options: their units, and what a value in the wrong unit looks like
_LOVE_UNITS = {"E": ("MPa", "; Young's modulus in MPa: 2.64 GPa is 2640 MPa"), "nu": ("", ""),
               "h0": ("mm", ""), "z": ("mm", ""), "r": ("mm", "")}


def _given_options(names: tuple[str, ...]) -> list[str]:
    """The parameters among ``names`` that the command line gave (not left at their defaults)."""
    from click.core import ParameterSource

    ctx = click.get_current_context()
    return [n for n in names if ctx.get_parameter_source(n) not in (ParameterSource.DEFAULT, None)]


def _refuse_love_option(pressures: np.ndarray, model: dict[str, Any], given: list[str]) -> None:
    """Refuse the first option given on the command line (``--E``, ``--nu``, ``--h0``, ``--z``, ``--r``)
    whose value lies outside the range where the love model runs with the others, naming it and that range.

    The model's own refusal names what failed in it (``relative_density`` with a hint at a mass the
    command has no option for, ``pressure`` = a point of the default --window): ``--h0 100`` and
    ``--E 2.64`` (GPa typed as MPa) had been refused that way.  Returns when no given option is at
    fault (the caller re-raises the model's refusal).

    Parameters
    ----------
    pressures : ndarray
        The simulated pressures, MPa.
    model : dict
        :func:`tabletcad.mechanics.love.simulate_compression`'s keyword arguments.
    given : list of str
        The model options the command line gave, in the order to blame them.

    Raises
    ------
    DesignError
        ``--<option>`` with its range (:func:`tabletcad.mechanics.love.model_range`).
    """
    from tabletcad.mechanics.love import model_allowed, model_range

    ranges = {name: model_range(name, pressures, **model) for name in given}
    # an option whose range exists but leaves its value out is at fault; one with no range at all (no value works
    # with the others as given) is blamed only when no other option is out of its own range (--z 0.5 --h0 0.6 had
    # blamed --nu = 0.3, the first option tried, where --h0 >= 4.23 mm makes it run)
    for name in sorted(given, key=lambda n: math.isnan(ranges[n][0])):
        lo, hi = ranges[name]
        value = model[name]
        if math.isnan(lo) or not lo <= value <= hi:
            unit, hint = _LOVE_UNITS[name]
            raise DesignError(f"--{name}", value, model_allowed(lo, hi, pressures.size, unit) + hint, unit) from None


@click.command("love")
@click.option("--E", "E", type=float, default=2640.0, show_default=True, help="Young's modulus, MPa.")
@click.option("--nu", type=float, default=0.21, show_default=True, help="Poisson's ratio.")
@click.option("--h0", type=float, default=6.0, show_default=True, help="Initial bed height, mm.")
@click.option("--z", type=float, default=2.9635, show_default=True,
              help="Height above the lower punch where ω_z is taken, mm (default: where eq 5.18 gives the thesis's "
                   "-0.2155 mm at 10 MPa).")
@click.option("--r", type=float, help="Radius where ω_z is taken, mm (default: die wall).")
@click.option("--omega-z0", type=float, help="Adjustment ω_z0, mm (default: the one that matches the thesis's "
                                             "measured -1.2935 mm at 10 MPa).")
@click.option("--window", nargs=2, type=float, default=(10.0, 50.0), show_default=True, metavar="LO HI",
              help="Simulated pressure range, MPa.")
@_with_json
def love_cmd(E, nu, h0, z, r, omega_z0, window, as_json, json_file) -> None:
    """Simulated die compression with the thesis's eq 5.18 and its Heckel fit (thesis defaults)."""
    from tabletcad.mechanics.love import THESIS_DIAMETER, simulate_compression

    _check_json_file(json_file)
    lo, hi = window
    if not (math.isfinite(hi) and 0 < lo < hi <= MAX_PRESSURE_MPA):
        raise DesignError("--window", window, f"must be two increasing positive pressures up to {MAX_PRESSURE_MPA:g}",
                          "MPa")
    # every option is checked here, by its own name, before the model runs
    check_range("--E", E, 0.0, MAX_MODULUS_MPA, "MPa", lo_open=True)
    check_range("--nu", nu, 0.0, 0.5, hi_open=True)
    check_range("--h0", h0, 0.0, DEFAULT.max_length, "mm", lo_open=True)  # a length, as every other (6000 had
    # been refused as a relative density)
    given = _given_options(("E", "nu", "h0", "z", "r"))
    if "z" not in given and z > h0:  # the default z names the bed's height, which the user chose
        raise DesignError("--h0", h0, f"must be >= {z:g} mm, the default --z (the height where ω_z is taken lies "
                          "within the bed; or give a lower --z)", "mm")
    check_range("--z", z, 0.0, h0, "mm")  # a height within the bed (above it, eq 5.18 gave K = -0.015 1/MPa)
    if r is not None:  # a radius within the die (the model's own check named it r)
        check_range("--r", r, DEFAULT.min_length, THESIS_DIAMETER / 2.0, "mm")  # (1e-300 had divided by 0)
    if omega_z0 is not None:  # a shift of the punch face by more than the bed's height: 1e300 mm had been
        # refused as a relative density; within it, where the model runs (-5.9 mm in a 6 mm bed had been
        # offered by "must be >= -6 and <= 6 mm", then refused as a bed pressed to nothing)
        from tabletcad.mechanics.love import omega_z0_allowed, omega_z0_range

        w_lo, w_hi = omega_z0_range(np.linspace(lo, hi, 41), E=E, nu=nu, h0=h0, z=z, r=r)
        if not math.isnan(w_lo):
            w_lo, w_hi = max(w_lo, -h0), min(w_hi, h0)  # (a closed end at -h0, else open: the bed's collapse)
            if not w_lo < w_hi:
                w_lo = w_hi = math.nan
        w0 = check_finite("--omega-z0", omega_z0, "mm")
        if not (w_lo < w0 or w0 == w_lo == -h0) or not w0 <= w_hi:  # (nan: nothing works)
            raise DesignError("--omega-z0", omega_z0, omega_z0_allowed(w_lo, w_hi, 41, cap=h0), "mm")
    # the model's refusal of a bed pressed to nothing names its keyword; here the option
    model = {"E": E, "nu": nu, "h0": h0, "z": z, "r": r, "omega_z0": omega_z0}
    with _collect() as msgs, option_names({"omega_z0": "--omega-z0", "pressure": "--window", "window": "--window"}):
        try:
            sim = simulate_compression(np.linspace(lo, hi, 41), **model)
        except DesignError:
            _refuse_love_option(np.linspace(lo, hi, 41), model, given)
            raise
    f = sim.heckel
    payload = {"K_per_MPa": f.K_per_MPa, "A": f.A, "Py_MPa": f.Py_MPa, "r2": f.r2, "window_MPa": list(f.window_MPa),
               "n_points": f.n_points, "omega_z0_mm": sim.omega_z0, "assumptions": sim.assumptions, "warnings": msgs}
    _finish(payload, as_json, json_file, [
        (f"ω_z0 = {sim.omega_z0:.4g} mm; K = {f.K_per_MPa:.4g} 1/MPa, A = {f.A:.4g}, Py = {f.Py_MPa:.4g} MPa, "
         f"R² = {f.r2:.4f} over {lo:g}-{hi:g} MPa")])


COMMANDS = [heckel_cmd, kawakita_cmd, walker_cmd, profiles_cmd, strength_cmd, contact_cmd, shell_cmd, love_cmd]
