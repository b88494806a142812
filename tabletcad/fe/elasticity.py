"""Linear isotropic elasticity on quadratic tetrahedra (scikit-fem ``ElementTetP2``).

The stiffness is scikit-fem's ``linear_elasticity`` form, evaluated with scikit-fem's
quadratic basis and quadrature in one vectorised product over the elements and summed
by 3 x 3 blocks of the scalar unknowns (:func:`stiffness`: the same matrix to round-off
as ``skfem.asm(linear_elasticity)``, tested, about fifteen times faster); the geometry is the
linear tetrahedral mesh of :mod:`tabletcad.fe.mesh`, the displacement is
quadratic, so the stress is linear in each element and is evaluated exactly
at the element vertices (no smoothing).

Loads are normal pressures on sets of boundary facets.  A tablet in a
diametral test and a punch tip under a balanced load carry *self-equilibrated*
loads: the body is then held by a statically determinate 3-2-1 support
(three unknowns fixed at one node, two at a second, one at a third) that only
removes the six rigid-body motions.  For a balanced load the support
reactions are zero up to round-off (they are returned and checked), so the
stresses are those of the free body; weak springs would instead load the body
slightly everywhere.  For traction loads the stresses do not depend on E (and
scale linearly with the load); E only scales the displacements.

Mirror-symmetric problems can be solved on the part of the body on one side of
two or three coordinate mirror planes (``symmetry=``): the normal displacement
vanishes on each plane (the tangential traction vanishes there naturally), one
unknown fixes the translation the planes leave free, and the solution is
unfolded to the whole body by reflection (:func:`unfold`), so that stresses are
read from a full, exactly symmetric field.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from tabletcad.errors import DesignError, GeometryError, check_finite, check_positive, check_range, run_interruptibly
from tabletcad.fe.mesh import TetMesh

__all__ = ["Material", "PressureLoad", "ElasticSolution", "boundary_facets", "solve_elasticity", "stiffness",
           "principal_stresses", "von_mises", "unfold"]


@dataclass(frozen=True)
class Material:
    """Isotropic linear-elastic material.

    Attributes
    ----------
    E : float
        Young's modulus, MPa.
    nu : float
        Poisson's ratio, ``-1 < nu < 0.5``.
    """

    E: float = 5000.0
    nu: float = 0.3

    def __post_init__(self) -> None:
        check_range("E", self.E, 1e-3, 1e7, "MPa")  # (diamond: 1.2e6 MPa; 1e-300 overflowed the solve)
        nu = check_finite("nu", self.nu)
        if not (-0.9 <= nu <= 0.49):  # nearly incompressible (0.4999) stalled the direct solve for minutes
            raise DesignError("nu", self.nu, "must be >= -0.9 and <= 0.49 (towards 0.5 the quadratic tetrahedra's "
                              "system becomes singular)")

    @property
    def lame(self) -> tuple[float, float]:
        """Lamé parameters (λ, μ), MPa."""
        lam = self.E * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))
        return lam, self.E / (2.0 * (1.0 + self.nu))


@dataclass(frozen=True, eq=False)
class PressureLoad:
    """A uniform normal pressure (MPa, positive pushes inwards) on boundary facets.

    ``facets`` index the rows of :func:`boundary_facets`' arrays.
    """

    facets: np.ndarray
    pressure: float


@dataclass(frozen=True, eq=False)
class BoundaryFacets:
    """Boundary facets of a mesh: skfem facet ids, centroids (mm), outward unit normals and areas (mm²)."""

    ids: np.ndarray
    centroids: np.ndarray
    normals: np.ndarray
    areas: np.ndarray

    def resultant(self, load: PressureLoad) -> np.ndarray:
        """Force vector (N) of a pressure load: ``-p Σ n A``."""
        f = load.facets
        return -load.pressure * (self.normals[f] * self.areas[f, None]).sum(axis=0)


def _skfem_mesh(mesh: TetMesh) -> Any:
    import skfem

    return skfem.MeshTet(np.ascontiguousarray(mesh.points.T, dtype=float),
                         np.ascontiguousarray(mesh.tets.T, dtype=np.int64))


def boundary_facets(m: Any) -> BoundaryFacets:
    """Boundary facets of a skfem ``MeshTet`` with outward normals."""
    ids = m.boundary_facets()
    tri = m.p[:, m.facets[:, ids]]  # (3, 3 vertices, k)
    c = tri.mean(axis=1).T
    nrm = np.cross((tri[:, 1] - tri[:, 0]).T, (tri[:, 2] - tri[:, 0]).T)
    area = 0.5 * np.linalg.norm(nrm, axis=1)
    nrm /= (2.0 * area)[:, None]
    cell = m.f2t[0, ids]
    inside = m.p[:, m.t[:, cell]].mean(axis=1).T
    flip = np.einsum("ij,ij->i", nrm, c - inside) < 0
    nrm[flip] *= -1.0
    return BoundaryFacets(ids=ids, centroids=c, normals=nrm, areas=area)


@dataclass(frozen=True, eq=False)
class ElasticSolution:
    """A solved elastic problem.

    Attributes
    ----------
    mesh : skfem.MeshTet
        The mesh (vertices ``mesh.p`` (3, n), mm; tetrahedra ``mesh.t`` (4, m)).
    displacement : ndarray, shape (n, 3)
        Displacement at the mesh vertices, mm.
    vertex_stress : ndarray, shape (m, 4, 3, 3)
        Cauchy stress (MPa) at the four vertices of every element (exact for P2).
    dofs : int
        Number of unknowns.
    reaction : float
        Largest support reaction, N (zero for a balanced load).
    load_scale : float
        Largest load resultant component, N (to judge ``reaction``).
    work : float
        Work of the loads ``f·u`` (N·mm), twice the strain energy; it increases
        towards its exact value as the mesh refines (the discrete body is stiffer).
    """

    mesh: Any
    displacement: np.ndarray
    vertex_stress: np.ndarray
    dofs: int
    reaction: float
    load_scale: float
    work: float = float("nan")

    @property
    def nodes(self) -> int:
        return int(self.mesh.p.shape[1])

    @property
    def elements(self) -> int:
        return int(self.mesh.t.shape[1])

    def nodal_stress(self) -> np.ndarray:
        """Stress (MPa) at every mesh vertex, shape (n, 3, 3): the mean of the element values there.

        Element values jump between elements by the discretisation error; their
        vertex mean is the usual smoothed field used to locate stress maxima.
        """
        m = self.mesh
        acc = np.zeros((m.p.shape[1], 3, 3))
        cnt = np.zeros(m.p.shape[1])
        for k in range(4):
            np.add.at(acc, m.t[k], self.vertex_stress[:, k])
            np.add.at(cnt, m.t[k], 1.0)
        return acc / cnt[:, None, None]

    def recovered_stress_at(self, x: Sequence[float], radius: float) -> np.ndarray:
        """Stress (3, 3), MPa, at ``x`` (mm) by a least-squares quadratic fit of the element values nearby.

        The element stresses of every element whose centroid lies within
        ``radius`` mm of ``x`` are sampled at its vertices and its centroid and fitted
        by a complete quadratic polynomial in (x, y, z) (patch recovery in the
        manner of Zienkiewicz and Zhu, 1992), which is evaluated at ``x``.  A single
        element's value jumps by the discretisation error from one unstructured mesh
        to the next; the fit averages this out, so the value converges smoothly.
        """
        q = np.asarray(x, float).ravel()
        m = self.mesh
        xv = m.p[:, m.t].transpose(2, 1, 0)  # (m, 4, 3)
        cen = xv.mean(axis=1)
        near = np.flatnonzero(np.linalg.norm(cen - q, axis=1) <= radius)
        if near.size < 20:
            raise GeometryError(f"stress recovery: only {near.size} elements within {radius:g} mm of {q.tolist()}", m)
        pts = np.concatenate([xv[near].reshape(-1, 3), cen[near]]) - q
        vals = np.concatenate([self.vertex_stress[near].reshape(-1, 9), self.vertex_stress[near].mean(axis=1).reshape(-1, 9)])
        X, Y, Z = (pts / radius).T
        A = np.column_stack([np.ones_like(X), X, Y, Z, X * X, Y * Y, Z * Z, X * Y, Y * Z, Z * X])
        q_, r_ = np.linalg.qr(A)  # least squares by a thin QR: the same fit as lstsq's SVD, several times faster
        coef = np.linalg.solve(r_, q_.T @ vals)
        s = coef[0].reshape(3, 3)
        return 0.5 * (s + s.T)

    def averaged_stress(self, points: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
        """Stress (k, 3, 3), MPa, averaged over balls of ``radius`` mm around ``points`` (k, 3), mm.

        The average is weighted by the smooth bump ``w = (1 - r²/R²)²`` (``r`` < ``R``, zero
        beyond, continuous with its derivative) over the part of the ball inside the body:
        ``σ̄(x₀) = ∫ w σ dV / ∫ w dV``.  It is a fixed linear functional of the exact stress field
        (an integral over a ball of fixed size, not over elements), so unlike a vertex or
        element value it converges as the mesh refines, and it stays finite where the pointwise
        elastic stress is singular.  Centres on or near the surface average over the part of
        the ball inside the body.

        The integral is a composite rule: each tetrahedron that can reach a ball is split into
        ``8^k`` sub-tetrahedra (scikit-fem's uniform refinement of the reference element, with
        ``k`` ≤ 2 chosen so that the sub-elements are about ``R`` across or less) carrying scikit-fem's
        degree-2 rule; the P2 stress is linear in each element, so it is evaluated exactly at
        those points from the element's vertex values.  The points' squared distances from a
        centre are evaluated as a quadratic form in their barycentric coordinates
        (:class:`_BumpRule`).

        Returns
        -------
        stress : ndarray, shape (k, 3, 3)
            The averaged stress tensors, MPa.
        fraction : ndarray, shape (k,)
            ``∫_body w dV / ∫_ball w dV``: 1 inside, about 1/2 on a flat face, 0 outside.
        """
        import skfem
        from scipy.spatial import cKDTree
        from skfem.quadrature import get_quadrature
        from skfem.refdom import RefTet

        R = check_positive("averaging_radius", radius, "mm")
        q = np.atleast_2d(np.asarray(points, float))
        m = self.mesh
        xv = m.p[:, m.t].transpose(2, 1, 0)  # (m, 4, 3)
        cen = xv.mean(axis=1)
        diam = np.linalg.norm(xv - cen[:, None], axis=2).max(axis=1)
        # elements whose bounding sphere meets one of the balls
        near_q = cKDTree(q).query_ball_point(cen, diam + R, return_length=True)
        el = np.flatnonzero(near_q > 0)
        if el.size == 0:
            return np.zeros((len(q), 3, 3)), np.zeros(len(q))
        k = int(np.clip(np.ceil(np.log2(max(2.0 * float(diam[el].max()) / R, 1.0))), 0, 2))
        ref = skfem.MeshTet(np.array([[0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]),
                            np.array([[0], [1], [2], [3]]))  # the reference tetrahedron
        ref = ref.refined(k) if k else ref
        X, W = get_quadrature(RefTet, 2)
        # composite rule on the reference tetrahedron: barycentric coordinates and weights
        sub = ref.p[:, ref.t]  # (3, 4, nsub)
        J = np.stack([sub[:, 1] - sub[:, 0], sub[:, 2] - sub[:, 0], sub[:, 3] - sub[:, 0]], axis=1)  # (3, 3, nsub)
        xi = (sub[:, 0][:, None, :] + np.einsum("ijs,jq->iqs", J, X)).reshape(3, -1)  # (3, nq*nsub)
        wr = (np.abs(np.linalg.det(J.transpose(2, 0, 1)))[None, :] * W[:, None]).ravel()
        lam = np.vstack([1.0 - xi.sum(axis=0), xi])  # (4, nq): vertex k of the reference is t[k]
        v = xv[el]  # (e, 4, 3)
        jac = np.abs(np.linalg.det(v[:, 1:] - v[:, :1]))  # 6 x volume
        rule = _BumpRule(v, lam, jac[:, None] * wr[None, :], R)
        ce, de = cen[el], diam[el]
        vs = self.vertex_stress[el].reshape(len(el), 4, 9)
        # per ball, the elements whose bounding sphere meets it; the weighted sum of the (linear) stress
        # over their points is Σ_e Σ_k (Σ_q w λ_k) σ_ek, so only the four vertex weights are summed per point
        cand = cKDTree(ce).query_ball_point(q, R + float(de.max()))
        out = np.zeros((len(q), 9))
        frac = np.zeros(len(q))
        full = 32.0 * np.pi * R**3 / 105.0  # ∫ (1 - r²/R²)² dV over the whole ball: 4πR³ (1/3 - 2/5 + 1/7)
        for i, c in enumerate(cand):
            if not c:
                continue
            c = np.asarray(c)
            c = c[np.linalg.norm(ce[c] - q[i], axis=1) <= R + de[c]]
            w = rule.weights(c, q[i])
            s = w.sum()
            frac[i] = s / full
            if s > 0:
                out[i] = np.einsum("ck,ckj->j", w @ lam.T, vs[c]) / s
        out = out.reshape(-1, 3, 3)
        return 0.5 * (out + out.transpose(0, 2, 1)), frac

    def stress_at(self, x: Sequence[float]) -> np.ndarray:
        """Stress tensor (3, 3), MPa, at point ``x`` (mm), linear in its element."""
        q = np.asarray(x, float).reshape(3, 1)
        try:
            e = int(self.mesh.element_finder()(*q)[0])
        except ValueError:
            raise GeometryError(f"point {np.ravel(q).tolist()} mm is outside the mesh", self.mesh) from None
        v = self.mesh.p[:, self.mesh.t[:, e]]  # (3, 4)
        A = np.vstack([v, np.ones(4)])
        lam = np.linalg.solve(A, np.append(q.ravel(), 1.0))
        return np.einsum("k,kij->ij", lam, self.vertex_stress[e])


class _BumpRule:
    """The weights ``w (1 - r²/R²)²`` (zero for ``r ≥ R``) of a composite quadrature rule's points about a centre.

    The squared distance of a point ``x = Σⱼ λⱼ vⱼ`` (barycentric coordinates λ in an element with
    vertices ``vⱼ``) from a centre ``x₀`` is the quadratic form ``r² = Σⱼ Σₖ λⱼ λₖ (vⱼ - x₀)·(vₖ - x₀)``
    (``Σ λⱼ = 1``): per element and centre only the ten products of the vertices' offsets are formed,
    and the rule's points are weighed by one matrix product with the ten products of their
    coordinates, instead of gathering and differencing every point's coordinates (the same squared
    distances to rounding, about 1e-16 of ``(R + element size)²``).

    Parameters
    ----------
    vertices : ndarray, shape (e, 4, 3)
        The elements' vertices, mm.
    lam : ndarray, shape (4, nq)
        Barycentric coordinates of the rule's points (the same in every element).
    point_weights : ndarray, shape (e, nq)
        The rule's weights in every element, mm³.
    radius : float
        ``R``, mm.
    """

    _PAIRS = np.triu_indices(4)

    def __init__(self, vertices: np.ndarray, lam: np.ndarray, point_weights: np.ndarray, radius: float) -> None:
        j, k = self._PAIRS
        self.vertices = vertices
        self.point_weights = point_weights
        self.radius = radius
        # λⱼ λₖ over the pairs j ≤ k, the off-diagonal ones twice: (10, nq)
        self.products = lam[j] * lam[k] * np.where(j == k, 1.0, 2.0)[:, None]

    def weights(self, elements: np.ndarray, centre: np.ndarray) -> np.ndarray:
        """The weights (len(elements), nq), mm³, of the points of ``elements`` about ``centre`` (3,), mm."""
        j, k = self._PAIRS
        off = self.vertices[elements] - centre  # (c, 4, 3)
        gram = np.einsum("cjd,ckd->cjk", off, off)[:, j, k] / (self.radius * self.radius)  # (c, 10)
        r2 = gram @ self.products
        np.minimum(r2, 1.0, out=r2)
        w = np.subtract(1.0, r2, out=r2)
        w *= w
        w *= self.point_weights[elements]
        return w


def principal_stresses(s: np.ndarray) -> np.ndarray:
    """Principal stresses (ascending), MPa, of stress tensors ``(..., 3, 3)``."""
    return np.linalg.eigvalsh(s)


def von_mises(s: np.ndarray) -> np.ndarray:
    """Von Mises equivalent stress, MPa, of stress tensors ``(..., 3, 3)``."""
    dev = s - np.trace(s, axis1=-2, axis2=-1)[..., None, None] * np.eye(3) / 3.0
    return np.sqrt(1.5 * np.einsum("...ij,...ij->...", dev, dev))


@dataclass(frozen=True, eq=False)
class BlockStiffness:
    """A vector stiffness matrix stored by nodes: one ``dim`` x ``dim`` block per pair of scalar unknowns.

    Attributes
    ----------
    blocks : ndarray, shape (k, dim, dim)
        The blocks, N/mm; block ``s`` couples scalar unknown ``row`` to scalar unknown ``indices[s]``,
        rows given by ``indptr`` (CSR layout of the scalar pattern, columns sorted in every row).
    indptr, indices : ndarray
        The scalar pattern (CSR), ``n`` rows.
    """

    blocks: np.ndarray
    indptr: np.ndarray
    indices: np.ndarray

    def tocsr(self) -> Any:
        """The matrix (CSR, ``dim n`` rows; vector unknown ``dim s + i`` is component ``i`` of scalar
        unknown ``s``), without the entries that are exactly zero."""
        import scipy.sparse as sp

        dim = self.blocks.shape[1]
        n = (len(self.indptr) - 1) * dim
        K = sp.bsr_matrix((self.blocks, self.indices, self.indptr), shape=(n, n)).tocsr()
        K.eliminate_zeros()
        return K

    def pattern(self) -> Any:
        """The scalar pattern as a CSC matrix of ones (symmetric: the stiffness's pattern is)."""
        import scipy.sparse as sp

        n = len(self.indptr) - 1
        return sp.csc_matrix((np.ones(len(self.indices)), self.indices, self.indptr), shape=(n, n))


def _scalar_pairs(sd: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The distinct pairs of scalar unknowns that share an element.

    Parameters
    ----------
    sd : ndarray, shape (nb, nel)
        Scalar unknowns of every element.
    n : int
        Number of scalar unknowns.

    Returns
    -------
    inverse : ndarray, shape (nel * nb * nb,)
        The pair (of the sorted distinct pairs) of local pair ``(e, a, b)``, flattened in that order.
    indptr, indices : ndarray
        The distinct pairs in CSR layout (rows ``a``'s unknown, sorted columns ``b``'s).
    """
    idx = np.int64
    key = sd.T.astype(idx)[:, :, None] * n + sd.T.astype(idx)[:, None, :]  # (nel, nb, nb)
    pairs, inverse = np.unique(key.ravel(), return_inverse=True)
    rows = pairs // n
    indptr = np.zeros(n + 1, dtype=idx)
    np.cumsum(np.bincount(rows, minlength=n), out=indptr[1:])
    return inverse.ravel(), indptr, pairs - rows * n


def block_stiffness(basis: Any, lam: float, mu: float, chunk: int = 8192) -> BlockStiffness:
    """Stiffness of isotropic linear elasticity on ``basis`` (scikit-fem ``ElementVector`` of a scalar
    element), by blocks of scalar unknowns (see :func:`stiffness`, whose matrix this is).

    Entry ``((a, i), (b, j))`` of an element is ``∫ λ ∂ᵢφₐ ∂ⱼφ_b + μ (∂ⱼφₐ ∂ᵢφ_b + δᵢⱼ ∇φₐ·∇φ_b) dx``
    (N/mm, with λ, μ in MPa and lengths in mm): the nine integrals ``∫ ∂ₖφₐ ∂ₗφ_b`` of every element
    (``chunk`` elements at a time) are summed into the pairs of scalar unknowns ``(a, b)`` they belong
    to first, and the blocks are formed from the sums.  Vector unknown ``dim s + i`` must be component ``i`` of scalar unknown ``s`` (as
    scikit-fem numbers an ``ElementVector``'s); ``ValueError`` otherwise.
    """
    import skfem

    sb = skfem.CellBasis(basis.mesh, basis.elem.elem, quadrature=(basis.X, basis.W))
    nb, dim = sb.Nbfun, basis.elem.dim
    expect = (dim * sb.element_dofs[:, None, :] + np.arange(dim)[None, :, None]).reshape(nb * dim, -1)
    if basis.Nbfun != nb * dim or basis.N != dim * sb.N or not np.array_equal(basis.element_dofs, expect):
        raise ValueError(f"stiffness: {basis.Nbfun} local functions not numbered as {nb} scalar ones x "
                         f"{dim} components")
    return _scalar_block_stiffness(sb, dim, lam, mu, chunk)


def _gradient_products(g: np.ndarray, dx: np.ndarray) -> np.ndarray:
    """The integrals ``∫ ∂ₖφₐ ∂ₗφ_b`` (mm) of every element, shape (e, nb, dim, nb, dim) in the order (e, a, k, b, l).

    Parameters
    ----------
    g : ndarray, shape (nb, dim, e, nq)
        The basis functions' gradients at the quadrature points, 1/mm.
    dx : ndarray, shape (e, nq)
        The quadrature weights times the Jacobians, mm³.

    One batched matrix product per element, ``(∂ₖφₐ dx)`` (rows a k) by ``∂ₗφ_b`` (columns b l) over the
    quadrature points: the product numpy's ``einsum("akeq,bleq->kleab", g dx, g, optimize=True)`` forms.
    """
    nb, dim, ne, nq = g.shape
    a = np.ascontiguousarray((g * dx).transpose(2, 0, 1, 3)).reshape(ne, nb * dim, nq)
    b = np.ascontiguousarray(g.transpose(2, 3, 0, 1)).reshape(ne, nq, nb * dim)
    return np.matmul(a, b).reshape(ne, nb, dim, nb, dim)


def _sum_by_pair(inverse: np.ndarray, G: np.ndarray, pairs: int) -> np.ndarray:
    """Sums of the element integrals ``G`` (e, nb, dim, nb, dim) by pair of scalar unknowns, shape (pairs dim, dim).

    Row ``dim p + k``, column ``l`` is the sum of ``G[e, a, k, b, l]`` over the local pairs ``(e, a, b)``
    with ``inverse[(e, a, b)] == p`` (flattened in that order), added in that order: a sparse
    incidence matrix (one 1 per column) times the rows of ``G`` taken ``dim`` at a time, so ``G``
    is read in place, not transposed per component first (the same sums as ``np.bincount`` of each
    component over ``inverse``).
    """
    import scipy.sparse as sp

    ne, nb, dim = G.shape[:3]
    n = ne * nb * dim * nb
    idx = np.int32 if max(pairs * dim, n) < 2**31 - 1 else np.int64
    rows = (inverse.reshape(ne, nb, 1, nb).astype(idx) * dim + np.arange(dim, dtype=idx)[:, None]).ravel()
    P = sp.csc_matrix((np.ones(n), rows, np.arange(n + 1, dtype=idx)), shape=(pairs * dim, n))
    return P @ G.reshape(n, dim)


def _scalar_block_stiffness(sb: Any, dim: int, lam: float, mu: float, chunk: int = 8192) -> BlockStiffness:
    """:func:`block_stiffness` from the scalar basis ``sb`` (scikit-fem ``CellBasis``, its quadrature the
    stiffness's) of the ``dim`` components."""
    nb = sb.Nbfun
    sd = sb.element_dofs  # (nb, nel)
    inverse, indptr, indices = _scalar_pairs(sd, sb.N)
    g = np.stack([sb.basis[a][0].grad for a in range(nb)])  # (nb, dim, nel, nq)
    nel = g.shape[2]
    S = np.zeros((len(indices) * dim, dim))  # Σ_e ∫ ∂ₖφₐ ∂ₗφ_b: row (pair, k), column l
    for e0 in range(0, nel, chunk):
        e1 = min(e0 + chunk, nel)
        G = _gradient_products(g[:, :, e0:e1], sb.dx[e0:e1])
        S += _sum_by_pair(inverse[e0 * nb * nb:e1 * nb * nb], G, len(indices))
    S = S.reshape(-1, dim, dim)  # (pairs, k, l)
    blocks = lam * S + mu * S.transpose(0, 2, 1)
    tr = mu * np.trace(S, axis1=1, axis2=2)
    for i in range(dim):
        blocks[:, i, i] += tr
    return BlockStiffness(blocks=blocks, indptr=indptr, indices=indices)


def stiffness(basis: Any, lam: float, mu: float, chunk: int = 8192) -> Any:
    """Stiffness matrix (CSR) of isotropic linear elasticity on ``basis`` (scikit-fem ``ElementVector`` of a
    scalar element), the matrix of ``skfem.asm(linear_elasticity(lam, mu), basis)`` to round-off.

    Entry ``((a, i), (b, j))`` of an element is ``∫ λ ∂ᵢφₐ ∂ⱼφ_b + μ (∂ⱼφₐ ∂ᵢφ_b + δᵢⱼ ∇φₐ·∇φ_b) dx`` over the
    scalar basis functions ``φ`` of scikit-fem's element with its quadrature (``basis``'s own); local
    vector function ``3a + i`` is component ``i`` of scalar function ``a``, as in ``ElementVector``.  Assembled
    by blocks of scalar unknowns (:func:`block_stiffness`, ``chunk`` elements at a time); entries that sum
    to exactly zero are dropped (the element matrices' zeros were, as scikit-fem's assembly drops them).
    """
    return block_stiffness(basis, lam, mu, chunk).tocsr()


def _vector_nodal_dofs(sb: Any, dim: int) -> np.ndarray:
    """Vector unknowns (dim, vertices) at the mesh vertices: ``dim s + i`` is component ``i`` of the scalar
    basis ``sb``'s unknown ``s`` (scikit-fem's numbering of ``ElementVector``)."""
    return dim * sb.nodal_dofs[0][None, :] + np.arange(dim)[:, None]


def _supports(m: Any, sb: Any, centre: np.ndarray, arm: float) -> np.ndarray:
    """The six unknowns of a 3-2-1 support at the vertices nearest ``centre``, ``centre + arm·x``, ``+ arm·y``."""
    def near(q: np.ndarray) -> int:
        return int(np.argmin(((m.p.T - q) ** 2).sum(axis=1)))

    a = near(centre)
    b = near(centre + [arm, 0.0, 0.0])
    c = near(centre + [0.0, arm, 0.0])
    pa, pb, pc = m.p[:, a], m.p[:, b], m.p[:, c]
    if np.linalg.norm(np.cross(pb - pa, pc - pa)) < 1e-6 * arm**2:
        raise GeometryError("supports: the three support vertices are collinear", m)
    nd = _vector_nodal_dofs(sb, 3)
    return np.array([nd[0, a], nd[1, a], nd[2, a], nd[1, b], nd[2, b], nd[2, c]])


def unfold(points: np.ndarray, tets: np.ndarray, displacement: np.ndarray, vertex_stress: np.ndarray,
           planes: Sequence[tuple[int, float]], tol: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Reflect a mesh and its fields across coordinate mirror planes, one after the other.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
        Vertices, mm; ``tets`` (m, 4) their tetrahedra.
    displacement : ndarray, shape (n, 3)
        Vertex displacements, mm.
    vertex_stress : ndarray, shape (m, 4, 3, 3)
        Stress (MPa) at the vertices of every element.
    planes : sequence of (axis, coordinate)
        Mirror planes ``x[axis] = coordinate`` (mm).
    tol : float
        Vertices within ``tol`` mm of a plane lie on it and are shared by the two halves.

    Returns
    -------
    The unfolded ``points``, ``tets``, ``displacement`` and ``vertex_stress``: each plane doubles
    the elements; a reflection ``Q`` maps the displacement to ``Q u`` and the stress to ``Q σ Q``;
    the reflected tetrahedra keep a positive orientation (two vertices swapped).
    """
    p, t, u, s = points, tets, displacement, vertex_stress
    for ax, c in planes:
        on = np.abs(p[:, ax] - c) <= tol
        new = np.flatnonzero(~on)
        idx = np.arange(len(p))
        idx[new] = len(p) + np.arange(len(new))
        q = p[new].copy()
        q[:, ax] = 2.0 * c - q[:, ax]
        sign = np.ones(3)
        sign[ax] = -1.0
        v = u[new] * sign
        swap = [1, 0, 2, 3]
        p = np.concatenate([p, q])
        u = np.concatenate([u, v])
        t = np.concatenate([t, idx[t][:, swap]])
        s = np.concatenate([s, (s * np.outer(sign, sign))[:, swap]])
    return p, t, u, s


def _symmetry_dofs(sb: Any, planes: Sequence[tuple[int, float]], centre: np.ndarray, tol: float) -> np.ndarray:
    """Unknowns fixed on mirror planes: the normal displacement of every node on each plane, and the
    translation along the one axis two planes leave free (at the vertex nearest ``centre``).  ``sb`` is the
    scalar basis of the three components (see :func:`_vector_nodal_dofs`)."""
    axes = sorted({int(a) for a, _ in planes})
    if len(axes) != len(planes) or len(axes) < 2:
        raise ValueError(f"symmetry: need two or three mirror planes normal to different axes, got {list(planes)}")
    comp = np.arange(3 * sb.N) % 3
    x = np.repeat(sb.doflocs, 3, axis=1)
    fixed = [np.flatnonzero((comp == a) & (np.abs(x[a] - c) <= tol)) for a, c in planes]
    if len(axes) == 2:
        free_axis = ({0, 1, 2} - set(axes)).pop()
        m = sb.mesh
        v = int(np.argmin(((m.p.T - centre) ** 2).sum(axis=1)))
        fixed.append(np.array([_vector_nodal_dofs(sb, 3)[free_axis, v]]))
    return np.unique(np.concatenate(fixed))


def _factor_and_solve(K: Any, b: np.ndarray, ordering: str = "default") -> np.ndarray:
    """``K⁻¹ b`` for the symmetric positive definite ``K`` (sparse, CSC; CHOLMOD reads one triangle of it, so
    ``K`` must be symmetric, as every stiffness matrix here is by construction).  ``ordering`` is CHOLMOD's
    fill-reducing ordering (``"natural"``: ``K``'s rows are already in a fill-reducing order, see
    :func:`_fill_reducing_order`); SuperLU makes its own.

    By CHOLMOD's supernodal Cholesky factorisation (scikit-sparse, the ``cholmod`` extra; fill-reducing
    ordering ``ordering``, by default AMD or METIS, CHOLMOD's choice), else, when scikit-sparse is not installed or
    CHOLMOD finds ``K`` not positive definite, by SuperLU's LU (scipy).  Both are direct solves of the
    same system, agreeing to round-off (relative 1e-12, tested); CHOLMOD was 2.8-7.6x faster on the FE
    tests' systems of 14,000-36,000 unknowns (half the work of an LU, in blocks through BLAS).

    The factors live and die in the calling thread: scipy's SuperLU frees its memory only in the
    thread that made it (factors freed by another thread leaked about 16 MB a solve).  (CHOLMOD, unlike
    SuperLU, keeps the GIL while it factorises, so a Ctrl-C waits for the factorisation to end: 3.4 s at
    69,000 unknowns and 11 s at 135,000, the 10 x 3 mm disc at 0.45 and 0.345 mm, one thread.)
    """
    try:
        from sksparse.cholmod import CholmodNotPositiveDefiniteError, cholesky
    except ImportError:
        pass
    else:
        try:
            return cholesky(K, ordering_method=ordering)(b)
        except CholmodNotPositiveDefiniteError:
            pass
    return _superlu_solve(K, b)


def _fill_reducing_order(pattern: Any, dim: int, fixed: np.ndarray) -> np.ndarray:
    """The free vector unknowns in a fill-reducing order for CHOLMOD's factorisation.

    The order is METIS's nested dissection (by CHOLMOD, postordered) of the pattern of the scalar unknowns,
    ``pattern`` (every ``dim`` x ``dim`` block of the stiffness is one entry), with the ``dim`` components of each
    scalar unknown kept together: about the fill of CHOLMOD's own choice on the whole matrix (which tried
    AMD, then METIS, on a graph ``dim²`` times larger), found in a third of the time (0.12 s instead of
    0.31 s for 36,000 unknowns; AMD on the scalar pattern filled in 24 % more).  CHOLMOD's default
    choice if its METIS is missing; without scikit-sparse the free unknowns stay in their order
    (SuperLU orders them itself).

    Parameters
    ----------
    pattern : sparse matrix
        Symmetric pattern of the scalar unknowns (``n`` x ``n``); vector unknown ``dim s + i`` is
        component ``i`` of scalar unknown ``s``.
    dim : int
        Components per scalar unknown.
    fixed : ndarray
        The vector unknowns held (left out).
    """
    n = pattern.shape[0]
    keep = np.ones(n * dim, dtype=bool)
    keep[fixed] = False
    try:
        from sksparse.cholmod import CholmodError, analyze
    except ImportError:
        return np.flatnonzero(keep)
    try:
        p = analyze(pattern.tocsc(), ordering_method="metis").P()
    except CholmodError:  # (a CHOLMOD built without METIS)
        p = analyze(pattern.tocsc()).P()
    q = (dim * p[:, None] + np.arange(dim)[None, :]).ravel()
    return q[keep[q]]


def _superlu_solve(K: Any, b: np.ndarray) -> np.ndarray:
    """``K⁻¹ b`` by SuperLU (``K`` sparse symmetric, CSC), in the calling thread (SuperLU orders ``K`` itself)."""
    import scipy.sparse.linalg as spla

    lu = spla.splu(K, permc_spec="MMD_AT_PLUS_A", options={"SymmetricMode": True})
    return lu.solve(b)


def _unit_pressure(m: Any, scalar: Any, facets: np.ndarray, dim: int) -> np.ndarray:
    """Load vector (N per MPa) of a unit normal pressure (pushing inwards) on boundary ``facets``: ``-∫ n·v dA``
    for every vector unknown ``v`` (``dim s + i``: component ``i`` of the scalar element's unknown ``s``).

    The integrals and their sums are scikit-fem's ``LinearForm`` of ``-dot(w.n, v)`` on the vector element's
    ``FacetBasis`` (degree 2) in its order (vector function ``dim a + i`` after ``dim a + i - 1``, facets in
    order; the other components' products are zeros), from the 10 scalar functions instead of 30 vector ones.
    """
    import skfem

    fb = skfem.FacetBasis(m, scalar, facets=facets, intorder=2)
    n = fb.normals  # (dim, facets, quadrature points)
    rows = np.concatenate([dim * fb.element_dofs[a] + i for a in range(fb.Nbfun) for i in range(dim)])
    data = np.concatenate([np.sum(-(n[i] * fb.basis[a][0].get(0)) * fb.dx, axis=1)
                           for a in range(fb.Nbfun) for i in range(dim)])
    return np.bincount(rows, weights=data, minlength=dim * fb.N)


def _vertex_strain(m: Any, scalar: Any, u: np.ndarray) -> np.ndarray:
    """Strain (dim, dim, elements, 4) at the four vertices of every element of the displacement ``u``
    (scalar unknowns, dim), mm, of the scalar element ``scalar`` in every component.

    The displacement gradient is summed over the element's scalar functions in their order, as
    scikit-fem's ``interpolate`` of the ``ElementVector`` sums it (its other components' terms are zeros),
    and symmetrised as ``skfem.helpers.sym_grad``: the same numbers, from a basis of 10 scalar functions
    instead of 30 vector ones.
    """
    import skfem

    ref = np.array([[0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])  # quadrature "points"
    vb = skfem.CellBasis(m, scalar, quadrature=(ref, np.full(4, 1.0 / 24.0)))
    G = np.zeros((u.shape[1],) + vb.basis[0][0].grad.shape)  # (i, k, elements, 4): ∂ₖuᵢ
    for a in range(vb.Nbfun):
        G += u[vb.element_dofs[a]].T[:, None, :, None] * vb.basis[a][0].grad[None]
    return 0.5 * (G + np.einsum("ij...->ji...", G))


def solve_elasticity(
    mesh: TetMesh,
    material: Material,
    loads: Sequence[PressureLoad],
    *,
    support_centre: Sequence[float],
    support_arm: float,
    facets: BoundaryFacets | None = None,
    skmesh: Any = None,
    symmetry: Sequence[tuple[int, float]] = (),
) -> ElasticSolution:
    """Solve linear elasticity with pressure loads and a 3-2-1 support.

    Parameters
    ----------
    mesh : TetMesh
        Linear tetrahedra, mm.
    material : Material
        E (MPa), ν.
    loads : sequence of PressureLoad
        Normal pressures (MPa); their resultant should vanish (self-equilibrated).
    support_centre, support_arm
        Where the 3-2-1 support sits (mm) and the spacing of its three vertices (mm).
    facets, skmesh
        The :func:`boundary_facets` and skfem mesh the loads were selected on.
    symmetry : sequence of (axis, coordinate)
        Two or three mirror planes ``x[axis] = coordinate`` (mm) bounding ``mesh``, a part of a
        mirror-symmetric body under a mirror-symmetric load: they replace the 3-2-1 support
        (see :func:`_symmetry_dofs`; ``support_centre`` places the one fixed translation), and the
        returned solution is unfolded to the whole body (:func:`unfold`): its mesh, displacement,
        stresses and ``work`` are the whole body's, ``dofs`` the unknowns solved, ``reaction`` that
        of the fixed translation.
    """
    import skfem
    from skfem.models.elasticity import linear_stress

    m = skmesh if skmesh is not None else _skfem_mesh(mesh)
    bf = facets if facets is not None else boundary_facets(m)
    elem = skfem.ElementVector(skfem.ElementTetP2())
    # the scalar P2 basis of the three components (no vector basis: its 30 functions were evaluated for nothing)
    sb = skfem.CellBasis(m, elem.elem, intorder=2)
    N = elem.dim * sb.N
    lam, mu = material.lame
    KB = _scalar_block_stiffness(sb, elem.dim, lam, mu)
    K = KB.tocsr()

    f = np.zeros(N)
    scale = 0.0
    for ld in loads:
        f += ld.pressure * _unit_pressure(m, elem.elem, bf.ids[ld.facets], elem.dim)
        scale = max(scale, float(np.abs(bf.resultant(ld)).max()))
    tol = 1e-9 * float(np.ptp(m.p, axis=1).max())
    if symmetry:
        D = _symmetry_dofs(sb, symmetry, np.asarray(support_centre, float), tol)
    else:
        D = _supports(m, sb, np.asarray(support_centre, float), float(support_arm))
    free = _fill_reducing_order(KB.pattern(), elem.dim, D)
    Kf = K[free][:, free].tocsc()
    # (in a helper thread: SuperLU holds no GIL, and a Ctrl-C must not wait minutes for it; CHOLMOD
    # keeps the GIL, but factorises the same system several times faster)
    u = np.zeros(N)
    u[free] = run_interruptibly(_factor_and_solve, Kf, f[free], "natural")
    reaction = float(np.abs((K @ u - f)[D]).max())
    sig = linear_stress(lam, mu)(_vertex_strain(m, elem.elem, u.reshape(-1, elem.dim)))  # (3, 3, m, 4)
    vertex_stress = np.ascontiguousarray(np.transpose(sig, (2, 3, 0, 1)))
    # vertex displacements (P2 nodal dofs at the vertices)
    disp = u[_vector_nodal_dofs(sb, elem.dim)].T
    work = float(f @ u)
    if symmetry:
        p, t, disp, vertex_stress = unfold(m.p.T, m.t.T, disp, vertex_stress, symmetry, tol)
        m = skfem.MeshTet(np.ascontiguousarray(p.T), np.ascontiguousarray(t.T))
        work *= 2 ** len(symmetry)
    return ElasticSolution(mesh=m, displacement=disp, vertex_stress=vertex_stress, dofs=int(N),
                           reaction=reaction, load_scale=scale, work=work)
