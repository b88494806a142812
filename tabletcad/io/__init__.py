"""File input/output helpers shared by every writer in tabletcad."""

from tabletcad.io.atomic import atomic_path, atomic_write_bytes, atomic_write_text
from tabletcad.io.outputs import MANIFEST, publish, read_manifest, staging_folder

__all__ = ["atomic_path", "atomic_write_bytes", "atomic_write_text", "MANIFEST", "publish", "read_manifest", "staging_folder"]
