"""Bloor-Wilson PDE surface patches (thesis eqs 3.9-3.18).

A patch is the solution ``X(u, v)``, ``u ∈ [0, 1]``, ``v ∈ [0, 2π)`` periodic,
of ``(∂²/∂u² + a² ∂²/∂v²)² X = 0`` fixed by four boundary data per
coordinate:

* ``form="curves"`` (the thesis's form, eq 3.11): four closed curves at
  ``u = 0, u1, u2, 1`` (default ``u1 = 1/3``, ``u2 = 2/3``);
* ``form="hermite"`` (Bloor and Wilson's form): the curves at ``u = 0`` and
  ``u = 1`` and the derivative curves ``X_u`` there.

The solution is the analytic series of eq 3.12 truncated at ``N`` modes
(eq 3.17) plus the remainder term ``R`` of eq 3.18, which makes the surface
pass exactly through boundary data that ``N`` modes do not represent.  Each
mode ``n`` has the profile ``Σ_k L_k(u; a n) c_{k,n}`` where ``L_k`` are the
cardinal functions of :mod:`tabletcad.geometry.basis` and ``c_{k,n}`` the mode's
coefficients in datum ``k``; ``R = Σ_k L_k(u; β) r_k(v)`` with ``r_k`` the
part of datum ``k`` above mode ``N`` (``β`` defaults to ``a (N + 1)``, the
decay of the first omitted mode; the thesis's ``N (a + 1)`` is available).

Amplification: between interior curves a mode grows by the Lebesgue factor of
its cardinal functions, about ``e^{a n / 4}`` for large ``a n``.  A patch
whose fine detail (modes the curves need only below :attr:`Tolerances.stray`,
plus ``R``) moves the surface by more than ``Tolerances.stray`` between the
curves is refused with :class:`~tabletcad.errors.DesignError`; pass a smaller
``a`` (or ``a="auto"``) for outlines such as a stadium.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import lru_cache
from dataclasses import dataclass, field

import numpy as np

from tabletcad.geometry.basis import cardinal, cardinal_coefficients, cardinals
from tabletcad.geometry.revolution import Revolution, Section, detect_revolution, detect_section
from tabletcad.geometry.tables import CARDINAL, TRIG
from tabletcad.geometry.curves import (basis_memo, basis_spectrum, combination_of, evaluate_curves, fourier_coefficients,
                                      fourier_samples, modes_needed, sample_v)
from tabletcad.errors import DesignError, check_positive
from tabletcad.tolerance import DEFAULT, Tolerances
from tabletcad.geometry.vectors import cross, cross_first, einsum, linspace, norm3, points_last

__all__ = ["PDEPatch", "AUTO_A_LADDER"]

#: ``v`` arrays of these sizes have their residuals cached per patch (:meth:`PDEPatch._memo`), and
#: of up to the larger their trigonometric tables shared by all patches (:func:`_trig_shared`):
#: longer ones (scattered points, not grid lines) would hold megabytes each.
_CACHED_V = (64, 8192)

#: ``u`` lines of this many values or more (to 1024) keep their modes' profile table apart
#: (:meth:`PDEPatch._profile_table`): a polish's dense line, read again between its short zoom grids.
_LONG_U = 257

#: Smoothing parameters tried, in order, when ``a="auto"``.
AUTO_A_LADDER = (1.0, 0.5, 0.25, 0.1, 0.05, 0.02, 0.01)


def _trig(v: np.ndarray, n: np.ndarray, dv: int) -> tuple[np.ndarray, np.ndarray]:
    """d^dv/dv^dv of cos(n v) and sin(n v); shapes (len(v), len(n)): :func:`_trig_rows`, transposed."""
    rows = _trig_rows(v, n, dv)
    return rows[: n.size].T, rows[n.size :].T


_EYE3 = np.eye(3)

#: Modes per block of :func:`_trig_base` (the first block's cosines and sines are computed directly).
_TRIG_BLOCK = 8


def _largest_length(a: np.ndarray) -> float:
    """Largest length (mm, or mm per unit parameter) of the vectors of a field stored coordinates
    first ``(3, ...)``: ``sqrt(max(x² + y² + z²))``, one root."""
    return math.sqrt(float((a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).max()))


def _horizontal(Xu: np.ndarray, Xv: np.ndarray, D: np.ndarray,
                sizes: tuple[float, float, float] | None = None) -> bool:
    """Whether a patch sampled as ``(3, nu, nv)`` blocks lies in a horizontal plane: no ``z`` in its
    partials or about its spine, beyond rounding of their sizes (a flat face of a family, a disc).
    ``sizes``: the fields' :func:`_largest_length` (mm per unit parameter, mm), when the caller has them."""
    sizes = sizes or (_largest_length(Xu), _largest_length(Xv), _largest_length(D))
    return all(float(np.abs(a[2]).max()) <= 1e-12 * max(size, 1e-300)
               for a, size in zip((Xu, Xv, D), sizes))


def _fold_back(u: np.ndarray, det: np.ndarray, length: Callable[[], np.ndarray], scale: float) -> float:
    """:meth:`PDEPatch.fold_depth` from the solid map's Jacobian ``det`` on the grid ``u × v`` ``(nu, nv)``
    and ``length``, which gives the length of the vector ``det`` is taken along (``|X_v × D|``; mm; called
    only where something folds): the largest, over ``v``, distance travelled backwards (mm) where ``det``
    has the sign its sum has not, beyond rounding of ``scale`` (the product of the fields' sizes); 0 when
    it nowhere has."""
    ref = 1.0 if float(np.sum(det)) >= 0.0 else -1.0
    folded = det * ref < -1e-9 * scale
    if not folded.any():
        return 0.0
    speed = np.abs(det) / np.maximum(length(), 1e-300) * folded
    du = np.diff(u)[:, None]
    back = np.sum(0.5 * (speed[1:] + speed[:-1]) * du, axis=0)
    return float(back.max())


def _fold_level(u: np.ndarray, X: np.ndarray, Xu: np.ndarray, Xv: np.ndarray,
                A: np.ndarray) -> tuple[float, float] | None:
    """``(fold depth, reach)`` (mm) of a :attr:`PDEPatch.level` patch from its :meth:`PDEPatch.jet_grid` and
    spine ``A`` ``(3, nu, 1)``, the figures of the general rule with the ``z`` parts it has not; None where
    some sample is not finite (the general rule's, whose zero products would then be NaN).

    ``X_z`` is the spine's own ``z`` and ``X_v`` has no ``z``, so ``D = X - A`` has none either (exactly 0):
    ``X_v × D = (0, 0, m)`` with ``m = X_v,x D_y - X_v,y D_x``, the Jacobian is ``X_u,z m`` and every length
    and test reads the two plan coordinates (each term left out is a signed zero: the sums, the signs
    taken and the lengths are those of the whole vectors, bit for bit).
    """
    D0, D1 = X[0] - A[0], X[1] - A[1]
    plan = lambda a, b: math.sqrt(float((a * a + b * b).max()))  # noqa: E731
    reach = plan(D0, D1)
    size_u, size_v = _largest_length(Xu), plan(Xv[0], Xv[1])
    if not (math.isfinite(reach) and math.isfinite(size_u) and math.isfinite(size_v)
            and np.isfinite(A).all()):
        return None
    scale = size_u * size_v * reach
    if scale == 0.0:
        return 0.0, reach
    if float(np.abs(Xu[2]).max()) <= 1e-12 * max(size_u, 1e-300):  # horizontal: the fold in its plane
        det = Xu[0] * Xv[1] - Xu[1] * Xv[0]
        return _fold_back(u, det, lambda: np.sqrt(Xv[0] * Xv[0] + Xv[1] * Xv[1]), size_u * size_v), reach
    m = Xv[0] * D1 - Xv[1] * D0
    return _fold_back(u, Xu[2] * m, lambda: np.sqrt(m * m), scale), reach


@lru_cache(maxsize=8)
def _fold_u(nu: int, n_ends: int) -> np.ndarray:
    """The fold checks' ``u`` samples: ``nu`` equally spaced and ``n_ends`` geometrically
    closer to each end (from 1e-6 to 0.05), where a dome's spine may run backwards (read-only)."""
    ends = np.geomspace(1e-6, 0.05, n_ends)
    u = np.unique(np.concatenate([ends, linspace(0.0, 1.0, nu)[1:-1], 1.0 - ends]))
    u.setflags(write=False)
    return u


