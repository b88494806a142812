"""CAD stage timing per sample tablet, beside the same nominal shape built directly in build123d.

Run:  .venv/bin/python benchmarks/bench_cad.py [--repeat 3] [samples/x.toml ...]

For every sample design that is not a cut-away, prints (best of ``--repeat`` runs, one core):

* ``solid``: :func:`tabletcad.cad.tablet_solid.tablet_solid` - B-spline (or profile) fit of
  every face, OCCT faces, sewing, orientation, ``BRepCheck_Analyzer``;
* ``check``: the stage's cross-checks (the faces' volume and area by Gauss-Legendre on their
  B-spline data against the core's quadrature, taken as given - the quadrature itself is core
  work and not timed) and the tessellation
  with its manifold3d/trimesh checks (:func:`tabletcad.cad.stage.check_tablet_solid`
  minus the solid, which it rebuilds: ``check = stage total - solid``);
* ``export``: tablet.step + tablet.stl + tablet.glb (:func:`tabletcad.cad.export.export`);
* ``b123d``: the same *nominal* shape made directly in build123d from exact arcs -
  a revolve of its profile (band, spherical caps / elliptic domes, sphere, spheroid,
  ring rectangle) - with ``is_valid()``, its volume, and its own ``export_step`` and
  ``export_stl`` at the same deflections (0.005 mm, 0.2 rad) as the tablet's STL; a round
  family (flat face, bevel or radius edge, concave with a land, compound cup, concave bevel)
  revolves its own face profile, every line and arc of it, and a capsule has its profile revolved
  about each end's centre and extruded along each side, the faces made one shell (the peer's
  volume is printed against the B-rep's); oval tablets (not solids of revolution) use the round tablet of equal width and
  the other shaped outlines (whose corners collapse inside the cup) and the stadium an extruded
  ``SlotOverall`` of their plan's extents (marked ``~``: stand-ins, not the same shape);
* the ratio ``(solid + check + export) / b123d``, and ``issue``: the same total over the issue's own peer
  (#12: a 10 mm standard concave round, band 3 mm, cups 1 mm deep, revolved from exact arcs, with the same
  validity check, volume, STEP and STL; :func:`issue_peer`), timed once per run before the samples, best of
  ``--repeat``: the goal reads CAD stage <= 3x that peer for tablets of revolution, <= 10x for shaped outlines.

Figures only; nothing is asserted.  The design load (PDE solve) is printed apart.
"""

from __future__ import annotations

import argparse
import glob
import math
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

ROOT = Path(__file__).resolve().parents[1]
LINEAR, ANGULAR = 0.005, 0.2


# --------------------------------------------------------------------------- build123d nominal shapes


def _revolve_profile(points_and_arcs):
    """Closed profile in the XZ plane (x = radius, z) from ('line', p0, p1) / ('arc', ...) items, revolved about Z."""
    import build123d as bd

    edges = []
    for item in points_and_arcs:
        kind = item[0]
        if kind == "line":
            edges.append(bd.Edge.make_line(bd.Vector(item[1][0], 0, item[1][1]), bd.Vector(item[2][0], 0, item[2][1])))
        elif kind == "arc3":  # exact circular arc through three points
            p0, pm, p1 = (bd.Vector(p[0], 0, p[1]) for p in item[1:])
            edges.append(bd.Edge.make_three_point_arc(p0, pm, p1))
        else:  # "ellipse": centre (x, z), radii (rx along x, rz along z), angles (deg) in the XZ plane
            _, (cx, cz), rx, rz, a0, a1 = item
            plane = bd.Plane(origin=(cx, 0, cz), x_dir=(1, 0, 0), z_dir=(0, -1, 0))
            if rx >= rz:
                e = bd.Edge.make_ellipse(rx, rz, plane, a0, a1)
            else:  # make_ellipse wants the major radius first: rotate the local frame by 90 deg
                plane = bd.Plane(origin=(cx, 0, cz), x_dir=(0, 0, 1), z_dir=(0, -1, 0))
                e = bd.Edge.make_ellipse(rz, rx, plane, a0 - 90.0, a1 - 90.0)
            edges.append(e)
    wire = bd.Wire(edges)
    face = bd.Face(wire)
    return bd.Solid.revolve(face, 360.0, bd.Axis.Z)


