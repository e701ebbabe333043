"""Readers and writers of photogrammetric exchange formats.

Every reader converts to TruOrtho's conventions (:mod:`truortho.core.geometry`)
on import and only parses: it never opens a path named inside a file and
never reads images. Malformed input raises
:class:`~truortho.core.errors.FormatError` naming the file (and line); files
over 512 MB are refused.

* COLMAP text model: :func:`read_colmap`, :func:`write_colmap`
* Orthority exterior CSV + interior YAML/JSON: :func:`read_opk`, :func:`write_opk`
* OpenSfM / ODM ``reconstruction.json``: :func:`read_opensfm`
* ODM ``gcp_list.txt``: :func:`read_gcp_list`, :func:`write_gcp_list`
"""

from .colmap import read_colmap, write_colmap
from .gcplist import GCPListWarning, read_gcp_list, write_gcp_list
from .opensfm import read_opensfm
from .opk import read_interior, read_opk, write_opk

__all__ = [
    "GCPListWarning",
    "read_colmap",
    "read_gcp_list",
    "read_interior",
    "read_opensfm",
    "read_opk",
    "write_colmap",
    "write_gcp_list",
    "write_opk",
]
