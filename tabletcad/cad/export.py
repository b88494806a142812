"""Exporters chosen by file suffix, each written atomically (:func:`tabletcad.io.atomic_path`).

=========  ======================================================================
suffix     format
=========  ======================================================================
.step/.stp STEP AP242 (``AP214`` on request), millimetres, PRODUCT named ``name``
.stl       binary STL of the checked tessellation (mm)
.3mf       3MF (unit millimetre) of the checked tessellation, object named ``name``
.glb       binary glTF of the tessellation; glTF's unit is the metre, so vertices
           are scaled by 1e-3 unless ``glb_scale`` says otherwise
.brep      OCCT native BREP
=========  ======================================================================

A STEP header and a 3MF's entries are dated by :func:`tabletcad.io.timestamp.stamp_time`
(``SOURCE_DATE_EPOCH`` when set, else the time of writing), and nothing else in a file depends on
the run: the same shape and environment give the same bytes.
"""

from __future__ import annotations

import itertools
import os
import re
import struct
from pathlib import Path
from typing import Any

import numpy as np
from OCP.APIHeaderSection import APIHeaderSection_MakeHeader
from OCP.BRepTools import BRepTools
from OCP.IFSelect import IFSelect_ReturnStatus
from OCP.Interface import Interface_Static
from OCP.STEPCAFControl import STEPCAFControl_Writer
from OCP.STEPControl import STEPControl_Controller, STEPControl_StepModelType
from OCP.TCollection import TCollection_ExtendedString, TCollection_HAsciiString
from OCP.TDataStd import TDataStd_Name
from OCP.TDocStd import TDocStd_Document
from OCP.TopoDS import TopoDS_Shape
from OCP.XCAFDoc import XCAFDoc_DocumentTool

from tabletcad.cad._occ import quiet
from tabletcad.cad.mesh import MeshResult, tessellate, tessellate_solid
from tabletcad.errors import DesignError, GeometryError
from tabletcad.io import atomic_path
from tabletcad.io.timestamp import stamp_time, zip_date_time
from tabletcad.tolerance import DEFAULT

__all__ = ["export", "export_step", "export_stl", "export_3mf", "export_glb", "export_brep", "SUFFIXES"]

MESH_DEFAULTS = {"linear_deflection": DEFAULT.mesh_deflection, "angular_deflection": DEFAULT.mesh_angle}


def _shape_of(obj: Any) -> TopoDS_Shape:
    """Accept a ``TopoDS_Shape``, a :class:`~tabletcad.cad.solid.TabletSolid` or a build123d/cadquery shape."""
    if isinstance(obj, TopoDS_Shape):
        return obj
    for attr in ("shape", "wrapped"):
        s = getattr(obj, attr, None)
        if isinstance(s, TopoDS_Shape):
            return s
    raise TypeError(f"cannot export {type(obj).__name__}: expected a TopoDS_Shape or TabletSolid")


_SCHEMAS = {"AP242": "AP242DIS", "AP214": "AP214IS", "AP203": "AP203"}


def step_document(schema: str = "AP242", *, assembly: bool = False):
    """A new XCAF document for STEP in millimetres and its shape tool: ``(doc, tool)``.

    Sets OCCT's (process-global) STEP writer options every time, so one export
    cannot leak its schema or assembly mode into the next.
    """
    if not isinstance(schema, str) or schema.upper() not in _SCHEMAS:  # (None had raised an AttributeError)
        raise DesignError("schema", schema, f"must be one of {', '.join(sorted(_SCHEMAS))}")
    STEPControl_Controller.Init_s()
    Interface_Static.SetCVal_s("write.step.schema", _SCHEMAS[schema.upper()])
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    Interface_Static.SetIVal_s("write.surfacecurve.mode", 1)
    Interface_Static.SetIVal_s("write.step.assembly", 1 if assembly else 0)
    doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    XCAFDoc_DocumentTool.SetLengthUnit_s(doc, 0.001)  # document unit in metres: shapes are in mm
    return doc, XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())


