"""Parameters of a synthetic scene (:class:`SceneConfig`).

All lengths are metres in the *local* frame (``world = local + offset``),
angles degrees, image quantities pixels. Every random choice is drawn from
generators seeded by :attr:`SceneConfig.seed`, so a config fully determines
the scene, the block and the rendered images.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..errors import InputError


@dataclass
class SceneConfig:
    """Everything :func:`~truortho.core.synthetic.make_scene` needs.

    Surface
    -------
    extent : (xmin, ymin, xmax, ymax)
        Local area holding the buildings and the GCPs, metres. The terrain
        continues analytically outside it.
    ground_height : float
        Mean terrain height (local z), metres.
    terrain_relief : float
        Sum of the amplitudes of the terrain undulations, metres (0 = flat).
    terrain_wavelengths : (min, max)
        Wavelength range of the terrain undulations, metres.
    n_buildings : int
        Ordinary buildings; roof shapes cycle flat, gable, hip, shed.
    building_size : (min, max)
        Footprint side lengths, metres.
    eave_height : (min, max)
        Wall height above the highest terrain under the footprint, metres.
    roof_pitch : (min, max)
        Pitch of gable/hip roofs in degrees (shed roofs use half of it).
    building_gap : float
        Minimum free ground between the bounding circles of two buildings.
    tower : bool
        Add a tall flat-roofed tower near the centre.
    tower_height, tower_size : float
        Tower wall height above the terrain and footprint side, metres.

    Texture
    -------
    texture_scale : float
        Lattice spacing of the finest noise octave, metres (~1 GSD).
    texture_octaves : int
        Octaves, each twice the spacing of the previous one.
    texture_contrast : float
        Contrast stretch of the noise (higher = more saturated texture).
    roof_contrast : (min, max)
        Each roof's texture contrast is ``texture_contrast`` times a factor
        drawn uniformly from this range (``(1, 1)``: all alike; near 0: a
        nearly uniform, hard to match roof).
    facade_windows : bool
        A repetitive grid of dark windows on every wall (storeys of 3 m, a
        window every 2.4 m).
    crop_share : float
        Share of the ground (in patches of about 25 m) that is fields of stalks: nearly uniform
        soil under a layer of stalks ``crop_height`` above it, which each photo sees from its own
        direction (a stubble or crop field; 0 = none). The truth DSM is the soil.
    crop_height : float
        Height of the stalk layer above the soil, metres.
    optics_blur : float
        Gaussian point spread of the optics, pixels (sigma; lens, focus, motion and demosaicing
        together), applied before noise and JPEG; 0 = the sharp rendering.

    Ray casting
    -----------
    fine_step : float
        Largest horizontal ray-marching step, metres (about GSD / 4).
    coarse_cell : float
        Cell size of the max-height acceleration grid, metres.
    grid_margin : float
        The acceleration grid extends this far beyond ``extent`` (oblique
        rays reach far); outside it only the terrain bound is used.

    Block
    -----
    image_size : (width, height)
    focal_px : float
    principal_offset : (dx, dy)
        Principal point minus the image centre, pixels.
    distortion : (k1, k2, p1, p2, k3)
        Brown/OpenCV coefficients.
    flying_height : float
        Height of the projection centres above ``ground_height``.
    forward_overlap, side_overlap : float
        Fractions in [0, 0.95].
    heading_deg : float
        Flight direction of the first strip, clockwise from grid north.
    attitude_sigma_deg, position_sigma : float
        Random perturbation of the nominal attitude (degrees, per axis) and
        position (metres, per axis).
    n_oblique : int
        Oblique images (0 to 8), looking at the scene centre from azimuths
        spread evenly, first from the south looking north.
    oblique_tilt_deg : float
        Off-nadir angle of the oblique optical axes.

    Rendering and radiometry
    ------------------------
    supersample : int
        Sub-pixel rays per pixel and axis (box filter), 1 to 6.
    adaptive_supersampling : bool
        Supersample only pixels at material/building/depth edges (the others
        keep their centre ray); False supersamples every pixel.
    gain_sigma, offset_sigma : float
        Per-image exposure: ``gain ~ N(1, gain_sigma)`` (common factor plus a
        third of it per channel), ``offset ~ N(0, offset_sigma)`` in [0, 1]
        units.
    vignetting : float
        Relative darkening at the image corners (0 = none).
    noise_sigma : float
        Gaussian noise in digital numbers (0-255 scale).
    jpeg_quality : int
        0 keeps the rendered digital numbers; 1-100 passes every image
        through a JPEG encoder at this quality (blocking, ringing, chroma
        subsampling), as camera JPEGs are.
    shadow_strength : float
        Cast shadows of the sun darken by this fraction (0 = no shadows); the
        truth orthophoto has the same shadows (they are the scene's colour).
    sun_azimuth_deg, sun_elevation_deg : float
        Direction of the sun (azimuth clockwise from grid north).

    Ground control
    --------------
    n_gcps : int
        Ground points on open ground.
    gcp_on_roof : bool
        Add one more point at the centre of a flat roof.
    check_fraction : float
        Fraction of all points given role ``'check'``.
    gcp_pixel_sigma : float
        Gaussian noise added to the GCP image observations, pixels.
    gcp_clearance : float
        Minimum horizontal distance of ground GCPs from any footprint.
    min_gcp_views : int
        Ground GCPs must be visible (inside the frame) in this many images.

    Georeference
    ------------
    crs : str
    offset : (E, N, H)
        ``world = local + offset``.
    seed : int
    """

    extent: tuple[float, float, float, float] = (-60.0, -50.0, 60.0, 50.0)
    ground_height: float = 0.0
    terrain_relief: float = 4.0
    terrain_wavelengths: tuple[float, float] = (60.0, 220.0)
    n_buildings: int = 7
    building_size: tuple[float, float] = (9.0, 18.0)
    eave_height: tuple[float, float] = (4.0, 11.0)
    roof_pitch: tuple[float, float] = (25.0, 40.0)
    building_gap: float = 6.0
    tower: bool = True
    tower_height: float = 32.0
    tower_size: float = 9.0

    texture_scale: float = 0.15
    texture_octaves: int = 5
    texture_contrast: float = 2.6
    roof_contrast: tuple[float, float] = (1.0, 1.0)
    facade_windows: bool = False
    crop_share: float = 0.0
    crop_height: float = 0.3
    optics_blur: float = 0.0

    fine_step: float = 0.03
    coarse_cell: float = 2.0
    grid_margin: float = 300.0

    image_size: tuple[int, int] = (640, 480)
    focal_px: float = 800.0
    principal_offset: tuple[float, float] = (1.7, -1.2)
    distortion: tuple[float, float, float, float, float] = (-0.05, 0.012, 4e-4, -3e-4, 0.0)
    flying_height: float = 100.0
    forward_overlap: float = 0.8
    side_overlap: float = 0.6
    heading_deg: float = 90.0
    attitude_sigma_deg: float = 0.8
    position_sigma: float = 0.4
    n_oblique: int = 4
    oblique_tilt_deg: float = 40.0

    supersample: int = 2
    adaptive_supersampling: bool = True
    gain_sigma: float = 0.08
    offset_sigma: float = 0.02
    vignetting: float = 0.15
    noise_sigma: float = 1.0
    jpeg_quality: int = 0
    shadow_strength: float = 0.0
    sun_azimuth_deg: float = 135.0
    sun_elevation_deg: float = 45.0

    n_gcps: int = 8
    gcp_on_roof: bool = True
    check_fraction: float = 0.25
    gcp_pixel_sigma: float = 0.0
    gcp_clearance: float = 4.0
    min_gcp_views: int = 3

    crs: str = "EPSG:32632"
    offset: tuple[float, float, float] = (500000.0, 5600000.0, 0.0)
    seed: int = 0
    metadata: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.validate()

    @property
    def gsd(self) -> float:
        """Nominal nadir ground sampling distance, metres per pixel."""
        return self.flying_height / self.focal_px

    def validate(self) -> None:
        """Raise :class:`InputError` naming the first unusable parameter."""

        def bad(name: str, why: str) -> None:
            raise InputError(f"SceneConfig.{name}: {why} (got {getattr(self, name)!r})")

        def finite(name: str, *values: float) -> None:
            for v in values:
                if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                    bad(name, "expected finite numbers")

        def pair(name: str, lo_min: float = 0.0) -> None:
            v = getattr(self, name)
            if len(v) != 2:
                bad(name, "expected (min, max)")
            finite(name, *v)
            if not lo_min <= v[0] <= v[1]:
                bad(name, f"expected {lo_min} <= min <= max")

        if len(self.extent) != 4:
            bad("extent", "expected (xmin, ymin, xmax, ymax)")
        finite("extent", *self.extent)
        x0, y0, x1, y1 = self.extent
        if not (x1 - x0 >= 20 and y1 - y0 >= 20):
            bad("extent", "must be at least 20 m on each side with xmin < xmax, ymin < ymax")
        for name in ("ground_height", "terrain_relief", "building_gap", "tower_height", "tower_size",
                     "texture_scale", "texture_contrast", "fine_step", "coarse_cell", "grid_margin",
                     "focal_px", "flying_height", "forward_overlap", "side_overlap", "heading_deg",
                     "attitude_sigma_deg", "position_sigma", "oblique_tilt_deg", "gain_sigma",
                     "offset_sigma", "vignetting", "noise_sigma", "check_fraction", "gcp_pixel_sigma",
                     "gcp_clearance", "shadow_strength", "sun_azimuth_deg", "sun_elevation_deg",
                     "crop_share", "crop_height", "optics_blur"):
            finite(name, getattr(self, name))
        for name in ("terrain_relief", "building_gap", "grid_margin", "attitude_sigma_deg", "position_sigma",
                     "gain_sigma", "offset_sigma", "noise_sigma", "gcp_pixel_sigma", "gcp_clearance"):
            if getattr(self, name) < 0:
                bad(name, "must not be negative")
        pair("terrain_wavelengths", 1.0)
        pair("building_size", 2.0)
        pair("eave_height", 1.0)
        pair("roof_pitch")
        pair("roof_contrast")
        if self.roof_pitch[1] >= 70:
            bad("roof_pitch", "must stay below 70 degrees")
        for name, lo, hi in (("texture_scale", 1e-3, 1e3), ("fine_step", 1e-3, 10.0),
                             ("coarse_cell", 0.1, 100.0), ("focal_px", 1.0, 1e6), ("flying_height", 1.0, 1e5),
                             ("forward_overlap", 0.0, 0.95), ("side_overlap", 0.0, 0.95),
                             ("oblique_tilt_deg", 5.0, 70.0), ("vignetting", 0.0, 0.9),
                             ("check_fraction", 0.0, 1.0), ("tower_height", 1.0, 1e3),
                             ("tower_size", 2.0, 1e3), ("shadow_strength", 0.0, 0.9),
                             ("sun_elevation_deg", 5.0, 90.0), ("crop_share", 0.0, 1.0),
                             ("crop_height", 0.0, 5.0), ("optics_blur", 0.0, 10.0)):
            if not lo <= getattr(self, name) <= hi:
                bad(name, f"must lie in [{lo}, {hi}]")
        if self.coarse_cell < self.fine_step:
            bad("coarse_cell", "must not be smaller than fine_step")
        for name, lo, hi in (("n_buildings", 0, 2000), ("texture_octaves", 1, 12), ("n_oblique", 0, 8),
                             ("supersample", 1, 6), ("n_gcps", 0, 1000), ("min_gcp_views", 1, 1000),
                             ("jpeg_quality", 0, 100),
                             ("seed", 0, 2**31 - 1)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
                bad(name, f"expected an integer in [{lo}, {hi}]")
        if len(self.image_size) != 2 or any(
            isinstance(v, bool) or not isinstance(v, int) or not 8 <= v <= 20000 for v in self.image_size
        ):
            bad("image_size", "expected (width, height), integers in [8, 20000]")
        if len(self.principal_offset) != 2:
            bad("principal_offset", "expected (dx, dy)")
        finite("principal_offset", *self.principal_offset)
        if len(self.distortion) != 5:
            bad("distortion", "expected (k1, k2, p1, p2, k3)")
        finite("distortion", *self.distortion)
        if len(self.offset) != 3:
            bad("offset", "expected (E, N, H)")
        finite("offset", *self.offset)
        if not isinstance(self.crs, str) or not self.crs:
            bad("crs", "expected a CRS string such as 'EPSG:32632'")
