"""Task panel to create or edit a Tablet: family, dimensions (units, ranges), density,
live validation by the core, the design's key figures, and "add punches and die".

:class:`TabletForm` holds the panel's state and logic without Qt (tested headless);
:class:`TabletTaskPanel` is the Qt form (FreeCAD's ``PySide`` shim) shown in the
combo view by ``FreeCADGui.Control.showDialog``.
"""

from __future__ import annotations

import math

import FreeCAD

from . import objects

__all__ = ["LIMITS", "TabletForm", "TabletTaskPanel", "edit_tablet"]

current = None  # the panel shown last (scripts and tests drive it)

# field ranges by unit, the core's own (Tolerances.max_length: 1000 mm); its checks (DesignError) give the
# exact allowed range of each dimension
LIMITS = {"mm": (0.0, 1000.0, 3), "deg": (0.0, 90.0, 2)}
DENSITY_LIMITS = objects.DENSITY_LIMITS  # mg/mm^3 (= g/cm^3), as the object checks it


class TabletForm:
    """What the panel edits, and the core's verdict on it (no Qt).

    ``values`` are in the family's units (mm, deg); ``density`` in mg/mm³.
    """

    def __init__(self, family: str = "thesis.flat_faced_round", values: dict | None = None, density: float = 1.2):
        self.families = objects.family_names()
        self.density = float(density)
        self.errors: dict[str, str] = {}  # a field whose text is no value of its kind: the refusal
        self.typed: dict[str, str] = {}  # a field's text as typed (a refusal of its value quotes it)
        self.set_family(family)
        if values:
            self.values.update({k: float(v) for k, v in values.items() if k in self.values})
        self._family0, self._values0, self._density0 = self.family, dict(self.values), self.density

    def read(self, key: str, text: str) -> bool:
        """Take what was typed into the field ``key``: a length or angle with its unit (``0.4 in``, ``1 cm``,
        ``0.5 rad``, FreeCAD's unit parser), or a plain number in the field's own unit (mm, deg).  Text that
        is no quantity, or one of another kind (``10 kg``), is kept as the field's refusal (:meth:`validate`)."""
        from .make import _value

        unit = "deg" if self.units[key] == "deg" else "mm"
        text = str(text).strip()
        try:
            value = float(_value(text, unit, objects.prop_name(key)).getValueAs(unit))
        except ValueError as exc:
            self.errors[key] = str(exc)
            return False
        if not math.isfinite(value):
            self.errors[key] = f"{objects.prop_name(key)} = {text!r} is not allowed: must be finite"
            return False
        self.errors.pop(key, None)
        self.values[key] = value
        self.typed[key] = text
        return True

    @classmethod
    def from_object(cls, obj) -> TabletForm:
        s = obj.Proxy.spec(obj)
        return cls(s["family"] or "thesis.flat_faced_round", s["params"], float(obj.Density))

    def set_family(self, family: str) -> None:
        fam = objects._family(family)
        if fam is None:
            raise ValueError(f"unknown family {family!r}")
        self.family = fam.name  # the catalogue's name (an old name of a renamed family becomes the new one)
        self.units = dict(fam.params)
        self.values = {k: float(v) for k, v in fam.defaults.items() if v is not None}
        self.errors = {}
        self.typed = {}

    def fields(self) -> list[tuple[str, str, str, float, float, float]]:
        """``(parameter, label, unit, minimum, maximum, value)`` per dimension."""
        out = []
        for k, unit in self.units.items():
            lo, hi, _ = LIMITS.get(unit, LIMITS["mm"])
            out.append((k, objects.prop_name(k), unit, lo, hi, self.values.get(k, lo)))
        return out

    def spec(self) -> dict:
        """What the form asks the core for, as :meth:`objects.TabletProxy.spec` gives an object's:
        ``{family, params, design}`` (mm, deg)."""
        return {"family": self.family, "params": dict(self.values), "design": None}

    def validate(self) -> tuple[bool, str, dict]:
        """``(ok, message, figures)``: the core builds the tablet (or says why not) with the function a
        Tablet's recompute uses (:func:`objects.core_tablet_of`), so what the panel shows is what OK does;
        figures: volume (mm³), surface area (mm²), weight (mg), height (mm)."""
        from tabletcad.errors import TabletcadError

        if self.errors:
            return False, next(iter(self.errors.values())), {}
        try:
            objects.check_density("Density", self.density)  # (the object's check of its Density)
            tablet = objects.core_tablet_of(self.spec())
            props = tablet.properties()
            dims = tablet.dimensions()
        except TabletcadError as exc:
            return False, str(self.as_typed(exc)), {}
        v = float(props["volume_mm3"])
        figs = dict(
            volume_mm3=v,
            surface_area_mm2=float(props["surface_area_mm2"]),
            weight_mg=v * self.density,
            height_mm=float(dims.get("height_mm", float("nan"))),
        )
        figs = {k: x for k, x in figs.items() if math.isfinite(x)}
        return True, "valid", figs

    def as_typed(self, exc):
        """The core's refusal ``exc`` quoting the refused field's text as typed (``'0.059 in'``, read as
        1.4986 mm), when it names a field whose text was more than a plain number in the field's unit.

        Parameters
        ----------
        exc : tabletcad.errors.TabletcadError
            The refusal (a :class:`~tabletcad.errors.DesignError` names ``tablet.<parameter>``).

        Returns
        -------
        tabletcad.errors.TabletcadError
            ``exc`` itself, or the same refusal quoting the text.
        """
        from tabletcad.errors import DesignError

        key = getattr(exc, "parameter", "").removeprefix("tablet.")
        text = self.typed.get(key) if isinstance(exc, DesignError) else None
        if text is None or exc.value != self.values.get(key):
            return exc
        try:
            float(text)
            return exc  # a plain number: the refusal's value in the field's unit is what was typed
        except ValueError:
            pass
        unit = "deg" if self.units[key] == "deg" else "mm"
        value = f"{self.values[key]:.12g} {unit}"
        same = text.replace(" ", "") in (value.replace(" ", ""), f"{self.values[key]:.12g}°")
        allowed = exc.allowed if same else f"{exc.allowed} (read as {value})"
        return DesignError(exc.parameter, text, allowed, exc.unit)

    def apply(self, obj) -> None:
        """Write what the form changed into a Tablet object: its family (which resets the dimensions) and then
        every dimension, else only the dimensions and density that changed (a field the user did not touch
        keeps the object's exact value: the fields show 3 decimals)."""
        new_family = obj.Family != self.family or self.family != self._family0
        if obj.Family != self.family:
            obj.Family = self.family
        for k, unit in self.units.items():
            if new_family or self.values[k] != self._values0.get(k):
                q = FreeCAD.Units.Quantity(float(self.values[k]), FreeCAD.Units.Unit("deg" if unit == "deg" else "mm"))
                setattr(obj, objects.prop_name(k), q)
        if new_family or self.density != self._density0:
            obj.Density = float(self.density)

    def create(self, doc, tooling: bool = False):
        """A new Tablet (and its punches and die) from the form; recomputed."""
        from .make import make_tablet, make_tooling

        obj = make_tablet(doc, self.family, recompute=False, density=self.density, **self.values)
        if tooling:
            try:
                make_tooling(doc, obj, recompute=False)
            except BaseException:  # nothing of the form is left (without undo, a script's document)
                doc.removeObject(obj.Name)
                raise
        doc.recompute()
        return obj