def _cap_items(R: float, z_rim: float, depth: float, up: bool):
    """Cap from the axis to the rim (bottom, up=False) or from the rim to the axis (top)."""
    if depth <= 0.0:
        return [("line", (0.0, z_rim), (R, z_rim))] if not up else [("line", (R, z_rim), (0.0, z_rim))]
    if depth <= R:  # spherical cap: exact circle arc through three points
        rc = (R * R + depth * depth) / (2.0 * depth)
        half = math.asin(R / rc)
        th = half / 2.0
        if up:
            zc = z_rim + depth - rc
            return [("arc3", (R, z_rim), (rc * math.sin(th), zc + rc * math.cos(th)), (0.0, z_rim + depth))]
        zc = z_rim - depth + rc
        return [("arc3", (0.0, z_rim - depth), (rc * math.sin(th), zc - rc * math.cos(th)), (R, z_rim))]
    # deeper than a hemisphere: half spheroid (an elliptic arc), as the shape families do
    if up:
        return [("ellipse", (0.0, z_rim), R, depth, 0.0, 90.0)]
    return [("ellipse", (0.0, z_rim), R, depth, 270.0, 360.0)]


def _band_tablet(R: float, z0: float, z1: float, d0: float, d1: float):
    items = _cap_items(R, z0, d0, up=False)
    if z1 > z0:
        items.append(("line", (R, z0), (R, z1)))
    items += _cap_items(R, z1, d1, up=True)
    items.append(("line", (0.0, z1 + d1), (0.0, z0 - d0)))
    return _revolve_profile(items)


def _round_family_items(tablet):
    """Profile items of a round family's exact nominal (every line and arc of its face profile,
    land, bevel, compound radii and band, at radius ``R - d``), or None for other tablets."""
    nom = tablet.nominal
    outline, chain = getattr(nom, "outline", None), getattr(nom, "chain", None)
    if outline is None or chain is None or getattr(outline, "name", "") != "circle":
        return None
    R = outline.segs[0].radius
    items = []
    for e in chain:  # bottom centre -> band -> top centre, each element in (d, z) with d inward from the rim
        a, m, b = ((R - float(q[0]), float(q[1])) for q in e.point(np.array([0.0, 0.5, 1.0])))
        if math.dist(a, b) <= 1e-12 * R:
            continue
        items.append(("line", a, b) if e.kind == "line" else ("arc3", a, m, b))
    items.append(("line", items[-1][-1], items[0][1]))  # the axis, top centre to bottom centre
    return items


def _profile_items(chain, to_3d):
    """build123d edges of a profile chain, each point ``(d, z)`` placed by ``to_3d``."""
    import build123d as bd

    edges = []
    for e in chain:
        a, m, b = (tuple(float(x) for x in q) for q in e.point(np.array([0.0, 0.5, 1.0])))
        if math.dist(a, b) <= 1e-12 * max(1.0, abs(a[0]), abs(a[1])):
            continue
        if e.kind == "line":
            edges.append(bd.Edge.make_line(to_3d(a), to_3d(b)))
        else:
            edges.append(bd.Edge.make_three_point_arc(to_3d(a), to_3d(m), to_3d(b)))
    return edges


def _swept_outline_peer(tablet):
    """The exact nominal of a tablet whose face profile is swept along an outline of lines and
    arcs none of which collapses (every arc's radius at least the profile's inward reach; the
    capsule): each profile edge revolved about an arc's centre through its angle, or extruded
    along a line, the faces made one shell.  None for other tablets."""
    import build123d as bd

    nom = tablet.nominal
    outline, chain = getattr(nom, "outline", None), getattr(nom, "chain", None)
    if outline is None or chain is None or getattr(outline, "name", "") == "circle":
        return None
    reach = max(float(np.max(e.point(np.linspace(0.0, 1.0, 65))[:, 0])) for e in chain)
    faces = []
    for s in outline.segs:
        if s.kind == "arc":
            if s.radius < reach * (1.0 - 1e-12):
                return None  # the arc's offsets collapse: not a plain sweep
            c, rho, th = s.center, s.radius, s.theta0
            axis = bd.Axis((c[0], c[1], 0.0), (0.0, 0.0, 1.0))
            for e in _profile_items(chain, lambda q: bd.Vector(c[0] + (rho - q[0]) * math.cos(th),
                                                                c[1] + (rho - q[0]) * math.sin(th), q[1])):
                faces.append(bd.Face.revolve(e, math.degrees(s.sweep), axis))
        else:
            p0, p1 = np.asarray(s.p0), np.asarray(s.p1)
            t = (p1 - p0) / np.linalg.norm(p1 - p0)
            n = np.array([t[1], -t[0]])  # outward for the counter-clockwise outline
            for e in _profile_items(chain, lambda q: bd.Vector(*(p0 - q[0] * n), q[1])):
                faces.append(bd.Face.extrude(e, bd.Vector(*(p1 - p0), 0.0)))
    return bd.Solid(bd.Shell(faces))


