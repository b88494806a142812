"""Independent read-back of written files (used by the tests).

* :func:`ocp_read_step` re-reads a STEP file with OCP's ``STEPControl_Reader``
  in a **fresh** Python process (no state shared with the writer).
* :func:`freecad_read_step` runs :mod:`support.freecad_check` under
  ``freecadcmd`` (FreeCAD's own Python and its own OCCT build), with
  ``FREECAD_USER_HOME`` set to a temporary folder, ``VIRTUAL_ENV`` unset and
  the venv removed from ``PATH``.
* :func:`mesh_volume` is the signed volume of a mesh read back (by trimesh, say): the
  volume alone, not trimesh's whole mass properties (its inertia integrals took 0.5 s of
  a 500,000-triangle STL).
* :func:`freecad_build_bspline` rebuilds kernel-neutral surfaces with FreeCAD's
  ``Part.BSplineSurface().buildFromPolesMultsKnots``.
* :func:`freecad_batch` does both for several files and surface sets in *one* ``freecadcmd``.

FreeCAD's ``Shape.Volume`` uses OCCT's default (non-adaptive) integration,
measured up to ~1e-3 relative off on dense B-spline tablets: compare it with
a relative tolerance of about 1e-3, or against OCP's default integration
(``mass_properties(shape, eps=None)``) for a tight comparison.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from tabletcad.errors import TabletcadError

__all__ = [
    "find_freecadcmd",
    "freecad_read_step",
    "freecad_read_steps",
    "freecad_build_bspline",
    "freecad_batch",
    "ocp_read_step",
    "ocp_read_steps",
    "mesh_volume",
    "ReadbackError",
]

FREECAD_SCRIPT = Path(__file__).with_name("freecad_check.py")


class ReadbackError(TabletcadError):
    """The read-back subprocess failed or printed no result."""


def _clean_env() -> dict[str, str]:
    env = dict(os.environ)
    venv = env.pop("VIRTUAL_ENV", None)
    env.pop("PYTHONPATH", None)
    env.pop("PYTHONHOME", None)
    drop = {str(Path(sys.prefix) / "bin")}
    if venv:
        drop.add(str(Path(venv) / "bin"))
    env["PATH"] = os.pathsep.join(p for p in env.get("PATH", "").split(os.pathsep) if p and p not in drop)
    return env


def find_freecadcmd() -> str | None:
    """Path of ``freecadcmd`` (or ``FreeCADCmd``) outside the venv, or None."""
    path = _clean_env()["PATH"]
    for name in ("freecadcmd", "FreeCADCmd"):
        exe = shutil.which(name, path=path)
        if exe:
            return exe
    return None


def _run_freecad(mode: str, input_path: Path, timeout: float, freecadcmd: Sequence[str] | None = None) -> dict[str, Any]:
    exe = find_freecadcmd() if freecadcmd is None else None
    if freecadcmd is None and exe is None:
        raise ReadbackError("freecadcmd not found on PATH")
    cmd = list(freecadcmd) if freecadcmd is not None else [exe]
    with tempfile.TemporaryDirectory(prefix="tabletcad-fc-") as home:
        out = Path(home) / "result.json"
        env = _clean_env()
        env.update(
            FREECAD_USER_HOME=home,
            TABLETCAD_FC_MODE=mode,
            TABLETCAD_FC_INPUT=str(input_path),
            TABLETCAD_FC_OUTPUT=str(out),
        )
        proc = subprocess.run(
            [*cmd, str(FREECAD_SCRIPT)], env=env, cwd=home, capture_output=True, text=True, timeout=timeout
        )
        if not out.exists():
            raise ReadbackError(
                f"freecadcmd produced no result (exit {proc.returncode}): {proc.stdout[-2000:]} {proc.stderr[-2000:]}"
            )
        result = json.loads(out.read_text())
    if not result.get("ok"):
        raise ReadbackError(f"FreeCAD check failed: {result.get('error')}\n{result.get('traceback', '')}")
    return result


def freecad_read_step(
    path: str | os.PathLike[str], timeout: float = 300.0, freecadcmd: Sequence[str] | None = None
) -> dict[str, Any]:
    """Read a STEP file with FreeCAD: ``{n_solids, valid, solids_valid, volume, area, labels, ...}``.

    ``freecadcmd``: the command that runs FreeCAD's ``freecadcmd`` (default: the one on PATH)."""
    return _run_freecad("read_step", Path(path).resolve(), timeout, freecadcmd)


