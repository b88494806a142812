"""Refusals named as the command line spells them.

The library names a bad argument by its Python keyword (``mesh_size``, ``band thickness``); a command
that passed an option's value on says ``--mesh-size``, ``--band``: :func:`option_names` renames a
:class:`~tabletcad.errors.DesignError` raised inside it.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator, Mapping

from tabletcad.errors import DesignError, one_token

__all__ = ["option_names"]


@contextlib.contextmanager
def option_names(names: Mapping[str, str]) -> Iterator[None]:
    """Re-raise a :class:`DesignError` whose parameter is a key of ``names`` under its option's name."""
    try:
        yield
    except DesignError as exc:
        option = {one_token(k): v for k, v in names.items()}.get(exc.parameter)  # (a DesignError's parameter is one token)
        if option is not None:
            raise exc.renamed(option) from None
        raise
