"""Run under FreeCAD's own Python (``freecadcmd freecad_check.py``): stdlib + FreeCAD only.

Inputs come from environment variables (freecadcmd treats extra arguments as
documents to open):

``TABLETCAD_FC_MODE``   ``read_step``, ``read_steps``, ``bspline`` or ``batch``
``TABLETCAD_FC_INPUT``  the STEP file, a JSON file of a list of STEP files (``read_steps``), a JSON file
                        ``{"surfaces": [BSplineSurfaceData.as_dict()...], "u": [...], "v": [...]}``, or (``batch``)
                        a JSON file ``{"read_step": [STEP files...], "bspline": [JSON files as bspline's...]}``
``TABLETCAD_FC_OUTPUT`` where the JSON result is written (also printed after ``TABLETCAD_JSON:``)

``read_step``: reads the file with ``Part.read`` (FreeCAD's OCCT STEP reader) and
with ``Import.insert`` (document objects, product names); reports the number of
solids, ``isValid()``, ``Volume`` and ``Area``.  Note ``Shape.Volume`` uses OCCT's
default (non-adaptive) integration.  ``read_steps``: the same for each file of the list, in one FreeCAD
process: ``{"results": [{"ok": ..., <read_step's result or "error">}, ...]}`` in the list's order.

``bspline``: rebuilds every surface with
``Part.BSplineSurface().buildFromPolesMultsKnots(...)`` from the kernel-neutral
data, evaluates it at the given ``(u, v)`` pairs, reads poles/knots back, then
sews the faces, makes a solid and reports validity, volume and area.

``batch``: ``read_step`` of each STEP file and ``bspline`` of each surfaces file, in one FreeCAD process
(one start-up and one ``Import`` load for all of them): ``{"read_step": [...], "bspline": [...]}`` in the
lists' order, each ``{"ok": ..., <the mode's result or "error">}``.
"""

import json
import os
import sys
import traceback


def _read_step(path):
    import FreeCAD
    import Part

    shape = Part.read(path)
    result = {
        "n_solids": len(shape.Solids),
        "n_shells": len(shape.Shells),
        "n_faces": len(shape.Faces),
        "valid": bool(shape.isValid()),
        "solids_valid": [bool(s.isValid()) for s in shape.Solids],
        "solids_closed": [bool(s.isClosed()) for s in shape.Solids],
        "volume": float(shape.Volume),
        "area": float(shape.Area),
        "freecad_version": ".".join(FreeCAD.Version()[:3]),
    }
    try:
        import Import

        doc = FreeCAD.newDocument("tabletcad_check")
        Import.insert(path, doc.Name)
        result["labels"] = [o.Label for o in doc.Objects]
        FreeCAD.closeDocument(doc.Name)
    except Exception as exc:  # Import module is optional for the check
        result["labels_error"] = repr(exc)
    return result


def _read_steps(path):
    with open(path) as fh:
        paths = json.load(fh)
    results = []
    for p in paths:
        try:
            results.append({"ok": True, "path": p, **_read_step(p)})
        except Exception as exc:
            results.append({"ok": False, "path": p, "error": repr(exc), "traceback": traceback.format_exc()})
    return {"results": results}


def _bspline(path):
    import FreeCAD
    import Part

    with open(path) as fh:
        data = json.load(fh)
    us, vs = data.get("u", []), data.get("v", [])
    faces, values, readback = [], [], []
    for d in data["surfaces"]:
        bs = Part.BSplineSurface()
        poles = [[FreeCAD.Vector(*p) for p in row] for row in d["poles"]]
        bs.buildFromPolesMultsKnots(
            poles,
            d["u_mults"],
            d["v_mults"],
            d["u_knots"],
            d["v_knots"],
            d["u_periodic"],
            d["v_periodic"],
            d["u_degree"],
            d["v_degree"],
        )
        values.append([list(bs.value(u, v)) for u, v in zip(us, vs)])
        readback.append(
            {
                "poles": [[list(p) for p in row] for row in bs.getPoles()],
                "u_knots": list(bs.getUKnots()),
                "v_knots": list(bs.getVKnots()),
                "u_mults": list(bs.getUMultiplicities()),
                "v_mults": list(bs.getVMultiplicities()),
                "u_periodic": bool(bs.isUPeriodic()),
                "v_periodic": bool(bs.isVPeriodic()),
            }
        )
        faces.append(bs.toShape())
    shell = Part.Shell(faces)
    sewn = shell.copy()
    sewn.sewShape()
    shells = sewn.Shells if sewn.ShapeType != "Shell" else [sewn]
    solid = Part.Solid(shells[0]) if len(shells) == 1 else None
    out = {
        "values": values,
        "readback": readback,
        "faces_valid": [bool(f.isValid()) for f in faces],
        "n_shells": len(shells),
        "shell_closed": bool(shells[0].isClosed()) if len(shells) == 1 else False,
        "freecad_version": ".".join(FreeCAD.Version()[:3]),
    }
    if solid is not None:
        if solid.Volume < 0:
            solid.reverse()
        out.update({"valid": bool(solid.isValid()), "volume": float(solid.Volume), "area": float(solid.Area)})
    return out


def _batch(path):
    with open(path) as fh:
        jobs = json.load(fh)
    out = {}
    for mode, run in (("read_step", _read_step), ("bspline", _bspline)):
        results = out[mode] = []
        for p in jobs.get(mode, []):
            try:
                results.append({"ok": True, "path": p, **run(p)})
            except Exception as exc:
                results.append({"ok": False, "path": p, "error": repr(exc), "traceback": traceback.format_exc()})
    return out


def main():
    mode = os.environ.get("TABLETCAD_FC_MODE", "read_step")
    inp = os.environ["TABLETCAD_FC_INPUT"]
    out_path = os.environ.get("TABLETCAD_FC_OUTPUT")
    try:
        result = {"ok": True, **{"read_step": _read_step, "read_steps": _read_steps, "batch": _batch}.get(mode, _bspline)(inp)}
    except Exception as exc:
        result = {"ok": False, "error": repr(exc), "traceback": traceback.format_exc()}
    text = json.dumps(result)
    if out_path:
        with open(out_path, "w") as fh:
            fh.write(text)
    sys.stdout.write("TABLETCAD_JSON:" + text + "\n")
    sys.stdout.flush()


main()
