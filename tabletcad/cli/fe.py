"""Finite-element commands: ``tabletcad fe diametral``, ``fe strength`` and ``fe punch``.

Units: mm, N (kN where named), MPa.  Everything is computed before any file
is written; bad input is one ``error:`` line and exit status 2 (see
:func:`tabletcad.cli.main`), and leaves nothing behind.  Needs the ``fe``
extra (scikit-fem, gmsh) and the ``cad`` extra.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import click

from tabletcad.cli.options import option_names
from tabletcad.cli.outputs import out_folder
from tabletcad.io.jsontext import json_text
from tabletcad.errors import MISSING, DesignError, check_range
from tabletcad.tolerance import (MAX_EFFECTIVE_LENGTH_FACTOR, MAX_MODULUS_MPA, MAX_YIELD_MPA, MIN_FORCE_N,
                                 MIN_PUNCH_MODULUS_MPA, MIN_YIELD_MPA)

__all__ = ["COMMANDS"]


def _require_fe() -> None:
    try:
        import gmsh  # noqa: F401
        import skfem  # noqa: F401
    except ImportError as exc:  # pragma: no cover - the fe extra is installed in CI
        raise DesignError("tabletcad fe", exc.name, "needs the fe extra: pip install 'tabletcad[fe]'") from None


def _echo(payload: dict[str, Any], as_json: bool, lines: list[str], json_file: Path | None = None,
          outputs: tuple[Path, Any, dict] | None = None) -> None:
    """Write ``--json-file`` and, with ``outputs`` (``--out``, the solution, the section's arguments),
    ``stress.vtu`` and ``section.png`` (:func:`_write_outputs`), print the JSON or the lines, and only then
    move the files into place: a refused standard output (a full disk) leaves none of them (it had left the
    folder's and the JSON file, exit 2)."""
    import contextlib

    from tabletcad.cli.outputs import staged

    with staged(json=json_file) as out, contextlib.ExitStack() as publishing:
        if json_file is not None:
            out["json"].write_text(json_text(payload) + "\n", encoding="utf-8")
        if outputs is not None:
            publishing.enter_context(_write_outputs(*outputs))
        if as_json:
            click.echo(json_text(payload))
        else:
            for ln in lines + ([f"json -> {json_file}"] if json_file is not None else []):
                click.echo(ln)


#: what ``--out`` of ``tabletcad fe diametral/punch`` holds
FE_FILES = ("stress.vtu", "section.png")


def _check_out(out: Path | None) -> None:
    """Refuse, before any solve, an ``--out`` folder holding a file of :data:`FE_FILES` that no earlier
    FE run wrote there or that was edited since (a run owns exactly the files it writes)."""
    if out is not None:
        from tabletcad.io.outputs import FE_MANIFEST, check_replaceable

        check_replaceable(out, FE_FILES, manifest=FE_MANIFEST)


def _out_files(out: Path) -> list[str]:
    """The paths of :data:`FE_FILES` in ``out``."""
    return [str(out / n) for n in FE_FILES]


@contextlib.contextmanager
def _write_outputs(out: Path, solution, section: dict) -> Iterator[None]:
    """``stress.vtu`` and ``section.png`` written to a staging folder and, when the block succeeds, moved
    into ``out`` together, recorded in its FE manifest."""
    from tabletcad.fe.output import plot_section, write_vtu
    from tabletcad.io.outputs import FE_MANIFEST, publish, staging_folder

    with staging_folder(out) as staging:
        write_vtu(solution, staging / "stress.vtu")
        plot_section(solution, staging / "section.png", **section)
        yield
        publish(staging, out, FE_MANIFEST)


def _check_json_file(json_file: Path | None) -> None:
    from tabletcad.cli.outputs import check_output

    check_output("--json-file", json_file, (".json",))


def _finished(design, tablet) -> tuple[Any, str]:
    """``(solid, what)``: the finished (scored, embossed) tablet's B-rep when the design's ``[tooling]``
    scores or embosses it (:func:`tabletcad.tooling.toolset.finished_solid`), else None (the FE
    builds the plain tablet's); ``what`` says which tablet is meshed: ``"finished"`` or ``"plain"``."""
    spec = getattr(design, "tooling_spec", None)
    if spec is None or not (spec.scores or spec.emboss):
        return None, "plain"
    from tabletcad.tooling.toolset import finished_solid

    return finished_solid(tablet, spec)[0], "finished"


# the keyword names tabletcad.fe's functions give their arguments, and the options that set them
OPTION_NAMES = {"force": "--force", "direction": "--direction", "strip_width": "--strip-width",
                "mesh_size": "--mesh-size", "E": "--E", "nu": "--nu"}


class _FEGroup(click.Group):
    """The ``fe`` group: a refusal of an argument the command line set names the option."""

    def invoke(self, ctx: click.Context) -> Any:
        with option_names(OPTION_NAMES):
            return super().invoke(ctx)


@click.group("fe", cls=_FEGroup)
def fe_group() -> None:
    """Finite-element stresses on the real shape (scikit-fem, quadratic tetrahedra; gmsh meshes)."""


@fe_group.command("diametral")
@click.argument("design", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--force", type=float, required=True, help="Force on each platen, N.")
@click.option("--direction", default="width", show_default=True,
              help="Load direction in plan: width|length|x|y (round tablets: any gives x unless y).")
@click.option("--strip-width", type=float, default=None, help="Width of each loaded strip, mm [default: D/10].")
@click.option("--mesh-size", type=float, default=None,
              help="Element size away from the strips, mm [default: min(t/2, plan extent/12)].")
@click.option("--E", "E", type=float, default=5000.0, show_default=True, help="Young's modulus, MPa (stresses do not depend on it).")
@click.option("--nu", type=float, default=0.3, show_default=True, help="Poisson's ratio.")
@click.option("--no-error-estimate", is_flag=True, help="Skip the second (coarser) mesh of the error estimate.")
@click.option("--out", type=out_folder(), default=None,
              help="Folder for stress.vtu and section.png (tensile stress on the mid-thickness section).")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON on stdout.")
@click.option("--json-file", type=click.Path(path_type=Path), default=None, help="Write the result as JSON to this file.")
def diametral_cmd(design: Path, force: float, direction: str, strip_width: float | None, mesh_size: float | None,
                  E: float, nu: float, no_error_estimate: bool, out: Path | None, as_json: bool,
                  json_file: Path | None) -> None:
    """Diametral compression of DESIGN.toml by FE: centre and largest tensile stress, shape factor."""
    from tabletcad.cli.report import load_family_design
    from tabletcad.fe.diametral import DIRECTIONS

    check_range("--force", force, MIN_FORCE_N, 1e9, "N")  # the whole range, as diametral states it
    if direction not in DIRECTIONS:
        raise DesignError("--direction", direction, "must be one of " + ", ".join(DIRECTIONS))
    _check_json_file(json_file)
    _check_out(out)
    _require_fe()
    from tabletcad.fe.diametral import diametral
    from tabletcad.fe.elasticity import Material

    material = Material(E=E, nu=nu)
    tablet, spec = load_family_design(design)
    solid, meshed = _finished(spec, tablet)
    res = diametral(tablet, force, direction, strip_width=strip_width, mesh_size=mesh_size, material=material,
                    error_estimate=not no_error_estimate, solid=solid)
    payload = {"design": str(design), "tablet_meshed": meshed, **res.to_dict()}
    files: list[str] = []
    outputs = None
    if out is not None:
        ax = "xy".index(res.axis)
        px = 1 - ax
        s = res.centre_tensile_stress_MPa
        outputs = (out, res.solution, dict(
            axis=2, level=res.centre_mm[2], component=(px, px),
            title=f"{tablet.name}: σ_{'xy'[px]}{'xy'[px]} at mid-thickness, {force:g} N along {res.axis}",
            label=f"σ_{'xy'[px]}{'xy'[px]} (MPa)", limits=(-3.0 * abs(s), 3.0 * abs(s))))
        files = payload["files"] = _out_files(out)
    err = res.discretisation_error_MPa
    _echo(payload, as_json, [
        f"{tablet.name}: {force:g} N along {res.axis} ({direction}), strip {res.strip_width_mm:.4g} mm, "
        f"D = {res.diameter_mm:.4g} mm, t = {res.thickness_mm:.4g} mm",
        f"mesh of the {meshed} tablet: {res.nodes} nodes, {res.elements} quadratic tetrahedra, {res.dofs} unknowns "
        f"(size {res.mesh_size_mm:.3g} mm)",
        f"centre tensile stress {res.centre_tensile_stress_MPa:.4g} MPa"
        + (f" (± {abs(err):.2g} MPa estimated)" if err is not None else ""),
        f"2P/(πDt) = {res.line_load_MPa:.4g} MPa, shape factor {res.shape_factor:.4f}",
        f"largest tensile stress {res.max_tensile_stress_MPa:.4g} MPa at "
        + "(" + ", ".join(f"{v:.3g}" for v in res.max_tensile_location_mm) + ") mm",
    ] + [f"-> {f}" for f in files], json_file=json_file, outputs=outputs)


#: ``fe strength``'s inputs: the design file's ``[report]`` key (as a refusal names it) and the option for it
_STRENGTH_OPTIONS = {"report.tensile_strength_MPa": "--tensile-strength",
                     "report.reference_breaking_force_N": "--reference-force",
                     "report.reference_diameter_mm": "--reference-diameter",
                     "report.reference_thickness_mm": "--reference-thickness"}
_REFERENCE_OPTIONS = "--reference-force (N), --reference-diameter and --reference-thickness (mm)"


def _refuse_missing_strength(exc: DesignError, given: dict[str, str]) -> None:
    """Refuse a strength input that is missing by the name the command line gives it.

    :class:`~tabletcad.fe.prediction.StrengthInputs` names the design file's ``[report]`` keys
    (``report.tensile_strength_MPa = (not given) ... reference_breaking_force_N``); ``fe strength``
    takes them as options too, which a new user's trial had not been told of.  With no input at all,
    ``--tensile-strength`` is named with the reference options and, as the alternative, the keys; a
    reference test begun with options names the option it lacks; one begun in the file names the key
    and its option.  Returns (the caller re-raises) for any other refusal.

    Parameters
    ----------
    exc : DesignError
        The refusal of :meth:`StrengthInputs.from_table`.
    given : dict of str to str
        The ``[report]`` keys the command line gave, to their options.

    Raises
    ------
    DesignError
        The missing input, named as above.
    """
    if exc.value != MISSING or exc.parameter not in _STRENGTH_OPTIONS:
        return
    option = _STRENGTH_OPTIONS[exc.parameter]
    if option == "--tensile-strength":
        raise DesignError(option, MISSING, f"give it (MPa), or all of {_REFERENCE_OPTIONS} of a flat-faced round "
                          "reference compact; or in DESIGN's [report] table tensile_strength_MPa, or all of "
                          "reference_breaking_force_N, reference_diameter_mm and reference_thickness_mm") from None
    if given:  # a reference test begun on the command line
        raise DesignError(option, MISSING, f"the reference test needs all of {_REFERENCE_OPTIONS} (or give "
                          "--tensile-strength instead)") from None
    raise DesignError(exc.parameter, MISSING, f"{exc.allowed}; or give it as {option}") from None


@fe_group.command("strength")
@click.argument("design", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--tensile-strength", type=float, default=None, help="Tensile strength of the material, MPa.")
@click.option("--reference-force", type=float, default=None,
              help="Breaking force of a flat-faced round reference compact (same material, solid fraction), N.")
@click.option("--reference-diameter", type=float, default=None, help="Reference compact diameter, mm.")
@click.option("--reference-thickness", type=float, default=None, help="Reference compact thickness, mm.")
@click.option("--direction", default="width", show_default=True, help="Load direction in plan: width|length|x|y.")
@click.option("--mesh-size", type=float, default=None, help="Element size, mm [default as fe diametral].")
@click.option("--coarse", is_flag=True, help="The optimiser's coarse mesh (as the design report's FE breaking force, which is the plain "
                   "tablet's for a scored or embossed design).")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON on stdout.")
@click.option("--json-file", type=click.Path(path_type=Path), default=None, help="Write the result as JSON to this file.")
def strength_cmd(design: Path, tensile_strength: float | None, reference_force: float | None,
                 reference_diameter: float | None, reference_thickness: float | None, direction: str,
                 mesh_size: float | None, as_json: bool, json_file: Path | None, coarse: bool = False) -> None:
    """Breaking force of DESIGN.toml predicted by FE (elastic first-crack estimate).

    Inputs from the options or the design file's [report] table: tensile_strength_MPa, or
    reference_breaking_force_N, reference_diameter_mm and reference_thickness_mm.
    """
    from tabletcad.cli.report import load_family_design
    from tabletcad.fe.diametral import DIRECTIONS

    if direction not in DIRECTIONS:
        raise DesignError("--direction", direction, "must be one of " + ", ".join(DIRECTIONS))
    if coarse and mesh_size is not None:
        raise DesignError("--mesh-size", mesh_size, "give either --mesh-size or --coarse", "mm")
    _check_json_file(json_file)
    _require_fe()
    from tabletcad.fe.objective import coarse_prediction
    from tabletcad.fe.prediction import StrengthInputs, predict_breaking_force

    tablet, spec = load_family_design(design)
    given = {f"report.{k}": o for k, o, v in (
        ("tensile_strength_MPa", "--tensile-strength", tensile_strength),
        ("reference_breaking_force_N", "--reference-force", reference_force),
        ("reference_diameter_mm", "--reference-diameter", reference_diameter),
        ("reference_thickness_mm", "--reference-thickness", reference_thickness)) if v is not None}
    with option_names(given):  # an option given overrides the design's [report] key: named as given
        try:  # before the finished tablet is built: a missing input is refused at once
            inputs = StrengthInputs.from_table(spec.report, tensile_strength_MPa=tensile_strength,
                                               reference_breaking_force_N=reference_force,
                                               reference_diameter_mm=reference_diameter,
                                               reference_thickness_mm=reference_thickness)
        except DesignError as exc:
            _refuse_missing_strength(exc, given)
            raise
        solid, meshed = _finished(spec, tablet)
        pred = (coarse_prediction(tablet, inputs, direction, solid=solid) if coarse
                else predict_breaking_force(tablet, inputs, direction, solid=solid, mesh_size=mesh_size,
                                            error_estimate=False))
    d = pred.to_dict()
    _echo({"design": str(design), "tablet_meshed": meshed, **d}, as_json, [
        f"{tablet.name}: predicted breaking force {pred.breaking_force_N:.4g} N across {direction} "
        f"(elastic first-crack estimate; {pred.breaking_force_centre_N:.4g} N if the crack starts at the centre)",
        f"tensile strength {pred.tensile_strength_MPa:.4g} MPa ({pred.tensile_strength_basis})",
        f"largest tensile stress {pred.max_tensile_per_N:.4g} MPa per N at "
        + "(" + ", ".join(f"{v:.3g}" for v in d["first_crack_location_mm"]) + ") mm; shape factor "
        f"{d['shape_factor']:.4f}",
        f"meshed: the {meshed} tablet",
    ], json_file=json_file)


@fe_group.command("punch")
@click.argument("design", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--force", type=float, required=True, help="Compaction force, kN.")
@click.option("--punch", "which", type=click.Choice(["upper", "lower"]), default="upper", show_default=True)
@click.option("--steel", default=None, help="Tool steel from tabletcad/data/tool_steels.toml (yield stress and E).")
@click.option("--yield-stress", type=float, default=None, help="Steel yield stress, MPa, 100-10000 (instead of --steel).")
@click.option("--E", "E", type=float, default=None, help="Steel Young's modulus, MPa, 5e4-1e7 [default: the steel's, else 206000].")
@click.option("--safety-factor", type=float, default=1.5, show_default=True)
@click.option("--effective-length-factor", type=float, default=2.0, show_default=True,
              help="Buckling: K of the tip column (2 = fixed at the barrel, free at the tip).")
@click.option("--mesh-size", type=float, default=None, help="Element size, mm [default: tip width/8].")
@click.option("--out", type=out_folder(), default=None,
              help="Folder for stress.vtu and section.png (von Mises stress on the tip's axial section).")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON on stdout.")
@click.option("--json-file", type=click.Path(path_type=Path), default=None, help="Write the result as JSON to this file.")
def punch_cmd(design: Path, force: float, which: str, steel: str | None, yield_stress: float | None, E: float | None,
              safety_factor: float, effective_length_factor: float, mesh_size: float | None, out: Path | None,
              as_json: bool, json_file: Path | None) -> None:
    """Punch-tip stress under the compaction force spread over the cup, and the allowed force."""
    from tabletcad.cli.report import load_family_design
    from tabletcad.errors import check_positive, check_range

    check_range("--force", force, MIN_FORCE_N / 1000.0, 1e6, "kN")  # the whole range, as punch_stress states it
    check_range("--safety-factor", safety_factor, 1.0, 100.0)  # as [tooling.fe_rating] safety_factor
    check_range("--effective-length-factor", effective_length_factor, 0.0, MAX_EFFECTIVE_LENGTH_FACTOR, lo_open=True)
    if yield_stress is not None:
        check_range("--yield-stress", yield_stress, MIN_YIELD_MPA, MAX_YIELD_MPA, "MPa")  # a steel's, in MPa
    if E is not None:  # a punch steel's, in MPa, as [tooling] punch_youngs_modulus_MPa (210 for 210 GPa had rated
        # the tip's buckling a thousand times too low, and 1e300 had been taken)
        check_range("--E", E, MIN_PUNCH_MODULUS_MPA, MAX_MODULUS_MPA, "MPa")
    _check_json_file(json_file)
    _check_out(out)
    from tabletcad.fe.punch import tool_steels

    steels = tool_steels()
    if steel is not None and yield_stress is not None:
        raise DesignError("--yield-stress", yield_stress, "give either --steel or --yield-stress, not both", "MPa")
    if steel is not None:
        if steel not in steels:
            raise DesignError("--steel", steel, "must be one of " + ", ".join(steels))
        yield_stress = steels[steel].yield_MPa
        E = steels[steel].E_MPa if E is None else E
    if yield_stress is None:
        raise DesignError("--yield-stress", MISSING, "give --yield-stress (MPa) or --steel " + "|".join(steels)
                          + ": no rating is invented")
    check_positive("--yield-stress", yield_stress, "MPa")
    E = 206000.0 if E is None else check_positive("--E", E, "MPa")
    _require_fe()
    from tabletcad.fe.punch import punch_stress, punch_tip_solid

    tablet, spec = load_family_design(design)
    import warnings

    # the tip's warnings (no land, ...) are shown once the solve has taken its inputs: a refusal stays one line
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        shape, tip = punch_tip_solid(tablet, spec.tooling_spec, which)
        res = punch_stress(shape, tip, force, which, yield_MPa=yield_stress, safety_factor=safety_factor, E=E,
                           mesh_size=mesh_size, effective_length_factor=effective_length_factor)
    for w in said:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    if force > res.allowed_force_kN:  # e.g. a force in N given as kN
        from tabletcad.cli import say_warning

        say_warning(f"--force {force:g} kN is {force / res.allowed_force_kN:.3g} times the allowed force "
                    f"({res.allowed_force_kN:.4g} kN): the tip would yield or buckle (--force is in kN)")
    payload = {"design": str(design), "steel": steel, **res.to_dict()}
    files: list[str] = []
    outputs = None
    if out is not None:
        outputs = (out, res.solution, dict(
            axis=1, level=float(res.solution.mesh.p[1].mean()), component="von_mises",
            title=f"{tablet.name}: {which} punch tip, von Mises stress at {force:g} kN", label="von Mises stress (MPa)"))
        files = payload["files"] = _out_files(out)
    b = res.buckling
    _echo(payload, as_json, [
        f"{tablet.name}: {which} punch tip, {force:g} kN over the cup face ({res.loaded_area_mm2:.4g} mm2)",
        f"mesh: {res.nodes} nodes, {res.elements} quadratic tetrahedra, {res.dofs} unknowns",
        f"largest von Mises stress {res.max_von_mises_MPa:.4g} MPa at ("
        + ", ".join(f"{v:.3g}" for v in res.max_von_mises_location_mm) + f") mm; F/A = {res.uniform_stress_MPa:.4g} MPa",
        f"allowed force {res.allowed_force_kN:.4g} kN (yield {yield_stress:g} MPa / {safety_factor:g}"
        + (f"; {b['method']} buckling {b['critical_force_kN']:.4g} kN at slenderness {b['slenderness']:.3g}" if b else "")
        + ")",
    ] + [f"-> {f}" for f in files], json_file=json_file, outputs=outputs)


COMMANDS = [fe_group]