def _trig_rows(v: np.ndarray, n: np.ndarray, dv: int) -> np.ndarray:
    """``_trig(v, n, dv)`` as rows ``(2 len(n), len(v))``, cosines over sines, taken from the table of every
    mode up to ``max(n)`` at ``v`` (:func:`_trig_base`): the same products and values, computed once for
    patches whose active modes differ."""
    if not n.size:
        return np.zeros((0, v.size))
    if int(n.min()) < 1:
        raise ValueError(f"modes = {n.tolist()} is not allowed: the rows are of modes 1 and up")
    C, S = _trig_base(v, int(n.max()))
    c, s = C[n - 1], S[n - 1]
    k = dv % 4
    out = np.concatenate({0: (c, s), 1: (-s, c), 2: (-c, -s), 3: (s, -c)}[k])
    if dv:
        fac = n.astype(float) ** dv
        out *= np.concatenate([fac, fac])[:, None]
    return out


def _trig_base(v: np.ndarray, nmax: int) -> tuple[np.ndarray, np.ndarray]:
    """``cos(n v)`` and ``sin(n v)`` for ``n = 1..nmax``, each ``(nmax, len(v))`` (read-only; shared
    for grid-sized ``v`` like :func:`_trig_shared`)."""

    def make():
        if nmax <= 2 * _TRIG_BLOCK:
            nv = np.outer(np.arange(1, nmax + 1), v)
            return np.cos(nv), np.sin(nv)
        # modes 1..B directly, and each later block n = B k + j from cos and sin of B k v by the
        # addition formulas: B + nmax / B cosines and sines a sample instead of nmax (each value within
        # a few ulp of the direct one; the direct one's argument n v is itself rounded, to n v eps)
        B = _TRIG_BLOCK
        k = -(-nmax // B)  # blocks
        jv = np.outer(np.arange(1, B + 1), v)
        cj, sj = np.cos(jv), np.sin(jv)  # (B, m)
        kv = np.outer(np.arange(1, k) * B, v)
        ck, sk = np.cos(kv)[:, None, :], np.sin(kv)[:, None, :]  # (k - 1, 1, m)
        C = np.empty((k, B, v.size))
        S = np.empty((k, B, v.size))
        C[0], S[0] = cj, sj
        np.multiply(ck, cj, out=C[1:])
        C[1:] -= sk * sj
        np.multiply(sk, cj, out=S[1:])
        S[1:] += ck * sj
        return C.reshape(k * B, v.size)[:nmax], S.reshape(k * B, v.size)[:nmax]

    if v.size > _CACHED_V[1]:
        return make()
    return TRIG.get(("base", nmax, v.tobytes()), make)


def _trig_shared(v: np.ndarray, n: np.ndarray, dv: int, rows: bool = False, vbytes: bytes | None = None):
    """:func:`_trig` (read-only), remembered across patches for grid-sized ``v``; with
    ``rows`` the table ``(2 len(n), len(v))`` of the cosines' rows over the sines' rows.

    The patches of one tablet are evaluated on the same ``v`` samples with the same modes
    (a swept tablet's nine patches, the checks' grids), so one table serves them all.  Keyed
    on the bytes of ``v`` and ``n``: equal samples hit, nothing is shared between different ones.
    ``vbytes``: ``v.tobytes()`` when the caller has it (one copy and one hash of the samples a call).
    """
    make = _trig_rows if rows else _trig
    if v.size > _CACHED_V[1] or 16 * v.size * n.size > TRIG.max_bytes:
        return make(v, n, dv)
    vb = v.tobytes() if vbytes is None else vbytes
    return TRIG.get((rows, dv, n.tobytes(), vb), lambda: make(v, n, dv))


#: scipy's BLAS ``dgemm``, looked up on the first product (:func:`_dgemm`): importing scipy.linalg takes
#: 0.05-0.17 s of CPU, which a command that refuses its design before any surface is evaluated need not pay
_DGEMM: list = []


def _dgemm():
    """scipy's BLAS ``dgemm`` (:func:`scipy.linalg.blas.dgemm`), imported on the first call."""
    if not _DGEMM:
        from scipy.linalg.blas import dgemm

        _DGEMM.append(dgemm)
    return _DGEMM[0]


def _gemm(a: np.ndarray, b: np.ndarray, c: np.ndarray, fresh: bool = True) -> np.ndarray:
    """``a @ b`` by BLAS ``dgemm`` written into ``c``, a Fortran-contiguous array or block, in place
    (``c = a @ b`` when ``fresh``, else ``c += a @ b``); transposes of C-ordered arrays pass with no copy."""
    out = (_DGEMM[0] if _DGEMM else _dgemm())(1.0, a, b, beta=0.0 if fresh else 1.0, c=c, overwrite_c=1)
    if out is not c and not np.shares_memory(out, c):  # (a copy: c was not Fortran-contiguous)
        c[...] = out
    return c


def _basis_fourier(basis, N: int, samples: int) -> tuple[np.ndarray, ...]:
    """``(a0, a, b, rows)`` of the ``k`` curves of ``basis`` by FFT of ``samples`` samples: ``(k, 3)``,
    ``(k, N, 3)``, ``(k, N, 3)`` mm and the cosine and sine coefficients as rows ``(N, 3k)`` each,
    stacked ``(2, N, 3k)`` (read-only; once per basis, modes and samples)."""
    memo = basis_memo(basis)
    key = ("fourier", N, samples)
    hit = memo.get(key)
    if hit is None:
        a0, a, b, _ = basis_spectrum(basis, N, samples)
        k = a.shape[0]
        rows = np.stack([a.transpose(1, 0, 2).reshape(N, 3 * k), b.transpose(1, 0, 2).reshape(N, 3 * k)])
        rows.setflags(write=False)
        hit = (a0, a, b, rows)
        memo[key] = hit
    return hit


def _basis_evidently_above(comb: tuple, N: int, limit: float) -> bool:
    """True when the largest residual of a patch's data ``W · basis + const`` above its ``N`` modes at
    the ``4 samples`` dense samples (``comb = (basis, W, samples)``; the figure :meth:`PDEPatch._above_modes`
    compares with ``limit``, mm) is surely above ``limit``, from the basis's residuals at every 45th of
    those samples (kept on the basis: one small evaluation for all its patches); False when that does not
    settle it.

    Each sample's combined residual is bounded below by its value here less the rounding of both
    evaluations: the series and the data at a sample are the same sums whatever the array they sit in, up
    to rounding, taken as 1e-12 of the sum of the sizes of their terms (far more than ``N`` terms' worth),
    and the combination's own as 8 ulp of its terms.  The dense maximum is at least any of its samples',
    so a lower bound above ``limit`` gives the dense test's answer."""
    basis, W, samples = comb
    v = sample_v(4 * samples)[::45]
    B = _basis_residuals(basis, N, samples, None, v, 0)  # (k, m, 3)
    a0, a, b, _ = _basis_fourier(basis, N, samples)
    k = B.shape[0]
    terms = (np.abs(B).reshape(k, -1).max(axis=1) + np.abs(a0).sum(axis=1)
             + np.abs(a).sum(axis=(1, 2)) + np.abs(b).sum(axis=(1, 2)))  # (k,) a bound of each curve's terms
    flat = B.reshape(k, -1)
    aw = np.abs(W)
    lower = (np.abs(W @ flat) - 8.0 * np.finfo(float).eps * (aw @ np.abs(flat))
             - (aw @ (2e-12 * terms))[:, None])
    return bool((lower > limit).any())


def _basis_active_rows(basis, N: int, samples: int, active: np.ndarray) -> np.ndarray:
    """The cosine rows over the sine rows of the basis curves' coefficients of the modes ``active``,
    ``(2 len(active), 3k)`` mm (read-only; once per basis, modes, samples and active set: every residual
    of a patch on the basis at new ``v`` reads them)."""
    memo = basis_memo(basis)
    key = ("active rows", N, samples, active.tobytes())
    hit = memo.get(key)
    if hit is None:
        rows = _basis_fourier(basis, N, samples)[3]
        hit = np.concatenate([rows[0][active - 1], rows[1][active - 1]])
        hit.setflags(write=False)
        memo[key] = hit
    return hit


def _basis_residuals(basis, N: int, samples: int, active: np.ndarray | None, v: np.ndarray, dv: int,
                     vbytes: bytes | None = None) -> np.ndarray:
    """The ``k`` basis curves less their Fourier series (``active`` modes, or all ``N`` when None), or
    the ``v``-derivative of that, at ``v``: ``(k, len(v), 3)`` mm, read-only; kept on the basis for
    grid-sized ``v`` (every patch on it reads the same ``v`` samples in a check).  ``vbytes``:
    ``v.tobytes()`` when the caller has it."""

    def make() -> np.ndarray:
        a0, _, _, rows = _basis_fourier(basis, N, samples)
        out = np.array(basis.evaluate(v, dv), dtype=float)  # (k, m, 3)
        k = out.shape[0]
        if dv == 0:
            out -= a0[:, None, :]
        if active is None and N:
            c, s = _trig_shared(v, np.arange(1, N + 1), dv)  # (m, N) each
            out -= (c @ rows[0] + s @ rows[1]).reshape(v.size, k, 3).transpose(1, 0, 2)
        elif active is not None and active.size:
            T = _trig_shared(v, active, dv, rows=True, vbytes=vbytes)  # (2n, m), cosines over sines
            R = _basis_active_rows(basis, N, samples, active)  # (2n, 3k)
            out -= (T.T @ R).reshape(v.size, k, 3).transpose(1, 0, 2)
        out.setflags(write=False)
        return out

    if not _CACHED_V[0] <= v.size <= _CACHED_V[1]:
        return make()
    memo = basis_memo(basis)
    vb = v.tobytes() if vbytes is None else vbytes
    key = ("res", N, samples, None if active is None else active.tobytes(), dv, vb)
    hit = memo.get(key)
    if hit is None:
        hit = make()
        old = next((k for k in memo if k[0] == "res"), None) if len(memo) >= 64 else None
        if old is not None:
            memo.pop(old, None)
        memo[key] = hit
    return hit


@dataclass(frozen=True, eq=False)
class PDEPatch:
    """One PDE surface patch.

    Parameters
    ----------
    data : tuple of 4 curves
        ``form="curves"``: the curves at ``u_nodes`` (the thesis's ``P1, d1, d2,
        P2``).  ``form="hermite"``: ``(X(0, v), X(1, v), X_u(0, v), X_u(1, v))``.
        Each is any object with ``evaluate(v, der)`` (see :mod:`tabletcad.geometry.curves`).
    a : float or "auto"
        Smoothing parameter ``a > 0`` of eq 3.9.  ``"auto"`` takes the first
        value of :data:`AUTO_A_LADDER` whose surface passes the stray check.
    modes : int, optional
        Number of Fourier modes ``N`` carried analytically.  Default: the fewest
        that represent every datum within ``tol.fourier``, capped at
        ``tol.max_modes``.
    u_nodes : tuple of 4 floats
        ``(0, u1, u2, 1)`` for ``form="curves"``.
    form : {"curves", "hermite"}
    beta : float, optional
        Decay rate of the remainder term (default ``a (N + 1)``).
    tol : Tolerances
    name : str
    check : bool
        Run the stray and fold checks on construction (default True).
    """

    data: tuple
    a: float | str = 1.0
    modes: int | None = None
    u_nodes: tuple[float, float, float, float] = (0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0)
    form: str = "curves"
    beta: float | None = None
    tol: Tolerances = field(default=DEFAULT, repr=False)
    name: str = ""
    check: bool = field(default=True, repr=False)

    # ------------------------------------------------------------------ construction
    def __post_init__(self) -> None:
        data = tuple(self.data)
        if len(data) != 4:
            raise DesignError("curves", len(data), "a patch needs exactly 4 boundary data")
        for i, c in enumerate(data):
            if not callable(getattr(c, "evaluate", None)):  # CurveLike (isinstance on a Protocol is slow)
                raise DesignError(f"curve {i}", type(c).__name__, "must be a curve with evaluate(v, der)")
        object.__setattr__(self, "data", data)
        if self.form not in ("curves", "hermite"):
            raise DesignError("form", self.form, "must be 'curves' or 'hermite'")
        nodes = tuple(float(x) for x in self.u_nodes)
        if len(nodes) != 4 or nodes[0] != 0.0 or nodes[3] != 1.0 or not (0.0 < nodes[1] < nodes[2] < 1.0):
            raise DesignError("u_nodes", self.u_nodes, "must be (0, u1, u2, 1) with 0 < u1 < u2 < 1")
        object.__setattr__(self, "u_nodes", nodes)

        n_modes = self.modes
        if n_modes is None:
            need = max(modes_needed(c, self.tol.fourier, self.tol.max_modes) for c in data)
            n_modes = min(need, self.tol.max_modes)
        elif not (isinstance(n_modes, (int, np.integer)) and 0 <= n_modes <= 512):
            raise DesignError("modes", n_modes, "must be an integer from 0 to 512")
        object.__setattr__(self, "modes", int(n_modes))

        if isinstance(self.a, str):
            if self.a != "auto":
                raise DesignError("a", self.a, "must be a number > 0 or 'auto'")
            last: DesignError | None = None
            for a in AUTO_A_LADDER:
                object.__setattr__(self, "a", a)
                self.__dict__.pop("_cards", None)
                try:
                    self._setup()
                    if self.check:
                        self._check_stray()
                    last = None
                    break
                except DesignError as exc:
                    last = exc
            if last is not None:
                raise last
            if self.check:
                self._check_fold()
            return
        object.__setattr__(self, "a", check_positive("a", self.a))
        if self.a > 50:
            raise DesignError("a", self.a, "must be <= 50 (larger values only amplify every mode)")
        self._setup()
        if self.check:
            self._check_stray()
            self._check_fold()

    def _setup(self) -> None:
        object.__setattr__(self, "_v_memo", {})
        object.__setattr__(self, "_v_memo_short", {})
        object.__setattr__(self, "_u_memo", {})
        self.__dict__.pop("_u_long", None)
        object.__setattr__(self, "_checks", {})
        self.__dict__.pop("_breakpoints", None)  # (they depend on the remainder found below)
        N = self.modes
        beta = self.beta
        if beta is None:
            beta = self.a * (N + 1)
        else:
            beta = check_positive("beta", beta)
        object.__setattr__(self, "_beta", float(beta))
        # Fourier coefficients of every datum: a0 (4,3), a (4,N,3), b (4,N,3)
        limits = [getattr(c, "band_limit", lambda: None)() for c in self.data]
        band_limited = all(lim is not None and lim <= N for lim in limits)
        # 8 N + 8 samples give a band-limited curve's coefficients exactly; others get dense ones, a
        # multiple of 240 (a symmetric outline's absent modes stay zero: fourier_samples)
        samples = 8 * N + 8 if band_limited else fourier_samples(N, self.tol.samples)
        comb = combination_of(self.data)
        if comb is not None:  # one basis's coefficients, shared by every patch on it (linear in the curve)
            basis, W, const = comb
            a0B, aB, bB = _basis_fourier(basis, N, samples)[:3]
            a0 = W @ a0B + const
            ac, bc = einsum("jk,knc->jnc", W, aB), einsum("jk,knc->jnc", W, bB)
            comb = (basis, np.asarray(W, dtype=float), samples)
        else:
            a0 = np.zeros((4, 3))
            ac = np.zeros((4, N, 3))
            bc = np.zeros((4, N, 3))
            for k, c in enumerate(self.data):
                a0[k], ac[k], bc[k] = fourier_coefficients(c, N, samples)
        object.__setattr__(self, "_comb", comb)
        object.__setattr__(self, "_a0", a0)
        object.__setattr__(self, "_ac", ac)
        object.__setattr__(self, "_bc", bc)
        object.__setattr__(self, "_ac_rows", np.ascontiguousarray(ac.transpose(1, 0, 2).reshape(N, 12)))
        object.__setattr__(self, "_bc_rows", np.ascontiguousarray(bc.transpose(1, 0, 2).reshape(N, 12)))
        # is there anything above mode N?  Not for curves band-limited to N modes (circles,
        # ellipses: the FFT of 8 N + 8 samples is exact); else the residual at dense samples
        scale = max(1.0, float(np.abs(a0).max()), float(np.abs(ac).max()) if N else 0.0)
        above = False if band_limited else self._above_modes(samples, scale)
        object.__setattr__(self, "_has_remainder", above)
        object.__setattr__(self, "_lams", self.a * np.arange(N + 1))
        # modes with any non-zero coefficient; the others are skipped in every sum
        amp = np.zeros(N + 1)
        if N:
            amp[1:] = np.maximum(np.abs(ac).max(axis=(0, 2)), np.abs(bc).max(axis=(0, 2)))
        zero = 1e-15 * scale
        object.__setattr__(self, "_active", [n for n in range(1, N + 1) if amp[n] > zero])
        # the active modes' cosine and sine coefficients side by side, (modes, 4 data, 6): one
        # product with the cardinal functions gives both halves of every mode's u-profile
        act = np.array(self._active, dtype=int)
        # the active modes' coefficients as rows (cosines over sines) by (4 data · 3): the residuals' series
        object.__setattr__(self, "_res_rows", np.ascontiguousarray(
            np.concatenate([self._ac_rows[act - 1], self._bc_rows[act - 1]]) if act.size else np.zeros((0, 12))))
        object.__setattr__(self, "_n_active", act)
        self._v_memo.clear()  # residuals taken above with every mode's series: from here on, the active ones'
        self._v_memo_short.clear()
        object.__setattr__(self, "_abT", np.ascontiguousarray(
            np.concatenate([ac[:, act - 1], bc[:, act - 1]], axis=2).transpose(1, 0, 2)))
        # what the cardinal tables in u depend on besides u (patches alike in these share them)
        object.__setattr__(self, "_u_key", (self._lams[self._active].tobytes(),
                                            self._beta if self._has_remainder else None, self.u_nodes, self.form))
        lam1 = float(self._lams[1]) if N else 0.0
        coeffs = (a0, ac, bc, self._active, self._has_remainder, lam1, self.u_nodes, self.form, self.tol.revolution)
        rev = detect_revolution(*coeffs)
        object.__setattr__(self, "_revolution", rev)
        object.__setattr__(self, "_section", detect_section(*coeffs) if rev is None else rev.section())
        if self.check:
            self._check_amplification(amp, zero)

    def _above_modes(self, samples: int, scale: float) -> bool:
        """Whether some datum has content above mode ``N``: its residual (every mode's series taken
        off) at ``4 samples`` dense samples beyond ``1e-14 scale`` (mm) somewhere.  A patch on a shared
        basis first asks :func:`_basis_evidently_above` (the same answer where it answers: a residual
        that the basis's at every 45th of those samples already shows, which a swept family's outline
        of lines and arcs always does), and the dense residual only where it does not."""
        limit = 1e-14 * scale
        comb = self.__dict__.get("_comb")
        fresh = "_n_active" not in self.__dict__  # (set up before: its active modes' series, as below)
        if comb is not None and fresh and _basis_evidently_above(comb, self.modes, limit):
            return True
        return float(np.abs(self._residuals(sample_v(4 * samples), 0)).max()) > limit

    def _check_amplification(self, amp: np.ndarray, zero: float) -> None:
        """Refuse modes (and the remainder) amplified more than ``tol.max_amplification`` between the curves.

        Such a mode's shape between the curves is set by the amplification,
        not by the design (and beyond ``LAMBDA_MAX`` it cannot be computed).
        """
        from tabletcad.geometry.basis import LAMBDA_MAX, lebesgue_max

        limit = self.tol.max_amplification
        used = [(f"mode {n}", float(self._lams[n]), amp[n]) for n in self._active]
        if self._has_remainder:
            used.append(("the remainder term", self._beta, 1.0))
        for what, lam, size in used:
            big = lam > min(LAMBDA_MAX, 200.0)
            lb = math.inf if big else lebesgue_max(lam, self.u_nodes, self.form)
            if not math.isfinite(lb) or lb > limit:
                raise DesignError(
                    f"patch {self.name or '?'} smoothing parameter a",
                    self.a,
                    f"{what} (a·n = {lam:.3g}, amplitude {size:.3g} mm) would be amplified "
                    f"{'beyond 1e80' if big else f'{lb:.3g}-fold'} between the curves (allowed {limit:g}): "
                    "use a smaller a or fewer modes",
                )

    # ------------------------------------------------------------------ symmetry
    def mirrors(self, other: "PDEPatch", z0: float) -> bool:
        """Whether this patch is ``other`` reflected in the plane ``z = z0`` with ``u`` reversed,
        ``X(u, v) = M X'(1 - u, v) + 2 z0 e_z`` with ``M = diag(1, 1, -1)``, as far as its series
        shows: both of the Hermite form with the same ``a``, ``β``, modes and remainder, and the
        Fourier coefficients of its data those of ``(M X'(1) + 2 z0 e_z, M X'(0) + 2 z0 e_z,
        -M X'_u(1), -M X'_u(0))`` within 1e-12 of their scale (mm).

        The remainder term reads the data curves at any ``v``, which coefficients alone do not
        fix: a caller relies on this only for data built as reflections of each other (a swept
        family's lower face, the mirror image of its upper one by construction).

        Remembered per pair (patches are immutable): a swept family's builder asks it of each new patch
        and its twin, and the tablet (:meth:`~tabletcad.geometry.tablet.Tablet.mirror`) of the same pairs.
        """
        memo = self.__dict__.get("_mirrors_of")
        if memo is None:
            memo = {}
            object.__setattr__(self, "_mirrors_of", memo)
        # (the middle patch of a chain is its own twin: no reference to itself, no cycle to collect)
        key = (None if other is self else id(other), float(z0))
        hit = memo.get(key)
        if hit is not None and (hit[0] is other or key[0] is None):
            return hit[1]
        out = self._mirrors(other, z0)
        memo[key] = (None if other is self else other, out)
        return out

    def _mirrors(self, other: "PDEPatch", z0: float) -> bool:
        """:meth:`mirrors`, computed."""
        if self.form != "hermite" or other.form != "hermite" or self.modes != other.modes:
            return False
        if (self.a, self._beta, self._has_remainder) != (other.a, other._beta, other._has_remainder):
            return False
        if not np.array_equal(self._n_active, other._n_active):
            return False
        m = np.array([1.0, 1.0, -1.0])
        shift = np.array([[0.0, 0.0, 2.0 * z0]] * 2 + [[0.0, 0.0, 0.0]] * 2)
        flip = np.array([1.0, 1.0, -1.0, -1.0])[:, None]
        order = [1, 0, 3, 2]
        a0 = flip * (other._a0[order] * m) + shift
        scale = max(1.0, float(np.abs(self._a0).max()), float(np.abs(self._ac).max(initial=0.0)),
                    float(np.abs(self._bc).max(initial=0.0)))
        tol = 1e-12 * scale
        if float(np.abs(self._a0 - a0).max()) > tol:
            return False
        for mine, theirs in ((self._ac, other._ac), (self._bc, other._bc)):
            if mine.size and float(np.abs(mine - flip[:, :, None] * (theirs[order] * m)).max()) > tol:
                return False
        return True

    # ------------------------------------------------------------------ pieces
    def breakpoints(self) -> np.ndarray:
        """Sorted ``v`` in [0, 2π) where the surface is not smooth in ``v``
        (junctions of its curves' segments; empty when ``R = 0``); read-only, computed once (each
        face's quadrature rule and the seams' samples ask for it)."""
        hit = self.__dict__.get("_breakpoints")
        if hit is None:
            hit = self._find_breakpoints()
            hit.setflags(write=False)
            object.__setattr__(self, "_breakpoints", hit)
        return hit

    def _find_breakpoints(self) -> np.ndarray:
        """:meth:`breakpoints`, computed."""
        if not self._has_remainder:
            return np.zeros(0)
        pts = []
        for c in self.data:
            bp = getattr(c, "breakpoints", None)
            if bp is not None:
                pts.append(np.mod(np.asarray(bp(), dtype=float), 2.0 * math.pi))
        if not pts:
            return np.zeros(0)
        allp = np.unique(np.concatenate(pts))
        if allp.size > 1:
            keep = np.concatenate([[True], np.diff(allp) > 1e-12])
            allp = allp[keep]
        return allp

    @property
    def beta_value(self) -> float:
        """Decay rate ``β`` of the remainder term actually used."""
        return self._beta

    @property
    def revolution(self) -> Revolution | None:
        """The patch's profile when it is a surface of revolution about the z axis, else None
        (see :mod:`tabletcad.geometry.revolution`)."""
        return self._revolution

    @property
    def section(self) -> Section | None:
        """The patch's profile when its data are scaled copies of one centred plan ellipse (a
        circle included), else None (see :mod:`tabletcad.geometry.revolution`)."""
        return self._section

    @property
    def has_remainder(self) -> bool:
        """True when some datum has content above mode ``N`` (so ``R != 0``)."""
        return self._has_remainder

    def _memo(self, key: tuple, make, short: bool = False):
        """Small per-patch cache of arrays that depend only on ``v`` (the data's residuals).

        The same ``v`` samples are evaluated many times (the surface and its
        derivatives, every datum's residual); keys hold the samples' bytes, so
        equal samples hit and no result is shared between different ones.  ``short``: the
        few samples of a polish (a point's value and its ``u`` partials), kept apart (the latest
        eight) so that they never push out a grid's.
        """
        name = "_v_memo_short" if short else "_v_memo"
        memo = self.__dict__.get(name)
        if memo is None:
            memo = {}
            object.__setattr__(self, name, memo)
        hit = memo.get(key)
        if hit is None:
            hit = make()
            if isinstance(hit, np.ndarray):
                hit.setflags(write=False)
            else:
                for a in hit:
                    a.setflags(write=False)
            if len(memo) >= (8 if short else 48):
                memo.pop(next(iter(memo)))
            memo[key] = hit
        return hit

    def _trig_cached(self, v: np.ndarray, N: int, dv: int) -> tuple[np.ndarray, np.ndarray]:
        """``_trig(v, 1..N, dv)`` (read-only), cached for repeated ``v``."""
        return _trig_shared(v, np.arange(1, N + 1), dv)

    def _residuals(self, v: np.ndarray, dv: int, vbytes: bytes | None = None) -> np.ndarray:
        """Every datum's part above mode ``N`` (or its v-derivative) at ``v``: (4, len(v), 3) mm, read-only.
        ``vbytes``: ``v.tobytes()`` when the caller has it (the memos' keys)."""

        def make() -> np.ndarray:
            N = self.modes
            comb = self.__dict__.get("_comb")
            if comb is not None:  # the basis's residuals (shared by the patches on it), combined
                basis, W, samples = comb
                act = self.__dict__.get("_n_active")
                return einsum("jk,kmc->jmc", W, _basis_residuals(basis, N, samples, act, v, dv, vbytes))
            out = evaluate_curves(self.data, v, dv)  # (a datum repeated, a fan's two equal derivatives, once)
            if dv == 0:
                out -= self._a0[:, None, :]
            act = self.__dict__.get("_n_active")
            if act is None and N:  # (while the patch is set up: every mode) the four truncated series
                c, s = self._trig_cached(v, N, dv)  # in two products: (m, N) by (N, 4·3)
                out -= (c @ self._ac_rows + s @ self._bc_rows).reshape(v.size, 4, 3).transpose(1, 0, 2)
            elif act is not None and act.size:  # the series the surface sums: its active modes, in one
                # product with the table of cosine over sine rows that evaluate_grid takes at these v
                T = _trig_shared(v, act, dv, rows=True, vbytes=vbytes)  # (2n, m)
                out -= (T.T @ self._res_rows).reshape(v.size, 4, 3).transpose(1, 0, 2)
            return out

        if v.size > _CACHED_V[1]:
            return make()
        return self._memo(("res", dv, v.tobytes() if vbytes is None else vbytes), make, v.size < _CACHED_V[0])

    def _u_tables(self, u: np.ndarray, du: int,
                  ubytes: bytes | None = None) -> tuple[np.ndarray | None, np.ndarray, np.ndarray | None]:
        """The cardinal functions at ``u`` (or their ``u``-derivative) of every active mode
        ``(modes, len(u), 4)``, of the spine ``(len(u), 4)`` and of the remainder term, read-only;
        cached for short ``u`` arrays, which the checks evaluate again and again (seams at
        ``u = 0, 1``, the same lines for a point and its derivatives), and shared with every
        patch alike in ``λ`` of its active modes, remainder rate, nodes and form
        (:data:`~tabletcad.geometry.tables.CARDINAL`).  ``ubytes``: ``u.tobytes()`` when the caller has it."""

        def make():
            n = np.array(self._active, dtype=int)
            # the modes', the spine's (λ = 0) and the remainder's (β) in one call
            lams = np.concatenate([self._lams[n], [0.0], [self._beta] if self._has_remainder else []])
            L = cardinals(u, lams, self.u_nodes, self.form, du)
            return L[: n.size], L[n.size], L[n.size + 1] if self._has_remainder else np.zeros((0, 4))

        if u.size > 1024:
            return make()
        return CARDINAL.get((du, u.tobytes() if ubytes is None else ubytes) + self._u_key, make)

    # ------------------------------------------------------------------ evaluation
    def evaluate(self, u, v, du: int = 0, dv: int = 0, *, nmin: int = 0, remainder: bool = True) -> np.ndarray:
        """Surface point or partial derivative ``∂^{du+dv} X / ∂u^{du} ∂v^{dv}``.

        Parameters
        ----------
        u, v : array_like
            Parameters, broadcast against each other (``u`` in [0, 1]).
        du, dv : int
            Derivative orders (``du <= 2``).
        nmin : int
            Sum only modes ``n >= nmin`` (0: the whole surface).
        remainder : bool
            Include the remainder term ``R``.

        Returns
        -------
        ndarray, shape ``broadcast(u, v).shape + (3,)`` in mm (per unit parameter
        for derivatives).
        """
        u, v = np.asarray(u, dtype=float), np.asarray(v, dtype=float)
        if u.ndim == 0 and v.ndim == 1 and v.size > 1 and nmin == 0 and remainder:  # one u line: as below
            return self.evaluate_grid(u.reshape(1), v, du, dv)[0]
        u, v = np.broadcast_arrays(u, v)
        shape = u.shape
        uf, vf = u.reshape(-1), v.reshape(-1)
        if nmin == 0 and remainder and uf.size == 1:  # one point: a grid of one (one table in u for all terms)
            return self.evaluate_grid(uf, vf, du, dv).reshape(shape + (3,))
        if nmin == 0 and remainder and uf.size > 1:  # points along one u or one v line: a grid of one row
            if uf[0] == uf[-1] and (uf == uf[0]).all():
                return self.evaluate_grid(uf[:1], vf, du, dv)[0].reshape(shape + (3,))
            if vf[0] == vf[-1] and (vf == vf[0]).all():
                return self.evaluate_grid(uf, vf[:1], du, dv)[:, 0].reshape(shape + (3,))
            if uf.size >= 64:  # points on a few u lines (samples of a grid's rows): a grid row each
                rows, which = np.unique(uf, return_inverse=True)
                if 16 * rows.size <= uf.size:
                    out = np.empty((uf.size, 3))
                    for k in range(rows.size):
                        at = np.flatnonzero(which == k)
                        out[at] = self.evaluate_grid(rows[k : k + 1], vf[at], du, dv)[0]
                    return out.reshape(shape + (3,))
        out = np.zeros((uf.size, 3))
        if nmin == 0 and dv == 0:
            out += cardinal(uf, 0.0, self.u_nodes, self.form, du) @ self._a0
        n = np.array([m for m in self._active if m >= nmin], dtype=int)
        if n.size:
            # every mode at once: A_n(u) = L(u; λ_n) @ a_n, then Σ_n A_n cos(nv) + B_n sin(nv),
            # in chunks of points that keep the (modes, points, 4) arrays near 1 MB
            ac, bc = self._ac[:, n - 1].transpose(1, 0, 2), self._bc[:, n - 1].transpose(1, 0, 2)
            step = max(1, 32768 // n.size)
            for i in range(0, uf.size, step):
                L = cardinals(uf[i : i + step], self._lams[n], self.u_nodes, self.form, du)  # (n, m, 4)
                c, s = _trig_shared(vf[i : i + step], n, dv)  # (m, n); the same v again for other du
                out[i : i + step] += np.einsum("mn,nmc->mc", c, np.matmul(L, ac))
                out[i : i + step] += np.einsum("mn,nmc->mc", s, np.matmul(L, bc))
        if remainder and self._has_remainder:
            L = cardinal(uf, self._beta, self.u_nodes, self.form, du)
            r = self._residuals(vf, dv)
            for k in range(4):
                out += L[:, k : k + 1] * r[k]
        return out.reshape(shape + (3,))

    def evaluate_grid(self, u, v, du: int = 0, dv: int = 0, *, components: bool = False,
                      axes: tuple[int, ...] = (0, 1, 2), out: np.ndarray | None = None) -> np.ndarray:
        """Tensor-grid evaluation: ``X[i, j] = ∂X(u[i], v[j])``, shape (len(u), len(v), 3).

        Uses matrix products (cost ~ (nu + nv)·N + nu·nv·N), the fast path
        for pictures, meshes and quadrature.  With ``components`` the same values
        come as ``(len(axes), len(u), len(v))`` (``X[c, i, j]`` for the coordinates ``axes``),
        the layout the product makes: no transposed copy, each coordinate one contiguous
        block (for reductions over the grid, such as extents and the plan's silhouette), and
        only the coordinates asked for are computed.  ``out`` (with ``components``): a C-contiguous
        float array ``(len(axes), len(u), len(v))`` (mm) the products write into and that is returned,
        such as a block of a larger array (no copy of the grid into it).
        """
        if tuple(axes) != (0, 1, 2) and not components:
            raise ValueError(f"axes = {axes} is not allowed: only with components=True")
        if out is not None and not components:
            raise ValueError("out is only allowed with components=True")
        u = np.asarray(u, dtype=float).reshape(-1)
        v = np.asarray(v, dtype=float).reshape(-1)
        ub = u.tobytes() if u.size <= 1024 else None  # (the u tables' and profiles' key: one copy, one hash)
        L, L0, Lr = self._u_tables(u, du, ub)  # (n, nu, 4), (nu, 4), (nu, 4)
        # X[c, i, j] = Σ_k U[c, i, k] V[k, j], built as its transpose Y = X^T (nv, len(axes) nu) in Fortran
        # order (so Y.T is X, C-ordered, with no copy) by BLAS products that write into Y: the modes (cos and
        # sin rows of V, their u-profiles in U) in one product of (nv, 2n) by (2n, len(axes) nu); then, per
        # coordinate, its remainder rows r_k,c(v) and the spine (a row of ones by A0_c(u), when dv = 0) in one
        # product of (nv, 5) by (5, nu) added in place (beta = 1): no temporary the size of the grid
        ax = list(axes) if components else [0, 1, 2]
        m, nu, nv = len(ax), u.size, v.size
        vb = v.tobytes() if nv <= _CACHED_V[1] else None  # (the tables' and memos' key: one copy, one hash)
        rem, spine = self._has_remainder, dv == 0
        if out is not None:
            if out.shape != (m, nu, nv) or out.dtype != np.float64 or not out.flags.c_contiguous:
                raise ValueError(f"out must be a C-contiguous float array of shape {(m, nu, nv)}")
        if not (self._active or rem or spine) or not (nu and nv):
            if out is not None:
                out[...] = 0.0
                return out
            return np.zeros((len(axes), nu, nv) if components else (nu, nv, 3))
        # (X as (m, nu, nv) in C order is Y in Fortran order: ``out``'s memory, when given, is Y's)
        Y = np.empty((nv, m * nu), order="F") if out is None else out.reshape(m * nu, nv).T
        fresh = True
        if self._active:
            T = _trig_shared(v, self._n_active, dv, rows=True, vbytes=vb)  # (2n, nv): cosines over sines
            _gemm(T.T, self._mode_profiles(u, du, L, ax, ub).T, Y)
            fresh = False
        if rem or spine:
            k = 4 * rem + spine
            r = self._residuals(v, dv, vb) if rem else None  # (4, nv, 3)
            A = L0 @ self._a0 if spine else None  # (nu, 3)
            rows, prof = np.empty((k, nv)), np.empty((nu, k))
            if spine:
                rows[k - 1] = 1.0
            if rem:
                prof[:, :4] = Lr
            for i, c in enumerate(ax):
                if rem:
                    rows[:4] = r[:, :, c]
                if spine:
                    prof[:, k - 1] = A[:, c]
                _gemm(rows.T, prof.T, Y[:, i * nu : (i + 1) * nu], fresh)
        if out is not None:
            return out
        X = Y.T.reshape(m, nu, nv)
        return X if components else points_last(X)

    def _mode_profiles(self, u: np.ndarray, du: int, L: np.ndarray, ax: list[int],
                       ubytes: bytes | None = None) -> np.ndarray:
        """:meth:`evaluate_grid`'s left factor: the active modes' cosine and sine profiles in ``u`` of the
        coordinates ``ax``, ``(len(ax) len(u), 2 n)`` mm (coordinate c's cosine profiles, then its sine
        ones), from the cardinal table ``L`` of ``u`` (``du``).  The latest four of ``u`` up to 1024 values
        are kept (read-only): the surface and its ``v`` partial on one grid (:meth:`jet_grid`, the seams'
        rows) share one.  ``ubytes``: ``u.tobytes()`` when the caller has it."""
        key = (du, tuple(ax), u.tobytes() if ubytes is None else ubytes) if u.size <= 1024 else None
        memo = self.__dict__.get("_u_memo")
        if memo is None:
            memo = {}
            object.__setattr__(self, "_u_memo", memo)
        hit = memo.get(key) if key is not None else None
        if hit is not None:
            return hit
        n, nu = L.shape[0], u.size
        AB = self._profile_table(u, du, L)  # (n, nu, 6): each mode's cosine and sine profiles
        # (3, nu, 2n): coordinate c's cosine profiles, then its sine profiles
        # (the coordinates a run from the first: a slice, one copy in the reshape; else gathered)
        P = AB.reshape(n, nu, 2, 3).transpose(3, 1, 2, 0)
        U = (P[: ax[-1] + 1] if ax == list(range(ax[-1] + 1)) else P[ax]).reshape(len(ax) * nu, 2 * n)
        if key is not None:
            U.setflags(write=False)
            if len(memo) >= 4:
                memo.pop(next(iter(memo)))
            memo[key] = U
        return U

    def _profile_table(self, u: np.ndarray, du: int, L: np.ndarray) -> np.ndarray:
        """Every active mode's cosine and sine profiles in ``u`` of the three coordinates, ``L @ abT``:
        ``(n, len(u), 6)`` mm, from the cardinal table ``L`` of ``u`` (``du``).  The latest one of a long
        line (:data:`_LONG_U` to 1024 values) is kept apart from :meth:`_mode_profiles`' memo, whose
        entries the short grids of a polish push out: the bounds' polishes read one line of 513 ``u``
        at their extremes' ``v`` in ``x`` and in ``y`` on the same patch, twice each (the same table)."""
        if not _LONG_U <= u.size <= 1024:
            return np.matmul(L, self._abT)
        key = (du, u.tobytes())
        hit = self.__dict__.get("_u_long")
        if hit is not None and hit[0] == key:
            return hit[1]
        AB = np.matmul(L, self._abT)
        AB.setflags(write=False)
        object.__setattr__(self, "_u_long", (key, AB))
        return AB

    def jet_grid(self, u, v) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``X``, ``X_u`` and ``X_v`` on the grid ``u × v``, each ``(3, len(u), len(v))`` (coordinates
        first, as :meth:`evaluate_grid` with ``components``; mm and mm per unit parameter).  A
        :attr:`level` patch takes ``x`` and ``y`` from its series and ``z`` from its spine (``A0_z(u)``,
        its derivative, and 0 along ``v``): two thirds of the products, the same values."""
        u = np.asarray(u, dtype=float).reshape(-1)
        v = np.asarray(v, dtype=float).reshape(-1)
        if not self.level:
            return (self.evaluate_grid(u, v, components=True), self.evaluate_grid(u, v, du=1, components=True),
                    self.evaluate_grid(u, v, dv=1, components=True))
        out = []
        for du, dv in ((0, 0), (1, 0), (0, 1)):
            G = np.empty((3, u.size, v.size))
            self.evaluate_grid(u, v, du, dv, components=True, axes=(0, 1), out=G[:2])  # x, y in place
            G[2] = self.spine(u, du)[:, 2:] if dv == 0 else 0.0
            out.append(G)
        return out[0], out[1], out[2]

    @property
    def level(self) -> bool:
        """True when every datum is :attr:`~tabletcad.geometry.curves.Curve.flat` (its z does not change with
        ``v``): then no mode and no remainder has a z part, and the surface's z at ``(u, v)`` is the spine's
        at ``u`` (a swept family's patches: each line ``u`` lies in one plane ``z = A0_z(u)``)."""
        return all(getattr(c, "flat", False) is True for c in self.data)

    def spine(self, u, du: int = 0) -> np.ndarray:
        """The spine ``A0(u)`` (eq 3.13, mm), the ``n = 0`` term; shape ``u.shape + (3,)``."""
        u = np.asarray(u, dtype=float)
        uf = u.reshape(-1)
        L = self._u_tables(uf, du)[1] if uf.size <= 1024 else cardinal(uf, 0.0, self.u_nodes, self.form, du)
        return (L @ self._a0).reshape(u.shape + (3,))

    def normal(self, u, v, *, eps: float = 1e-7, xu: np.ndarray | None = None,
               xv: np.ndarray | None = None) -> np.ndarray:
        """Unit normal ``X_u × X_v / |X_u × X_v|`` (eq 6.4); at degenerate points
        (poles) the limit from inside the patch is used.  ``xu``, ``xv``: the partials at these
        points when the caller has them (mm per unit parameter)."""
        u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
        xu = self.evaluate(u, v, du=1) if xu is None else xu
        xv = self.evaluate(u, v, dv=1) if xv is None else xv
        n = cross(xu, xv)
        norm = norm3(n)
        scale = norm3(xu).max() + 1e-300
        bad = norm <= 1e-9 * scale * scale
        if bad.any():
            ub = u[bad]
            ush = np.where(ub > 0.5, ub - 1e-5, ub + 1e-5)
            nb = cross(self.evaluate(ush, v[bad], du=1), self.evaluate(ush, v[bad], dv=1))
            n[bad] = nb
            norm[bad] = norm3(nb)
        return n / np.maximum(norm, 1e-300)[..., None]

    # ------------------------------------------------------------------ coefficients (thesis form)
    def mode_coefficients(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """Coefficients of mode ``n`` in the thesis's form (eqs 3.13-3.15).

        For ``n = 0`` returns ``(a_0m, None)`` with ``A0 = Σ_m a_0m u^{m-1}``
        (array (4, 3)).  For ``n >= 1`` returns ``(a_n, b_n)``, arrays (4, 3)
        with rows ``(a_n1, a_n2, a_n3, a_n4)`` such that
        ``A_n = (a_n1 + a_n3 u) e^{λu} + (a_n2 + a_n4 u) e^{-λu}``, ``λ = a n``
        (the thesis writes ``e^{nu}``, i.e. ``a = 1``).  Large ``λ`` overflow:
        only meaningful for ``λ`` below ~700.
        """
        if n == 0:
            # basis {1, u, u², u³/3} at λ = 0
            c = cardinal_coefficients(0.0, self.u_nodes, self.form) @ self._a0
            return np.stack([c[0], c[1], c[2], c[3] / 3.0]), None
        if not 1 <= n <= self.modes:
            raise DesignError("n", n, f"must be between 0 and N = {self.modes}")
        lam = float(self._lams[n])
        C = cardinal_coefficients(lam, self.u_nodes, self.form)
        out = []
        for coef in (self._ac[:, n - 1], self._bc[:, n - 1]):
            c = C @ coef  # coefficients of the computational basis, (4, 3)
            if lam > 1.0:
                em = math.exp(-lam)
                out.append(np.stack([em * c[0], c[2], em * c[1], c[3]]))
            else:
                # cosh = (E+ + E-)/2 ; sinh(λu)/λ = (E+ - E-)/(2λ) ; u sinh/λ ; (u cosh - sinh/λ)/λ²
                l2 = lam * lam
                a1 = c[0] / 2 + c[1] / (2 * lam) - c[3] / (2 * lam * l2)
                a2 = c[0] / 2 - c[1] / (2 * lam) + c[3] / (2 * lam * l2)
                a3 = c[2] / (2 * lam) + c[3] / (2 * l2)
                a4 = -c[2] / (2 * lam) + c[3] / (2 * l2)
                out.append(np.stack([a1, a2, a3, a4]))
        return out[0], out[1]

    def radius_profile(self, u) -> np.ndarray:
        """Radius ``r(u) = sqrt(A_1x² + A_1y²)`` of the first mode (eq 4.22), mm.

        Exact for circles stacked along z; see :func:`tabletcad.families.reshape.circularity`.
        """
        u = np.asarray(u, dtype=float)
        if self.modes < 1:
            return np.zeros(u.shape)
        L = cardinal(u.reshape(-1), self._lams[1], self.u_nodes, self.form)
        A1 = L @ self._ac[:, 0]
        return np.hypot(A1[:, 0], A1[:, 1]).reshape(u.shape)

    # ------------------------------------------------------------------ checks
    def stray(self, nu: int = 97, nv: int | None = None) -> float:
        """Largest distance (mm) by which the patch's fine detail moves the surface.

        Fine detail = the modes above those needed to represent every datum
        within ``tol.stray / 4`` plus the remainder term.  At the curves it is
        at most ``tol.stray / 4``; between them it grows with the mode's
        amplification.
        """
        key = ("stray", nu, nv)
        if key not in self.__dict__.get("_checks", {}):
            self.__dict__.setdefault("_checks", {})[key] = self._stray(nu, nv)
        return self._checks[key]

    def _stray(self, nu: int, nv: int | None) -> float:
        # every datum's design content counts (in the Hermite form the derivative
        # curves X_u(0), X_u(1) carry design modes of their own)
        if self._revolution is not None:  # one mode: a datum needs it unless it is a point within tol
            n_design = int(float(np.abs(self._revolution.radius).max()) > self.tol.stray / 4)
        else:
            n_design = max(modes_needed(self.data[k], self.tol.stray / 4, self.modes) for k in range(4))
        if n_design >= self.modes and not self._has_remainder:
            return 0.0
        n_design = min(n_design, self.modes)
        u = linspace(0.0, 1.0, nu)
        v = sample_v(nv or max(256, 8 * self.modes))
        # the fine part on the grid, coordinates first (3, nu, nv), in one matrix product as in
        # evaluate_grid: the fine modes' u-profiles (cosine and sine) by their rows of the v table
        L, _, Lr = self._u_tables(u, 0)
        left, right = [], []
        fine_modes = np.flatnonzero(self._n_active > n_design)
        if fine_modes.size:
            AB = np.matmul(L[fine_modes], self._abT[fine_modes])  # (k, nu, 6)
            left += [AB[:, :, :3].transpose(2, 1, 0), AB[:, :, 3:].transpose(2, 1, 0)]
            T = _trig_shared(v, self._n_active, 0, rows=True)  # (2 active, nv): cosines over sines
            right.append(T[np.concatenate([fine_modes, self._n_active.size + fine_modes])])
        if self._has_remainder:
            k = 2 if self.form == "hermite" else 4  # (the Hermite form's derivative data: not counted)
            r = self._residuals(v, 0)[:k]  # (k, nv, 3)
            left.append((_EYE3[:, None, None, :] * Lr[None, :, :k, None]).reshape(3, u.size, 3 * k))
            right.append(r.transpose(0, 2, 1).reshape(3 * k, v.size))
        if not left:
            return 0.0
        U = np.concatenate(left, axis=2)
        F = (U.reshape(-1, U.shape[2]) @ np.concatenate(right)).reshape(3, u.size, v.size)
        return math.sqrt(float((F[0] * F[0] + F[1] * F[1] + F[2] * F[2]).max()))  # the largest |fine|

    def _check_stray(self) -> None:
        s = self.stray()
        if not s <= self.tol.stray:  # also refuses NaN
            raise DesignError(
                f"patch {self.name or '?'} smoothing parameter a",
                self.a,
                f"fine detail of the curves is amplified to {s:.3g} mm between them "
                f"(allowed {self.tol.stray:g} mm): use a smaller a (e.g. a = 'auto') or fewer modes",
            )

    def _check_nv(self) -> int:
        """``v`` samples for the fold checks: 128, or fewer for a surface that is a trigonometric
        polynomial of low degree ``N`` in ``v`` (no remainder term): 16 (N + 1), at least 32, so
        that the checks' products of three such factors (degree 3N) get five samples per period;
        4 for a surface of revolution (:attr:`revolution`), whose checks do not depend on ``v``."""
        if self._has_remainder or not self._active:
            return 128 if self._has_remainder else 32
        if self._revolution is not None:
            return 4  # a surface of revolution: every meridian is the same, so are the checks
        return int(min(128, max(32, 16 * (max(self._active) + 1))))

    def fold_depth(self, nu: int = 257, nv: int | None = None) -> float:
        """How far (mm) the solid map of eq 4.12 runs backwards where it folds.

        The map ``X(u, v, w)`` folds where its Jacobian ``X_u · (X_v × (X - A0))``
        changes sign.  The depth is the largest, over ``v``, distance travelled
        backwards (along the normal of the ``(v, w)`` surface) through the folded
        ``u``-intervals; 0 when the map does not fold.  The thesis's domes fold
        slightly at their poles: the spine, a cubic through the curves' centres,
        runs backwards for ``u`` below ~0.015 (0.8 µm for the 5 mm sphere).
        ``nv`` defaults to the fold checks' sampling in ``v`` (``_check_nv``); a surface of
        revolution, or of scaled copies of one plan ellipse (:attr:`section`), whose depth is the
        same on every meridian (a level one's deepest on a principal meridian), is always measured
        on four.
        """
        return self._fold_entry(nu, nv)[0]

    def _fold_entry(self, nu: int, nv: int | None) -> tuple[float, float]:
        """:meth:`_fold_depth_of` on :meth:`fold_depth`'s samples, computed once."""
        v = None
        if self._revolution is not None:  # every meridian alike (the section's argument, M a rotation)
            nv = self._check_nv()
        elif self._section is not None:
            # a surface of revolution, or of one plan ellipse (x, y) = R(u) M e(v), z = Z(u), M = [p q], folds
            # alike on every meridian: D = X - A0 = (R M e, 0), X_v × D = (0, 0, -R² det M) and the Jacobian
            # X_u · (X_v × D) = -Z' R² det M, so the speed |Jacobian| / |X_v × D| is |Z'(u)| on every v.  A level
            # patch (Z constant) folds in its plane, at the speed |R'| |det M| / |M e'(v)|, deepest where |M e'(v)|
            # is least: on a principal meridian.  The four principal meridians also give the largest |X_u|, |X_v|
            # and |D| of any, the scale of the threshold below which a sign change is round-off
            nv, v = "principal", self._principal_v()
        elif nv is None:
            nv = self._check_nv()
        key = ("fold", nu, nv)
        if key not in self.__dict__.get("_checks", {}):
            self.__dict__.setdefault("_checks", {})[key] = self._fold_depth_of(nu, nv, v)
        return self._checks[key]

    def fold_limit(self, nu: int = 257, nv: int | None = None) -> float:
        """The deepest fold (mm) the patch may have: ``tol.fold``, or ``tol.fold_fraction`` of its reach
        (the largest distance of the surface from its spine, on :meth:`fold_depth`'s samples ``nu, nv``)
        where that is more.  A fold is a length: the same shape at another size folds in proportion (the
        thesis's sphere 0.8 µm at 5 mm, 5.1 µm at 31 mm, which a fixed 5 µm refused)."""
        return max(self.tol.fold, self.tol.fold_fraction * self._fold_entry(nu, nv)[1])

    @property
    def checked_fold_depth(self) -> float:
        """The fold depth (mm) the patch was checked with: its own check's (:meth:`fold_depth` at the
        defaults), or the builder's that checked it instead (a swept family's, on 65 rows of ``u``);
        :meth:`fold_depth` when it was never checked."""
        hit = self.__dict__.get("_fold_depth")
        return self.fold_depth() if hit is None else hit

    def _principal_v(self) -> np.ndarray:
        """The four meridians of a :attr:`section` patch where ``|M e(v)|`` and ``|M e'(v)|`` are extreme
        (``M e(v) = p cos v + q sin v``, its plan vectors): ``e(v)`` along the eigenvectors of ``MᵀM``."""
        pq = self._section.plan  # rows p, q
        V = np.linalg.eigh(pq @ pq.T)[1]  # MᵀM = [p·p p·q; p·q q·q]
        return float(np.arctan2(V[1, 0], V[0, 0])) + 0.5 * math.pi * np.arange(4)

    def _fold_depth_of(self, nu: int, nv: int, v: np.ndarray | None = None) -> tuple[float, float]:
        """``(fold depth, reach)`` (mm) on ``nu`` rows and ``nv`` (or ``v``) meridians: see :meth:`fold_depth`
        and :meth:`fold_limit`."""
        u = _fold_u(nu, 48)
        v = sample_v(nv) if v is None else v
        # coordinates as contiguous (nu, nv) blocks (evaluate_grid's components layout)
        X, Xu, Xv = self.jet_grid(u, v)
        A = self.spine(u).T[:, :, None]
        hit = _fold_level(u, X, Xu, Xv, A) if self.level else None
        if hit is not None:
            return hit
        D = X - A
        m = cross_first(Xv, D)  # Xv × D
        det = Xu[0] * m[0] + Xu[1] * m[1] + Xu[2] * m[2]
        reach = _largest_length(D)
        size_u, size_v = _largest_length(Xu), _largest_length(Xv)
        scale = size_u * size_v * reach
        if scale == 0.0:
            return 0.0, reach
        if _horizontal(Xu, Xv, D, (size_u, size_v, reach)):
            # a flat patch's solid map has no volume (det = 0): it folds where its own Jacobian in its
            # plane, (X_u × X_v)_z, changes sign (a fan over an outline not star-shaped about its centre counts
            # the overlap twice), travelling backwards across each v line at |(X_u × X_v)_z| / |X_v|
            det = Xu[0] * Xv[1] - Xu[1] * Xv[0]
            m = Xv
            scale = size_u * size_v
        return _fold_back(u, det, lambda: np.sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]), scale), reach

    def _check_fold(self) -> None:
        """Refuse a patch whose surface folds over itself, passes through its
        spine, or whose solid map folds deeper than ``tol.fold``."""
        depth = self.fold_depth()
        limit = self.fold_limit()
        object.__setattr__(self, "_fold_depth", depth)
        if depth > limit:
            raise DesignError(
                f"patch {self.name or '?'} curves",
                f"a fold {depth:.3g} mm deep",
                f"the surface must not cross its spine by more than {limit:.3g} mm (Tolerances.fold, or "
                "fold_fraction of its reach; a radius would turn negative or the surface self-intersects)",
            )
        u = _fold_u(401, 24)
        v = sample_v(self._check_nv())
        if self._section is not None and self._revolution is None:  # (of revolution: four meridians suffice)
            self._check_fold_section(u, v)
        else:
            self._check_fold_sampled(u, v)

    def _check_fold_sampled(self, u: np.ndarray, v: np.ndarray) -> None:
        """:meth:`_check_fold`'s radius and fold-back checks on the grid ``u × v``."""
        X = self.evaluate_grid(u, v)
        D = X - self.spine(u)[:, None, :]
        # (a) the radius must not turn negative: the radial vector may not point
        #     against that of the widest curve (the surface would pass through its spine)
        Dn = norm3(D)
        k = int(np.argmax(Dn.max(axis=1)))
        ref = D[k] / np.maximum(Dn[k], 1e-300)[:, None]
        along = np.einsum("uvc,vc->uv", D, ref)
        self._refuse_negative_radius(along, u, v)
        # (b) the surface itself must not fold back (normal reversing between neighbours)
        Xu = self.evaluate_grid(u, v, du=1)
        Xv = self.evaluate_grid(u, v, dv=1)
        n = cross(Xu, Xv)
        nn = norm3(n)
        dots = np.einsum("uvc,uvc->uv", n[1:], n[:-1])
        self._refuse_fold_back(dots, nn, u, v)

    def _check_fold_section(self, u: np.ndarray, v: np.ndarray) -> None:
        """:meth:`_check_fold`'s radius and fold-back checks of a patch of one plan ellipse
        (:attr:`section`) from its profile, on the meridians ``v`` and the four where ``|M e(v)|``
        and ``|M e'(v)|`` are extreme (``M = [p q]``, ``e(v) = (cos v, sin v)``).

        With ``P = M e``, ``Q = M e'``: ``X - A0 = (R P, 0)``, so the radius along the widest curve's
        direction is ``sign(R_k) R(u) |P|``; and ``X_u × X_v = (Z' R J Q, R R' det M)``
        (``J`` a quarter turn), so the normals of one meridian lie in the plane of ``J Q`` and z,
        at ``(Z' R |Q|, R R' det M)``: the same figures the sampled check forms, without the grid.
        """
        v = np.concatenate([v, self._principal_v()])
        R, (radial, a, b) = self._section_profile(u)[0], self._section_normals(u, v)
        kk = int(np.argmax(np.abs(R)))
        along = np.sign(R[kk]) * radial
        self._refuse_negative_radius(along, u, v)
        nn = np.sqrt(a * a + b * b)
        dots = a[1:] * a[:-1] + b[1:] * b[:-1]
        self._refuse_fold_back(dots, nn, u, v)

    def _section_profile(self, u: np.ndarray) -> tuple[np.ndarray, ...]:
        """``R, Z, R', Z'`` of a :attr:`section` patch at ``u``."""
        R, Z = self._section.profile(u).T
        R1, Z1 = self._section.profile(u, 1).T
        return R, Z, R1, Z1

    def _section_normals(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Of a :attr:`section` patch on the grid ``u × v``: the signed radius ``R(u) |P(v)|`` (the plan
        distance of ``X - A0``, along ``P``), and ``X_u × X_v = (a J Q / |Q|, b)``: the in-plane part's
        signed length ``a = Z' R |Q|`` and the z part ``b = R R' det M`` (``P = M e(v)``, ``Q = M e'(v)``,
        ``M = [p q]``, ``J`` a quarter turn)."""
        pq = self._section.plan  # the patch's own plan vectors: M e(v) = p cos v + q sin v
        P = np.outer(np.cos(v), pq[0]) + np.outer(np.sin(v), pq[1])
        Q = np.outer(-np.sin(v), pq[0]) + np.outer(np.cos(v), pq[1])
        det = float(pq[0, 0] * pq[1, 1] - pq[0, 1] * pq[1, 0])
        R, _, R1, Z1 = self._section_profile(u)
        return (np.outer(R, np.hypot(P[:, 0], P[:, 1])), np.outer(Z1 * R, np.hypot(Q[:, 0], Q[:, 1])),
                np.repeat((R * R1 * det)[:, None], v.size, axis=1))

    def _refuse_negative_radius(self, along: np.ndarray, u: np.ndarray, v: np.ndarray) -> None:
        worst = float(-along.min())
        if worst > self.tol.fold:  # (no shape of the catalogue has one at any size: tol.fold alone)
            i, j = np.unravel_index(int(np.argmin(along)), along.shape)
            raise DesignError(
                f"patch {self.name or '?'} curves",
                f"radius {-worst:.3g} mm at u = {u[i]:.3f}, v = {v[j]:.3f}",
                "the radius about the spine must stay positive (the surface would pass through its spine)",
            )

    def _refuse_fold_back(self, dots: np.ndarray, nn: np.ndarray, u: np.ndarray, v: np.ndarray) -> None:
        """Refuse normals (lengths ``nn`` on the grid ``u × v``) turning by more than 120° between
        neighbouring ``u`` rows (``dots``: their dot products)."""
        big = nn > 1e-6 * float(nn.max())
        rev = (dots < -0.5 * nn[1:] * nn[:-1]) & big[1:] & big[:-1]
        if rev.any():
            i, j = np.argwhere(rev)[0]
            raise DesignError(
                f"patch {self.name or '?'} curves",
                f"surface folds back near u = {u[i]:.3f}, v = {v[j]:.3f}",
                "the surface must not fold over itself (e.g. a flat face whose radius overshoots its rim)",
            )

    # ------------------------------------------------------------------ misc
    @property
    def curves(self) -> tuple:
        """The boundary data (alias of ``data``)."""
        return self.data

    def replace_data(self, data, **kw) -> "PDEPatch":
        """A new patch with other boundary data and the same settings (``modes`` re-chosen unless given)."""
        args = dict(
            a=self.a, modes=None, u_nodes=self.u_nodes, form=self.form, beta=None, tol=self.tol, name=self.name
        )
        args.update(kw)
        return PDEPatch(tuple(data), **args)