def write_step_document(doc, path: str | os.PathLike[str], *, what: str, obj: Any = None) -> Path:
    """Transfer an XCAF document to STEP (names kept) and write it atomically to ``path``."""
    writer = STEPCAFControl_Writer()
    writer.SetNameMode(True)
    with quiet():  # once for both steps (0.2 ms each time)
        if not writer.Transfer(doc, STEPControl_StepModelType.STEPControl_AsIs):
            raise GeometryError(f"STEP transfer of {what} failed", obj)
        return _write_step(writer, path, obj)


def _write_step(writer: STEPCAFControl_Writer, path: str | os.PathLike[str], obj: Any) -> Path:
    """Write a transferred STEP model atomically to ``path``: its header stamped with
    :func:`~tabletcad.io.timestamp.stamp_time`, its names in Part 21's basic alphabet, its styles in an
    order of their content (:func:`canonical_style_order`), its assembly links numbered from 1
    (:func:`canonical_nauo_ids`)."""
    _stamp_header(writer)
    with atomic_path(path) as tmp:
        status = writer.Write(str(tmp))
        if status != IFSelect_ReturnStatus.IFSelect_RetDone:
            raise GeometryError(f"writing STEP {path} failed: {status}", obj)
        raw = Path(tmp).read_bytes()
        text = None
        if not raw.isascii():  # OCC writes names as raw UTF-8
            text = part21_text(raw.decode("utf-8"))
        if raw.count(_STYLE_ROOT.encode("ascii")) > 1:  # two parts coloured or more
            text = canonical_style_order(text if text is not None else raw.decode("ascii"))
        if _NAUO.encode("ascii") in raw:  # an assembly
            text = canonical_nauo_ids(text if text is not None else raw.decode("ascii"))
        if text is not None:
            Path(tmp).write_bytes(text.encode("ascii"))
    return Path(path)


def _stamp_header(writer: STEPCAFControl_Writer) -> None:
    """Set the header's FILE_NAME time stamp (OCC puts the local time of the transfer there) to
    :func:`~tabletcad.io.timestamp.stamp_time` in ISO 8601 with its UTC offset (``SOURCE_DATE_EPOCH``
    when set)."""
    header = APIHeaderSection_MakeHeader(writer.ChangeWriter().Model())
    if header.IsDone():
        header.SetTimeStamp(TCollection_HAsciiString(stamp_time().isoformat()))


_NON_ASCII = re.compile(r"[^\x00-\x7f]+")


def part21_text(text: str) -> str:
    """``text`` with every run of characters outside ASCII written as ISO 10303-21's control
    directive ``\\X2\\hhhh...\\X0\\`` (UCS-2, four hex digits a character) or, for a run
    holding a character beyond U+FFFF, ``\\X4\\hhhhhhhh...\\X0\\``.

    The file header declares Part 21's second edition (``'2;1'``), whose strings hold only the
    basic alphabet; OCC's writer puts a name such as "Paracétamol 500 µg" in as UTF-8 bytes,
    which its own reader and FreeCAD take back, but which a reader of the standard need not.
    Outside strings a STEP file is ASCII, so the runs are all inside strings."""

    def directive(m: re.Match) -> str:
        run = m.group(0)
        if max(map(ord, run)) <= 0xFFFF:
            return "\\X2\\" + "".join(f"{ord(c):04X}" for c in run) + "\\X0\\"
        return "\\X4\\" + "".join(f"{ord(c):08X}" for c in run) + "\\X0\\"

    return _NON_ASCII.sub(directive, text)


_NAUO = "NEXT_ASSEMBLY_USAGE_OCCURRENCE"
_NAUO_ID = re.compile(r"(=\s*" + _NAUO + r"\(\s*)'\d+'")


