"""Surface products: DSM filtering, ground filtering (DTM), point clouds and meshes.

Modules
-------
meshio
    :class:`~.meshio.Mesh` and its files (PLY, OBJ): :func:`~.meshio.write_mesh`,
    :func:`~.meshio.read_mesh`.
"""

from .meshio import Mesh, read_mesh, write_mesh

__all__ = ["Mesh", "read_mesh", "write_mesh"]
