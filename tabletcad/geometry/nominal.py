"""Exact nominal shapes as signed distance functions (mm).

Each function returns ``f(points (m, 3)) -> (m,)``, negative inside.  Used to
certify how far a PDE surface lies from the shape it stands for
(:meth:`tabletcad.geometry.tablet.Tablet.nominal_deviation`).  A function whose shape
is a solid of revolution about the z axis carries ``f.axisymmetric = True`` (the
deviation of a PDE surface of revolution is then measured on a few meridians).
"""

from __future__ import annotations

from typing import Callable

import numpy as np

__all__ = ["cylinder", "sphere", "spheroid", "convex_round", "capsule_z", "intersection"]

SDF = Callable[[np.ndarray], np.ndarray]


def _about_z(f: SDF, axisymmetric: bool = True) -> SDF:
    f.axisymmetric = bool(axisymmetric)  # type: ignore[attr-defined]
    return f


def _on_axis(center) -> bool:
    return float(np.hypot(center[0], center[1])) == 0.0


def cylinder(radius: float, z0: float, z1: float) -> SDF:
    """Solid cylinder of ``radius`` about the z axis between ``z0`` and ``z1``."""

    def f(p: np.ndarray) -> np.ndarray:
        dr = np.hypot(p[:, 0], p[:, 1]) - radius
        dz = np.maximum(z0 - p[:, 2], p[:, 2] - z1)
        out = np.maximum(dr, dz)
        both = (dr > 0) & (dz > 0)
        out[both] = np.hypot(dr[both], dz[both])
        return out

    return _about_z(f)


def sphere(radius: float, center=(0.0, 0.0, 0.0)) -> SDF:
    c = np.asarray(center, dtype=float)
    return _about_z(lambda p: np.linalg.norm(p - c, axis=1) - radius, _on_axis(c))


def spheroid(a: float, c: float, center=(0.0, 0.0, 0.0)) -> SDF:
    """Spheroid with equatorial semi-axis ``a`` and polar semi-axis ``c`` (first-order distance)."""
    c0 = np.asarray(center, dtype=float)

    def f(p: np.ndarray) -> np.ndarray:
        q = p - c0
        g = (q[:, 0] ** 2 + q[:, 1] ** 2) / a**2 + q[:, 2] ** 2 / c**2 - 1.0
        grad = 2.0 * np.column_stack([q[:, 0] / a**2, q[:, 1] / a**2, q[:, 2] / c**2])
        return g / np.maximum(np.linalg.norm(grad, axis=1), 1e-300)

    return _about_z(f, _on_axis(c0))


def intersection(*fs: SDF) -> SDF:
    return _about_z(lambda p: np.max(np.stack([f(p) for f in fs]), axis=0),
                    all(getattr(f, "axisymmetric", False) for f in fs))


def convex_round(radius: float, band_z0: float, band_z1: float, cup_depth: float) -> SDF:
    """Round tablet: cylinder band ``[band_z0, band_z1]`` with a spherical cap of
    depth ``cup_depth`` on each face (radius of curvature ``(R² + d²)/(2d)``)."""
    if cup_depth <= 0.0:
        return cylinder(radius, band_z0, band_z1)
    rc = (radius**2 + cup_depth**2) / (2.0 * cup_depth)
    top = sphere(rc, (0.0, 0.0, band_z1 + cup_depth - rc))
    bot = sphere(rc, (0.0, 0.0, band_z0 - cup_depth + rc))
    cyl = cylinder(radius, band_z0 - cup_depth, band_z1 + cup_depth)

    def f(p: np.ndarray) -> np.ndarray:
        # each cap bounds only its own side of the band
        t = np.minimum(top(p), p[:, 2] - band_z1)
        b = np.minimum(bot(p), band_z0 - p[:, 2])
        return np.maximum(cyl(p), np.maximum(t, b))

    return _about_z(f)


def capsule_z(radius: float, z0: float, z1: float) -> SDF:
    """Capsule: cylinder of ``radius`` on [z0, z1] closed by hemispheres."""

    def f(p: np.ndarray) -> np.ndarray:
        zc = np.clip(p[:, 2], z0, z1)
        return np.sqrt(p[:, 0] ** 2 + p[:, 1] ** 2 + (p[:, 2] - zc) ** 2) - radius

    return _about_z(f)