def canonical_nauo_ids(text: str) -> str:
    """A STEP file's NEXT_ASSEMBLY_USAGE_OCCURRENCEs (an assembly's links to its parts) with the ids
    ``'1'``, ``'2'``, ... in the order of the file.

    OCC's writer (``STEPConstruct_Assembly::MakeRelationship``) takes each id from a counter that lives
    as long as the process: the same assembly written again in one process (the second size of a tooling
    batch, a notebook's second build) had ids 5 to 8 where a fresh process writes 1 to 4.  The ids only
    need to be unique within the file; entities refer to each other by their ``#`` numbers.
    """
    counter = itertools.count(1)
    return _NAUO_ID.sub(lambda m: f"{m.group(1)}'{next(counter)}'", text)


_STYLE_ROOT = "MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION_REPRESENTATION"
_STRING = r"'(?:[^']|'')*'"  # a Part 21 string ('' is a quote inside it)
_ENTITY = re.compile(r"#(\d+)\s*=\s*((?:" + _STRING + r"|[^;'])*);")
_REF_OR_STRING = re.compile(_STRING + r"|#(\d+)")


def _refs(body: str) -> list[int]:
    """The entity numbers ``body`` refers to, in field order (none inside strings)."""
    return [int(m.group(1)) for m in _REF_OR_STRING.finditer(body) if m.group(1)]


def canonical_style_order(text: str) -> str:
    """A STEP file's presentation styles numbered in an order of their content, not of memory addresses.

    OCC's XCAF writer adds each coloured part's MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION_REPRESENTATION,
    with the styles and colours it refers to, at the end of the data section, in the order of a map
    hashed on the parts' addresses in memory: the same assembly came out with its colours in another
    order from one run to the next.  That tail is renumbered here: its representations sorted by the
    entities before the tail that they refer to (the parts' contexts and the styled solids, numbered
    in transfer order), each followed by what it refers to, depth first, as OCC lays it out.  A file
    whose tail is anything else (an entity before it refers into it, or text that is not entities)
    is returned as it is.
    """
    data = text.find("\nDATA;")
    first = text.find("= " + _STYLE_ROOT, data)
    end = text.rfind("ENDSEC;")
    if data < 0 or first < 0 or end < first:
        return text
    start = text.rfind("\n#", data, first) + 1
    tail = text[start:end]
    bodies = {int(m.group(1)): m.group(2) for m in _ENTITY.finditer(tail)}
    if _ENTITY.sub("", tail).strip() or not bodies:
        return text
    low = min(bodies)
    if any(r >= low for r in _refs(text[data:start])):
        return text
    order = _style_order(bodies, low)
    new = {old: low + k for k, old in enumerate(order)}

    def renumber(m: re.Match) -> str:
        return f"#{new.get(int(m.group(1)), int(m.group(1)))}" if m.group(1) else m.group(0)

    lines = [f"#{new[old]} = {_REF_OR_STRING.sub(renumber, bodies[old])};\n" for old in order]
    return text[:start] + "".join(lines) + text[end:]


def _style_order(bodies: dict[int, str], low: int) -> list[int]:
    """The tail's entity numbers in their new order: roots by the earlier entities they reach, each
    root's closure depth first (a shared colour where it is first reached), then any left over."""

    def outside(root: int) -> tuple[int, ...]:
        seen, stack, found = set(), [root], []
        while stack:
            n = stack.pop()
            if n in seen:
                continue
            seen.add(n)
            refs = _refs(bodies[n])
            found += [r for r in refs if r < low]
            stack += [r for r in reversed(refs) if r in bodies]
        return tuple(found)

    def skeleton(body: str) -> str:  # the text without its references: a tie-break that no numbering changes
        return _REF_OR_STRING.sub(lambda m: "#" if m.group(1) else m.group(0), body)

    roots = sorted((n for n, b in bodies.items() if b.lstrip().startswith(_STYLE_ROOT)),
                   key=lambda n: (outside(n), skeleton(bodies[n])))
    order: list[int] = []
    placed: set[int] = set()

    def visit(n: int) -> None:  # iteratively: pre-order, children in field order
        stack = [n]
        while stack:
            k = stack.pop()
            if k in placed or k not in bodies:
                continue
            placed.add(k)
            order.append(k)
            stack += [r for r in reversed(_refs(bodies[k])) if r in bodies and r not in placed]

    for r in roots:
        visit(r)
    order += [n for n in sorted(bodies) if n not in placed]
    return order


