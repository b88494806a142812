"""Geometry commands: ``shapes``, ``build``, ``mesh``, ``report``."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import click

from tabletcad.cli.outputs import out_folder
from tabletcad.errors import DesignError
from tabletcad.tolerance import DEFAULT, Tolerances

__all__ = ["COMMANDS"]


#: the designs of any shape, in ``shapes --json`` as the families are (their keys: tabletcad.pipeline.design)
_ANY_SHAPE = {
    "custom_outline": dict(
        params={"outline": "points", "segments": "lines and arcs", "band": "mm", "cup_depth": "mm", "land": "mm",
                "cup_width": "mm", "central_radius": "mm", "edge_radius": "mm"},
        required=["outline", "band", "cup_depth"], optional=["segments", "land", "cup_width", "central_radius",
                                                            "edge_radius"],
        alternatives={"outline": "segments"},
        defaults={"outline": None, "segments": None, "band": None, "cup_depth": None, "land": 0.0, "cup_width": 0.0,
                  "central_radius": 0.0, "edge_radius": 0.0},
        description="Any closed plan outline, given as [x, y] points (a spline through them) or as segments "
                    "([\"line\", [x0, y0], [x1, y1]] or [\"arc\", [cx, cy], r, theta0, sweep], angles in rad), with "
                    "a cup swept over it (see README: design files)."),
    "free_form": dict(
        params={"patch": "[[patch]] tables of 4 curves each"}, required=["patch"], optional=[], alternatives={},
        defaults={"patch": None},
        description="PDE patches through boundary curves of your own, one [[patch]] table of 4 curves each "
                    "(see README: design files)."),
}


@click.command("shapes")
@click.option("--json", "as_json", is_flag=True, help="Print the families as JSON on stdout.")
@click.option("--json-file", type=click.Path(path_type=Path), help="Write the families as JSON to this file.")
def shapes_cmd(as_json: bool, json_file: Path | None) -> None:
    """List the tablet families: required and optional parameters (units, defaults) and what each is."""
    import textwrap

    from tabletcad.cli.outputs import check_output, staged
    from tabletcad.families import FAMILIES, INDUSTRY_FAMILIES, THESIS_FAMILIES

    check_output("--json-file", json_file, (".json",))
    if as_json or json_file is not None:
        # a required parameter has no default: its constructor's value is only an example
        text = json.dumps({n: dict(params=f.params, required=list(f.required),
                                   optional=[k for k in f.params if k not in f.required],
                                   alternatives=dict(f.alternatives),  # a required one another may replace
                                   defaults={k: (None if k in f.required else v) for k, v in f.defaults.items()},
                                   description=f.description)
                           for n, f in FAMILIES.items()} | _ANY_SHAPE, indent=2)
        with staged(json=json_file) as out:
            if json_file is not None:
                out["json"].write_text(text + "\n", encoding="utf-8")
        if as_json:
            click.echo(text)
            return
        if json_file is not None:
            click.echo(f"json -> {json_file}")
            return
    w = max(map(len, FAMILIES)) + 1
    heads = {INDUSTRY_FAMILIES[0]: "Industry families (exact nominal shapes, certified PDE patches):",
             THESIS_FAMILIES[0]: "The thesis's shapes (PDE patches through the thesis's curves, Tables 4.1 and 4.5):"}
    for name, fam in FAMILIES.items():
        if name in heads:
            click.echo(("" if name == INDUSTRY_FAMILIES[0] else "\n") + heads[name])
        req = ", ".join(f"{k} [{fam.params[k]}]" + (f" (or {fam.alternatives[k]})" if k in fam.alternatives else "")
                        for k in fam.required)
        opt = ", ".join(f"{k} [{u}] = {fam.defaults[k]:g}" for k, u in fam.params.items() if k not in fam.required)
        click.echo(f"{name:{w}s} required: {req}" + (f"; optional: {opt}" if opt else ""))
        click.echo(textwrap.fill(fam.description, width=100, initial_indent=" " * (w + 1), subsequent_indent=" " * (w + 1)))
    click.echo("\nDesigns of any shape:")
    click.echo(f"{'custom_outline':{w}s} required: outline [mm] (points) or segments (lines and arcs), band [mm], "
               "cup_depth [mm]; optional: land, cup_width, central_radius, edge_radius [mm] = 0 (see README: design files)")
    click.echo(f"{'free_form':{w}s} required: [[patch]] tables of 4 curves each (see README: design files)")
    click.echo(f"{'':{w}s} every design may also give the smoothing parameter a (default 1, or the thesis "
               "shape's own; 0.01 for the industry families, which a larger a can take beyond their 1 µm certificate; "
               "\"auto\" chooses it)")


@click.command("build")
@click.argument("design", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--out", "out_dir", required=True, type=out_folder(), help="Output folder.")
@click.option("--quiet", is_flag=True, help="No progress display.")
def build_cmd(design: Path, out_dir: Path, quiet: bool) -> None:
    """Build DESIGN.toml: report.json, tablet.png and CAD files in OUT."""
    from tabletcad.cli.report import nominal_note
    from tabletcad.collector import fewer_full_collections

    def announce(rep: dict) -> None:  # printed before the files are put in place: a refused standard output
        # (a full disk) leaves the folder as it was (it had left the whole build, exit 2)
        written = rep["outputs"]  # this build's files only (the folder may hold files tabletcad did not write)
        d = rep["design"]
        size = f"{rep['length_mm']:.4g} x {rep['width_mm']:.4g} x {rep['height_mm']:.4g} mm"
        click.echo(
            f"{d['name']}: volume {rep['volume_mm3']:.4g} mm3, area {rep['surface_area_mm2']:.4g} mm2, {size}"
            f"{nominal_note(d['family'], d['params'], rep['length_mm'], rep['width_mm'], rep['height_mm'])}"
            f"{_finished_note(rep)} -> {out_dir}/ ({', '.join(written)})"
        )

    with fewer_full_collections():  # the build's imports and its work (see tabletcad.collector)
        from tabletcad.pipeline.build import build_design

        build_design(design, out_dir, progress=not quiet, parallel=True, announce=announce)


def _finished_note(rep: dict) -> str:
    """``; finished tablet ...`` when scores or embossing changed the tablet (``tablet.*`` is that one).

    The summary's volume and area, and ``design_report``, are the plain PDE tablet's; the finished
    tablet's volume and weight are in ``tooling.tablet``.
    """
    tab = (rep.get("tooling") or {}).get("tablet")
    if not tab or tab["volume_mm3"] == tab["volume_plain_mm3"]:
        return ""
    weight = "" if tab.get("weight_mg") is None else f", weight {tab['weight_mg']:.4g} mg"
    return f"; finished (scored/embossed) tablet: volume {tab['volume_mm3']:.4g} mm3{weight}"


@click.command("mesh")
@click.argument("design", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--nodes", nargs=3, type=int, required=True, metavar="NU NV NW",
              help="Nodes per patch along u (across the patch), v (around) and w (centre to surface); "
                   "thesis Table 4.4's sx, sy, sz.")
@click.option("--out", "out_file", required=True, type=click.Path(dir_okay=False, path_type=Path), help="Mesh file (.vtu, .xdmf, .msh, .vtk).")
def mesh_cmd(design: Path, nodes: tuple[int, int, int], out_file: Path) -> None:
    """Hexahedral solid mesh of DESIGN.toml (thesis section 4.3).

    Prints the mesh volume beside the solid's exact volume, and warns on stderr when they
    differ by more than Tolerances.mesh_volume (1 %): straight-edged cells cut the curved
    faces, so a coarse mesh holds less volume than the tablet.
    """
    from tabletcad.pipeline.design import load_design
    from tabletcad.volume_mesh import degenerate_cells, hex_mesh, mesh_volume

    for n in nodes:
        if n < 2 or n > 2000:
            raise DesignError("--nodes", n, "must be an integer from 2 to 2000")
    from tabletcad.cli.outputs import check_output

    check_output("--out", out_file, (".vtu", ".xdmf", ".msh", ".vtk"))  # before the geometry, named as given
    tablet = load_design(design)
    _check_mesh_memory(nodes, len(tablet.patches))
    from tabletcad.cli.options import option_names

    with option_names({"nodes": "--nodes"}):
        mesh = hex_mesh(tablet, nodes=nodes)
    counts = ", ".join(f"{len(c)} {k}" for k, c in mesh.cells.items() if len(c))
    v_mesh, v_exact = mesh_volume(mesh), tablet.solid_volume()
    if not (math.isfinite(v_exact) and v_exact > 0.0):  # pragma: no cover - valid designs have a volume
        _write_then_place(mesh, out_file, f"{out_file}: {len(mesh.points)} nodes, {counts}; mesh volume {v_mesh:.6g} mm3")
        return
    rel = v_mesh / v_exact - 1.0
    _write_then_place(mesh, out_file, f"{out_file}: {len(mesh.points)} nodes, {counts}; mesh volume {v_mesh:.6g} mm3 "
                                      f"({rel * 100:+.3g} % of the exact {v_exact:.6g} mm3)")
    from tabletcad.cli import say_warning

    bad = {k: n for k, n in degenerate_cells(mesh).items() if n}
    if bad:
        which = ", ".join(f"{n} {k}" for k, n in bad.items())
        say_warning(f"{sum(bad.values())} of {mesh.n_cells} cells ({which}) have a zero Jacobian at a corner: "
                    "the cup folds onto its centre line or corners next to the spine, where the solid map of eq 4.12 "
                    "collapses; their volumes are positive, but a solver that checks corner Jacobians refuses them "
                    "(tabletcad fe meshes the B-rep with tetrahedra)")
    if mesh.nonconforming:
        say_warning(f"the mesh is not conforming across {', '.join(mesh.nonconforming)}: a flat patch has no "
                    "volume, and the solids on either side of it meet there without sharing their nodes (separate "
                    "blocks to a solver); tabletcad fe meshes the B-rep with conforming tetrahedra")
    if abs(rel) > tablet.tol.mesh_volume:
        # the error falls as the square of the cell size in u and v (the solid map is linear in w):
        # scale those node spacings to land at half the bound
        s = math.sqrt(abs(rel) / (0.5 * tablet.tol.mesh_volume))
        hint = f"{math.ceil((nodes[0] - 1) * s) + 1} {math.ceil((nodes[1] - 1) * s) + 1} {nodes[2]}"
        say_warning(f"the mesh volume is {abs(rel) * 100:.3g} % {'below' if rel < 0 else 'above'} the exact "
                    f"volume (more than {tablet.tol.mesh_volume * 100:g} %): use more nodes, e.g. --nodes {hint}")


class _Unprinted(Exception):
    """A refused write of standard output, carried out of :func:`tabletcad.io.atomic_path`'s block as it
    is (that block names its file for an ``OSError``; standard output is ``output``)."""


def _write_then_place(mesh, out_file: Path, line: str) -> None:
    """Write ``mesh`` to a temporary file beside ``out_file``, print ``line``, then rename the file onto
    ``out_file``: a refused standard output (a full disk) leaves no mesh file (it had, exit 2)."""
    from tabletcad.io import atomic_path
    from tabletcad.volume_mesh import write_mesh

    try:
        with atomic_path(out_file) as tmp:
            write_mesh(mesh, tmp)
            try:
                click.echo(line)
            except OSError as exc:
                raise _Unprinted(exc) from None
    except _Unprinted as held:
        raise held.args[0] from None


def available_memory() -> int | None:
    """Bytes of memory the system reports available (Linux ``MemAvailable``; else free pages), or None."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):
        return None


def _check_mesh_memory(nodes: tuple[int, int, int], n_patches: int, tol: Tolerances = DEFAULT) -> None:
    """Refuse a mesh whose estimated peak memory exceeds ``tol.memory_fraction`` of the available memory."""
    count = n_patches * nodes[0] * nodes[1] * nodes[2]
    need = count * tol.mesh_bytes_per_node
    avail = available_memory()
    if avail is not None and need > tol.memory_fraction * avail:
        most = int(tol.memory_fraction * avail / (tol.mesh_bytes_per_node * n_patches))
        raise DesignError("--nodes", " ".join(map(str, nodes)),
                          f"needs about {need / 2**30:.3g} GiB for {count:.3g} nodes ({n_patches} patches), more than "
                          f"{tol.memory_fraction:g} of the {avail / 2**30:.3g} GiB available: keep NU*NV*NW below {most:.3g}")


COMMANDS = [shapes_cmd, build_cmd, mesh_cmd]
