"""Height and radius of PDE tablets from their coefficients, and reshaping (thesis section 4.4).

For a patch whose curves are circles stacked along z, the spine's z
component gives the patch height (eqs 4.15, 4.16) and the first Fourier mode
gives the radius ``r = sqrt(A_1x² + A_1y²)`` with ``A_1x = B_1y`` and
``A_1y = -B_1x`` (eqs 4.22, 4.23).  Because the PDE solution is linear in its
boundary data, scaling those coefficients is the same as scaling the
boundary curves: :func:`scale_heights` multiplies a patch's spine height
(the thesis's ``k·A0z_j``) and re-stacks the following patches so the chain
stays closed; :func:`scale_radius` multiplies every radial mode (``k·r``).
:func:`thesis_table_4_5` rebuilds Table 4.5 this way.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from tabletcad.geometry.curves import Transformed
from tabletcad.errors import DesignError, check_positive
from tabletcad.geometry.patch import PDEPatch
from tabletcad.geometry.tablet import Tablet, Trim

__all__ = [
    "spine_height",
    "radius",
    "circularity",
    "scale_heights",
    "scale_radius",
    "select_patches",
    "thesis_table_4_5",
]


def spine_height(patch: PDEPatch) -> float:
    """``h = A0z(1) - A0z(0)`` (eq 4.16; equals ``a_01z`` when the spine is linear), mm."""
    s = patch.spine(np.array([0.0, 1.0]))
    return float(s[1, 2] - s[0, 2])


def radius(patch: PDEPatch, u) -> np.ndarray:
    """``r(u) = sqrt(A_1x² + A_1y²)`` (eq 4.22), mm."""
    return patch.radius_profile(u)


def circularity(patch: PDEPatch, samples: int = 33) -> dict[str, float]:
    """How far a patch is from circles about its spine.

    Returns the largest ``|A_1x - B_1y|`` and ``|A_1y + B_1x|`` over ``u``
    (eq 4.23 holds when both are 0) and the largest amplitude of the modes
    ``n >= 2`` (zero for circles), all in mm.
    """
    u = np.linspace(0.0, 1.0, samples)
    if patch.modes < 1:
        return dict(eq_4_23_a=0.0, eq_4_23_b=0.0, higher_modes=0.0)
    from tabletcad.geometry.basis import cardinal

    L = cardinal(u, patch.a * 1.0, patch.u_nodes, patch.form)
    A1 = L @ patch._ac[:, 0]
    B1 = L @ patch._bc[:, 0]
    higher = 0.0
    if patch.modes >= 2:
        higher = float(max(np.max(np.abs(patch._ac[:, 1:])), np.max(np.abs(patch._bc[:, 1:]))))
    return dict(
        eq_4_23_a=float(np.max(np.abs(A1[:, 0] - B1[:, 1]))),
        eq_4_23_b=float(np.max(np.abs(A1[:, 1] + B1[:, 0]))),
        higher_modes=higher,
    )


def _rebuild(tablet: Tablet, maps: list) -> Tablet:
    """Apply one curve map per patch, sharing transformed curves between neighbours."""
    done: dict[int, object] = {}
    patches = []
    for j, (p, f) in enumerate(zip(tablet.patches, maps)):
        data = []
        for k, c in enumerate(p.data):
            if k == 0 and j > 0 and id(c) in done:
                data.append(done[id(c)])
                continue
            nc = f(c)
            data.append(nc)
        done[id(p.data[3])] = data[3]
        patches.append(p.replace_data(data, modes=None if p.has_remainder else p.modes))
    # the family's dimensions and exact shape no longer describe the reshaped tablet
    return replace(tablet, patches=tuple(patches), nominal=None, params={})


def scale_heights(tablet: Tablet, factors) -> Tablet:
    """Scale each patch's spine height by ``factors[j]`` (the thesis's ``k·A0z_j``).

    The first patch keeps its start; every following patch starts where the
    previous one now ends, so shared curves stay shared.
    """
    factors = [check_positive(f"spine factor {j}", f) for j, f in enumerate(factors)]
    if len(factors) != len(tablet.patches):
        raise DesignError("spine factors", len(factors), f"need one per patch ({len(tablet.patches)})")
    z_start = float(tablet.patches[0].data[0].centroid()[2])
    maps = []
    for p, s in zip(tablet.patches, factors):
        z0 = float(p.data[0].centroid()[2])
        z1 = float(p.data[3].centroid()[2])
        m = np.diag([1.0, 1.0, s])
        off = np.array([0.0, 0.0, z_start - s * z0])
        maps.append(lambda c, m=m, off=off: Transformed(c, m, off))
        z_start = z_start + s * (z1 - z0)
    return _rebuild(tablet, maps)


def scale_radius(tablet: Tablet, factor: float) -> Tablet:
    """Scale every curve about its centroid in the xy plane by ``factor`` (the thesis's ``k·r``)."""
    k = check_positive("radius factor", factor)
    m = np.diag([k, k, 1.0])

    def f(c):
        cen = c.centroid()
        return Transformed(c, m, cen - m @ cen)

    return _rebuild(tablet, [f] * len(tablet.patches))


def select_patches(tablet: Tablet, indices) -> Tablet:
    """Keep only the listed patches (e.g. the band of a flat-faced round tablet for a ring)."""
    idx = list(indices)
    for i in idx:
        if not 0 <= i < len(tablet.patches):
            raise DesignError("patch index", i, f"must be between 0 and {len(tablet.patches) - 1}")
    return replace(tablet, patches=tuple(tablet.patches[i] for i in idx), nominal=None, params={})


def thesis_table_4_5() -> dict[str, dict]:
    """Table 4.5 rebuilt by coefficient scaling from the Table 4.1 shapes.

    Returns ``name -> dict(tablet=..., thesis_dims_mm=..., changes=...)``.
    """
    from tabletcad.families import thesis

    out: dict[str, dict] = {}

    def add(name, t, dims, changes):
        out[name] = dict(tablet=replace(t, name=name, family=f"thesis.{name}", nominal=None), thesis_dims_mm=dims,
                         changes=changes)

    ffr = thesis.flat_faced_round()
    body = select_patches(ffr, [1])
    ring = scale_radius(scale_heights(body, [0.75]), 1.2)
    add("ring", replace(ring, trim=Trim(w=(0.5, 1.0))), "12 x 4.5", "0.75 A0z2, 1.2 r, w in [0.5, 1]")
    scr = thesis.shallow_convex_round()
    add("deep_convex_round", scale_heights(scr, [3, 0.5, 3]), "10 x 4", "3 A0z1, 0.5 A0z2, 3 A0z3")
    sph = thesis.spherical()
    add("oblate_spheroid", scale_radius(scale_heights(sph, [0.5, 0.5]), 2.0), "10 x 2.5", "0.5 A0z1, 0.5 A0z2, 2 r")
    add("prolate_spheroid", scale_heights(sph, [2, 2]), "5 x 10", "2 A0z1, 2 A0z2")
    obl = thesis.oblong()
    add("rod", scale_radius(scale_heights(obl, [0.2, 0.6, 0.2]), 0.6), "3 x 7.5", "0.2 A0z1, 0.6 A0z2, 0.2 A0z3, 0.6 r")
    ova = thesis.shallow_convex_oval()
    add("caplet", scale_radius(scale_heights(ova, [5, 5, 5]), 0.585), "3.5 x 7 x 15", "5 A0z1, 5 A0z2, 5 A0z3, 0.585 r")
    add("deep_convex_oval", scale_heights(ova, [2, 0.55, 2]), "6 x 12 x 3.1", "2 A0z1, 0.55 A0z2, 2 A0z3")
    return out