def export_step(obj: Any, path: str | os.PathLike[str], *, name: str = "tablet", schema: str = "AP242") -> Path:
    """STEP (``AP242`` -> OCCT's ``AP242DIS``, or ``AP214``) in millimetres; the PRODUCT is called ``name``."""
    shape = _shape_of(obj)
    doc, tool = step_document(schema)
    label = tool.AddShape(shape, False)
    TDataStd_Name.Set_s(label, TCollection_ExtendedString(str(name), True))  # UTF-8 (multibyte), not bytes as Latin-1
    return write_step_document(doc, path, what=str(name), obj=shape)


def _mesh_of(obj: Any, mesh: MeshResult | None, **kw: Any) -> MeshResult:
    if mesh is not None:
        return mesh
    unknown = sorted(set(kw) - {"linear_deflection", "angular_deflection", "relative"})
    if unknown:  # as Python's own call would: a misspelt option is not dropped in silence
        raise TypeError(f"export got an unexpected keyword argument {unknown[0]!r} (mesh options: linear_deflection "
                        "mm, angular_deflection rad, relative)")
    opts = {**MESH_DEFAULTS, "relative": False, **kw}
    if not isinstance(opts["relative"], (bool, np.bool_)):  # ("no" had been read as true)
        raise DesignError("relative", opts["relative"], "must be true or false")
    if hasattr(obj, "surfaces") and hasattr(obj, "shape") and not opts["relative"]:
        # a TabletSolid: meshed from its faces' data, as the CAD stage does
        m = tessellate_solid(obj, opts["linear_deflection"], opts["angular_deflection"])
    else:
        m = tessellate(_shape_of(obj), opts["linear_deflection"], opts["angular_deflection"], relative=bool(opts["relative"]))
    if not m.ok:
        raise GeometryError(
            f"tessellation is not a closed manifold (manifold3d: {m.manifold_status}, "
            f"watertight {m.watertight}, winding consistent {m.winding_consistent})",
            m,
        )
    return m


def export_stl(obj: Any, path, *, name: str = "tablet", mesh: MeshResult | None = None, **mesh_kw: Any) -> Path:
    """Binary STL (little-endian, float32, facet normals) of the checked tessellation."""
    m = _mesh_of(obj, mesh, **mesh_kw)
    V, T = m.vertices, m.triangles
    a, b, c = (np.take(V, T[:, k], axis=0) for k in range(3))  # (take: the same rows as V[T[:, k]], 3x faster)
    n = np.cross(b - a, c - a)
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    rec = np.zeros(len(T), dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")]))
    rec["n"] = n
    rec["v"] = np.stack([a, b, c], axis=1)
    header = f"tabletcad binary STL, unit mm: {name}".encode("ascii", "replace")[:80].ljust(80, b" ")
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(header)
            fh.write(struct.pack("<I", len(T)))
            fh.write(rec.tobytes())
    return Path(path)


_3MF_TYPES = """<?xml version="1.0" encoding="UTF-8"?>
<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">
<Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>
<Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>
</Types>
"""
_3MF_RELS = """<?xml version="1.0" encoding="UTF-8"?>
<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">
<Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>
</Relationships>
"""


def export_3mf(obj: Any, path, *, name: str = "tablet", mesh: MeshResult | None = None, **mesh_kw: Any) -> Path:
    """3MF core (unit millimetre, one object named ``name``), written with the standard library."""
    import zipfile
    from xml.sax.saxutils import quoteattr

    m = _mesh_of(obj, mesh, **mesh_kw)
    verts = "".join(f'<vertex x="{x:.9g}" y="{y:.9g}" z="{z:.9g}"/>' for x, y, z in np.asarray(m.vertices))
    tris = "".join(f'<triangle v1="{a}" v2="{b}" v3="{c}"/>' for a, b, c in np.asarray(m.triangles))
    model = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<model unit="millimeter" xml:lang="en-US" '
        'xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">\n'
        f'<metadata name="Title">{_xml_text(name)}</metadata>\n'
        f'<resources><object id="1" type="model" name={quoteattr(name)}><mesh>'
        f"<vertices>{verts}</vertices><triangles>{tris}</triangles></mesh></object></resources>\n"
        '<build><item objectid="1"/></build>\n</model>\n'
    )
    when = zip_date_time(stamp_time())  # (zipfile dates a named entry with the local time of writing)
    with atomic_path(path) as tmp:
        with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED) as zf:
            for member, text in (("[Content_Types].xml", _3MF_TYPES), ("_rels/.rels", _3MF_RELS),
                                 ("3D/3dmodel.model", model)):
                info = zipfile.ZipInfo(member, date_time=when)
                info.compress_type = zipfile.ZIP_DEFLATED
                info.external_attr = 0o600 << 16  # -rw-------, as writestr gives a named entry
                zf.writestr(info, text)
    return Path(path)


