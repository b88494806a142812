"""The example notebook runs from end to end in a kernel of this very Python (nbclient)."""

import math
import re
import sys
from pathlib import Path

import pytest

pytest.importorskip("OCP")
pytest.importorskip("build123d")
nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")
pytest.importorskip("ipykernel")

pytestmark = [pytest.mark.cad, pytest.mark.slow]
NOTEBOOK = Path(__file__).resolve().parents[1] / "samples" / "notebooks" / "tablet_design.ipynb"


def _text(cell) -> str:
    return "".join(o.get("text", "") for o in cell.get("outputs", []) if o.get("output_type") == "stream")


def test_notebook_runs_and_reports_the_closed_form_volume(tmp_path):
    from jupyter_client.kernelspec import KernelSpecManager

    nb = nbformat.read(NOTEBOOK, as_version=4)
    # the kernel must be this interpreter: jupyter_client starts 'python3' with sys.executable
    spec = KernelSpecManager().get_kernel_spec("python3")
    assert spec.argv[0] in ("python", "python3", sys.executable, f"python{sys.version_info[0]}.{sys.version_info[1]}")
    client = nbclient.NotebookClient(nb, kernel_name="python3", timeout=600, resources={"metadata": {"path": str(tmp_path)}})
    client.execute()
    out = "\n".join(_text(c) for c in nb.cells if c.cell_type == "code")
    vol = float(re.search(r"volume ([0-9.]+) mm3, closed form", out).group(1))
    R = (5.0**2 + 1.0**2) / 2.0
    exact = math.pi * 25.0 * 2.0 + 2 * math.pi * (3 * R - 1.0) / 3
    assert vol == pytest.approx(exact, rel=1e-6)  # families agree with closed forms to 1e-6 relative
    drilled = float(re.search(r"drilled ([0-9.]+) mm3, valid True", out).group(1))
    assert 0 < vol - drilled < math.pi * 1.0**2 * 4.0  # less than a full 4 mm cylinder is removed
    step = tmp_path / "concave_round.step"
    assert step.is_file() and step.read_bytes().startswith(b"ISO-10303-21")
    kinds = {o.get("output_type") for c in nb.cells for o in c.get("outputs", [])}
    assert "error" not in kinds
    assert any("image/png" in o.get("data", {}) for c in nb.cells for o in c.get("outputs", []))
    assert any("text/html" in o.get("data", {}) for c in nb.cells for o in c.get("outputs", []))
