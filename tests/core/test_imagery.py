"""Image access and EXIF on the shared real data sets and small generated files."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from truortho.core.errors import FormatError, InputError, MissingFileError
from truortho.core.exif import focal_prior_px, read_exif
from truortho.core.geometry import Camera
from truortho.core.imagery import (
    halve_image,
    image_info,
    level_size,
    luminance,
    read_image,
    read_image_level,
    read_window,
    scaled_size,
)

DATA = Path(os.environ["TRUORTHO_DATA"])
need_data = pytest.mark.skipif(not DATA.is_dir(), reason="shared data sets not available")


@pytest.fixture
def rgb_png(tmp_path):
    import cv2

    rng = np.random.default_rng(1)
    img = rng.integers(0, 256, (60, 80, 3), dtype=np.uint8)
    p = tmp_path / "rgb.png"
    cv2.imwrite(str(p), img[:, :, ::-1])  # cv2 writes BGR
    return p, img


def test_read_image_rgb_order_and_info(rgb_png):
    p, img = rgb_png
    assert np.array_equal(read_image(p), img)
    assert np.array_equal(read_image(p, band=2), img[:, :, 2])
    info = image_info(p)
    assert (info.width, info.height, info.bands, info.dtype) == (80, 60, 3, "uint8")
    with pytest.raises(InputError, match="band 3"):
        read_image(p, band=3)


def test_sixteen_bit_kept(tmp_path):
    import cv2

    img = (np.arange(40 * 30, dtype=np.uint16).reshape(30, 40) * 50).astype(np.uint16)
    p = tmp_path / "g16.png"
    cv2.imwrite(str(p), img)
    out = read_image(p)
    assert out.dtype == np.uint16 and np.array_equal(out, img)
    lum = luminance(out)
    assert lum.dtype == np.float32 and np.allclose(lum, img / 65535.0, atol=1e-6)


def test_downscale_matches_camera_scaled(tmp_path):
    """The centroid of a blob at a known position lands where Camera.scaled maps it."""
    import cv2

    x, y = 301.3, 151.7
    yy, xx = np.mgrid[0:400, 0:600]
    img = np.rint(60000 * np.exp(-((xx - x) ** 2 + (yy - y) ** 2) / (2 * 8.0**2))).astype(np.uint16)
    p = tmp_path / "dot.png"
    cv2.imwrite(str(p), img)
    s = 0.25
    small = read_image(p, scale=s).astype(np.float64)
    w, h, sx, sy = scaled_size(600, 400, s)
    assert small.shape == (h, w)
    yy, xx = np.mgrid[0:h, 0:w]
    cx, cy = (small * xx).sum() / small.sum(), (small * yy).sum() / small.sum()
    cam = Camera(600, 400, 500.0, 500.0, x, y).scaled(s)  # principal point maps like a pixel
    assert abs(cx - cam.cx) < 0.01 and abs(cy - cam.cy) < 0.01


def test_read_window_inside_and_padded(rgb_png):
    p, img = rgb_png
    assert np.array_equal(read_window(p, 10, 5, 20, 15), img[5:20, 10:30])
    w = read_window(p, -5, 50, 20, 20, fill=7)
    assert w.shape == (20, 20, 3)
    assert np.all(w[:, :5] == 7) and np.all(w[10:] == 7)
    assert np.array_equal(w[:10, 5:], img[50:60, 0:15])


def test_tiff_window_through_rasterio(tmp_path):
    pytest.importorskip("rasterio")
    import cv2

    img = np.arange(50 * 70, dtype=np.uint16).reshape(50, 70)
    p = tmp_path / "a.tif"
    cv2.imwrite(str(p), img)
    assert np.array_equal(read_window(p, 3, 4, 10, 6), img[4:10, 3:13])
    assert image_info(p).dtype == "uint16"


def test_level_window_reads_the_decimated_window(tmp_path):
    import rasterio

    from truortho.core.imagery import read_level_window

    rng = np.random.default_rng(0)
    a = rng.integers(0, 255, (3, 100, 130), dtype=np.uint8)
    p = tmp_path / "t.tif"
    with rasterio.open(p, "w", driver="GTiff", width=130, height=100, count=3, dtype="uint8",
                       tiled=True, blockxsize=32, blockysize=32) as ds:  # fmt: skip
        ds.write(a)
    img = np.moveaxis(a, 0, -1)
    assert np.array_equal(read_level_window(p, (130, 100), 0, 10, 20, 30, 25), img[20:45, 10:40])
    # level 1: 2 x 2 means; the last column of the level (65) is cropped at the image border
    w = read_level_window(p, (130, 100), 1, 60, 10, 10, 4)
    assert w.shape == (4, 5, 3)
    means = img.reshape(50, 2, 65, 2, 3).astype(float).mean(axis=(1, 3))[10:14, 60:65]
    assert np.abs(w.astype(float) - means).max() <= 1
    with pytest.raises(InputError, match="outside the image"):
        read_level_window(p, (130, 100), 1, 70, 0, 4, 4)
    with pytest.raises(InputError, match="bad image window"):
        read_level_window(p, (130, 100), 0, 0, 0, 0, 4)


def test_luminance_rec601():
    img = np.zeros((1, 3, 3), np.uint8)
    img[0, 0] = (255, 0, 0)
    img[0, 1] = (0, 255, 0)
    img[0, 2] = (0, 0, 255)
    assert np.allclose(luminance(img)[0], [0.299, 0.587, 0.114], atol=1e-6)
    assert luminance(np.full((2, 2, 4), 255, np.uint8)).max() == pytest.approx(1.0, abs=1e-6)


def test_non_image_and_missing_files(tmp_path):
    bad = tmp_path / "notes.jpg"
    bad.write_text("this is not a JPEG")
    with pytest.raises(FormatError, match="notes.jpg"):
        read_image(bad)
    with pytest.raises(FormatError, match="notes.jpg"):
        image_info(bad)
    with pytest.raises(FormatError, match="notes.jpg"):
        read_exif(bad)
    with pytest.raises(MissingFileError, match="nothere.png"):
        read_image(tmp_path / "nothere.png")


@need_data
def test_exif_copr_focal_prior():
    p = DATA / "copr/images/IMG_0022.jpg"
    e = read_exif(p)
    assert e.model == "Canon EOS DIGITAL REBEL XSi" and e.focal_mm == pytest.approx(30.0)
    assert e.sensor_width_mm == pytest.approx(22.3, abs=0.05)
    assert e.sensor_height_mm == pytest.approx(14.8, abs=0.05)
    f, src = focal_prior_px(e, 2136, 1424)
    assert src == "exif_sensor" and f == pytest.approx(30.0 * 2136 / 22.3, rel=0.003)


@need_data
def test_exif_brighton_gps_and_35mm():
    e = read_exif(DATA / "brighton/images/DJI_0018.JPG")
    assert e.has_gps and 46.8423 <= e.latitude <= 46.8430 and -91.9946 <= e.longitude <= -91.9935
    assert 198.3 <= e.altitude <= 198.7 and e.relative_altitude == pytest.approx(39.8, abs=0.5)
    f, src = focal_prior_px(e, 2000, 1125)
    assert src == "exif_35mm" and f == pytest.approx(20.0 / 36.0 * 2000)


@need_data
def test_no_exif_default_prior_and_orientation_rule():
    e = read_exif(DATA / "fountain-P11/images/0000.jpg")
    assert not e.has_gps and e.focal_mm is None
    f, src = focal_prior_px(e, 3072, 2048)
    assert src == "default" and f == pytest.approx(1.2 * 3072)
    # boruszyn: Orientation 8, pixels are read as stored (landscape), never rotated
    b = DATA / "boruszyn/images/img_4854.jpg"
    assert read_exif(b).orientation == 8
    assert read_image(b, scale=0.125).shape[:2] == (216, 288)
    assert (image_info(b).width, image_info(b).height) == (2304, 1728)


def _textured(h, w, seed):
    """A photo-like texture: luminance detail at every pyramid level (down to 2 px), smoother
    colour (as a JPEG's subsampled chroma keeps it), no clipping."""
    import cv2

    rng = np.random.default_rng(seed)

    def noise(s, bands):
        n = rng.normal(0, 1, (h // s + 2, w // s + 2, bands)).astype(np.float32)
        return cv2.resize(n, (w, h), interpolation=cv2.INTER_CUBIC).reshape(h, w, bands)

    lum = 18 * noise(2, 1) + 18 * noise(5, 1) + 18 * noise(13, 1)
    tint = 1.0 + 0.15 * noise(9, 3)
    return np.clip(110 + lum * tint, 0, 255).astype(np.uint8)


@pytest.mark.parametrize("grey", [False, True])
def test_image_levels_of_a_jpeg_are_block_means(tmp_path, grey):
    """JPEG levels 1..3 are decoded at the reduced scale, level 4 halved from level 3: the sizes are
    the halvings rounded up (odd sizes) and the values the area means of the full image (within
    JPEG rounding), the same as the area pyramid of the full decode."""
    import cv2

    img = _textured(151, 203, 3)
    if grey:
        img = img[:, :, 1].copy()
    p = tmp_path / "t.jpg"
    cv2.imwrite(str(p), img if grey else img[:, :, ::-1], [cv2.IMWRITE_JPEG_QUALITY, 95])
    full = read_image(p)
    chain = full.astype(np.float32)
    for level in range(1, 5):
        chain = halve_image(chain)
        got = read_image_level(p, (203, 151), level)
        assert got.dtype == np.uint8 and got.shape[1::-1] == level_size((203, 151), level)
        assert got.ndim == (2 if grey else 3)
        err = np.abs(got.astype(np.float32) - chain)
        # the block means of the stored image, not a sample or a blur of it
        assert err.mean() < 1.0 and np.percentile(err, 99) < 4.0, (level, err.mean())
    assert np.array_equal(read_image_level(p, (203, 151), 0), full)
    # a conversion before the halvings keeps the float precision of the means
    lum = read_image_level(p, (203, 151), 4, luminance)
    assert lum.dtype == np.float32 and lum.shape == (10, 13)


def test_image_levels_of_png_and_tiff_and_bad_input(tmp_path, rgb_png):
    import cv2
    import rasterio

    p, img = rgb_png  # 80 x 60
    two = read_image_level(p, (80, 60), 2)
    assert np.array_equal(two, halve_image(halve_image(img)))  # PNG: the exact area pyramid
    tif = tmp_path / "t.tif"
    with rasterio.open(tif, "w", driver="GTiff", width=80, height=60, count=3, dtype="uint8") as ds:
        ds.write(np.moveaxis(img, -1, 0))
    t2 = read_image_level(tif, (80, 60), 2)
    assert t2.shape == (15, 20, 3) and np.abs(t2.astype(float) - two).mean() < 1.0
    with pytest.raises(FormatError, match="rgb.png.*80 x 60.*camera says 81 x 60"):
        read_image_level(p, (81, 60), 1)
    with pytest.raises(InputError, match="level must be a whole number"):
        read_image_level(p, (80, 60), -1)
    with pytest.raises(MissingFileError, match="nope.jpg"):
        read_image_level(tmp_path / "nope.jpg", (80, 60), 1)
    bad = tmp_path / "bad.jpg"
    bad.write_bytes(b"\xff\xd8\xff" + b"\0" * 50)
    with pytest.raises(FormatError, match="bad.jpg"):
        read_image_level(bad, (80, 60), 1)
    cv2.imwrite(str(tmp_path / "x.png"), img)  # a PNG named .jpg decodes through the full path
    (tmp_path / "x.png").rename(tmp_path / "png_named.jpg")
    named = read_image_level(tmp_path / "png_named.jpg", (80, 60), 1)
    assert np.array_equal(named, halve_image(img[:, :, ::-1]))