def freecad_read_steps(
    paths: Sequence[str | os.PathLike[str]], timeout: float = 300.0, freecadcmd: Sequence[str] | None = None
) -> list[dict[str, Any]]:
    """:func:`freecad_read_step` for several files in *one* ``freecadcmd`` process, in their order."""
    paths = [str(Path(p).resolve()) for p in paths]
    with tempfile.TemporaryDirectory(prefix="tabletcad-fcin-") as d:
        p = Path(d) / "paths.json"
        p.write_text(json.dumps(paths))
        results = _run_freecad("read_steps", p, timeout, freecadcmd)["results"]
    if [r.get("path") for r in results] != paths:
        raise ReadbackError(f"FreeCAD read {len(results)} results for {len(paths)} files")
    for r in results:
        if not r.get("ok"):
            raise ReadbackError(f"FreeCAD check failed on {r.get('path')}: {r.get('error')}\n{r.get('traceback', '')}")
    return results


def freecad_build_bspline(
    surfaces: Sequence[Any],
    u: Sequence[float] = (),
    v: Sequence[float] = (),
    timeout: float = 300.0,
    freecadcmd: Sequence[str] | None = None,
) -> dict[str, Any]:
    """Rebuild :class:`~tabletcad.brep.surface.BSplineSurfaceData` with FreeCAD; values at ``(u, v)``, solid volume."""
    payload = {"surfaces": [s.as_dict() for s in surfaces], "u": [float(x) for x in u], "v": [float(x) for x in v]}
    with tempfile.TemporaryDirectory(prefix="tabletcad-fcin-") as d:
        p = Path(d) / "surfaces.json"
        p.write_text(json.dumps(payload))
        return _run_freecad("bspline", p, timeout, freecadcmd)


def freecad_batch(
    steps: Sequence[str | os.PathLike[str]] = (),
    bsplines: Sequence[tuple[Sequence[Any], Sequence[float], Sequence[float]]] = (),
    timeout: float = 300.0,
    freecadcmd: Sequence[str] | None = None,
) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """:func:`freecad_read_step` of each of ``steps`` and :func:`freecad_build_bspline` of each
    ``(surfaces, u, v)`` of ``bsplines``, in *one* ``freecadcmd`` process.

    Parameters
    ----------
    steps : sequence of path-like
        STEP files to read.
    bsplines : sequence of (surfaces, u, v)
        :class:`~tabletcad.brep.surface.BSplineSurfaceData` sets and the parameters to evaluate them at.
    timeout : float
        Seconds the process may take.
    freecadcmd : sequence of str, optional
        The command that runs FreeCAD's ``freecadcmd`` (default: the one on PATH).

    Returns
    -------
    tuple of (list of dict, list of dict)
        The results of :func:`freecad_read_step` and of :func:`freecad_build_bspline`, in the given orders.
    """
    steps = [str(Path(p).resolve()) for p in steps]
    with tempfile.TemporaryDirectory(prefix="tabletcad-fcin-") as d:
        payloads = []
        for k, (surfaces, u, v) in enumerate(bsplines):
            p = Path(d) / f"surfaces{k}.json"
            p.write_text(json.dumps({"surfaces": [s.as_dict() for s in surfaces], "u": [float(x) for x in u],
                                     "v": [float(x) for x in v]}))
            payloads.append(str(p))
        jobs = Path(d) / "jobs.json"
        jobs.write_text(json.dumps({"read_step": steps, "bspline": payloads}))
        result = _run_freecad("batch", jobs, timeout, freecadcmd)
    read, built = result["read_step"], result["bspline"]
    if [r.get("path") for r in read] != steps or [r.get("path") for r in built] != payloads:
        raise ReadbackError(f"FreeCAD gave {len(read)} + {len(built)} results for {len(steps)} + {len(payloads)} jobs")
    for r in read + built:
        if not r.get("ok"):
            raise ReadbackError(f"FreeCAD check failed on {r.get('path')}: {r.get('error')}\n{r.get('traceback', '')}")
    return read, built