def nominal_build123d(tablet):
    """(build123d solid, kind) for the nominal shape of a sample tablet; kind '~' marks a stand-in."""
    import build123d as bd

    items = _round_family_items(tablet)
    if items is not None:  # a round family: its own face profile, exactly
        return _revolve_profile(items), "revolve (the family's profile)"
    swept = _swept_outline_peer(tablet)
    if swept is not None:  # a capsule: its profile around the outline, exactly
        return swept, "revolve/extrude (the family's profile around the outline)"
    f, p = tablet.family.removeprefix("thesis."), dict(getattr(tablet, "params", {}) or {})
    if f in ("shallow_convex_round", "deep_convex_round"):
        T, b, D = p["thickness"], p["band"], p["diameter"]
        d = (T - b) / 2
        return _band_tablet(D / 2, d, d + b, d, d), "revolve"
    if f in ("shallow_convex_oval", "deep_convex_oval", "caplet"):
        T, b, W = p["thickness"], p["band"], p["width"]
        d = (T - b) / 2
        return _band_tablet(W / 2, d, d + b, d, d), "~revolve (round of equal width)"
    if f in ("flat_faced_round", "flat_face_round") and "thickness" in p:
        return _band_tablet(p["diameter"] / 2, 0.0, p["thickness"], 0.0, 0.0), "revolve"
    if f == "concave_round":  # the issue's peer: band and spherical cups (a land, if any, left out: '~')
        R, b, d = p["diameter"] / 2, p["band"], p["cup_depth"]
        return _band_tablet(R, d, d + b, d, d), "revolve" if not p.get("land") else "~revolve (no land)"
    if f in ("oblong", "rod"):
        R, L, d = p["diameter"] / 2, p["length"], p["dome"]
        return _band_tablet(R, d, L - d, d, d), "revolve"
    if f == "spherical":
        return bd.Solid.make_sphere(p["diameter"] / 2), "sphere"
    if f in ("oblate_spheroid", "prolate_spheroid"):
        R, c = p["diameter"] / 2, p["height"] / 2
        items = [("ellipse", (0.0, 0.0), R, c, 270.0, 360.0), ("ellipse", (0.0, 0.0), R, c, 0.0, 90.0),
                 ("line", (0.0, c), (0.0, -c))]
        return _revolve_profile(items), "revolve"
    if f == "ring":
        ro, ri, T = p["outer_diameter"] / 2, p["inner_diameter"] / 2, p["thickness"]
        items = [("line", (ri, 0.0), (ro, 0.0)), ("line", (ro, 0.0), (ro, T)), ("line", (ro, T), (ri, T)),
                 ("line", (ri, T), (ri, 0.0))]
        return _revolve_profile(items), "revolve"
    if {"diameter", "band", "cup_depth"} <= p.keys():  # other round families (compound cup, bevels)
        R, b, d = p["diameter"] / 2, p["band"], p["cup_depth"]
        return _band_tablet(R, d, d + b, d, d), "~revolve (spherical cups)"
    bb = tablet_bbox(tablet)
    if abs((bb[3] - bb[0]) - (bb[4] - bb[1])) <= 1e-6 * (bb[3] - bb[0]):  # round plan: a cylinder
        return _band_tablet(0.5 * (bb[3] - bb[0]), bb[2], bb[5], 0.0, 0.0), "~revolve (cylinder of its size)"
    # free form (the stadium sample): its bounding plan extruded
    sk = bd.SlotOverall(bb[3] - bb[0], bb[4] - bb[1])
    return bd.extrude(sk, amount=bb[5] - bb[2]).solids()[0], "~extruded SlotOverall plan"


def issue_peer():
    """The peer issue #12 names: a 10 mm standard concave round tablet (band 3 mm, spherical cups 1 mm
    deep, no land) revolved in build123d from exact arcs."""
    return _band_tablet(5.0, 1.0, 4.0, 1.0, 1.0)


def tablet_bbox(tablet):
    import numpy as np

    u = np.linspace(0, 1, 33)
    v = np.linspace(0, 2 * np.pi, 257)
    pts = np.concatenate([p.evaluate_grid(u, v).reshape(-1, 3) for p in tablet.patches])
    return (*pts.min(axis=0), *pts.max(axis=0))


def time_build123d(tablet, tmp: Path):
    """Seconds to make ``tablet``'s peer (:func:`nominal_build123d`; the issue's peer when ``tablet`` is
    None), check it, take its volume and write its STEP and STL; with its kind, validity and volume."""
    import build123d as bd

    t0 = time.perf_counter()
    shape, kind = nominal_build123d(tablet) if tablet is not None else (issue_peer(), "the issue's peer")
    ok = shape.is_valid
    vol = shape.volume
    bd.export_step(shape, str(tmp / "nominal.step"))
    bd.export_stl(shape, str(tmp / "nominal.stl"), tolerance=LINEAR, angular_tolerance=ANGULAR)
    return time.perf_counter() - t0, kind, ok, vol


# --------------------------------------------------------------------------- tabletcad


