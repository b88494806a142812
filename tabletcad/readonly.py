"""Read-only tables: a design's tables and a tablet's parameters, which are their owners' value
(a model keeps its tablet, hashes and equality read them), so that no reader can change them."""

from __future__ import annotations

import copy
from typing import Any

__all__ = ["TableDict", "TableList"]


class _ReadOnly:
    """What a read-only table raises on any change."""

    def _refuse(self, *args: Any, **kw: Any):
        raise TypeError(f"this table is read-only ({type(self).__name__}): change a copy (dict(table), "
                        "design.to_dict()) and make a new design from it (Design.from_dict, TabletModel.replace)")

    __setitem__ = __delitem__ = __iadd__ = __imul__ = __ior__ = _refuse
    append = extend = insert = remove = pop = popitem = clear = update = setdefault = sort = reverse = _refuse


class TableDict(_ReadOnly, dict):
    """A read-only ``dict`` (still a ``dict`` to every reader); a copy (``copy.deepcopy``, ``dict(t)``)
    is a plain, changeable one."""

    def __deepcopy__(self, memo):
        return {k: copy.deepcopy(v, memo) for k, v in self.items()}

    def __copy__(self):
        return dict(self)

    def __reduce__(self):  # pickled (sweeps send designs to their workers) as itself, without __setitem__
        return TableDict, (dict(self),)


class TableList(_ReadOnly, list):
    """A read-only ``list`` (``[[patch]]`` tables, a table's arrays); copies are plain lists."""

    def __deepcopy__(self, memo):
        return [copy.deepcopy(v, memo) for v in self]

    def __copy__(self):
        return list(self)

    def __reduce__(self):
        return TableList, (list(self),)
