"""Press data reading, compliance correction and derived curves (thesis Appendix B)."""

from __future__ import annotations

import csv
import warnings
from pathlib import Path

import numpy as np
import pytest

from tabletcad.errors import DesignError
from tabletcad.mechanics.compaction import compaction_curves, split_branches
from tabletcad.mechanics.pressdata import MachineCompliance, PressData, PressMetadata, read_press_data
from tabletcad.mechanics.validity import DataWarning

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "samples" / "press" / "lactose_appendix_b.csv"


def _printed_rows():
    with SAMPLE.open() as fh:
        rows = [r for r in csv.reader(fh) if r and not r[0].startswith("#")]
    return rows[0], rows[1:]


def _decimals(s: str) -> int:
    return len(s.split(".")[1]) if "." in s else 0


def test_sample_metadata_and_columns():
    d = read_press_data(SAMPLE)
    assert len(d) == 243
    assert d.metadata.mass_mg == 300.0 and d.metadata.true_density == 1.3 and d.metadata.diameter == 10.0
    # printed line y = 0.00002x - 0.0267 is applied as deflection = 0.00002 F + 0.0267
    assert d.metadata.compliance.slope == pytest.approx(2e-5)
    assert d.metadata.compliance.offset == pytest.approx(0.0267)
    assert set(d.extra) == {"thickness_mm", "relative_density", "pressure_MPa", "ln_1_over_1_minus_D"}


@pytest.mark.parametrize(
    "column,attr",
    [(2, "thickness"), (3, "relative_density"), (4, "pressure"), (5, "heckel")],
)
def test_appendix_b_columns_reproduced_to_printed_precision(column, attr):
    """Every printed value is matched within half a unit of its last printed digit."""
    c = compaction_curves(read_press_data(SAMPLE))
    _, rows = _printed_rows()
    ours = getattr(c, attr)
    worst = max(abs(ours[i] - float(r[column])) / (0.5 * 10.0 ** -_decimals(r[column])) for i, r in enumerate(rows))
    assert worst <= 1.0 + 1e-6


def test_appendix_thickness_rule_is_minus_displacement_plus_line_with_flipped_intercept():
    d = read_press_data(SAMPLE)
    th = -d.displacement + 0.00002 * d.force + 0.0267
    assert np.max(np.abs(np.round(th, 4) - d.extra["thickness_mm"])) < 1e-12
    # the literal reading "thickness = -x - (0.00002 F - 0.0267)" is off by up to ~0.19 mm
    literal = -d.displacement - (0.00002 * d.force - 0.0267)
    assert np.max(np.abs(literal - d.extra["thickness_mm"])) > 0.15


def test_branches_of_appendix_b():
    c = compaction_curves(read_press_data(SAMPLE))
    b = c.branches
    assert b.loading == (0, 81)  # first force peak 4836.278 N, rows 80-81 (1-based)
    assert c.pressure[b.peak] == pytest.approx(4836.278 / (np.pi * 25))
    assert b.reloading_from is not None and b.reloading_from > b.unloading[0]
    assert b.unloading[1] <= b.reloading_from
    # the record is reloaded before unloading completes: no elastic recovery reported
    assert c.elastic_recovery is None and "61 %" in c.recovery_note
    assert "reload" in c.describe_rows()


def test_elastic_recovery_of_a_complete_cycle():
    F = np.concatenate([np.linspace(10, 1000, 30), np.linspace(990, 20, 20)])
    h = np.concatenate([np.linspace(5.0, 3.0, 30), np.linspace(3.002, 3.06, 20)])
    meta = PressMetadata(mass_mg=100, true_density=1.5, diameter=8)
    c = compaction_curves(PressData.from_arrays(F, thickness=h, metadata=meta))
    assert c.branches.loading == (0, 30)
    assert c.elastic_recovery == pytest.approx(0.06 / 3.0)


def test_compliance_table_matches_line():
    line = MachineCompliance(slope=2e-5, offset=0.01)
    table = MachineCompliance(table_force=(0.0, 1000.0, 5000.0), table_deflection=(0.01, 0.03, 0.11))
    F = np.array([-100.0, 0.0, 500.0, 3000.0, 8000.0])
    assert np.allclose(table.deflection(F), line.deflection(F))


@pytest.mark.parametrize("force, deflection, line", [
    ((0.0, 5000.0, 10000.0), (0.0, -0.1, -0.2), "compliance.deflection[1] = -0.1 mm is not allowed: its step from 0 mm "
     "at 0 N to -0.1 mm at 5000 N is -2e-05 mm/N; a step must be >= 0 and <= 0.001 mm/N"),
    ((5000.0, 0.0, 10000.0), (0.1, 0.0, 0.2), "compliance.force[1] = 0 N is not allowed: must be > compliance.force[0] "
     "= 5000 N (the forces strictly increasing)"),
    ((0.0,), (0.0,), "compliance.table = 1 is not allowed: needs >= 2 finite (force, deflection) pairs"),
])
def test_a_compliance_table_built_in_python_is_checked_as_a_files(force, deflection, line):
    """The rule is one function, :func:`check_compliance_table`, for a file's table and the dataclass's."""
    with pytest.raises(DesignError) as e:
        MachineCompliance(table_force=force, table_deflection=deflection)
    assert str(e.value).startswith(line), str(e.value)
    flat = MachineCompliance(table_force=(0.0, 5000.0), table_deflection=(0.01, 0.01))  # a rigid frame: step 0
    assert np.allclose(flat.deflection([0.0, 9000.0]), 0.01)