def _xml_text(text: str) -> str:
    from xml.sax.saxutils import escape

    return escape(str(text))


def export_glb(
    obj: Any, path, *, name: str = "tablet", mesh: MeshResult | None = None, glb_scale: float = 1e-3, **mesh_kw: Any
) -> Path:
    """Binary glTF in glTF's frame: vertices multiplied by ``glb_scale`` (default mm -> m, glTF's unit) and
    turned so that the tablet's z axis is glTF's up, +Y (``(x, y, z) -> (x, z, -y)``, a rotation: viewers had
    shown the tablet lying on its side)."""
    import trimesh

    m = _mesh_of(obj, mesh, **mesh_kw)
    v = np.asarray(m.vertices, dtype=float) * float(glb_scale)
    tm = trimesh.Trimesh(np.column_stack([v[:, 0], v[:, 2], -v[:, 1]]), m.triangles, process=False)
    scene = trimesh.Scene()
    scene.add_geometry(tm, node_name=name, geom_name=name)
    data = trimesh.exchange.gltf.export_glb(scene)
    with atomic_path(path) as tmp:
        Path(tmp).write_bytes(data)
    return Path(path)


def export_brep(obj: Any, path, *, name: str = "tablet") -> Path:
    """OCCT native BREP text."""
    shape = _shape_of(obj)
    with atomic_path(path) as tmp:
        if not BRepTools.Write_s(shape, str(tmp)):
            raise GeometryError(f"writing BREP {path} failed", shape)
    return Path(path)


SUFFIXES = {
    ".step": export_step,
    ".stp": export_step,
    ".stl": export_stl,
    ".3mf": export_3mf,
    ".glb": export_glb,
    ".brep": export_brep,
}


def export(obj: Any, path: str | os.PathLike[str], *, name: str | None = None, **kw: Any) -> Path:
    """Write ``obj`` (TopoDS_Shape / TabletSolid / build123d / cadquery shape) in the format named by the suffix.

    ``name`` defaults to ``obj.name`` (a TabletSolid) or ``"tablet"``.
    """
    suffix = Path(path).suffix.lower()
    if suffix not in SUFFIXES:
        # a DesignError (a ValueError) naming the path, as a folder given as the file is named
        raise DesignError("path", str(path), f"its file suffix {suffix or '(none)'!r} must be one of "
                          f"{', '.join(sorted(SUFFIXES))}")
    exact = {".step": ("schema",), ".stp": ("schema",), ".brep": ()}  # the exact formats take no mesh options
    if suffix in exact and set(kw) - set(exact[suffix]):
        extra = sorted(set(kw) - set(exact[suffix]))[0]
        takes = f"takes only {exact[suffix][0]}=" if exact[suffix] else "takes no options"
        raise TypeError(f"export got an unexpected keyword argument {extra!r}: a {suffix} file (exact B-rep, not a "
                        f"mesh) {takes}")
    name = name or getattr(obj, "name", None) or "tablet"
    return SUFFIXES[suffix](obj, path, name=str(name), **kw)
