"""Finite-element commands: ``tabletcad fe diametral`` (and ``fe punch``).

Units: mm, N (kN where named), MPa.  Everything is computed before any file
is written; bad input is one ``error:`` line and exit status 2 (see
:func:`tabletcad.cli.main`), and leaves nothing behind.  Needs the ``fe``
extra (scikit-fem, gmsh) and the ``cad`` extra.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import click

from tabletcad.errors import DesignError

__all__ = ["COMMANDS"]


def _require_fe() -> None:
    try:
        import gmsh  # noqa: F401
        import skfem  # noqa: F401
    except ImportError as exc:  # pragma: no cover - the fe extra is installed in CI
        raise DesignError("tabletcad fe", exc.name, "needs the fe extra: pip install 'tabletcad[fe]'") from None


def _echo(payload: dict[str, Any], as_json: bool, lines: list[str]) -> None:
    if as_json:
        click.echo(json.dumps(payload, indent=2))
    else:
        for ln in lines:
            click.echo(ln)


def _check_out(out: Path | None) -> None:
    if out is not None and out.exists() and not out.is_dir():
        raise DesignError("--out", str(out), "must be a folder (it is a file)")


@click.group("fe")
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
@click.option("--out", type=click.Path(file_okay=True, path_type=Path), default=None,
              help="Folder for stress.vtu and section.png (tensile stress on the mid-thickness section).")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
def diametral_cmd(design: Path, force: float, direction: str, strip_width: float | None, mesh_size: float | None,
                  E: float, nu: float, no_error_estimate: bool, out: Path | None, as_json: bool) -> None:
    """Diametral compression of DESIGN.toml by FE: centre and largest tensile stress, shape factor."""
    from tabletcad.cli.report import load_family_design
    from tabletcad.errors import check_positive
    from tabletcad.fe.diametral import DIRECTIONS

    check_positive("--force", force, "N")
    if direction not in DIRECTIONS:
        raise DesignError("--direction", direction, "must be one of " + ", ".join(DIRECTIONS))
    _check_out(out)
    _require_fe()
    from tabletcad.fe.diametral import diametral
    from tabletcad.fe.elasticity import Material

    material = Material(E=E, nu=nu)
    tablet, _ = load_family_design(design)
    res = diametral(tablet, force, direction, strip_width=strip_width, mesh_size=mesh_size, material=material,
                    error_estimate=not no_error_estimate)
    payload = {"design": str(design), **res.to_dict()}
    files: list[str] = []
    if out is not None:
        from tabletcad.fe.output import plot_section, write_vtu

        ax = "xy".index(res.axis)
        px = 1 - ax
        s = res.centre_tensile_stress_MPa
        try:
            files.append(str(write_vtu(res.solution, out / "stress.vtu")))
            files.append(str(plot_section(
                res.solution, out / "section.png", axis=2, level=res.centre_mm[2], component=(px, px),
                title=f"{tablet.name}: σ_{'xy'[px]}{'xy'[px]} at mid-thickness, {force:g} N along {res.axis}",
                label=f"σ_{'xy'[px]}{'xy'[px]} (MPa)", limits=(-3.0 * abs(s), 3.0 * abs(s)))))
        except BaseException:
            for f in files:
                Path(f).unlink(missing_ok=True)
            raise
        payload["files"] = files
    err = res.discretisation_error_MPa
    _echo(payload, as_json, [
        f"{tablet.name}: {force:g} N along {res.axis} ({direction}), strip {res.strip_width_mm:.4g} mm, "
        f"D = {res.diameter_mm:.4g} mm, t = {res.thickness_mm:.4g} mm",
        f"mesh: {res.nodes} nodes, {res.elements} quadratic tetrahedra, {res.dofs} unknowns (size {res.mesh_size_mm:.3g} mm)",
        f"centre tensile stress {res.centre_tensile_stress_MPa:.5g} MPa"
        + (f" (± {abs(err):.2g} MPa estimated)" if err is not None else ""),
        f"2P/(πDt) = {res.line_load_MPa:.5g} MPa, shape factor {res.shape_factor:.4f}",
        f"largest tensile stress {res.max_tensile_stress_MPa:.5g} MPa at "
        + "(" + ", ".join(f"{v:.3g}" for v in res.max_tensile_location_mm) + ") mm",
    ] + [f"-> {f}" for f in files])


COMMANDS = [fe_group]
