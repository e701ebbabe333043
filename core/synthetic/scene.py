"""The synthetic scene: surface, block, rendered images and ground truth.

:func:`make_scene` builds everything from a :class:`~.config.SceneConfig`;
the returned :class:`SyntheticScene` holds the rendered images, re-renders
noise-free colour, depth and label maps on request
(:meth:`SyntheticScene.render`, :meth:`SyntheticScene.depth_map`) and writes
a complete test data set with :meth:`SyntheticScene.write`.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..geometry.camera import Camera
from ..geometry.frame import LocalFrame
from ..orientation import Image, Orientation, atomic_write_text
from ..progress import Progress, as_progress, check
from . import truth
from .cameras import make_camera, nadir_block, oblique_cameras
from .config import SceneConfig
from .raycast import cast_rays
from .render import (
    Radiometry,
    apply_radiometry,
    jpeg_file,
    jpeg_roundtrip,
    random_radiometry,
    render_colour,
    subpixel_rays,
    sun_vector,
)
from .surface import Surface
from .texture import _colour_many, field_mask, palette, texture_params


@dataclass
class RenderResult:
    """Output of :meth:`SyntheticScene.render` (see :func:`~.render.render_colour`)."""

    colour: np.ndarray
    depth: np.ndarray
    material: np.ndarray
    building: np.ndarray
    seconds: float


@dataclass
class SyntheticScene:
    """A rendered synthetic block with its truth.

    Attributes
    ----------
    config : SceneConfig
    surface : Surface
        Analytic height field (local frame).
    orientation : Orientation
        Exact cameras (one :class:`Camera`), images ``img_000.png``... and GCPs.
    images : list of (H, W, 3) uint8
        Rendered RGB images, with per-image radiometry (and, with ``config.jpeg_quality``, the
        JPEG round trip).
    jpeg_files : list of bytes
        With ``config.jpeg_quality``: the images' JPEG files, which :meth:`write` stores as they
        are (the images are named ``img_NNN.jpg`` then); empty otherwise.
    radiometry : list of Radiometry
        The exposure truth of every image.
    n_nadir : int
        The first ``n_nadir`` images are nadir, the rest oblique.
    render_seconds : float
        Wall time of rendering all images (including JIT on first use).
    """

    config: SceneConfig
    surface: Surface
    orientation: Orientation
    images: list[np.ndarray]
    radiometry: list[Radiometry]
    n_nadir: int
    render_seconds: float
    palette: np.ndarray = field(repr=False, default_factory=lambda: np.zeros((2, 3)))
    tex: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(4))
    sun: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(4))
    _rays: dict = field(repr=False, default_factory=dict)
    jpeg_files: list = field(repr=False, default_factory=list)

    # ---------------------------------------------------------- access
    @property
    def camera(self) -> Camera:
        return next(iter(self.orientation.cameras.values()))

    @property
    def offset(self) -> np.ndarray:
        return self.orientation.offset

    def image(self, which: int | str) -> Image:
        """Image by index or name."""
        if isinstance(which, str):
            return self.orientation.image(which)
        if isinstance(which, bool) or not isinstance(which, int | np.integer):
            raise InputError(f"image: expected an index or a name, got {which!r}")
        if not 0 <= which < len(self.orientation.images):
            raise InputError(f"image index {which} out of range (0..{len(self.orientation.images) - 1})")
        return self.orientation.images[int(which)]

    def extent_world(self) -> tuple[float, float, float, float]:
        x0, y0, x1, y1 = self.config.extent
        o = self.offset
        return (x0 + o[0], y0 + o[1], x1 + o[0], y1 + o[1])

    # ---------------------------------------------------------- truth
    def height(self, xy_world) -> np.ndarray:
        """Surface height (world z) at world (N, 2) plan points."""
        p = np.asarray(xy_world, dtype=np.float64).reshape(-1, 2) - self.offset[:2]
        return self.surface.height(p)[0] + self.offset[2]

    def colour(self, points_world, material, building) -> np.ndarray:
        """Texture colour (N, 3) float64 in [0, 1] of world points.

        ``material``: 0 ground, 1 roof, 2 wall; ``building``: index into
        ``surface.buildings`` (ignored for ground); both broadcast to (N,).
        """
        P = np.ascontiguousarray(np.asarray(points_world, dtype=np.float64).reshape(-1, 3) - self.offset)
        n = len(P)
        mat = np.ascontiguousarray(np.broadcast_to(np.asarray(material, dtype=np.int64), (n,)))
        bid = np.ascontiguousarray(np.broadcast_to(np.asarray(building, dtype=np.int64), (n,)))
        nb = len(self.surface.buildings)
        if np.any((mat < 0) | (mat > 2)) or np.any((mat > 0) & ((bid < 0) | (bid >= nb))):
            raise InputError("colour: material must be 0, 1 or 2 and roofs/walls need a valid building index")
        return _colour_many(P, mat, bid, self.palette, self.tex)

    def dsm(self, resolution: float, extent=None):
        """Truth DSM: ``(float32 (rows, cols), geotransform)``.

        Heights in world z sampled at cell centres (not the cell maximum);
        ``extent`` = world ``(xmin, ymin, xmax, ymax)``, default the scene
        extent; geotransform ``(x_min, res, 0, y_max, 0, -res)``.
        """
        return truth.dsm(self.surface, resolution, extent or self.extent_world(), self.offset)

    def orthophoto(self, resolution: float, extent=None, as_uint8: bool = True):
        """True orthophoto ``((rows, cols, 3) uint8 or float32 in [0, 1], geotransform)``.

        The colour seen vertically from above at each cell centre, without
        exposure differences (roof or ground, never walls).
        """
        rgb, gt = truth.orthophoto(self.surface, self.palette, self.tex, resolution,
                                   extent or self.extent_world(), self.offset, self.sun)
        return (np.clip(np.round(rgb * 255), 0, 255).astype(np.uint8) if as_uint8 else rgb), gt

    def crop_heights(self, resolution: float, extent=None) -> np.ndarray:
        """(rows, cols) height of the crop fields' stalk layer above the soil at the cell centres of
        the grid of :meth:`orthophoto` (``config.crop_height`` in a field, 0 elsewhere, on roofs
        and without fields)."""
        xy, shape, _ = truth.grid_centres(resolution, extent or self.extent_world(), self.offset)
        cfg = self.config
        if not (cfg.crop_share > 0 and cfg.crop_height > 0):
            return np.zeros(shape)
        _, bid = self.surface.height(xy)
        inside = field_mask(xy, cfg.seed, cfg.crop_share) & (bid < 0)
        return np.where(inside, cfg.crop_height, 0.0).reshape(shape)

    def visibility(self, points_world, image: int | str, tol: float = 0.01, check_frame: bool = True):
        """``(visible (N,) bool, uv (N, 2), hit_distance (N,))`` of world points in one image.

        See :func:`~.truth.visibility`: in front, inside the frame, and no
        surface closer than ``|P - C| - tol`` along the ray.
        """
        P = np.asarray(points_world, dtype=np.float64).reshape(-1, 3) - self.offset
        return truth.visibility(self.surface, P, self.image(image), self.camera, tol, check_frame)

    def cast(self, image: int | str, uv):
        """Hits of the viewing rays of pixels ``uv`` (N, 2) of an image.

        Returns ``(points_world (N, 3), material (N,), building (N,))``; NaN
        points and material -1 for rays that hit nothing.
        """
        from ..geometry.camera import pixel_to_ray

        im = self.image(image)
        C, d = pixel_to_ray(uv, im.R, im.C, self.camera)
        t, mat, bid = cast_rays(self.surface, C, d)
        return C + t[:, None] * d + self.offset, mat, bid

    def _subpixel(self, supersample: int) -> np.ndarray:
        if supersample not in self._rays:
            self._rays[supersample] = subpixel_rays(self.camera, supersample)
        return self._rays[supersample]

    def render(self, image: int | str, radiometry: bool = False, supersample: int | None = None,
               adaptive: bool | None = None):
        """Re-render one image (defaults: the config's supersampling).

        Returns the uint8 image with its radiometry when ``radiometry``,
        otherwise a :class:`RenderResult` with the noise-free float colour
        and the depth, material and building maps at pixel centres.
        """
        im = self.image(image)
        s = self.config.supersample if supersample is None else int(supersample)
        ad = self.config.adaptive_supersampling if adaptive is None else bool(adaptive)
        t0 = time.perf_counter()
        colour, depth, mat, bid = render_colour(self.surface, self.palette, self.tex, im.R, im.C,
                                                self._subpixel(1), self._subpixel(s) if s > 1 else None, ad,
                                                self.sun)
        if radiometry:
            idx = self.orientation.images.index(im)
            blurred = optics_blur(colour, self.config.optics_blur)
            return jpeg_roundtrip(apply_radiometry(blurred, self.camera, self.radiometry[idx]),
                                  self.config.jpeg_quality)
        return RenderResult(colour, depth, mat, bid, time.perf_counter() - t0)

    def depth_map(self, image: int | str) -> np.ndarray:
        """Camera-z depth (H, W) float64, metres, of the surface at every pixel centre; NaN for sky."""
        return self.render(image, supersample=1).depth

    # ---------------------------------------------------------- output
    def write(self, folder: str | os.PathLike, resolution: float | None = None) -> Path:
        """Write the data set to ``folder`` (created if needed).

        Files: ``img_NNN.png`` (RGB; ``img_NNN.jpg``, the JPEG files themselves, with
        ``config.jpeg_quality``), ``orientation.json`` (image root = the
        folder), ``gcp_list.txt`` (ODM: ``EPSG:...`` then
        ``X Y Z px py image name`` in world coordinates, pixel centres as in
        TruOrtho/OpenSfM), ``dsm.tif`` (float32, nodata -9999) and
        ``ortho.tif`` (RGB uint8, nodata 0, truth colours clipped to >= 1) at
        ``resolution`` (default the nominal GSD), and ``truth.json``
        (config, buildings, radiometry). Every file is written atomically.
        """
        import cv2

        out = Path(folder)
        out.mkdir(parents=True, exist_ok=True)
        if self.jpeg_files and len(self.jpeg_files) != len(self.images):
            raise InputError(f"write: {len(self.jpeg_files)} JPEG files for {len(self.images)} images")
        for k, (im, img) in enumerate(zip(self.orientation.images, self.images, strict=True)):
            if self.jpeg_files:
                data = self.jpeg_files[k]
            else:
                ok, buf = cv2.imencode(".png", np.ascontiguousarray(img[:, :, ::-1]))
                if not ok:
                    raise InputError(f"could not encode {im.name}")
                data = buf.tobytes()
            _atomic_write_bytes(out / (im.path or im.name), data)
        o = dataclasses.replace(self.orientation, image_root=str(out.resolve()))
        o.save(out / "orientation.json")
        lines = [self.config.crs]
        for g in self.orientation.gcps:
            for name, u, v in g.observations:
                lines.append(f"{g.xyz[0]:.6f} {g.xyz[1]:.6f} {g.xyz[2]:.6f} {u:.6f} {v:.6f} {name} {g.name}")
        atomic_write_text(out / "gcp_list.txt", "\n".join(lines) + "\n")
        res = float(resolution or self.config.gsd)
        h, gt = self.dsm(res)
        _write_geotiff(out / "dsm.tif", h[None], gt, self.config.crs, -9999.0)
        rgb, gt = self.orthophoto(res)
        _write_geotiff(out / "ortho.tif", np.maximum(rgb, 1).transpose(2, 0, 1), gt, self.config.crs, 0)
        info = {
            "config": dataclasses.asdict(self.config),
            "n_nadir": self.n_nadir,
            "buildings": [dataclasses.asdict(b) for b in self.surface.buildings],
            "radiometry": [r.as_dict() for r in self.radiometry],
        }
        atomic_write_text(out / "truth.json", json.dumps(info, indent=1))
        return out


def _atomic_write_bytes(path: Path, data: bytes) -> None:
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    try:
        with open(tmp, "wb") as fh:
            fh.write(data)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def _write_geotiff(path: Path, bands: np.ndarray, gt, crs: str, nodata) -> None:
    import rasterio
    from rasterio.transform import Affine

    tmp = path.with_name(f".{path.stem}.tmp{os.getpid()}{path.suffix}")
    profile = {"driver": "GTiff", "width": bands.shape[2], "height": bands.shape[1], "count": bands.shape[0],
               "dtype": bands.dtype.name, "crs": crs, "transform": Affine.from_gdal(*gt), "nodata": nodata,
               "compress": "deflate"}
    if bands.shape[0] == 3:
        profile["photometric"] = "RGB"
    try:
        with rasterio.open(tmp, "w", **profile) as ds:
            ds.write(bands)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def optics_blur(colour: np.ndarray, sigma: float) -> np.ndarray:
    """``colour`` (H, W, 3) seen through optics whose point spread is a Gaussian of ``sigma`` pixels
    (lens, focus, motion and demosaicing together; 0 = as rendered). Sky and surface alike."""
    c = np.asarray(colour)
    if c.ndim != 3 or c.shape[2] != 3:
        raise InputError(f"optics_blur: expected (H, W, 3) colours, got shape {c.shape}")
    if not (math.isfinite(float(sigma)) and sigma >= 0):
        raise InputError(f"optics_blur: sigma must be a finite number of pixels >= 0, got {sigma!r}")
    if sigma == 0:
        return colour
    import cv2

    out = cv2.GaussianBlur(np.ascontiguousarray(colour, np.float32), (0, 0), float(sigma),
                           borderType=cv2.BORDER_REFLECT)  # fmt: skip
    return out.astype(colour.dtype, copy=False)


def make_scene(
    config: SceneConfig | None = None, progress: Progress | None = None, image_sink=None, skip_image=None
) -> SyntheticScene:
    """Build, render and control a synthetic block (deterministic in ``config``).

    Nadir block over ``config.extent`` (:func:`~.cameras.nadir_block`), then
    ``config.n_oblique`` obliques aimed at the extent centre; images are
    rendered with occlusion and per-image radiometry; GCPs are chosen and
    observed (:func:`~.truth.select_gcps`).

    ``image_sink(index, image, rgb)``: when given, every rendered image is
    handed to it and not kept (``scene.images`` stays empty), so that blocks
    of hundreds of large images are rendered in bounded memory.

    ``skip_image(index, image) -> bool`` (with ``image_sink``): the images it
    accepts are not rendered and reach the sink with ``rgb=None`` (a render
    interrupted half way resumes with the images it has not written). Their
    random draws are still made, so every other image is the same as in a
    full render.
    """
    cfg = config if config is not None else SceneConfig()
    if not isinstance(cfg, SceneConfig):
        raise InputError(f"make_scene: expected a SceneConfig, got {type(cfg).__name__}")
    cfg.validate()
    if skip_image is not None and image_sink is None:
        raise InputError("make_scene: skip_image needs an image_sink (the skipped images are not kept)")
    progress = as_progress(progress)
    surface = Surface(cfg)
    w, h = cfg.image_size
    cam = make_camera(w, h, cfg.focal_px, cfg.principal_offset, cfg.distortion)
    images = nadir_block(cfg.extent, cam, cfg.flying_height, cfg.ground_height, cfg.forward_overlap,
                         cfg.side_overlap, cfg.heading_deg, cfg.attitude_sigma_deg, cfg.position_sigma,
                         cfg.seed)
    n_nadir = len(images)
    if cfg.n_oblique:
        x0, y0, x1, y1 = cfg.extent
        images += oblique_cameras(((x0 + x1) / 2, (y0 + y1) / 2, cfg.ground_height), cam, cfg.flying_height,
                                  cfg.n_oblique, cfg.oblique_tilt_deg, 0.0, cfg.attitude_sigma_deg / 2,
                                  cfg.position_sigma / 2, cfg.seed, first_index=n_nadir)
    if cfg.jpeg_quality:
        # the images are JPEG files, as a camera writes them (write() stores their bytes)
        jpg = [os.path.splitext(im.name)[0] + ".jpg" for im in images]
        images = [dataclasses.replace(im, name=n, path=n) for im, n in zip(images, jpg, strict=True)]
    meta = {"synthetic": {"seed": cfg.seed, "n_nadir": n_nadir, "n_oblique": len(images) - n_nadir}}
    frame = LocalFrame(cfg.crs, np.asarray(cfg.offset, dtype=np.float64))
    orientation = Orientation(frame, {cam.id: cam}, images, None, [], ".", meta)
    nb = len(surface.buildings)
    roof_contrast = np.random.default_rng([cfg.seed, 43]).uniform(*cfg.roof_contrast, nb)
    tex = texture_params(cfg.seed, cfg.texture_scale, cfg.texture_octaves, cfg.texture_contrast,
                         cfg.facade_windows, roof_contrast, cfg.crop_share, cfg.crop_height)
    sun = sun_vector(cfg.sun_azimuth_deg, cfg.sun_elevation_deg, cfg.shadow_strength)
    scene = SyntheticScene(cfg, surface, orientation, [], [], n_nadir, 0.0, palette(nb), tex, sun)
    rng = np.random.default_rng([cfg.seed, 41])
    t0 = time.perf_counter()
    sub = scene._subpixel(cfg.supersample) if cfg.supersample > 1 else None
    for k, im in enumerate(images):
        check(progress)
        rad = random_radiometry(rng, cfg.gain_sigma, cfg.offset_sigma, cfg.vignetting, cfg.noise_sigma,
                                cfg.seed * 1000 + k)
        scene.radiometry.append(rad)
        if skip_image is not None and skip_image(k, im):
            image_sink(k, im, None)
            progress.update(0.95 * (k + 1) / len(images), f"kept {im.name}")
            continue
        colour, _, _, _ = render_colour(surface, scene.palette, scene.tex, im.R, im.C, scene._subpixel(1),
                                        sub, cfg.adaptive_supersampling, sun)
        seen = optics_blur(colour, cfg.optics_blur)
        rgb, jpeg = jpeg_file(apply_radiometry(seen, cam, rad), cfg.jpeg_quality)
        if image_sink is None:
            scene.images.append(rgb)
            if jpeg is not None:
                scene.jpeg_files.append(jpeg)
        else:
            image_sink(k, im, rgb)
        progress.update(0.95 * (k + 1) / len(images), f"rendered {im.name}")
    scene.render_seconds = time.perf_counter() - t0
    orientation.gcps = truth.select_gcps(surface, images, cam, cfg.offset, cfg.n_gcps, cfg.gcp_on_roof,
                                         cfg.check_fraction, cfg.gcp_pixel_sigma, cfg.gcp_clearance,
                                         cfg.min_gcp_views, cfg.seed)
    orientation.validate()
    progress.update(1.0, "synthetic scene ready")
    return scene
