"""Hexahedral meshes of the tablet solid (thesis section 4.3, Appendix A).

Every patch defines a solid through the extended PDE map of eq 4.12,

    X(u, v, w) = A0(u) + w (X(u, v) - A0(u)),      0 <= w <= 1,

which fills the region between the patch's spine ``A0(u)`` (eq 3.13) and its
surface.  The thesis meshes it with "cuboids": a structured grid of ``sx``
nodes along ``u``, ``sy`` along ``v`` and ``sz`` along ``w`` (its Table 4.4
uses 11×21×5, 21×39×6 and 41×39×6 nodes, i.e. ``(sx-1)(sy-1)(sz-1)`` = 800,
3800 and 7600 cuboids per patch), over the parameter ranges the tablet's
:class:`~tabletcad.geometry.tablet.Trim` keeps.

:func:`hex_mesh` builds that grid for every patch of a tablet, fully
vectorised, and turns it into a *conforming* finite-element mesh:

* nodes that the map sends to the same place are merged **by index**, where
  the degeneracy is known, then the merge is verified with a distance check:

  - ``w = 0``: every ``v`` collapses onto the spine point ``A0(u)``;
  - a pole (a patch end ``u = 0`` or ``1`` whose curve is a single point): all
    ``(v, w)`` collapse;
  - a full turn in ``v``: the last ``v`` node is the first (periodic);
  - consecutive patches: patch ``j`` at ``u = 1`` and patch ``j + 1`` at
    ``u = 0`` (same ``v`` and ``w``) share their nodes (untrimmed ``u`` only);

  and then every other pair of nodes within that distance is merged too
  (:func:`_geometric_merge`): a shaped cup folds onto its centre line or its
  corner arcs, where nodes of mirror ``v`` meet;

* a cell whose eight corners are not distinct is written as the lower-order
  cell it is: a wedge next to the spine (6 distinct nodes), a pyramid next to
  a pole (5), a tetrahedron where both meet (4), and likewise for the same
  collapses in any orientation (:data:`_DEGENERATE`); a cell next to both the
  spine and a shaped cup's fold, whose sides are bilinear quads sharing two
  edges, is no standard cell and stays a degenerate hexahedron (repeated
  nodes, shared with its neighbours), and cells beside a fold onto a line (a capsule's centre
  line) keep a face whose four distinct nodes lie on that line; both have positive volumes but a
  zero Jacobian at a corner (:func:`degenerate_cells` counts them as Gmsh's ``minSJ`` rates
  them; ``tabletcad mesh`` warns); cells with fewer nodes, and
  all cells of a flat patch (a zero-volume solid, such as the flat faces of
  a flat-faced round tablet, whose volume the band patch's solid fills), are
  dropped;
* node order follows meshio's conventions (those of VTK for hexahedra,
  pyramids and tetrahedra; for wedges meshio, like Gmsh, has the triangle
  ``(0, 1, 2)`` facing ``(3, 4, 5)`` and permutes to VTK's order itself when
  writing VTK files), and every patch is oriented so that every written cell
  has positive volume.  Where the solid map folds over (the spine runs
  backwards for ``u`` within ~0.015 of the poles of the thesis's domes, see
  :func:`_drop_fold_nodes`) the ``u`` node layers inside the fold are left
  out, so that no written cell is inverted.

:func:`mesh_volume` is the exact volume of the trilinear cells; it converges
to :meth:`Tablet.solid_volume` at second order in the node spacing.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from tabletcad.errors import DesignError, GeometryError

if TYPE_CHECKING:  # pragma: no cover
    from tabletcad.geometry.tablet import Tablet

__all__ = [
    "SolidMesh",
    "CELL_TYPES",
    "THESIS_NODES",
    "hex_mesh",
    "cell_volumes",
    "corner_quality",
    "degenerate_cells",
    "mesh_volume",
]

#: Cell types written, in block order, with their node counts.
CELL_TYPES: dict[str, int] = {"hexahedron": 8, "wedge": 6, "pyramid": 5, "tetra": 4}

#: The thesis's node counts ``(sx, sy, sz)`` of Table 4.4 (MATLAB times 8, 88, 195 s).
THESIS_NODES: tuple[tuple[int, int, int], ...] = ((11, 21, 5), (21, 39, 6), (41, 39, 6))

# Corner numbering of a hexahedron in the reference cube (ξ, η, ζ) = (u, v, w)
# index offsets; VTK/meshio order: bottom face 0-1-2-3 (ζ = 0) turning about +ζ.
_HEX_OFFSETS = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=np.intp
)

# Lower-order cells from a positively oriented hexahedron whose corners collapse
# (columns of the 8-corner array, in the written cell's node order):
#   spine (ζ = 0 edge pairs 0≡3, 1≡2): wedge, triangles on the ξ = 0 and ξ = 1 faces
#   pole at ξ = 0 (0≡3≡4≡7): pyramid on the ξ = 1 face, apex the pole
#   pole at ξ = 1 (1≡2≡5≡6): pyramid on the ξ = 0 face, apex the pole
#   pole and spine: tetrahedron
_TEMPLATES: dict[str, list[int]] = {
    "hexahedron": [0, 1, 2, 3, 4, 5, 6, 7],
    "wedge": [0, 7, 4, 1, 6, 5],
    "pyramid0": [1, 5, 6, 2, 0],
    "pyramid1": [0, 3, 7, 4, 1],
    "tetra0": [1, 5, 6, 0],
    "tetra1": [0, 7, 4, 1],
}
# the corner pairs that must coincide for each template (index-logic check)
_COLLAPSED: dict[str, list[tuple[int, int]]] = {
    "hexahedron": [],
    "wedge": [(0, 3), (1, 2)],
    "pyramid0": [(0, 3), (0, 4), (0, 7)],
    "pyramid1": [(1, 2), (1, 5), (1, 6)],
    "tetra0": [(0, 3), (0, 4), (0, 7), (1, 2)],
    "tetra1": [(1, 2), (1, 5), (1, 6), (0, 3)],
}

# Each written cell type as a (possibly degenerate) trilinear hexahedron:
# columns of the cell's own connectivity in hexahedron order.
_AS_HEX: dict[str, list[int]] = {
    "hexahedron": [0, 1, 2, 3, 4, 5, 6, 7],
    "wedge": [0, 1, 2, 2, 3, 4, 5, 5],
    "pyramid": [0, 1, 2, 3, 4, 4, 4, 4],
    "tetra": [0, 1, 2, 2, 3, 3, 3, 3],
}


def _rotations() -> list[np.ndarray]:
    """The 24 rotations of the reference cube as permutations of its 8 corners (``c[σ]`` is the
    rotated cell's corner array)."""
    import itertools

    centred = 2 * _HEX_OFFSETS - 1
    index = {tuple(c): i for i, c in enumerate(centred)}
    out = []
    for perm in itertools.permutations(range(3)):
        for signs in itertools.product((1, -1), repeat=3):
            m = np.zeros((3, 3), dtype=np.intp)
            for r, (c, sg) in enumerate(zip(perm, signs)):
                m[r, c] = sg
            if round(np.linalg.det(m)) == 1:
                out.append(np.array([index[tuple(m @ c)] for c in centred], dtype=np.intp))
    return out


def _signature(pairs) -> frozenset:
    """The classes of coincident corners (of two or more) that the corner ``pairs`` make."""
    cls = {i: {i} for i in range(8)}
    for a, b in pairs:
        if cls[a] is not cls[b]:
            merged = cls[a] | cls[b]
            for i in merged:
                cls[i] = merged
    return frozenset(frozenset(c) for c in cls.values() if len(c) > 1)


# every collapse of a positively oriented hexahedron into a wedge, pyramid or tetrahedron: the templates
# above in each of the cube's 24 rotations, keyed by the classes of coincident corners; the value is the
# written cell's type and its columns of the hexahedron's corners (rotations keep the orientation)
_DEGENERATE: dict[frozenset, tuple[str, np.ndarray]] = {}
for _sigma in _rotations():
    for _name in ("wedge", "pyramid0", "pyramid1", "tetra0", "tetra1"):
        _key = _signature([(_sigma[a], _sigma[b]) for a, b in _COLLAPSED[_name]])
        _DEGENERATE.setdefault(_key, (_name.rstrip("01"), _sigma[_TEMPLATES[_name]]))

#: A patch's solid is flat (zero volume, all its cells dropped) when the sum of
#: its cells' signed volumes is at most FLAT × (bounding-box diagonal)³.
FLAT = 1e-9

_CHUNK = 1 << 17


@dataclass(frozen=True, eq=False)
class SolidMesh:
    """A conforming mesh of a tablet's solid.

    Attributes
    ----------
    points : ndarray, shape (m, 3)
        Node coordinates, mm.  Every node is used by at least one cell.
    cells : dict[str, ndarray]
        Connectivity per cell type, meshio names and node order:
        ``"hexahedron"`` (k, 8), ``"wedge"`` (k, 6), ``"pyramid"`` (k, 5),
        ``"tetra"`` (k, 4).  Types without cells are omitted.
    patch_id : dict[str, ndarray]
        For every block of ``cells``, the index of the patch each cell comes from.
    nodes : (int, int, int)
        The ``(sx, sy, sz)`` node counts per patch the mesh was built with.
    u_nodes : tuple of ndarray
        Per patch, the ``u`` values of its node layers (all ``sx`` of them
        unless some were left out of a fold of the solid map).
    dropped : int
        Grid cells not written: flat ones (zero volume) and those collapsing
        to fewer than four nodes.
    nonconforming : tuple of str
        Names of the flat patches (a land) between two patches with volume whose end rows differ: the two
        solids beside them meet across the flat patch's plane without sharing their nodes there (the cup's
        nodes along its rim's radius, the band's along its own), so the mesh is not conforming across
        that plane (empty when it is conforming throughout).
    """

    points: np.ndarray
    cells: dict
    patch_id: dict
    nodes: tuple = (0, 0, 0)
    u_nodes: tuple = ()
    dropped: int = field(default=0)
    nonconforming: tuple = ()

    @property
    def n_points(self) -> int:
        """Number of nodes."""
        return int(self.points.shape[0])

    @property
    def n_cells(self) -> int:
        """Number of cells of every type."""
        return int(sum(c.shape[0] for c in self.cells.values()))

    def counts(self) -> dict[str, int]:
        """Number of cells per type."""
        return {k: int(c.shape[0]) for k, c in self.cells.items()}

    def to_meshio(self):
        """The mesh as a :class:`meshio.Mesh` with cell data ``patch_id``."""
        import meshio

        blocks = [(k, c) for k, c in self.cells.items()]
        return meshio.Mesh(
            self.points,
            blocks,
            cell_data={"patch_id": [self.patch_id[k].astype(np.int32) for k, _ in blocks]},
        )


# ---------------------------------------------------------------------------- volumes
def _face_flux(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """``(a + b + c + d) · ((c - a) × (d - b))`` for bilinear quads ``a b c d`` (..., 3).

    Summed over the six faces of a trilinear hexahedron (outward order) and
    divided by 24, it is the hexahedron's exact volume ``∫ det J``.
    """
    s = a + b + c + d
    p = c - a
    q = d - b
    return (
        s[..., 0] * (p[..., 1] * q[..., 2] - p[..., 2] * q[..., 1])
        + s[..., 1] * (p[..., 2] * q[..., 0] - p[..., 0] * q[..., 2])
        + s[..., 2] * (p[..., 0] * q[..., 1] - p[..., 1] * q[..., 0])
    )


# outward faces of the reference hexahedron (VTK order)
_HEX_FACES = ((0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (2, 3, 7, 6), (0, 4, 7, 3), (1, 2, 6, 5))


def _hex_volumes(x: np.ndarray) -> np.ndarray:
    """Exact volumes (mm³) of trilinear hexahedra with corners ``x`` (k, 8, 3).

    Equal to 2×2×2 Gauss quadrature of ``det J`` (exact for the trilinear map)
    and to the volume bounded by the six bilinear faces.  Corners are taken
    relative to corner 0 to keep rounding small.
    """
    x = x - x[:, :1, :]
    vol = np.zeros(x.shape[0])
    for f in _HEX_FACES:
        vol += _face_flux(x[:, f[0]], x[:, f[1]], x[:, f[2]], x[:, f[3]])
    return vol / 24.0


def cell_volumes(mesh: SolidMesh) -> dict[str, np.ndarray]:
    """Volume (mm³) of every cell, per block of ``mesh.cells``.

    Each cell is evaluated as the trilinear hexahedron it is a (possibly
    degenerate) case of; for a tetrahedron that is its exact volume, for a
    wedge or pyramid the volume bounded by its planar triangles and bilinear
    quadrilaterals.  Positive for every cell in meshio's node order.
    """
    out = {}
    for kind, conn in mesh.cells.items():
        cols = _AS_HEX[kind]
        vols = np.empty(conn.shape[0])
        for s in range(0, conn.shape[0], _CHUNK):
            c = conn[s : s + _CHUNK][:, cols]
            vols[s : s + _CHUNK] = _hex_volumes(mesh.points[c])
        out[kind] = vols
    return out


# the three neighbours of every corner, ordered so that the edges to them form a right-handed
# triple in a positively oriented cell (meshio order; a pyramid's apex has none of its own)
_CORNER_EDGES: dict[str, tuple[tuple[int, int, int, int], ...]] = {
    "hexahedron": ((0, 1, 3, 4), (1, 2, 0, 5), (2, 3, 1, 6), (3, 0, 2, 7),
                   (4, 7, 5, 0), (5, 4, 6, 1), (6, 5, 7, 2), (7, 6, 4, 3)),
    "wedge": ((0, 1, 2, 3), (1, 2, 0, 4), (2, 0, 1, 5), (3, 5, 4, 0), (4, 3, 5, 1), (5, 4, 3, 2)),
    "pyramid": ((0, 1, 3, 4), (1, 2, 0, 4), (2, 3, 1, 4), (3, 0, 2, 4)),
    "tetra": ((0, 1, 2, 3), (1, 2, 0, 3), (2, 0, 1, 3), (3, 2, 1, 0)),
}


def corner_quality(mesh: SolidMesh) -> dict[str, np.ndarray]:
    """The smallest scaled Jacobian of every cell over its corners, per block of ``mesh.cells``.

    At a corner with edges ``a, b, c`` to its three neighbours (a right-handed triple in a
    positively oriented cell) the scaled Jacobian is ``det[a, b, c] / (|a| |b| |c|)``: 1 for a
    right angle, 0 where the edges are coplanar or one has no length (a cell whose face
    collapses onto a line, or a hexahedron with repeated nodes), negative for an inverted
    corner.  This is the corner value of Gmsh's ``minSJ`` quality (dimensionless).
    """
    out = {}
    for kind, conn in mesh.cells.items():
        q = np.full(conn.shape[0], np.inf)
        for corner, i, j, k in _CORNER_EDGES[kind]:
            x = mesh.points[conn[:, corner]]
            a, b, c = mesh.points[conn[:, i]] - x, mesh.points[conn[:, j]] - x, mesh.points[conn[:, k]] - x
            det = np.einsum("ij,ij->i", a, np.cross(b, c))
            size = np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1) * np.linalg.norm(c, axis=1)
            q = np.minimum(q, np.divide(det, size, out=np.zeros_like(det), where=size > 0))
        out[kind] = q
    return out


def degenerate_cells(mesh: SolidMesh, threshold: float = 1e-9) -> dict[str, int]:
    """Cells whose smallest corner scaled Jacobian (:func:`corner_quality`) is at most ``threshold``:
    where the solid map of eq 4.12 collapses (a shaped cup folded onto its centre line or corners,
    next to the spine).  Their volumes are positive; a solver that checks corner Jacobians refuses them."""
    return {k: int(np.count_nonzero(q <= threshold)) for k, q in corner_quality(mesh).items()}


def mesh_volume(mesh: SolidMesh) -> float:
    """Total volume (mm³) of the mesh's cells (see :func:`cell_volumes`).

    Converges to :meth:`Tablet.solid_volume` (the triple integral of the
    Jacobian of eq 4.12) at second order in the node spacing.
    """
    return float(sum(float(np.sum(v)) for v in cell_volumes(mesh).values()))


def _structured_volumes(P: np.ndarray) -> np.ndarray:
    """Signed volumes of all cells of a structured node grid ``P`` (nx, ny, nz, 3).

    Uses the face-flux form of :func:`_hex_volumes` with each grid face
    computed once.  Returns (nx-1, ny-1, nz-1), ordered (ξ, η, ζ) = (i, j, k).
    """
    P = P - P.reshape(-1, 3).mean(axis=0)
    # ξ-faces (normal +ξ): (j,k) -> (j+1,k) -> (j+1,k+1) -> (j,k+1)
    Fx = _face_flux(P[:, :-1, :-1], P[:, 1:, :-1], P[:, 1:, 1:], P[:, :-1, 1:])
    vol = Fx[1:] - Fx[:-1]
    del Fx
    # η-faces (normal +η): (k,i) -> (k+1,i) -> (k+1,i+1) -> (k,i+1)
    Fy = _face_flux(P[:-1, :, :-1], P[:-1, :, 1:], P[1:, :, 1:], P[1:, :, :-1])
    vol += Fy[:, 1:] - Fy[:, :-1]
    del Fy
    # ζ-faces (normal +ζ): (i,j) -> (i+1,j) -> (i+1,j+1) -> (i,j+1)
    Fz = _face_flux(P[:-1, :-1, :], P[1:, :-1, :], P[1:, 1:, :], P[:-1, 1:, :])
    vol += Fz[:, :, 1:] - Fz[:, :, :-1]
    return vol / 24.0


# ---------------------------------------------------------------------------- mesh
def _check_nodes(nodes, v_span: float) -> tuple[int, int, int]:
    """Validate ``(sx, sy, sz)``; the ``v`` step must stay below π (a wider step
    would cut the section with a chord on the wrong side of the spine)."""
    try:
        sx, sy, sz = (int(n) for n in nodes)
        ok = len(nodes) == 3 and all(float(n) == int(n) for n in nodes)
    except (TypeError, ValueError):
        raise DesignError("nodes", nodes, "must be three integers (sx, sy, sz)") from None
    sy_min = max(2, int(np.floor(v_span / np.pi)) + 2)
    if not ok or sx < 2 or sz < 2 or sy < sy_min:
        raise DesignError(
            "nodes", tuple(nodes),
            f"must be integers with sx >= 2, sz >= 2 and sy >= {sy_min} (v step below π for this trim)",
        )
    return sx, sy, sz


def _patch_grid(patch, u: np.ndarray, v: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nodes ``X(u_i, v_j, w_k)`` of eq 4.12, shape (nu, nv, nw, 3) mm, and the surface (nu, nv, 3)."""
    S = patch.evaluate_grid(u, v)  # (nu, nv, 3)
    A = patch.spine(u)  # (nu, 3)
    D = S - A[:, None, :]
    P = A[:, None, None, :] + w[None, None, :, None] * D[:, :, None, :]
    return P, S


def _oriented_volumes(P: np.ndarray, sign: float) -> tuple[np.ndarray, np.ndarray]:
    """(signed volumes × sign, inverted mask: volume <= 0) of the cells of grid ``P``."""
    vol = _structured_volumes(P) * sign
    return vol, vol <= 0.0


def _is_flat(P: np.ndarray, total: float) -> bool:
    """Whether a patch's solid has no volume: |Σ cell volumes| <= FLAT · (bounding-box diagonal)³."""
    ext = np.ptp(P.reshape(-1, 3), axis=0)
    return abs(total) <= FLAT * float(np.dot(ext, ext)) ** 1.5


def _drop_fold_nodes(patch, u: np.ndarray, v: np.ndarray, w: np.ndarray, sign: float, p: int):
    """Remove interior ``u`` nodes bounding layers of inverted cells, until none is left.

    Where the spine ``A0(u)`` of eq 4.12 runs backwards (near the poles of the
    thesis's domes the cubic spine through the curve centres dips below the
    pole by up to a few µm for ``u`` < ~0.03) the solid map folds over and a
    fine layer of cells there is inverted.  Merging those layers with their
    neighbours gives cells of positive volume that span the fold.
    """
    keep = np.ones(u.size, dtype=bool)
    while True:
        P, S = _patch_grid(patch, u[keep], v, w)
        vol, inverted = _oriented_volumes(P, sign)
        bad = np.flatnonzero(np.any(inverted, axis=(1, 2)))
        if bad.size == 0:
            return u[keep], P, S, vol
        idx = np.flatnonzero(keep)
        n = idx.size
        drop = set()
        for layer in bad:
            for node in (layer, layer + 1):
                if 0 < node < n - 1:
                    drop.add(int(idx[node]))
        if not drop:
            raise GeometryError(
                f"patch {p}: {int(np.sum(inverted))} of {vol.size} cells have negative volume "
                f"(the solid map of eq 4.12 folds over)",
                patch,
            )
        keep[sorted(drop)] = False


def hex_mesh(tablet: "Tablet", nodes: tuple[int, int, int] = (11, 21, 5), *, check: bool = True) -> SolidMesh:
    """Mesh the tablet's solid with hexahedra (thesis section 4.3, eq 4.12).

    Parameters
    ----------
    tablet : Tablet
        The tablet; its :class:`~tabletcad.geometry.tablet.Trim` gives the ``u``, ``v``
        and ``w`` ranges meshed (e.g. the ring's ``w ∈ [0.5, 1]`` or a cut-away
        ``v ∈ [π/2, 2π]``).
    nodes : (sx, sy, sz)
        Nodes per patch along ``u``, ``v`` and ``w``, equally spaced over the
        trim ranges and including both ends (for a full turn in ``v`` the last
        ``v`` node is merged with the first).  A patch without degenerate
        cells gives ``(sx-1)(sy-1)(sz-1)`` hexahedra (thesis Table 4.4).
        Exception: interior ``u`` nodes inside a fold of the solid map (where
        the spine runs backwards, see :func:`_drop_fold_nodes`) are left out so
        that no cell is inverted; :attr:`SolidMesh.u_nodes` lists the ``u``
        values actually used per patch.
    check : bool
        Verify the index-based merges (every merged node within
        ``tablet.tol.seam_gap`` mm of its representative, collapsed corners
        identical, written corners distinct).  Cheap; on by default.

    Returns
    -------
    SolidMesh

    Raises
    ------
    DesignError
        For invalid node counts.
    GeometryError
        If a merge fails its distance check or a cell has negative volume that
        removing ``u`` nodes cannot cure (the solid map of eq 4.12 folds over).
    """
    t = tablet.trim
    sx, sy, sz = _check_nodes(nodes, t.v[1] - t.v[0])
    grids = _patch_grids(tablet, np.linspace(t.u[0], t.u[1], sx), np.linspace(t.v[0], t.v[1], sy),
                         np.linspace(t.w[0], t.w[1], sz))
    offsets = np.cumsum([0] + [g.P.shape[0] * sy * sz for g in grids])
    raw, rep = _merged_nodes(tablet, grids, offsets)
    if check:
        _check_merge(tablet, raw, rep, offsets)
    rep = _geometric_merge(tablet, raw, rep)
    blocks: dict[str, list[np.ndarray]] = {k: [] for k in CELL_TYPES}
    pids: dict[str, list[np.ndarray]] = {k: [] for k in CELL_TYPES}
    dropped = 0
    for p, g in enumerate(grids):
        cells, n_dropped = _patch_cells(tablet, p, g, int(offsets[p]), rep, check)
        dropped += n_dropped
        for kind, conn in cells:
            blocks[kind].append(conn)
            pids[kind].append(np.full(conn.shape[0], p, dtype=np.int32))
    cells = {k: np.concatenate(b) for k, b in blocks.items() if b}
    if not cells:
        raise GeometryError("the tablet's solid has no cell of positive volume", tablet)
    # compact: keep only referenced nodes
    used = np.zeros(raw.shape[0], dtype=bool)
    for conn in cells.values():
        used[conn.ravel()] = True
    new = np.cumsum(used, dtype=np.int64) - 1
    return SolidMesh(points=raw[used], cells={k: new[c] for k, c in cells.items()},
                     patch_id={k: np.concatenate(pids[k]) for k in cells}, nodes=(sx, sy, sz),
                     u_nodes=tuple(g.u for g in grids), dropped=dropped,
                     nonconforming=_nonconforming(tablet, grids))


def _nonconforming(tablet: "Tablet", grids: list["_Grid"]) -> tuple[str, ...]:
    """Names of the runs of flat patches between two patches with volume whose first and last rows differ
    (by more than ``tol.seam_gap``): see :attr:`SolidMesh.nonconforming`."""
    out = []
    p = 1
    while p < len(grids) - 1:
        if not grids[p].flat:
            p += 1
            continue
        q = p
        while q < len(grids) - 1 and grids[q].flat:
            q += 1
        # flat patches p .. q-1, then patch q; patch p-1 before them
        if q < len(grids) and not grids[q].flat and not grids[p - 1].flat:
            gap = float(np.max(np.linalg.norm(grids[p].P[0] - grids[q - 1].P[-1], axis=-1)))
            if gap > tablet.tol.seam_gap:
                out.extend(tablet.patches[k].name or f"patch {k}" for k in range(p, q))
        p = q
    return tuple(out)


class _Grid(NamedTuple):
    """One patch's nodes: ``u`` values kept, points ``P`` (nu, sy, sz, 3), cell volumes, whether the
    patch is flat (no volume), its orientation sign, poles at ``u = 0``/``1``, and whether its
    ``u = 0`` row is the previous patch's ``u = 1`` row."""

    u: np.ndarray
    P: np.ndarray
    vol: np.ndarray
    flat: bool
    sign: float
    pole0: bool
    pole1: bool
    shared: bool


def _patch_grids(tablet: "Tablet", u_all: np.ndarray, v: np.ndarray, w: np.ndarray) -> list[_Grid]:
    """Every patch's node grid over the trim ranges (fold nodes dropped), with its degeneracies."""
    t = tablet.trim
    gap = float(tablet.tol.seam_gap)
    full_u = t.u[0] == 0.0 and t.u[1] == 1.0
    grids: list[_Grid] = []
    for p, patch in enumerate(tablet.patches):
        P, S = _patch_grid(patch, u_all, v, w)
        vol = _structured_volumes(P)
        total = float(np.sum(vol))
        sign = 1.0 if total >= 0.0 else -1.0
        u = u_all
        flat = _is_flat(P, total)
        if not flat:
            vol *= sign
            if np.any(vol <= 0.0):
                u, P, S, vol = _drop_fold_nodes(patch, u_all, v, w, sign, p)
        scale = max(1.0, float(np.max(np.abs(S))))
        pole0 = t.u[0] == 0.0 and float(np.max(np.ptp(S[0], axis=0))) <= gap * scale
        pole1 = t.u[1] == 1.0 and float(np.max(np.ptp(S[-1], axis=0))) <= gap * scale
        shared = False
        if p > 0 and full_u:
            prev_end = grids[-1].P[-1, :, -1]  # previous patch's surface at u = 1
            shared = float(np.max(np.linalg.norm(prev_end - S[0], axis=-1))) <= gap * scale
        grids.append(_Grid(u, P, vol, flat, sign, pole0, pole1, shared))
    return grids


def _merged_nodes(tablet: "Tablet", grids: list[_Grid], offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All nodes (``raw``, patch after patch) and each node's representative index ``rep``: the
    seam in ``v``, the spine, the poles and the rows shared between patches merged by index."""
    t = tablet.trim
    sy, sz = grids[0].P.shape[1:3]
    raw = np.empty((int(offsets[-1]), 3))
    rep = np.arange(int(offsets[-1]), dtype=np.intp)
    for p, g in enumerate(grids):
        nu = g.u.size
        raw[offsets[p] : offsets[p + 1]] = g.P.reshape(-1, 3)
        r = rep[offsets[p] : offsets[p + 1]].reshape(nu, sy, sz)  # a view: edits land in rep
        if t.full_v:
            r[:, -1, :] = r[:, 0, :]
        if t.w[0] == 0.0:  # the spine layer
            r[:, :, 0] = r[:, 0:1, 0]
        if g.pole0:
            r[0] = r[0, 0, 0]
        if g.pole1:
            r[-1] = r[-1, 0, 0]
        if g.shared:
            nprev = grids[p - 1].u.size
            r[0] = rep[offsets[p - 1] : offsets[p]].reshape(nprev, sy, sz)[-1]
    return raw, rep


def _check_merge(tablet: "Tablet", raw: np.ndarray, rep: np.ndarray, offsets: np.ndarray) -> None:
    """Every merged node within ``tablet.tol.seam_gap`` (relative to the size, at least 1 mm) of its
    representative; raises :class:`GeometryError` when the degeneracies assumed by index do not hold."""
    if not np.array_equal(rep[rep], rep):  # pragma: no cover - index logic
        raise GeometryError("node merge is not idempotent (internal error)")
    dist = np.linalg.norm(raw - raw[rep], axis=1)
    scale = max(1.0, float(np.max(np.abs(raw))))
    bad = dist > float(tablet.tol.seam_gap) * scale
    if np.any(bad):
        k = int(np.argmax(dist))
        p = int(np.searchsorted(offsets, k, side="right")) - 1
        raise GeometryError(
            f"{int(np.sum(bad))} merged nodes are up to {dist[k]:.3g} mm from their representative "
            f"(patch {p}); the degeneracies assumed by index do not hold",
            tablet,
        )


def _patch_cells(tablet: "Tablet", p: int, g: _Grid, offset: int, rep: np.ndarray,
                 check: bool) -> tuple[list[tuple[str, np.ndarray]], int]:
    """The cells of patch ``p`` as ``(kind, connectivity)`` blocks, and the number of cells dropped
    (collapsed to nothing, or all cells of a flat patch)."""
    sy, sz = g.P.shape[1:3]
    nu = g.u.size
    shape = (nu - 1, sy - 1, sz - 1)
    # corner raw indices; a negatively oriented patch swaps η -> 1 - η
    offs = _HEX_OFFSETS.copy()
    if g.sign < 0:
        offs[:, 1] = 1 - offs[:, 1]
    ii = np.arange(nu - 1)[:, None, None]
    jj = np.arange(sy - 1)[None, :, None]
    kk = np.arange(sz - 1)[None, None, :]
    base = offset + (ii * sy + jj) * sz + kk  # (nu-1, sy-1, sz-1)
    corner = np.empty(shape + (8,), dtype=np.intp)
    for c, (a, b, d) in enumerate(offs):
        corner[..., c] = rep[base + (a * sy + b) * sz + d]
    # classify by index: which degeneracies touch the cell
    spine = np.zeros(shape, dtype=bool)
    if tablet.trim.w[0] == 0.0:
        spine[:, :, 0] = True
    at0 = np.zeros(shape, dtype=bool)
    at1 = np.zeros(shape, dtype=bool)
    if g.pole0:
        at0[0] = True
    if g.pole1:
        at1[-1] = True
    keep = ~(at0 & at1) if not g.flat else np.zeros(shape, dtype=bool)
    if check and np.any(keep & (g.vol <= 0.0)):  # pragma: no cover - guarded by _drop_fold_nodes
        raise GeometryError(f"patch {p}: cells of non-positive volume", tablet.patches[p])
    kinds = {
        "hexahedron": keep & ~spine & ~at0 & ~at1,
        "wedge": keep & spine & ~at0 & ~at1,
        "pyramid0": keep & ~spine & at0,
        "pyramid1": keep & ~spine & at1,
        "tetra0": keep & spine & at0,
        "tetra1": keep & spine & at1,
    }
    out: list[tuple[str, np.ndarray]] = []
    dropped = 0
    for name, mask in kinds.items():
        if not np.any(mask):
            continue
        cc = corner[mask]
        if check:
            for x, y in _COLLAPSED[name]:
                if not np.array_equal(cc[:, x], cc[:, y]):  # pragma: no cover - index logic
                    raise GeometryError(f"patch {p}: {name} cells with corners {x}, {y} not merged")
        conn = cc[:, _TEMPLATES[name]]
        srt = np.sort(conn, axis=1)
        more = np.any(srt[:, 1:] == srt[:, :-1], axis=1)  # collapsed further than the index logic knows
        out.append((name.rstrip("01"), conn[~more]))
        if np.any(more):
            extra, n_gone = _collapsed_cells(tablet, p, cc[more])
            out += extra
            dropped += n_gone
    return [(k, c) for k, c in out if len(c)], int(np.sum(~keep)) + dropped


def _collapsed_cells(tablet: "Tablet", p: int, corners: np.ndarray) -> tuple[list[tuple[str, np.ndarray]], int]:
    """Hexahedra (rows of 8 corner node indices) whose corners coincide in a way the index logic does
    not know (a shaped cup's centre line, where the surface folds onto a segment and nodes of mirror
    ``v`` meet): each written as the wedge, pyramid or tetrahedron its classes of coincident corners
    make (:data:`_DEGENERATE`), or dropped with fewer than four distinct corners; one that none of
    them describes (next to both the spine and a collapsed corner: two bilinear sides share two edges)
    is kept as the degenerate hexahedron it is, its repeated nodes shared with its neighbours (conforming
    as a map: its collapsed quads interpolate linearly and match the neighbouring triangles; tools that
    match faces by node lists, VTK's surface filter and gmsh, see them as extra faces, and its corner
    Jacobians vanish there).  Returns the blocks and the number dropped."""
    blocks: dict[str, list[np.ndarray]] = {}
    gone = 0
    for row in corners:
        if len(set(row.tolist())) < 4:
            gone += 1
            continue
        pairs = [(a, b) for a in range(8) for b in range(a + 1, 8) if row[a] == row[b]]
        hit = _DEGENERATE.get(_signature(pairs))
        if hit is None:  # (a pyramid-like cell whose sides are bilinear quads: a degenerate hexahedron)
            blocks.setdefault("hexahedron", []).append(row)
        else:
            blocks.setdefault(hit[0], []).append(row[hit[1]])
    return [(k, np.array(v, dtype=np.intp)) for k, v in blocks.items()], gone


def _geometric_merge(tablet: "Tablet", raw: np.ndarray, rep: np.ndarray) -> np.ndarray:
    """``rep`` with representatives that lie within ``tablet.tol.seam_gap`` (relative to the size, at
    least 1 mm) of each other merged too: coincidences the index logic does not know, such as the two
    sides of a shaped cup's centre line, where the surface folds onto a segment.  Each group of such
    nodes takes its lowest index (connected components of the pairs, scipy.sparse.csgraph)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    reps = np.flatnonzero(rep == np.arange(rep.size))  # the representatives (rep is idempotent)
    scale = max(1.0, float(np.max(np.abs(raw))))
    pairs = cKDTree(raw[reps]).query_pairs(float(tablet.tol.seam_gap) * scale, output_type="ndarray")
    if len(pairs) == 0:
        return rep
    n = reps.size
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    lowest = np.full(label.max() + 1, n, dtype=np.intp)
    np.minimum.at(lowest, label, np.arange(n))
    final = np.empty(raw.shape[0], dtype=np.intp)
    final[reps] = reps[lowest[label]]
    return final[rep]


# ---------------------------------------------------------------------------- output
