"""PDE patches that are surfaces of revolution about the z axis, and their profiles.

A patch whose four boundary data are circles about the z axis, each in a plane
``z = const`` and all starting at the same angle, carries only Fourier mode 1 in
``x, y`` and mode 0 in ``z`` (eqs 3.12-3.15).  Mode 1 of ``x + i y`` is then one
complex coefficient per datum, all of one phase ``φ``, so the solution is

    ``x + i y = R(u) e^{i (φ + s v)}``,  ``z = Z(u)``,

``s = ±1`` the sense in which ``v`` turns, with the *profile*
``R(u) = Σ_k L_k(u; a) ρ_k`` and ``Z(u) = Σ_k L_k(u; 0) z_k`` (``L_k`` the
cardinal functions of :mod:`tabletcad.geometry.basis`, ``ρ_k`` the circles'
signed radii, ``z_k`` their heights).  Everything a surface of revolution
needs (extents, plan area, the CAD stage's revolved faces) then comes from this
one-variable profile instead of the two-variable surface.

Detection reads the patch's own Fourier coefficients (the ones it evaluates
with), so the profile *is* the patch's surface, not an approximation of it: the
coefficients that would break the symmetry must be below
:attr:`Tolerances.revolution` (mm).

More generally, a patch whose data are scaled copies of one centred plan ellipse
(the thesis's ovals and caplet, eqs 4.3-4.4: ellipses of one aspect about the z axis)
is the linear image of a surface of revolution: its mode-1 coefficients are
``ρ_k p`` (cosine) and ``ρ_k q`` (sine) for two fixed plan vectors ``p, q``, so

    ``(x, y) = R(u) (p cos v + q sin v)``,  ``z = Z(u)``,

with the same profile ``R(u) = Σ_k L_k(u; a) ρ_k``.  Its :class:`Section` holds
``R, Z`` and the ellipse's shape ``S = p pᵀ + q qᵀ`` scaled to ``det S = 1``: the
section at ``u`` is the ellipse ``xᵀ S⁻¹ x = R(u)²`` of area ``π R(u)²``, reaching
``± R(u) √S_xx`` in x and ``± R(u) √S_yy`` in y.  A circle is the case ``S = I``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tabletcad.geometry.basis import cardinal
from tabletcad.geometry.tables import CARDINAL
from tabletcad.geometry.vectors import clip, linspace

__all__ = ["Revolution", "Section", "detect_revolution", "detect_section", "profile_extreme"]


class _Profile:
    """``profile(u, du)``: ``(R(u), Z(u))`` from the fields ``radius``, ``height``, ``lam``,
    ``u_nodes`` and ``form`` of the dataclasses below, whose arrays are read-only copies (a tablet is
    immutable: ``tablet.revolution[0].radius[1] = 99`` had changed its report, not its solid)."""

    _arrays: tuple[str, ...] = ("radius", "height")

    def _freeze(self, *names: str) -> None:
        for name in names:
            a = np.array(getattr(self, name), dtype=float)
            a.setflags(write=False)
            object.__setattr__(self, name, a)

    def __setstate__(self, state: dict) -> None:  # (unpickled and deep-copied arrays come back writeable)
        self.__dict__.update(state)
        self._freeze(*self._arrays)

    radius: np.ndarray
    height: np.ndarray
    lam: float
    u_nodes: tuple[float, float, float, float]
    form: str

    def profile(self, u, du: int = 0) -> np.ndarray:
        """``(R, Z)`` (mm, or their ``du``-th derivatives) at ``u``; shape ``u.shape + (2,)``.

        ``R`` is signed: a profile that crossed the axis would turn negative.
        """
        u = np.asarray(u, dtype=float)
        uf = u.reshape(-1)
        R = self._cardinal(uf, self.lam, du) @ self.radius
        Z = self._cardinal(uf, 0.0, du) @ self.height
        return np.stack([R, Z], axis=-1).reshape(u.shape + (2,))

    def _cardinal(self, u: np.ndarray, lam: float, du: int) -> np.ndarray:
        """:func:`~tabletcad.geometry.basis.cardinal`, shared by every profile of the same
        ``λ``, nodes and form on sample lines of up to 1024 points."""
        make = lambda: cardinal(u, lam, self.u_nodes, self.form, du)  # noqa: E731
        if u.size > 1024:
            return make()
        return CARDINAL.get(("profile", du, u.tobytes(), lam, self.u_nodes, self.form), make)


@dataclass(frozen=True, eq=False)
class Revolution(_Profile):
    """The profile of a PDE patch of revolution about the z axis.

    Parameters
    ----------
    phase : float
        ``φ`` (rad): the surface point at ``v`` lies at plan angle ``φ + sense·v``.
    sense : int
        +1 when ``v`` turns counter-clockwise seen from +z, -1 otherwise.
    radius : ndarray (4,)
        Signed radius ``ρ_k`` (mm) of each datum along the angle ``φ``.
    height : ndarray (4,)
        Height ``z_k`` (mm) of each datum.
    lam : float
        ``λ = a·1`` of mode 1 (the smoothing parameter of eq 3.9).
    u_nodes : tuple of 4 floats
    form : {"curves", "hermite"}
    """

    phase: float
    sense: int
    radius: np.ndarray
    height: np.ndarray
    lam: float
    u_nodes: tuple[float, float, float, float]
    form: str

    def __post_init__(self) -> None:
        self._freeze(*self._arrays)

    def section(self) -> "Section":
        """The same profile as a :class:`Section` (``S = I``; ``p = e_φ``, ``q = sense · e_φ+90°``)."""
        c, s = math.cos(self.phase), math.sin(self.phase)
        return Section(plan=np.array([[c, s], [-self.sense * s, self.sense * c]]), radius=self.radius,
                       height=self.height, lam=self.lam, u_nodes=self.u_nodes, form=self.form)

    def v_of_angle(self, angle: float) -> float:
        """The parameter ``v`` (rad) of the meridian at plan angle ``angle``."""
        return float(np.mod(self.sense * (angle - self.phase), math.tau))


@dataclass(frozen=True, eq=False)
class Section(_Profile):
    """The profile of a PDE patch whose data are scaled copies of one centred plan ellipse
    in planes ``z = const`` (see the module's text): ``(x, y) = R(u) (p cos v + q sin v)``.

    Parameters
    ----------
    plan : ndarray (2, 2)
        Rows ``p, q`` (``|det| = 1``) with the patch's own phase: its point at ``(u, v)`` is
        ``R(u) (p cos v + q sin v)`` in plan.
    radius : ndarray (4,)
        Signed scale ``ρ_k`` (mm) of each datum: the radius of the circle of the same area.
    height : ndarray (4,)
        Height ``z_k`` (mm) of each datum.
    lam : float
        ``λ = a·1`` of mode 1 (eq 3.9).
    u_nodes : tuple of 4 floats
    form : {"curves", "hermite"}
    """

    plan: np.ndarray
    radius: np.ndarray
    height: np.ndarray
    lam: float
    u_nodes: tuple[float, float, float, float]
    form: str

    _arrays = ("plan", "radius", "height")

    def __post_init__(self) -> None:
        self._freeze(*self._arrays)

    @property
    def shape(self) -> np.ndarray:
        """``S = p pᵀ + q qᵀ`` (``det S = 1``): the section at ``u`` is ``xᵀ S⁻¹ x = R(u)²``."""
        return self.plan.T @ self.plan

    def reach(self) -> np.ndarray:
        """``(√S_xx, √S_yy)``: the section's half extents in x and y per unit ``R``."""
        return np.sqrt(np.diag(self.shape))

    def span(self, v0: float, v1: float) -> tuple[np.ndarray, np.ndarray]:
        """Least and largest x and y of ``p cos v + q sin v`` for ``v`` in ``[v0, v1]`` (closed form:
        each coordinate is ``A cos(v - φ)``, extreme at the ends or where ``v - φ`` is a multiple of π)."""
        lo, hi = np.empty(2), np.empty(2)
        for i in range(2):
            a, b = float(self.plan[0, i]), float(self.plan[1, i])
            amp, phi = math.hypot(a, b), math.atan2(b, a)
            vals = [a * math.cos(v0) + b * math.sin(v0), a * math.cos(v1) + b * math.sin(v1)]
            k = math.ceil((v0 - phi) / math.pi)
            while phi + k * math.pi <= v1:
                vals.append(amp if k % 2 == 0 else -amp)
                k += 1
            lo[i], hi[i] = min(vals), max(vals)
        return lo, hi


def detect_section(a0: np.ndarray, ac: np.ndarray, bc: np.ndarray, active, has_remainder: bool,
                   lam1: float, u_nodes, form: str, tol: float) -> Section | None:
    """The :class:`Section` of a patch from its Fourier coefficients, or None (the arguments
    as for :func:`detect_revolution`).

    Every datum's mode-1 coefficients must be ``ρ_k`` times those of the widest position
    datum (``p`` for the cosines, ``q`` for the sines), within ``tol`` (mm), and ``p, q`` must span
    the plan (an ellipse, not a segment).
    """
    if has_remainder or list(active) != [1]:
        return None
    c, s = ac[:, 0], bc[:, 0]
    if max(np.max(np.abs(a0[:, :2])), np.max(np.abs(c[:, 2])), np.max(np.abs(s[:, 2]))) > tol:
        return None
    cxy, sxy = c[:, :2], s[:, :2]
    positions = 2 if form == "hermite" else 4
    size = np.sqrt(np.sum(cxy * cxy, axis=1) + np.sum(sxy * sxy, axis=1))
    k = int(np.argmax(size[:positions]))
    if size[k] <= tol:
        return None
    p, q = cxy[k], sxy[k]
    n2 = float(p @ p + q @ q)
    rho = (cxy @ p + sxy @ q) / n2
    if max(np.max(np.abs(cxy - np.outer(rho, p))), np.max(np.abs(sxy - np.outer(rho, q)))) > tol:
        return None
    det = float(p[0] * q[1] - p[1] * q[0])
    if abs(det) <= 1e-9 * n2:  # a flat ellipse: no plan area to speak of, the sampled path decides
        return None
    scale = math.sqrt(abs(det))
    p, q = p / scale, q / scale
    return Section(
        plan=np.stack([p, q]),
        radius=np.ascontiguousarray(rho * scale),
        height=np.ascontiguousarray(a0[:, 2]),
        lam=float(lam1),
        u_nodes=tuple(u_nodes),
        form=form,
    )


def detect_revolution(a0: np.ndarray, ac: np.ndarray, bc: np.ndarray, active, has_remainder: bool,
                      lam1: float, u_nodes, form: str, tol: float) -> Revolution | None:
    """The :class:`Revolution` of a patch from its Fourier coefficients, or None.

    Parameters
    ----------
    a0 : ndarray (4, 3)
        Mean of each datum (mm).
    ac, bc : ndarray (4, N, 3)
        Cosine and sine coefficients of each datum (mm).
    active : sequence of int
        The modes with a non-zero coefficient.
    has_remainder : bool
        True when some datum has content above mode ``N`` (then it is no revolution).
    lam1 : float
        ``λ`` of mode 1.
    tol : float
        Largest coefficient (mm) that may break the symmetry.
    """
    if has_remainder or list(active) != [1]:
        return None
    c, s = ac[:, 0], bc[:, 0]  # x + i y = (c_x + i c_y) cos v + (s_x + i s_y) sin v
    if max(np.max(np.abs(a0[:, :2])), np.max(np.abs(c[:, 2])), np.max(np.abs(s[:, 2]))) > tol:
        return None
    sense = 0
    for sg in (1, -1):  # s = +1: (s_x, s_y) = (-c_y, c_x); s = -1: (c_y, -c_x)
        if np.max(np.abs(s[:, 0] + sg * c[:, 1])) <= tol and np.max(np.abs(s[:, 1] - sg * c[:, 0])) <= tol:
            sense = sg
            break
    if sense == 0:
        return None
    # the direction of the widest *position* datum (the Hermite form's last two are derivatives),
    # so that the radius R(u) is positive on the surface
    positions = 2 if form == "hermite" else 4
    k = int(np.argmax(np.hypot(c[:positions, 0], c[:positions, 1])))
    big = float(np.hypot(c[k, 0], c[k, 1]))
    if big <= tol:
        return None
    e = c[k, :2] / big
    across = c[:, 0] * e[1] - c[:, 1] * e[0]  # every circle must start on the same meridian
    if np.max(np.abs(across)) > tol:
        return None
    return Revolution(
        phase=float(math.atan2(e[1], e[0])),
        sense=sense,
        radius=np.ascontiguousarray(c[:, :2] @ e),
        height=np.ascontiguousarray(a0[:, 2]),
        lam=float(lam1),
        u_nodes=tuple(u_nodes),
        form=form,
    )


def profile_extreme(f, lo: float, hi: float, samples: int = 513, step: float = 1e-12) -> tuple[float, float]:
    """Largest value of a smooth scalar function ``f(u)`` (vectorised) on ``[lo, hi]``: ``(u, f(u))``.

    The best of ``samples`` equally spaced values is polished by zooming: 33
    points across the bracket about the best so far (one sample spacing each
    side), the bracket shrinking sixteenfold per round until it is below ``step``.  Never worse than the best sample; an interior
    maximum converges quadratically in the bracket (error ~ bracket² · f'').
    """
    u = linspace(lo, hi, samples)
    g = f(u)
    i = int(np.argmax(g))
    best_u, best = float(u[i]), float(g[i])
    h = (hi - lo) / (samples - 1)
    while h > step:
        uu = clip(best_u + linspace(-h, h, 33), lo, hi)
        g = f(uu)
        i = int(np.argmax(g))
        if g[i] >= best:
            best_u, best = float(uu[i]), float(g[i])
        h /= 16.0
    return best_u, best