def _fmt_figures(figs: dict) -> str:
    names = [
        ("volume_mm3", "Volume", "mm³"),
        ("surface_area_mm2", "Surface area", "mm²"),
        ("weight_mg", "Weight", "mg"),
        ("height_mm", "Height", "mm"),
    ]
    return "\n".join(f"{label}: {figs[k]:.4g} {unit}" for k, label, unit in names if k in figs)


class TabletTaskPanel:
    """The Qt panel (``self.form``) over a :class:`TabletForm`; ``obj`` is edited if given,
    else ``accept()`` creates a new tablet in ``doc``."""

    def __init__(self, obj=None, doc=None):
        from PySide import QtGui

        self.obj = obj
        self.doc = doc or (obj.Document if obj is not None else FreeCAD.ActiveDocument)
        self.model = TabletForm.from_object(obj) if obj is not None else TabletForm()
        self.form = QtGui.QWidget()
        self.form.setWindowTitle("tabletcad tablet")
        layout = QtGui.QVBoxLayout(self.form)
        top = QtGui.QFormLayout()
        self.family = QtGui.QComboBox()
        self.family.addItems(self.model.families)
        self.family.setCurrentIndex(self.model.families.index(self.model.family))
        top.addRow("Family", self.family)
        self.density = QtGui.QDoubleSpinBox()
        self.density.setRange(*DENSITY_LIMITS)
        self.density.setDecimals(3)
        self.density.setSingleStep(0.05)
        self.density.setSuffix(" mg/mm³")
        self.density.setValue(self.model.density)
        top.addRow("Density", self.density)
        layout.addLayout(top)
        self.dims_box = QtGui.QGroupBox("Dimensions")
        self.dims = QtGui.QFormLayout(self.dims_box)
        layout.addWidget(self.dims_box)
        self.status = QtGui.QLabel()
        self.status.setWordWrap(True)
        layout.addWidget(self.status)
        self.figures = QtGui.QLabel()
        layout.addWidget(self.figures)
        self.tooling = QtGui.QCheckBox("Add upper punch, lower punch and die")
        self.tooling.setChecked(False)
        layout.addWidget(self.tooling)
        layout.addStretch(1)
        self.spins: dict[str, object] = {}
        self._build_dimensions()
        self.family.currentIndexChanged.connect(self._family_changed)
        self.density.valueChanged.connect(self._changed)
        self.refresh()

    # ------------------------------------------------------------------ widgets
    def _build_dimensions(self):
        from PySide import QtGui

        # the old rows are taken out and deleted later, once the new fields exist (a field made at a freed
        # field's address can be handed the old field's deleted wrapper in PySide2)
        self.spins = {}
        while self.dims.count():
            item = self.dims.takeAt(self.dims.count() - 1)
            w = item.widget() if item is not None else None
            if w is not None:
                w.hide()
                w.deleteLater()
        for k, label, unit, lo, hi, value in self.model.fields():
            # a text field read by FreeCAD's unit parser as typed ('0.4 in', '1.2345 cm', '0.5 rad', a plain
            # number in mm or degrees): a plain spin box had taken '0.4 in' as 0.4 mm and capped values at
            # 100 mm, 3 decimals; FreeCAD's QuantitySpinBox signals its text rounded to the display's decimals
            # and, on 0.20, drops keys it does not accept ('10 kg' became '10 k', read as 10 mm)
            sb = QtGui.QLineEdit(self.dims_box)
            sb.setText(f"{value:.12g} {'°' if unit == 'deg' else unit}")
            sb.setToolTip(f"{k} ({unit}, or any {'angle' if unit == 'deg' else 'length'} unit: 0.4 in, 1 cm, "
                          f"0.5 rad), {lo:g} to {hi:g}; the tablet is checked as you type")
            sb.textChanged.connect(lambda text, key=k: self._typed(key, text))
            self.dims.addRow(label, sb)
            self.spins[k] = sb

    def type_text(self, key: str, text: str) -> None:
        """Replace the field ``key``'s text with ``text`` as an edit, as typing over it does (``insert`` on the
        selected text: the same signals, without key events, which a virtual X display answered in seconds)."""
        from PySide import QtGui

        field = self.spins[key]
        field.selectAll()
        field.insert(text)
        QtGui.QApplication.processEvents()

    def _family_changed(self, index):
        self.model.set_family(self.model.families[int(index)])
        self._build_dimensions()
        self.refresh()

    def _typed(self, key: str, text: str):
        self.model.read(key, text)  # only the field typed in: the others keep their exact values
        self.refresh()
        self.spins[key].setStyleSheet("color: #c62828;" if key in self.model.errors else "")

    def _changed(self, *_):
        self.model.density = float(self.density.value())
        self.refresh()

    def refresh(self) -> bool:
        """Live validation: status line and key figures."""
        ok, msg, figs = self.model.validate()
        self.ok = ok
        self.status.setText("✔ valid" if ok else f"✘ {msg}")
        self.status.setStyleSheet("color: #1a7f37;" if ok else "color: #c62828;")
        self.figures.setText(_fmt_figures(figs) if ok else "")
        return ok

    # ------------------------------------------------------------------ task dialog
    def getStandardButtons(self):
        from PySide import QtGui

        return int(QtGui.QDialogButtonBox.Ok | QtGui.QDialogButtonBox.Cancel)

    def accept(self):
        if not self.refresh():
            FreeCAD.Console.PrintError(f"tabletcad: {self.status.text()[2:]}\n")
            return False
        from .commands import _transaction

        def work():
            if self.obj is None:
                return self.model.create(self.doc, tooling=self.tooling.isChecked())
            self.model.apply(self.obj)
            if self.tooling.isChecked():
                from .make import make_tooling

                make_tooling(self.doc, self.obj, recompute=False)
            self.doc.recompute()
            return self.obj

        try:  # one undo step, rolled back when it fails (a die a tablet is too large for: the tablet had stayed)
            self.obj = _transaction(self.doc, "tabletcad tablet", work)
        except Exception as exc:
            msg = " ".join(str(exc).split())
            self.status.setText(f"✘ {msg}")
            self.status.setStyleSheet("color: #c62828;")
            FreeCAD.Console.PrintError(f"tabletcad: {msg}\n")
            return False
        self._close()
        return True

    def reject(self):
        self._close()
        return True

    def _close(self):
        if FreeCAD.GuiUp:
            import FreeCADGui

            FreeCADGui.Control.closeDialog()


def edit_tablet(obj=None, doc=None) -> TabletTaskPanel | None:
    """Show the panel (GUI): edit ``obj`` or create a new tablet.  A tablet read from a design file is not
    edited here (None, and a message): its shape is the file's, which the panel's families cannot show (OK had
    turned it into the panel's first family)."""
    import FreeCADGui

    global current
    if obj is not None and obj.Family == objects.DESIGN_FILE:
        FreeCAD.Console.PrintWarning(f"tabletcad: {obj.Label} is read from {obj.DesignFile}: edit that file (or "
                                     "DesignFile), then recompute\n")
        current = None
        return None
    panel = TabletTaskPanel(obj, doc)
    FreeCADGui.Control.showDialog(panel)
    current = panel
    return panel
