"""Surface products: DSM filtering, ground filtering (DTM), point clouds and meshes.

Modules
-------
filter
    :func:`~.filter.filter_dsm` (files, by tiles) / :func:`~.filter.filter_dsm_array`:
    edge sharpening, outlier removal, hole filling, edge-preserving smoothing.
dtm
    :func:`~.dtm.dtm_from_dsm` / :func:`~.dtm.dtm_from_dsm_array`: SMRF-style ground filter.
mesh
    :func:`~.mesh.mesh_from_dsm` / :func:`~.mesh.mesh_from_dsm_array`: 2.5D mesh with
    vertical walls and error-bounded decimation; :func:`~.mesh.mesh_from_point_cloud`;
    :func:`~.mesh.rasterize_mesh`.
meshio
    :class:`~.meshio.Mesh` and its files (PLY, OBJ): :func:`~.meshio.write_mesh`,
    :func:`~.meshio.read_mesh`.
pointcloud
    :class:`~.pointcloud.PointCloud`, LAS/LAZ (+ EPT) files, merging of reference systems,
    DSM export.
ept
    Entwine Point Tile datasets (QGIS without PDAL).
"""

from .meshio import Mesh, read_mesh, write_mesh

__all__ = ["Mesh", "read_mesh", "write_mesh"]
