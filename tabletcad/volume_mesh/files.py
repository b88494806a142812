"""Mesh files of a :class:`~tabletcad.volume_mesh.hexahedra.SolidMesh`: VTU, legacy VTK, XDMF
(inline XML data) or Gmsh, written atomically (meshio, and a hand-written XDMF for mixed cells)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from tabletcad.errors import DesignError
from tabletcad.volume_mesh.hexahedra import SolidMesh

__all__ = ["write_mesh"]

_FORMATS = {".vtu": "vtu", ".vtk": "vtk", ".xdmf": "xdmf", ".xmf": "xdmf", ".msh": "gmsh"}

# XDMF mixed-topology cell codes (XdmfTopologyType) and node counts
_XDMF_CODE = {"tetra": 0x6, "pyramid": 0x7, "wedge": 0x8, "hexahedron": 0x9}
_XDMF_NAME = {"tetra": "Tetrahedron", "pyramid": "Pyramid", "wedge": "Wedge", "hexahedron": "Hexahedron"}
#: meshio (Gmsh) wedge order -> VTK wedge order (VTK's triangle 0-1-2 faces away from 3-4-5)
_WEDGE_TO_VTK = [0, 2, 1, 3, 5, 4]


def _xml_numbers(a: np.ndarray, fmt: str) -> str:
    a = np.asarray(a)
    rows = a.reshape(a.shape[0], -1) if a.ndim > 1 else a.reshape(-1, 1)
    line = " ".join([fmt] * rows.shape[1])
    return "\n" + "\n".join(line % tuple(r) for r in rows.tolist()) + "\n"


def _write_xdmf_inline(path: Path, mesh: SolidMesh) -> None:
    """XDMF 3 with every array inline (Format="XML"): one self-contained file.

    Wedges are written in VTK's node order (XDMF readers, e.g. ParaView's,
    hand the connectivity to VTK unchanged); the other types share meshio's
    and VTK's order.
    """
    import xml.etree.ElementTree as ET

    root = ET.Element("Xdmf", Version="3.0")
    grid = ET.SubElement(ET.SubElement(root, "Domain"), "Grid", Name="tablet", GridType="Uniform")
    kinds = list(mesh.cells)
    conns = [mesh.cells[k][:, _WEDGE_TO_VTK] if k == "wedge" else mesh.cells[k] for k in kinds]
    n_cells = sum(c.shape[0] for c in conns)
    if len(kinds) == 1:
        topo = ET.SubElement(
            grid, "Topology", TopologyType=_XDMF_NAME[kinds[0]], NumberOfElements=str(n_cells),
            NodesPerElement=str(conns[0].shape[1]),
        )
        item = ET.SubElement(
            topo, "DataItem", DataType="Int", Precision="8", Format="XML", Dimensions=f"{n_cells} {conns[0].shape[1]}"
        )
        item.text = _xml_numbers(conns[0], "%d")
    else:
        flat = np.concatenate(
            [np.hstack([np.full((c.shape[0], 1), _XDMF_CODE[k], dtype=np.int64), c]).ravel() for k, c in zip(kinds, conns)]
        )
        topo = ET.SubElement(grid, "Topology", TopologyType="Mixed", NumberOfElements=str(n_cells))
        item = ET.SubElement(topo, "DataItem", DataType="Int", Precision="8", Format="XML", Dimensions=str(flat.size))
        item.text = _xml_numbers(flat, "%d")
    geo = ET.SubElement(grid, "Geometry", GeometryType="XYZ")
    item = ET.SubElement(
        geo, "DataItem", DataType="Float", Precision="8", Format="XML", Dimensions=f"{mesh.n_points} 3"
    )
    item.text = _xml_numbers(mesh.points, "%.17g")
    att = ET.SubElement(grid, "Attribute", Name="patch_id", AttributeType="Scalar", Center="Cell")
    pid = np.concatenate([mesh.patch_id[k] for k in kinds]).astype(np.int64)
    item = ET.SubElement(att, "DataItem", DataType="Int", Precision="8", Format="XML", Dimensions=str(pid.size))
    item.text = _xml_numbers(pid, "%d")
    ET.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)


def _gmsh_mesh(mesh: SolidMesh, per_block_entities: bool):
    """meshio mesh with Gmsh tags: physical = patch + 1 (geometrical too in 2.2).

    The patch id travels as the physical tag only: meshio 5.3's ASCII
    ``$ElementData`` writer formats values with ``repr``, which under numpy 2
    writes ``np.int32(0)`` and makes the file unreadable.

    Gmsh 4.1 (``per_block_entities``) ties every element block to one volume
    entity and every node to an entity, so blocks are split per (type, patch)
    with entity tags 1, 2, ... and nodes get ``gmsh:dim_tags``.
    """
    import meshio

    blocks, phys, geo = [], [], []
    for kind, conn in mesh.cells.items():
        p_of = mesh.patch_id[kind]
        parts = [(int(p), p_of == p) for p in np.unique(p_of)] if per_block_entities else [(None, slice(None))]
        for p, sel in parts:
            c = conn[sel]
            pp = p_of[sel].astype(np.int32)
            blocks.append((kind, c))
            phys.append(pp + 1)
            geo.append(np.full(c.shape[0], len(blocks), dtype=np.int32) if per_block_entities else pp + 1)
    point_data = {}
    if per_block_entities:
        dim_tags = np.zeros((mesh.n_points, 2), dtype=np.int32)
        dim_tags[:, 0] = 3
        for (kind, c), g in zip(blocks, geo):
            dim_tags[c.ravel(), 1] = g[0]
        point_data["gmsh:dim_tags"] = dim_tags
    return meshio.Mesh(
        mesh.points,
        blocks,
        point_data=point_data,
        cell_data={"gmsh:physical": phys, "gmsh:geometrical": geo},
    )


def write_mesh(mesh: SolidMesh, path: str | os.PathLike[str], *, msh_version: str = "2.2") -> Path:
    """Write the mesh atomically; format from the suffix.

    Parameters
    ----------
    mesh : SolidMesh
    path : path
        ``.vtu`` (VTK XML, binary; meshio), ``.vtk`` (legacy VTK 4.2, binary;
        meshio), ``.msh`` (Gmsh; meshio) or ``.xdmf``/``.xmf`` (XDMF 3 with
        inline XML data: a single self-contained file, so no companion HDF5
        file can be left half-written; written by this module because
        meshio's XDMF writer needs h5py even for inline data).
    msh_version : {"2.2", "4.1"}
        Gmsh file format version for ``.msh`` (ASCII; meshio reads both back).
        In 4.1 every (cell type, patch) block is its own volume entity.

    Notes
    -----
    Cell data ``patch_id`` (the patch of every cell) is written; Gmsh files
    carry it as the physical tag (patch index + 1) instead.  The
    file is written to a temporary name with the same suffix in the same
    folder and renamed (:func:`tabletcad.io.atomic_path`).

    Returns
    -------
    Path of the written file.
    """
    from tabletcad.io import atomic_path

    path = Path(path)
    fmt = _FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise DesignError("mesh file suffix", path.suffix, f"must be one of {', '.join(sorted(_FORMATS))}")
    if fmt == "gmsh" and msh_version not in ("4.1", "2.2"):
        raise DesignError("msh_version", msh_version, "must be '4.1' or '2.2'")
    if fmt == "xdmf":
        with atomic_path(path) as tmp:
            _write_xdmf_inline(tmp, mesh)
        return path

    import meshio

    kw: dict = {}
    if fmt == "gmsh":
        m = _gmsh_mesh(mesh, per_block_entities=msh_version == "4.1")
        fmt = "gmsh22" if msh_version == "2.2" else "gmsh"
        kw["binary"] = False
    else:
        m = mesh.to_meshio()
        if fmt == "vtk":
            fmt = "vtk42"
            kw["binary"] = True
    with atomic_path(path) as tmp:
        meshio.write(tmp, m, file_format=fmt, **kw)
    return path