def _write(tmp_path: Path, text: str, name="run.csv") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


META = {"mass_mg": 300.0, "true_density": 1.3, "diameter": 10.0}


def test_missing_values_dropped_with_count(tmp_path):
    p = _write(tmp_path, "force (N),displacement (mm)\n10,-6\n,-5.9\n30,\n40,-5.7\n50,-5.6\n")
    with pytest.warns(DataWarning, match="dropped 2 row"):
        d = read_press_data(p, **META)
    assert len(d) == 3 and d.dropped_rows == 2
    assert list(d.line_numbers) == [2, 5, 6]


def test_tab_separated_thickness_and_time(tmp_path):
    p = _write(tmp_path, "time (s)\tforce (N)\tthickness (mm)\n0\t1\t5\n0.1\t2\t4.9\n0.2\t3\t4.8\n", "run.tsv")
    d = read_press_data(p, **META)
    assert np.allclose(d.thickness, [5, 4.9, 4.8]) and np.allclose(d.time, [0, 0.1, 0.2])


@pytest.mark.parametrize(
    "text,match",
    [
        ("force_N,displacement_mm\n1,-5\nabc,-4\n", "must be a number"),
        # decimal commas in a comma-separated file (a new user's): the refusal says why the cells are too many
        ("force_N,displacement_mm\n3,891,-6,032\n3,891,-5,992\n", "a decimal comma in a comma-separated file"),
        ("load_cell,time\n1,0\n2,1\n", "displacement or thickness"),
        ("pos,displacement\n1,-5\n", "force column"),
    ],
)
def test_bad_files(tmp_path, text, match):
    with pytest.raises(DesignError, match=match):
        read_press_data(_write(tmp_path, text), **META)


@pytest.mark.parametrize("key,value,match", [
    ("mass_mg", 0.0, "must be > 0"), ("true_density", -1.3, "must be >= 0.1"),
    ("true_density", 0.00154, "must be >= 0.1 and <= 25"),  # g/mm³
    ("diameter", 0.0, "must be > 0"),
    # a new user's compliances: 1e300 mm/N had given K = -2.6e-303, an offset of 1e300 mm Py = inf, a
    # negative slope a thickness of -3.9e300 mm, and a calibration typed in kN K = -0.0024 1/MPa
    ("compliance", (1e300, 0.0), r"compliance\.slope = 1e\+300 mm/N is not allowed: must be >= 0 and <= 0\.001"),
    ("compliance", (0.0, 1e300), r"compliance\.offset = 1e\+300 mm is not allowed: must be >= -1000 and <= 1000"),
    ("compliance", (-2e-5, 0.0), r"compliance\.slope = -2e-05 mm/N is not allowed"),
    ("compliance", {"force": [0.0, 10.0], "deflection": [0.0267, 0.2267]},
     r"compliance\.deflection\[1\] = 0\.2267 mm is not allowed: its step from 0\.0267 mm at 0 N to 0\.2267 mm at "
     r"10 N is 0\.02 mm/N; a step must be >= 0 and <= 0\.001 mm/N"),
])
def test_bad_metadata(tmp_path, key, value, match):
    p = _write(tmp_path, "force_N,displacement_mm\n1,-5\n2,-4.9\n3,-4.8\n")
    with pytest.raises(DesignError, match=match):
        read_press_data(p, **(META | {key: value}))


def test_missing_diameter(tmp_path):
    p = _write(tmp_path, "force_N,displacement_mm\n1,-5\n2,-4.9\n3,-4.8\n")
    with pytest.raises(DesignError, match="diameter"):
        read_press_data(p, mass_mg=1.0, true_density=1.0)


def test_no_loading_branch():
    with pytest.raises(DesignError, match="no loading branch"):
        split_branches([100.0, 90.0, 80.0, 70.0])


def test_a_baseline_before_the_punches_meet_the_powder_is_not_the_end_of_loading(tmp_path):
    """A press export starts with the load cell's noise before the punches meet the powder: 0.5 N then 0.3 N ahead
    of the thesis's 4.8 kN record had ended the loading branch at row 1 ("has no loading branch"), its fall
    measured against the running peak (0.5 N) rather than the record's.  The branches are the record's own,
    two rows later, and the Heckel fit over 10-50 MPa is the record's to the last bit."""
    from tabletcad.mechanics.heckel import fit_heckel

    lines = [ln for ln in SAMPLE.read_text(encoding="utf-8").splitlines() if not ln.startswith("#")]
    rows = [ln.split(",")[:2] for ln in lines[1:]]
    plain = _write(tmp_path, "force_N,displacement_mm\n" + "".join(f"{f},{x}\n" for f, x in rows), "plain.csv")
    first_x = float(rows[0][1])
    noisy = _write(tmp_path, "force_N,displacement_mm\n" + f"0.5,{first_x - 0.04}\n0.3,{first_x - 0.02}\n"
                   + "".join(f"{f},{x}\n" for f, x in rows), "noisy.csv")
    meta = dict(mass_mg=300.0, true_density=1.3, diameter=10.0)  # (the sample's)
    b0 = split_branches(read_press_data(plain, **meta).force)
    b1 = split_branches(read_press_data(noisy, **meta).force)
    assert b1.loading == (0, b0.loading[1] + 2) and b1.peak == b0.peak + 2
    assert b1.reloading_from == b0.reloading_from + 2
    k0, k1 = (fit_heckel(compaction_curves(read_press_data(p, **meta)), window=(10.0, 50.0)) for p in (plain, noisy))
    assert (k1.K_per_MPa, k1.A, k1.n_points) == (k0.K_per_MPa, k0.A, k0.n_points) and k0.n_points > 20
    # a dip of more than 2 % of the record's largest force still ends the loading branch (a pre-compression)
    assert split_branches([10.0, 500.0, 1000.0, 900.0, 2000.0, 4800.0]).loading == (0, 3)