_OCP_READER = r"""
import json, sys
from OCP.STEPControl import STEPControl_Reader
from OCP.IFSelect import IFSelect_ReturnStatus
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.TopExp import TopExp_Explorer
from OCP.TopAbs import TopAbs_SOLID, TopAbs_FACE
from OCP.Bnd import Bnd_Box
from OCP.BRepBndLib import BRepBndLib

def read(path):
    reader = STEPControl_Reader()
    status = reader.ReadFile(path)
    if status != IFSelect_ReturnStatus.IFSelect_RetDone:
        return {"ok": False, "error": str(status), "path": path}
    reader.TransferRoots()
    shape = reader.OneShape()
    def count(kind):
        e = TopExp_Explorer(shape, kind); n = 0
        while e.More():
            n += 1; e.Next()
        return n
    def props(eps):
        p = GProp_GProps()
        if eps is None:
            BRepGProp.VolumeProperties_s(shape, p)
        else:
            BRepGProp.VolumeProperties_s(shape, p, Eps=eps)
        return p.Mass()
    out = {}
    if "area" in MEASURE:
        sp = GProp_GProps(); BRepGProp.SurfaceProperties_s(shape, sp, Eps=1e-9)
        out["area"] = sp.Mass()
    if "bbox" in MEASURE:
        box = Bnd_Box(); BRepBndLib.AddOptimal_s(shape, box, False, False)
        pmin, pmax = box.CornerMin(), box.CornerMax()
        out["bbox"] = [pmin.X(), pmin.Y(), pmin.Z(), pmax.X(), pmax.Y(), pmax.Z()]
    if "volume_default" in MEASURE:
        out["volume_default"] = props(None)
    names = []
    try:
        model = reader.WS().Model()
        from OCP.StepBasic import StepBasic_Product
        for i in range(1, model.NbEntities() + 1):
            ent = model.Value(i)
            if isinstance(ent, StepBasic_Product):
                names.append(ent.Name().ToCString())
    except Exception as exc:
        names = ["?" + repr(exc)]
    return {
        "ok": True,
        "path": path,
        "n_solids": count(TopAbs_SOLID),
        "n_faces": count(TopAbs_FACE),
        "valid": bool(BRepCheck_Analyzer(shape).IsValid()),
        "volume": props(1e-9),
        **out,
        "products": names,
    }

MEASURE = set(sys.argv[1].split(",")) - {""}
for path in sys.argv[2:]:
    try:
        result = read(path)
    except Exception as exc:
        result = {"ok": False, "error": repr(exc), "path": path}
    print("TABLETCAD_JSON:" + json.dumps(result), flush=True)
"""


#: what the reader measures beyond the solids, faces, validity, adaptive volume and product names
MEASURES = ("volume_default", "area", "bbox")


def ocp_read_steps(
    paths: Sequence[str | os.PathLike[str]], timeout: float = 300.0, python: str | None = None,
    measure: Sequence[str] = MEASURES,
) -> list[dict[str, Any]]:
    """:func:`ocp_read_step` for several files in *one* fresh process (one OCP import).

    ``measure``: which of :data:`MEASURES` to compute (all by default); a caller that reads none of
    them passes ``()`` (the optimal bounding box and the area took up to 1.3 s a cut-away's file), and
    a key not measured is absent from the result (reading it is a KeyError, not a silent pass)."""
    unknown = set(measure) - set(MEASURES)
    if unknown:
        raise ValueError(f"unknown measures {sorted(unknown)}: choose from {MEASURES}")
    paths = [str(Path(p).resolve()) for p in paths]
    proc = subprocess.run(
        [python or sys.executable, "-c", _OCP_READER, ",".join(measure), *paths],
        capture_output=True, text=True, timeout=timeout,
    )
    results = [
        json.loads(line[len("TABLETCAD_JSON:"):])
        for line in proc.stdout.splitlines()
        if line.startswith("TABLETCAD_JSON:")
    ]
    if len(results) != len(paths):
        raise ReadbackError(
            f"OCP read-back printed {len(results)} results for {len(paths)} files "
            f"(exit {proc.returncode}): {proc.stderr[-2000:]}"
        )
    for r in results:
        if not r.get("ok"):
            raise ReadbackError(f"STEPControl_Reader failed on {r.get('path')}: {r.get('error')}")
    return results


def ocp_read_step(path: str | os.PathLike[str], timeout: float = 300.0, python: str | None = None,
                  measure: Sequence[str] = MEASURES) -> dict[str, Any]:
    """Read STEP with OCP's ``STEPControl_Reader`` in a fresh process (``python`` defaults to this interpreter).

    Returns ``{n_solids, n_faces, valid, volume (adaptive, eps 1e-9), volume_default, area, bbox, products}``
    (of the last three those ``measure`` names: all by default).
    """
    return ocp_read_steps([path], timeout=timeout, python=python, measure=measure)[0]


def mesh_volume(triangles: Any) -> float:
    """The signed volume (mm³) bounded by a mesh's triangles (``(n, 3, 3)`` corners, mm), outward
    by the right-hand rule: ``sum(a . ((b - a) x (c - a))) / 6`` (the divergence theorem; trimesh's
    ``Trimesh.volume``, which also integrates the inertia, to 7e-16 relative on a cut-away's STL)."""
    import numpy as np

    t = np.asarray(triangles, dtype=np.float64)
    a, b, c = t[:, 0], t[:, 1], t[:, 2]
    return float(np.einsum("ij,ij->", a, np.cross(b - a, c - a)) / 6.0)
