"""Volume meshes of the tablet solid (thesis section 4.3, Appendix A).

* :mod:`tabletcad.volume_mesh.hexahedra` - the conforming hexahedral mesh of the solid map of
  eq 4.12 (wedges, pyramids and tetrahedra where the map degenerates) and its exact volume;
* :mod:`tabletcad.volume_mesh.files` - VTU, legacy VTK, XDMF and Gmsh files of it.

(Tetrahedral meshes for finite elements come from the B-rep, :mod:`tabletcad.fe.mesh`.)
"""

from tabletcad.volume_mesh.files import write_mesh
from tabletcad.volume_mesh.hexahedra import (CELL_TYPES, THESIS_NODES, SolidMesh, cell_volumes, corner_quality,
                                             degenerate_cells, hex_mesh, mesh_volume)

__all__ = ["SolidMesh", "CELL_TYPES", "THESIS_NODES", "hex_mesh", "cell_volumes", "corner_quality", "degenerate_cells",
           "mesh_volume", "write_mesh"]