def time_tabletcad(tablet, report, tmp: Path):
    from tabletcad.cad.export import export
    from tabletcad.cad.stage import check_tablet_solid
    from tabletcad.cad.tablet_solid import tablet_solid

    t0 = time.perf_counter()
    tablet_solid(tablet)
    t1 = time.perf_counter()
    solid, mesh, sections = check_tablet_solid(tablet, report)  # rebuilds the solid: check = total - solid
    t2 = time.perf_counter()
    export(solid, tmp / "tablet.step", name=tablet.name)
    export(solid, tmp / "tablet.stl", name=tablet.name, mesh=mesh)
    export(solid, tmp / "tablet.glb", name=tablet.name, mesh=mesh)
    t3 = time.perf_counter()
    solid_s = t1 - t0
    return solid_s, (t2 - t1) - solid_s, t3 - t2, solid, mesh, sections


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("designs", nargs="*", help="design files (default: samples/*.toml, cut-aways skipped)")
    ap.add_argument("--repeat", type=int, default=3, help="runs per tablet; the best is printed (default 3)")
    args = ap.parse_args(argv)

    import build123d  # noqa: F401  (imports outside the timings)
    import manifold3d  # noqa: F401
    import trimesh  # noqa: F401

    from tabletcad.pipeline.design import load_design

    paths = args.designs or sorted(glob.glob(str(ROOT / "samples" / "*.toml")))
    head = (f"{'sample':24s} {'load':>6s} {'solid':>6s} {'check':>6s} {'export':>6s} {'total':>6s} "
            f"{'b123d':>6s} {'ratio':>5s} {'issue':>5s}  {'poles':>10s} {'fit dev':>8s} {'tris':>6s} {'mesh-brep':>9s} "
            f"{'bound':>8s}  nominal")
    print(f"one core, best of {args.repeat}; seconds; deflections {LINEAR} mm / {ANGULAR} rad")
    print(head)
    totals, refs = [], []
    with tempfile.TemporaryDirectory(prefix="bench-cad-") as d:
        tmp = Path(d)
        issue_s = min(time_build123d(None, tmp)[0] for _ in range(max(1, args.repeat)))
        print(f"the issue's peer (10 mm concave round, band 3, cups 1; revolve, check, volume, STEP, STL): {issue_s:.3f} s")
        for path in paths:
            t0 = time.perf_counter()
            tablet = load_design(path)
            load_s = time.perf_counter() - t0
            tr = tablet.trim
            if tr.u != (0.0, 1.0) or not tr.full_v:
                print(f"{Path(path).stem:24s} (cut-away view: no solid)")
                continue
            report = {"volume_mm3": tablet.volume(), "surface_area_mm2": tablet.surface_area()}
            best = None
            for _ in range(max(1, args.repeat)):
                r = time_tabletcad(tablet, report, tmp)
                if best is None or sum(r[:3]) < sum(best[:3]):
                    best = r
            solid_s, check_s, export_s, solid, mesh, _sections = best
            ref = min((time_build123d(tablet, tmp) for _ in range(max(1, args.repeat))), key=lambda x: x[0])
            total = solid_s + check_s + export_s
            totals.append(total)
            refs.append(ref[0])
            poles = "x".join(str(n) for n in solid.surfaces[0].shape) + (f"+{len(solid.surfaces) - 1}" if len(solid.surfaces) > 1 else "")
            rel = (mesh.manifold_volume - solid.volume) / solid.volume
            bound = LINEAR * solid.area / solid.volume
            print(
                f"{Path(path).stem:24s} {load_s:6.2f} {solid_s:6.3f} {check_s:6.3f} {export_s:6.3f} {total:6.3f} "
                f"{ref[0]:6.3f} {total / ref[0]:5.1f} {total / issue_s:5.1f}  {poles:>10s} {solid.max_fit_deviation:8.1e} "
                f"{len(mesh.triangles):6d} {rel:9.1e} {bound:8.1e}  {ref[1]}{'' if ref[2] else ' (INVALID)'}"
                f"{'' if ref[1].startswith('~') else f', volume {(ref[3] - solid.volume) / solid.volume:+.0e}'}",
                flush=True,
            )
    if totals:
        print(f"{'mean':24s} {'':6s} {'':6s} {'':6s} {'':6s} {sum(totals) / len(totals):6.3f} "
              f"{sum(refs) / len(refs):6.3f} {sum(totals) / sum(refs):5.1f} {sum(totals) / len(totals) / issue_s:5.1f}")
    print("ratio: total / b123d (this sample's peer or stand-in); issue: total / the issue's peer")
    print("mesh-brep: (manifold3d mesh volume - B-rep volume) / B-rep volume; bound: deflection x area / volume")


if __name__ == "__main__":
    main()
