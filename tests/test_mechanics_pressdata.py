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
    p = _write(tmp_path, "time (s)\tforce\tthickness (mm)\n0\t1\t5\n0.1\t2\t4.9\n0.2\t3\t4.8\n", "run.tsv")
    d = read_press_data(p, **META)
    assert np.allclose(d.thickness, [5, 4.9, 4.8]) and np.allclose(d.time, [0, 0.1, 0.2])


@pytest.mark.parametrize(
    "text,match",
    [
        ("force,displacement\n1,-5\nabc,-4\n", "must be a number"),
        ("load_cell,time\n1,0\n2,1\n", "displacement or thickness"),
        ("pos,displacement\n1,-5\n", "force column"),
    ],
)
def test_bad_files(tmp_path, text, match):
    with pytest.raises(DesignError, match=match):
        read_press_data(_write(tmp_path, text), **META)


@pytest.mark.parametrize("key,value", [("mass_mg", 0.0), ("true_density", -1.3), ("diameter", 0.0)])
def test_bad_metadata(tmp_path, key, value):
    p = _write(tmp_path, "force,displacement\n1,-5\n2,-4.9\n3,-4.8\n")
    with pytest.raises(DesignError, match="must be > 0"):
        read_press_data(p, **(META | {key: value}))


def test_missing_diameter(tmp_path):
    p = _write(tmp_path, "force,displacement\n1,-5\n2,-4.9\n3,-4.8\n")
    with pytest.raises(DesignError, match="diameter"):
        read_press_data(p, mass_mg=1.0, true_density=1.0)


def test_no_loading_branch():
    with pytest.raises(DesignError, match="no loading branch"):
        split_branches([100.0, 90.0, 80.0, 70.0])


def test_metadata_beside_file_is_found(tmp_path):
    p = _write(tmp_path, "force,displacement\n1,-5\n2,-4.9\n3,-4.8\n")
    (tmp_path / "run.toml").write_text("mass_mg = 10\ntrue_density = 1.5\nface_area = 20\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        d = read_press_data(p)
    assert d.metadata.area == 20.0
    assert np.allclose(d.gap, [5, 4.9, 4.8])