def test_metadata_beside_file_is_found(tmp_path):
    p = _write(tmp_path, "force_N,displacement_mm\n1,-5\n2,-4.9\n3,-4.8\n")
    (tmp_path / "run.toml").write_text("mass_mg = 10\ntrue_density = 1.5\nface_area = 20\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        d = read_press_data(p)
    assert d.metadata.area == 20.0
    assert np.allclose(d.gap, [5, 4.9, 4.8])


# --------------------------------------------------------------------------- units, separators, column roles
from decimal import Decimal  # noqa: E402

from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from tabletcad.mechanics.heckel import fit_heckel  # noqa: E402
from tabletcad.mechanics.units import UNITS, header_unit, strip_unit  # noqa: E402

SAMPLE_META = SAMPLE.with_suffix(".toml")


def _sample_columns():
    """Force (N) and displacement (mm) cells of Appendix B as printed, and a 1 ms time column."""
    _, rows = _printed_rows()
    return [r[0] for r in rows], [r[1] for r in rows], [f"{k / 1000:.3f}" for k in range(len(rows))]


def _convert(cell: str, unit: str, decimal_comma: bool) -> str:
    """``cell`` (in N, mm or s) written in ``unit``: exact decimal shift for powers of ten, else 17 digits."""
    _, factor, exponent = UNITS[unit]
    if exponent is not None:
        out = format(Decimal(cell).scaleb(-exponent), "f")
    else:
        out = repr(float(cell) / factor)
    return out.replace(".", ",") if decimal_comma else out


def _write_sample(tmp_path, fu="N", lu="mm", tu="s", delim=",", decimal_comma=False, style="({})", name="conv.csv",
                  encoding="utf-8", comment="# converted copy of Appendix B\n"):
    F, x, t = _sample_columns()
    head = [f"Time {style.format(tu)}", f"Upper Punch Force {style.format(fu)}",
            f"Punch displacement {style.format(lu)}"]
    lines = [delim.join(head)] + [
        delim.join([_convert(a, tu, decimal_comma), _convert(b, fu, decimal_comma), _convert(c, lu, decimal_comma)])
        for a, b, c in zip(t, F, x)
    ]
    p = tmp_path / name
    p.write_bytes((comment + "\n".join(lines) + "\n").encode(encoding))
    return p


def _fits(path, **kw):
    c = compaction_curves(read_press_data(path, SAMPLE_META, **kw))
    return c, fit_heckel(c, window=(10.0, 50.0)), fit_heckel(c)


def test_kN_um_ms_decimal_comma_semicolon_gives_identical_heckel(tmp_path):
    """Appendix B in N/mm/s with '.' and in kN/µm/ms with decimal commas and ';' gives bit-identical K, A, Py."""
    c0, w0, a0 = _fits(_write_sample(tmp_path, name="n.csv"))
    c1, w1, a1 = _fits(_write_sample(tmp_path, "kN", "µm", "ms", ";", True, "[{}]", "k.csv",
                                     encoding="utf-8-sig"))
    assert np.array_equal(c0.pressure, c1.pressure) and np.array_equal(c0.thickness, c1.thickness)
    for f0, f1 in ((w0, w1), (a0, a1)):
        assert (f0.K_per_MPa, f0.A, f0.Py_MPa, f0.r2) == (f1.K_per_MPa, f1.A, f1.Py_MPa, f1.r2)
    # and the thesis-window fit is the one of the bundled sample
    assert w0.K_per_MPa == pytest.approx(0.0095647, rel=1e-4) and w0.n_points == 29
    d1 = read_press_data(tmp_path / "k.csv", SAMPLE_META)
    assert d1.time[1] == pytest.approx(0.001, rel=1e-12) and d1.force[-1] == pytest.approx(float(_sample_columns()[0][-1]))


@settings(max_examples=30, deadline=None)
@given(
    fu=st.sampled_from([k for k, v in UNITS.items() if v[0] == "force"]),
    lu=st.sampled_from([k for k, v in UNITS.items() if v[0] == "length"]),
    tu=st.sampled_from([k for k, v in UNITS.items() if v[0] == "time"]),
    fmt=st.sampled_from([(",", False), (";", True), ("\t", True), ("\t", False), (";", False)]),
    style=st.sampled_from(["({})", "[{}]", "_{}", "( {} )"]),
)
def test_any_unit_choice_gives_the_same_heckel(tmp_path_factory, fu, lu, tu, fmt, style):
    tmp = tmp_path_factory.mktemp("units")
    ref = getattr(test_any_unit_choice_gives_the_same_heckel, "ref", None)
    if ref is None:
        ref = _fits(_write_sample(tmp, name="ref.csv"))[1]
        test_any_unit_choice_gives_the_same_heckel.ref = ref
    _, w, _ = _fits(_write_sample(tmp, fu, lu, tu, fmt[0], fmt[1], style))
    exact = all(UNITS[u][2] is not None for u in (fu, lu))
    if exact:  # powers of ten are converted in the decimal text: the very same doubles
        assert (w.K_per_MPa, w.A, w.Py_MPa) == (ref.K_per_MPa, ref.A, ref.Py_MPa)
    else:  # one division when writing, one multiplication when reading
        assert w.K_per_MPa == pytest.approx(ref.K_per_MPa, rel=1e-12)
        assert w.A == pytest.approx(ref.A, rel=1e-12)
    assert w.n_points == ref.n_points


def test_units_override_headers_and_columns_are_chosen(tmp_path):
    p = _write_sample(tmp_path, "kN", "µm", "ms", "\t", True, "({})")
    lower = tmp_path / "two.csv"
    lines = p.read_text().splitlines()
    lines[1] += "\tLower Punch Force (kN)"
    lines[2:] = [ln + "\t0,001" for ln in lines[2:]]
    lower.write_text("\n".join(lines) + "\n")
    with pytest.raises(DesignError, match=r"force\.column = .*Upper.*Lower.* is ambiguous; choose one with --force-column"):
        read_press_data(lower, SAMPLE_META)
    ref = read_press_data(p, SAMPLE_META)
    d = read_press_data(lower, SAMPLE_META, columns={"force": "upper punch force (kN)"})
    assert np.array_equal(d.force, ref.force) and "Lower Punch Force (kN)" in d.extra
    d = read_press_data(lower, SAMPLE_META, columns={"force": "2"})
    assert np.array_equal(d.force, ref.force)
    # an unrecognised header can be given a role; the column it takes is not offered to its own role
    renamed = tmp_path / "renamed.csv"
    renamed.write_text(lower.read_text().replace("Punch displacement (µm)", "Weg (µm)"))
    d = read_press_data(renamed, SAMPLE_META, columns={"displacement": "Weg (µm)", "force": "Lower Punch Force (kN)"})
    assert np.allclose(d.force, 1.0) and np.array_equal(d.displacement, ref.displacement)
    # the same file declared in other units: the option wins over the header
    d = read_press_data(p, SAMPLE_META, units={"force": "N", "displacement": "mm", "time": "s"})
    assert np.allclose(d.force * 1000.0, ref.force, rtol=1e-14)
    assert np.allclose(d.time, ref.time * 1000.0, rtol=1e-14)


@pytest.mark.parametrize(
    "header,kw,match",
    [
        ("Force (kN/cm2);Displacement (mm)", {}, r"^column = 'Force \(kN/cm2\)' is not allowed: states the unit 'kN/cm2', which is not a known force unit .*; or give --force-unit$"),
        ("Force (mm);Displacement (mm)", {}, "is not a known force unit"),
        ("Force [kN];Punch position [furlong]", {}, "furlong"),
        ("Force;Displacement", {"units": {"force": "stone"}}, "--force-unit = 'stone' is not allowed"),
        ("Force;Displacement", {"units": {"time": "mm"}}, "--time-unit = 'mm'"),
        ("Force;Displacement", {"columns": {"force": "Kraft"}}, "--force-column = 'Kraft'"),
        ("Force;Displacement", {"columns": {"force": "2", "displacement": "2"}},
         "--displacement-column = '2' is not allowed: is already the force column"),
        ("Force;Upper punch position (mm);Lower punch position (mm)", {}, "--displacement-column"),
    ],
)
def test_unknown_units_and_ambiguous_roles_are_refused(tmp_path, header, kw, match):
    n = header.count(";") + 1
    p = _write(tmp_path, header + "\n" + "\n".join(";".join(["1,5"] * n) for _ in range(3)) + "\n")
    with pytest.raises(DesignError, match=match):
        read_press_data(p, **kw, **META)


@pytest.mark.parametrize(
    "header,role,unit",
    [
        ("Upper Punch Force (kN)", "force", "kN"),
        ("Force [daN]", "force", "daN"),
        ("Time [ms]", "time", "ms"),
        ("Punch distance (mm)", "displacement", "mm"),
        ("Displacement (µm)", "displacement", "µm"),
        ("Displacement (\u03bcm)", "displacement", "µm"),
        ("Displacement (um)", "displacement", "um"),
        ("force_N", "force", "N"),
        ("Tablet thickness in", "thickness", None),
        ("Gap_in", "thickness", "in"),
        ("Punch travel (cm)", "displacement", "cm"),
        ("Load (lbf)", "force", "lbf"),
        ("Elapsed time (min)", "time", "min"),
        ("Compression force MN", "force", "MN"),
        ("Height", "thickness", None),
    ],
)
def test_header_roles_and_units(header, role, unit):
    from tabletcad.mechanics.pressdata import _role

    assert _role(header) == role and header_unit(header) == unit
    assert unit is None or unit not in strip_unit(header).split()


@pytest.mark.parametrize("header, unit", [("Force/kN", "kN"), ("Force [kN] upper", "kN"), ("Force (kN) upper punch", "kN"),
                                          ("Displacement/µm", "µm"), ("Upper punch kN force", "kN"),
                                          ("Displacement in mm of the punch", "mm")])
def test_a_unit_where_the_header_is_not_read_for_one_is_refused(tmp_path, header, unit):
    """A new user's ``Force/kN`` and ``Force [kN] upper``: no unit was read there, so the forces in kN were taken
    as N (K 9.632 1/MPa for 0.008557) with only a warning on Py.  Refused now, naming the column and its unit;
    a name whose words are also unit symbols (``in``, ``m``, ``min``) is not (the cases above)."""
    assert strip_unit(header)  # (the role is still found from the name)
    with pytest.raises(DesignError) as e:
        header_unit(header)
    assert e.value.parameter == "column" and e.value.value == header
    assert f"states the unit {unit!r} where tabletcad does not read one" in str(e.value)
    other = "Displacement (mm)" if unit == "kN" else "Force (N)"
    p = _write(tmp_path, f"{header};{other}\n" + "\n".join(f"{k},5;{k}" for k in range(1, 4)) + "\n")
    with pytest.raises(DesignError, match="where tabletcad does not read one"):
        read_press_data(p, **META)


@pytest.mark.parametrize("header, role, units", [
    ("force;displacement_mm", "force", {"force": "N"}),
    ("Force [N];Displacement", "displacement", {"displacement": "mm"}),
    ("Load;Gap", "force", {"force": "N", "thickness": "mm"}),
])
def test_a_force_or_position_column_without_a_unit_is_refused_not_guessed(tmp_path, header, role, units):
    """A new user's ``force,displacement`` record in kN and µm had been read as N and mm (Py 0.1 MPa, or a
    relative density of 0.0005), exit 0: a unit is never guessed.  The option gives it instead."""
    p = _write(tmp_path, f"{header}\n" + "\n".join(f"{k};{6 - 0.1 * k:.1f}" for k in range(1, 4)) + "\n")
    with pytest.raises(DesignError) as e:
        read_press_data(p, **META)
    assert e.value.parameter == "column" and f"states no unit for its {role}" in str(e.value)
    assert np.allclose(read_press_data(p, units=units, **META).force, [1.0, 2.0, 3.0])


def test_cp1252_micro_sign_comments_and_inch(tmp_path):
    text = "# exported by a press\r\nZeit [s]\tKraft\tForce (lbf)\tGap (\u00b5m)\r\n# note\r\n0\t0\t10\t5000\r\n0,1\t0\t20\t4900\r\n"
    p = tmp_path / "w.tsv"
    p.write_bytes(text.encode("cp1252"))
    d = read_press_data(p, **META)
    assert np.allclose(d.force, [44.482216152605, 88.96443230521], rtol=1e-14)
    assert np.allclose(d.thickness, [5.0, 4.9]) and d.time is None
    assert list(d.line_numbers) == [4, 5]


def test_fast_and_line_by_line_reading_agree(tmp_path):
    """A record without comments inside is split in one go; a '#' line in the body forces the row-by-row reader."""
    lines = SAMPLE.read_text().splitlines()
    fast = read_press_data(_write(tmp_path, "\n".join(lines) + "\n", "fast.csv"), SAMPLE_META)
    slow_lines = lines[:20] + ["# a remark in the middle", ""] + lines[20:]
    slow = read_press_data(_write(tmp_path, "\n".join(slow_lines) + "\n", "slow.csv"), SAMPLE_META)
    assert np.array_equal(fast.force, slow.force) and np.array_equal(fast.thickness, slow.thickness)
    assert list(slow.line_numbers[:15]) == list(fast.line_numbers[:15])  # 4 comments, header, 15 rows
    assert np.array_equal(slow.line_numbers[15:], fast.line_numbers[15:] + 2)
    with pytest.raises(DesignError, match=r"line\[4\] = 3 is not allowed: has more cells than the 2 headers"):
        read_press_data(_write(tmp_path, "force_N,displacement_mm\n1,-5\n2,-4.9\n3,-4.8,7\n"), **META)


def test_utf16_without_bom_and_tensile_forces(tmp_path):
    p = tmp_path / "u16.csv"
    p.write_bytes("force_N,displacement_mm\n1,-5\n2,-4.9\n3,-4.8\n".encode("utf-16-le"))
    assert np.allclose(read_press_data(p, **META).force, [1, 2, 3])
    neg = _write(tmp_path, "force_N,displacement_mm\n-1,5\n-2,4.5\n-3,4\n", "neg.csv")
    with pytest.raises(DesignError, match=r"row\[1\]\.force = -1 N is not allowed: has no loading branch"):
        compaction_curves(read_press_data(neg, **META))


# ----------------------------------------------------------------------------- metadata is read strictly
_META = ROOT / "samples" / "press" / "lactose_appendix_b.toml"


@pytest.mark.parametrize("edit, parameter, fragment", [
    (lambda t: t.replace("compensation_line", "compensation_lin"), "compliance", "exactly one form"),
    (lambda t: t.replace("[compliance]", "[complience]"), "complience", "not a metadata key"),
    (lambda t: t.replace("mass_mg = 300.0", "mass_g = 0.3"), "mass_g", "not a metadata key"),
    (lambda t: t.replace("mass_mg = 300.0", 'mass_mg = "300"'), "mass_mg", "not text"),
    (lambda t: t.replace("diameter = 10.0", "diameter = 1e308"), "diameter", "<= 1000 mm"),
    (lambda t: t.replace("true_density = 1.3", "true_density = 130"), "true_density", "<= 25"),
    (lambda t: t.replace("[0.00002, -0.0267]", "[0.00002]"), "compliance.compensation_line", "list of 2 numbers"),
])
def test_a_metadata_file_that_would_be_misread_is_refused(tmp_path, edit, parameter, fragment):
    """A misspelled key used to be ignored: without the compensation line the lactose record's K moved
    from 0.008557 to 0.00988 1/MPa with no word; a quoted number, an absurd size: refused as well."""
    from tabletcad.errors import DesignError
    from tabletcad.mechanics.pressdata import read_metadata

    p = tmp_path / "m.toml"
    p.write_text(edit(_META.read_text(encoding="utf-8")), encoding="utf-8")
    with pytest.raises(DesignError) as exc:
        read_metadata(p)
    assert exc.value.parameter == parameter and fragment in str(exc.value), str(exc.value)


@pytest.mark.parametrize("edit, parameter, value, fragment", [
    # a compensation line's entries, as the file gives them (they had been named compliance.slope and
    # compliance.offset, keys the file did not have, the intercept with its sign flipped)
    ("[1.0, -0.0267]", "compliance.compensation_line[0]", 1.0, "must be >= 0 and <= 0.001 mm/N"),
    ("[0.00002, 1e300]", "compliance.compensation_line[1]", 1e300, "must be >= -1000 and <= 1000 mm"),
    ('[0.00002, "x"]', "compliance.compensation_line[1]", "x", "not text"),
])
def test_a_compensation_lines_refusal_names_its_entry(tmp_path, edit, parameter, value, fragment):
    from tabletcad.mechanics.pressdata import read_metadata

    p = tmp_path / "m.toml"
    p.write_text(_META.read_text(encoding="utf-8").replace("[0.00002, -0.0267]", edit), encoding="utf-8")
    with pytest.raises(DesignError) as exc:
        read_metadata(p)
    assert (exc.value.parameter, exc.value.value) == (parameter, value) and fragment in str(exc.value), str(exc.value)
    p.write_text("mass_mg = 300.0\ntrue_density = 1.3\ndiameter = 10.0\n[compliance]\nforce = [0.0, \"a\"]\n"
                 "deflection = [0.0, 0.02]\n", encoding="utf-8")
    with pytest.raises(DesignError, match=r"^compliance\.force\[1\] = 'a' is not allowed"):
        read_metadata(p)


@pytest.mark.parametrize("row, column, value, line", [
    # a force no press makes: 1e300 N had been refused as the fit's window, a negative one as a thickness;
    # in a row after the loading branch it had moved the branch: K = 0.046 1/MPa, a warning only, exit 0
    (15, 0, "1e300", "force_N = 1e+300 N is not allowed: must be within ±7.854e+06 N (100000 MPa on the 78.54 mm² "
                     "punch face: check the column's unit and the die diameter or face area)"),
    (15, 0, "-1e300", "force_N = -1e+300 N is not allowed: must be within ±7.854e+06 N"),
    (15, 0, "1e7", "force_N = 1e+07 N is not allowed"),
    (215, 0, "1e300", "force_N = 1e+300 N is not allowed"),
    # a displacement of -1e300 mm had been read as a bed 1e300 mm thick (the fit unchanged, exit 0)
    (15, 1, "-1e300", "thickness = 1e+300 mm is not allowed: must be <= 1000 mm (size limit"),
])
def test_a_reading_no_press_makes_is_refused_by_its_line_and_column(tmp_path, row, column, value, line):
    header, rows = _printed_rows()
    rows[row][column] = value
    p = tmp_path / "edited.csv"
    p.write_text("\n".join(",".join(r) for r in [header, *rows]) + "\n", encoding="utf-8")
    with pytest.raises(DesignError) as exc:
        compaction_curves(read_press_data(p, meta=_META))
    assert str(exc.value).startswith(f"line[{row + 2}].{line}"), str(exc.value)  # (the header is line 1)
    if column == 0:  # a load cell's small negative reading is read as it was
        rows[row][column] = "-5"
        p.write_text("\n".join(",".join(r) for r in [header, *rows]) + "\n", encoding="utf-8")
        assert read_press_data(p, meta=_META).force[row] == -5.0


@pytest.mark.parametrize("cell", ["inf", "-inf", "1e400"])
def test_an_infinite_reading_is_refused_not_dropped_as_missing(tmp_path, cell):
    """A trial: ``inf`` and ``1e400`` (a float's overflow) had been dropped with the warning "missing force or
    position value"; an empty or ``nan`` cell still is."""
    p = _write(tmp_path, f"force_N,displacement_mm\n1,-5\n{cell},-4.95\n2,-4.9\n3,-4.8\n")
    with pytest.raises(DesignError, match=r"^line\[3\]\.force_N = -?inf N is not allowed: must be a finite number"):
        read_press_data(p, **META)
    p = _write(tmp_path, f"force_N,displacement_mm\n1,-5\n2,{cell}\n3,-4.8\n4,-4.7\n")
    with pytest.raises(DesignError, match=r"^line\[3\]\.displacement_mm = -?inf mm is not allowed"):
        read_press_data(p, **META)
    p = _write(tmp_path, "force_N,displacement_mm\n1,-5\nnan,-4.95\n,-4.93\n2,-4.9\n3,-4.8\n")
    with pytest.warns(DataWarning, match="dropped 2 row"):
        assert len(read_press_data(p, **META)) == 3


def test_a_column_header_naming_two_columns_is_refused_not_taken_first(tmp_path):
    """A trial: ``--force-column force_N`` with two columns of that name had taken the first without a word."""
    p = _write(tmp_path, "force_N,force_N,displacement_mm\n1,10,-5\n2,20,-4.9\n3,30,-4.8\n")
    with pytest.raises(DesignError, match=r"^--force-column = 'force_N' is not allowed: names 2 columns \(numbers 1, "
                                          r"2\): give the column's number$"):
        read_press_data(p, **META, columns={"force": "force_N"})
    assert np.array_equal(read_press_data(p, **META, columns={"force": "2"}).force, [10.0, 20.0, 30.0])


def test_metadata_overrides_binary_files_and_a_byte_order_mark(tmp_path):
    from tabletcad.errors import DesignError
    from tabletcad.mechanics.pressdata import read_metadata

    with pytest.raises(DesignError, match="diameter = 1e.200 mm is not allowed"):
        read_metadata(_META, diameter=1e200)  # the --diameter option: was an OverflowError in the area
    p = tmp_path / "m.toml"
    p.write_bytes(b"mass_mg = 300\n\xff\xfe")
    with pytest.raises(DesignError, match="UTF-8"):
        read_metadata(p)
    p.write_bytes(b"\xef\xbb\xbf" + _META.read_bytes())  # as some editors save it: the same metadata
    assert read_metadata(p) == read_metadata(_META)


def test_the_face_area_is_given_once_and_an_option_replaces_the_files(tmp_path):
    """A file holding both ``diameter`` and ``face_area`` is refused (one of them was ignored without a
    word); ``--diameter`` or ``--face-area`` replaces the file's area however the file gives it (a
    ``--diameter`` beside a file's ``face_area`` was dropped: K 6.5 times too large in a trial)."""
    import math

    from tabletcad.mechanics.pressdata import read_metadata

    text = _META.read_text(encoding="utf-8")
    both = tmp_path / "both.toml"
    both.write_text(text.replace("diameter = 10.0", "diameter = 10.0\nface_area = 50.0"), encoding="utf-8")
    with pytest.raises(DesignError) as e:
        read_metadata(both)
    assert str(e.value) == ("face_area = 50 mm² is not allowed: give diameter or face_area, not both "
                            "(the punch face area is one quantity; or give --diameter or --face-area)")
    assert read_metadata(both, diameter=10.0).area == pytest.approx(math.pi * 25.0, rel=1e-15)  # an option rescues it
    assert read_metadata(both, face_area=60.0).area == 60.0
    area = tmp_path / "area.toml"
    area.write_text(text.replace("diameter = 10.0", "face_area = 50.0"), encoding="utf-8")
    assert read_metadata(area).area == 50.0
    m = read_metadata(area, diameter=10.0)
    assert (m.diameter, m.face_area, m.area) == (10.0, None, pytest.approx(math.pi * 25.0, rel=1e-15))
    m = read_metadata(_META, face_area=78.0)
    assert (m.diameter, m.face_area, m.area) == (None, 78.0, 78.0)
    with pytest.raises(DesignError, match="not both"):
        read_metadata(_META, diameter=10.0, face_area=78.0)
    with pytest.raises(DesignError, match="not both"):
        PressMetadata(mass_mg=300.0, true_density=1.5, diameter=10.0, face_area=78.0)


def test_heckel_with_diameter_beside_a_files_face_area_fits_with_the_diameter(tmp_path, capsys):
    """The command line: the lactose record with its metadata's diameter replaced by a wrong face area
    in the file, and ``--diameter 10`` given, fits exactly as the original metadata does."""
    import json

    from tabletcad.cli import main

    meta = tmp_path / "m.toml"
    meta.write_text(_META.read_text(encoding="utf-8").replace("diameter = 10.0", "face_area = 50.0"), encoding="utf-8")
    assert main(["heckel", str(SAMPLE), "--json"]) == 0
    want = json.loads(capsys.readouterr().out)
    assert main(["heckel", str(SAMPLE), "--meta", str(meta), "--diameter", "10", "--json"]) == 0
    got = json.loads(capsys.readouterr().out)
    assert got["K_per_MPa"] == want["K_per_MPa"] and got["A"] == want["A"]


def test_a_record_no_powder_could_give_is_refused():
    """A new user's mass in grams (0.3 for 300 mg): a relative density of at most 0.0008, which no powder bed
    has, and Py = 3.6e5 MPa with a warning, exit 0.  Refused now, naming the relative density and what to check;
    the same record with its own metadata fits as before (K = 0.008557 1/MPa on the automatic window)."""
    fit = fit_heckel(compaction_curves(read_press_data(SAMPLE)))
    assert fit.K_per_MPa == pytest.approx(0.008557, abs=5e-7)
    with pytest.raises(DesignError) as e:
        compaction_curves(read_press_data(SAMPLE, mass_mg=0.3))
    assert e.value.parameter == "relative_density" and e.value.value == "at most 0.000819"
    assert "check the mass (mg, not g)" in str(e.value)


def test_a_compliance_table_short_of_the_records_forces_is_warned_of():
    """A new user's calibration over 0-10 N on a record reaching 5128 N was extrapolated 500-fold in silence
    (K = -0.0024 1/MPa; such a table in kN is now refused by its slope).  A table over part of the forces
    warns, naming both ranges; one over all of them does not."""
    from tabletcad.mechanics.pressdata import read_metadata

    short = read_metadata(SAMPLE_META, compliance={"force": [0.0, 1000.0], "deflection": [-0.0267, -0.0067]})
    with pytest.warns(DataWarning, match="covers 0-1000 N and the record 3.891-5128 N"):
        read_press_data(SAMPLE, short)
    whole = read_metadata(SAMPLE_META, compliance={"force": [0.0, 6000.0], "deflection": [-0.0267, 0.0933]})
    with warnings.catch_warnings():
        warnings.simplefilter("error", DataWarning)
        read_press_data(SAMPLE, whole)


# ----------------------------------------------------------------------------- the gap must close under load
def _travel_record(tmp_path: Path, meta: str) -> Path:
    """A new user's record: punch travel (mm) rising as the force rises, 8 mm of gap at zero travel."""
    F = np.concatenate([np.linspace(0.05, 15.0, 40), np.linspace(14.0, 0.5, 10)])  # kN
    gap = 300.0 / (1.3 * np.pi * 25.0 * (1.0 - np.exp(-(0.01 * F * 1000 / (np.pi * 25.0) + 0.9))))
    gap[40:] = gap[39] * (1.0 + 0.02 * (1.0 - F[40:] / 15.0))
    rows = "\n".join(f"{0.5 * i:g}\t{f:.5f}\t{8.0 - g:.5f}" for i, (f, g) in enumerate(zip(F, gap)))
    p = _write(tmp_path, "Time (ms)\tUpper Punch Force (kN)\tPunch Travel (mm)\n" + rows + "\n", "travel.csv")
    (tmp_path / "travel.toml").write_text("mass_mg = 300.0\ntrue_density = 1.3\ndiameter = 10.0\n" + meta)
    return p


def test_auto_sign_refuses_punch_travel_read_as_the_gap(tmp_path):
    """A new user's trial: travel rising with the force was read by 'auto' as the gap itself (the gap grew
    under load) and gave K = -0.000329 1/MPa, Py = -3040 MPa, exit 0 with a warning.  Refused now, naming
    displacement_sign and displacement_zero; given, the same record reads as its made-up K = 0.01 1/MPa."""
    from tabletcad.mechanics.heckel import fit_heckel

    p = _travel_record(tmp_path, "")
    with pytest.raises(DesignError) as e:
        read_press_data(p)
    msg = str(e.value)
    assert msg.startswith("displacement_sign = 'auto' is not allowed: makes the punch gap 0 + 'Punch Travel (mm)' "
                          "grow from ")
    assert "(file lines 2-41)" in msg and "'auto' read the readings as the gap itself" in msg
    assert "displacement_sign = -1 and displacement_zero = the gap at zero travel (mm)" in msg
    d = read_press_data(_travel_record(tmp_path, "displacement_sign = -1\ndisplacement_zero = 8.0\n"))
    assert fit_heckel(compaction_curves(d), window=(20.0, 150.0)).K_per_MPa == pytest.approx(0.01, rel=1e-3)


def test_a_sign_given_the_wrong_way_round_is_refused(tmp_path):
    """The check is of the physics, not of 'auto': a sign given as +1 for travel is refused as well,
    and so is 'auto' reading negative travel (every reading <= 0) as minus the gap."""
    with pytest.raises(DesignError, match=r"^displacement_sign = 1 is not allowed: makes the punch gap 8 \+ .*"
                                          r"\+1 as given"):
        read_press_data(_travel_record(tmp_path, "displacement_sign = 1\ndisplacement_zero = 8.0\n"))
    F = np.linspace(10.0, 5000.0, 30)
    with pytest.raises(DesignError, match=r"^displacement_sign = 'auto' .* read the readings as minus the gap"):
        PressData.from_arrays(F, displacement=-np.linspace(0.0, 3.0, 30) - 0.1,
                              metadata=PressMetadata(mass_mg=300, true_density=1.3, diameter=10))
