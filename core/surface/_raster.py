"""Small raster helpers shared by the surface products."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..grid import RasterGrid


def colours_on_grid(ortho_path, grid: RasterGrid, ortho_grid: RasterGrid) -> np.ndarray:
    """(rows, cols, 3) float colours (0-255) of an orthoimage on ``grid``; 0 where it has no data.

    Bands 1-3 (a single-band image is repeated); ``average`` resampling when the
    image is finer than the grid, bilinear otherwise.
    """
    from ..rasterio_io import read_onto_grid

    resampling = "average" if ortho_grid.res < 0.75 * grid.res else "bilinear"
    bands: list[np.ndarray] = []
    for b in (1, 2, 3):
        try:
            bands.append(read_onto_grid(ortho_path, grid, band=b, resampling=resampling))
        except InputError:
            if not bands:
                raise
            bands.append(bands[0])
    out = np.stack(bands, axis=-1).astype(np.float64)
    return np.nan_to_num(out, nan=0.0)
