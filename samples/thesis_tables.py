"""Tables 4.2 and 4.3 of the thesis beside tabletcad's figures and the exact shapes.

Run: python samples/thesis_tables.py   (prints a Markdown table; asserts the key figures)
"""

from __future__ import annotations

import math

from tabletcad import families

# thesis figures: (area mm², volume mm³), Tables 4.2(a), 4.2(b), 4.3
THESIS = {
    "flat_faced_round": (345.062, 470.320),
    "spherical": (77.913, 64.464),
    "shallow_convex_round": (221.038, 198.215),
    "shallow_convex_oval": (172.846, 142.075),
    "oblong": (250.032, 298.663),
}


def _cap(a: float, h: float) -> tuple[float, float]:
    """Area and volume of a spherical cap of base radius a and height h."""
    return math.pi * (a * a + h * h), math.pi * h * (3 * a * a + h * h) / 6


def exact(name: str, t) -> tuple[float, float] | None:
    p = t.params
    if name == "flat_faced_round":
        r, T = p["diameter"] / 2, p["thickness"]
        return 2 * math.pi * r * (r + T), math.pi * r * r * T
    if name == "spherical":
        r = p["diameter"] / 2
        return 4 * math.pi * r * r, 4 / 3 * math.pi * r**3
    if name == "shallow_convex_round":
        r, T, b = p["diameter"] / 2, p["thickness"], p["band"]
        ca, cv = _cap(r, (T - b) / 2)
        return 2 * ca + 2 * math.pi * r * b, 2 * cv + math.pi * r * r * b
    if name == "oblong":
        r, L, d = p["diameter"] / 2, p["length"], p["dome"]
        ca, cv = _cap(r, d)
        return 2 * ca + 2 * math.pi * r * (L - 2 * d), 2 * cv + math.pi * r * r * (L - 2 * d)
    return None


def rows():
    for name, (ta, tv) in THESIS.items():
        t = families.FAMILIES[f"thesis.{name}"].build()
        pr = t.properties()
        ex = exact(name, t)
        dev = t.nominal_deviation()
        yield name, pr["surface_area_mm2"], pr["volume_mm3"], ta, tv, ex, dev


def main() -> None:
    print("| shape | tabletcad area mm² | thesis area | exact area | tabletcad volume mm³ | thesis volume | exact volume | PDE vs exact shape |")
    print("|---|---|---|---|---|---|---|---|")
    out = {}
    for name, a, v, ta, tv, ex, dev in rows():
        exa = f"{ex[0]:.3f}" if ex else "—"
        exv = f"{ex[1]:.3f}" if ex else "—"
        d = f"{dev * 1000:.1f} µm" if dev is not None else "—"
        print(f"| {name} | {a:.3f} | {ta:.3f} | {exa} | {v:.3f} | {tv:.3f} | {exv} | {d} |")
        out[name] = (a, v, ex, dev)
    # key figures (fail loudly if the core changes them)
    a, v, ex, dev = out["flat_faced_round"]
    assert abs(v - 471.382) < 1e-3 and abs(ex[1] - 471.239) < 1e-3
    a, v, ex, dev = out["spherical"]
    assert abs(v - 65.691) < 1e-3 and 0.005 < dev < 0.02
    for name, (a, v, ex, dev) in out.items():
        if ex:
            assert abs(v - ex[1]) / ex[1] < 0.01, name


if __name__ == "__main__":
    main()
