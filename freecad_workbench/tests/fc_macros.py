"""Runs every macro of freecad_workbench/macros headless and re-reads what they wrote.

Env: TABLETCAD_FC_OUTPUT, TABLETCAD_FC_WORK, TABLETCAD_ROOT; the macros read TABLETCAD_DESIGN,
TABLETCAD_PRESS, TABLETCAD_PROBLEM and TABLETCAD_OUT.
"""

import json
import os
import time
import traceback

import FreeCAD

out_path = os.environ["TABLETCAD_FC_OUTPUT"]
work = os.environ["TABLETCAD_FC_WORK"]
root = os.environ["TABLETCAD_ROOT"]
macros = os.path.join(root, "freecad_workbench", "macros")
result = {"ok": False, "macros": {}}


def run(name, **env):
    os.environ.update(env)
    t0 = time.perf_counter()
    path = os.path.join(macros, name + ".FCMacro")
    with open(path, encoding="utf-8") as fh:
        code = compile(fh.read(), path, "exec")
    exec(code, {"__name__": "__main__", "__file__": path})
    return time.perf_counter() - t0


try:
    os.environ["TABLETCAD_OUT"] = work
    # 1. tablet from a design file
    doc = FreeCAD.newDocument("macro_design")
    s = run(
        "tabletcad_tablet_from_design",
        TABLETCAD_DESIGN=os.path.join(root, "samples", "families", "concave_round.toml"),
    )
    t = [o for o in doc.Objects if getattr(getattr(o, "Proxy", None), "Type", "") == "TabletcadTablet"]
    result["macros"]["design"] = dict(
        seconds=s,
        n=len(t),
        valid=[o.isValid() for o in t],
        family=t[0].Family if t else None,
        volume=float(t[0].Volume) if t else None,
    )

    # 2. STEP export of that tablet and its tooling, read back with Part.read
    s = run("tabletcad_export_step")
    import Part

    files = sorted(f for f in os.listdir(work) if f.endswith(".step"))
    back = {}
    for f in files:
        shp = Part.read(os.path.join(work, f))
        back[f] = dict(n_solids=len(shp.Solids), valid=bool(shp.isValid()), volume=float(shp.Volume))
    objs = {o.Label: float(o.Shape.Volume) for o in doc.Objects}
    result["macros"]["step"] = dict(seconds=s, files=back, objects=objs)

    # 3. Heckel analysis (PNG written; shown only with the GUI)
    png = os.path.join(work, "lactose_appendix_b_heckel.png")
    s = run(
        "tabletcad_heckel", TABLETCAD_PRESS=os.path.join(root, "samples", "press", "lactose_appendix_b.csv")
    )
    result["macros"]["heckel"] = dict(
        seconds=s,
        png=png,
        exists=os.path.exists(png),
        size=os.path.getsize(png) if os.path.exists(png) else 0,
    )

    # 4. optimisation: optimum loaded as a Tablet
    doc = FreeCAD.newDocument("macro_opt")
    s = run(
        "tabletcad_optimise",
        TABLETCAD_PROBLEM=os.path.join(root, "samples", "optimise", "cylinder_min_area.toml"),
    )
    t = [o for o in doc.Objects if getattr(getattr(o, "Proxy", None), "Type", "") == "TabletcadTablet"]
    result["macros"]["optimise"] = dict(
        seconds=s,
        n=len(t),
        valid=[o.isValid() for o in t],
        family=t[0].Family if t else None,
        volume=float(t[0].Volume) if t else None,
        area=float(t[0].Area) if t else None,
        dims={
            p: float(getattr(t[0], p).Value)
            for p in t[0].PropertiesList
            if t[0].getGroupOfProperty(p) == "Dimensions"
        }
        if t
        else {},
        design=sorted(f for f in os.listdir(work) if f.endswith(".toml")),
    )
    result["ok"] = True
except Exception as exc:
    result["error"] = repr(exc)
    result["traceback"] = traceback.format_exc()
with open(out_path, "w") as fh:
    json.dump(result, fh)
