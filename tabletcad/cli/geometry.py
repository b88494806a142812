"""Geometry commands: ``shapes``, ``build``, ``mesh``, ``report``."""

from __future__ import annotations

import json
from pathlib import Path

import click

from tabletcad.errors import DesignError

__all__ = ["COMMANDS"]


@click.command("shapes")
@click.option("--json", "as_json", is_flag=True, help="Print the families as JSON.")
def shapes_cmd(as_json: bool) -> None:
    """List the tablet families and their parameters (with units and defaults)."""
    from tabletcad.shapes import FAMILIES, _load_plugins

    _load_plugins()
    if as_json:
        click.echo(json.dumps({n: dict(params=f.params, defaults=f.defaults, doc=f.doc) for n, f in FAMILIES.items()}, indent=2))
        return
    for name, fam in FAMILIES.items():
        args = ", ".join(f"{k} [{u}] = {fam.defaults[k]:g}" for k, u in fam.params.items())
        click.echo(f"{name:22s} {args}")
        click.echo(f"{'':22s} {fam.doc}")
    click.echo(f"{'free_form':22s} [[patch]] tables of 4 curves each (see README: design files)")


@click.command("build")
@click.argument("design", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--out", "out_dir", required=True, type=click.Path(file_okay=False, path_type=Path), help="Output folder.")
@click.option("--quiet", is_flag=True, help="No progress display.")
def build_cmd(design: Path, out_dir: Path, quiet: bool) -> None:
    """Build DESIGN.toml: report.json, tablet.png and CAD files in OUT."""
    from tabletcad.build import build_design

    rep = build_design(design, out_dir, progress=not quiet)
    written = rep["outputs"]  # this build's files only (the folder may hold files tabletcad did not write)
    click.echo(
        f"{rep['design']['name']}: volume {rep['volume_mm3']:.6g} mm3, area {rep['surface_area_mm2']:.6g} mm2, "
        f"{rep['length_mm']:.4g} x {rep['width_mm']:.4g} x {rep['height_mm']:.4g} mm -> {out_dir}/ ({', '.join(written)})"
    )


@click.command("mesh")
@click.argument("design", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--nodes", nargs=3, type=int, required=True, metavar="SX SY SZ", help="Nodes along u, v and w per patch.")
@click.option("--out", "out_file", required=True, type=click.Path(dir_okay=False, path_type=Path), help="Mesh file (.vtu, .xdmf, .msh, .vtk).")
def mesh_cmd(design: Path, nodes: tuple[int, int, int], out_file: Path) -> None:
    """Hexahedral solid mesh of DESIGN.toml (thesis section 4.3)."""
    from tabletcad.design import load_design
    from tabletcad.solid import hex_mesh, mesh_volume, write_mesh

    for name, n in zip(("--nodes SX", "--nodes SY", "--nodes SZ"), nodes):
        if n < 2 or n > 2000:
            raise DesignError(name, n, "must be an integer from 2 to 2000")
    suffix = out_file.suffix.lower()
    if suffix not in (".vtu", ".xdmf", ".msh", ".vtk"):
        raise DesignError("--out suffix", suffix or "(none)", "must be .vtu, .xdmf, .msh or .vtk")
    tablet = load_design(design)
    mesh = hex_mesh(tablet, nodes=nodes)
    write_mesh(mesh, out_file)
    counts = ", ".join(f"{len(c)} {k}" for k, c in mesh.cells.items() if len(c))
    click.echo(f"{out_file}: {len(mesh.points)} nodes, {counts}; mesh volume {mesh_volume(mesh):.6g} mm3")


COMMANDS = [shapes_cmd, build_cmd, mesh_cmd]
