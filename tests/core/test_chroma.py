"""JPEG chroma subsampling: read from the header, and the colour edges restored from the luma."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from truortho.core.chroma import jpeg_chroma_subsampling, restore_chroma
from truortho.core.errors import InputError

FACTORS = {
    (2, 2): cv2.IMWRITE_JPEG_SAMPLING_FACTOR_420,
    (2, 1): cv2.IMWRITE_JPEG_SAMPLING_FACTOR_422,
    (1, 1): cv2.IMWRITE_JPEG_SAMPLING_FACTOR_444,
}


def _scene(seed: int, size: int = 160) -> np.ndarray:
    """RGB: textured ground with saturated rectangles ("roofs") of random colours and places."""
    rng = np.random.default_rng(seed)
    noise = cv2.GaussianBlur(rng.normal(0.0, 1.0, (size, size)).astype(np.float32), (0, 0), 1.2)
    img = np.empty((size, size, 3), np.float32)
    img[:] = rng.uniform(60, 140, 3)
    img += 10.0 * noise[..., None]
    for _ in range(6):
        h, w = rng.integers(12, 40, 2)
        r, c = rng.integers(0, size - 40, 2)
        colour = rng.uniform(0, 255, 3)
        colour[rng.integers(0, 3)] = rng.uniform(200, 255)  # saturated
        img[r : r + h, c : c + w] = colour + 6.0 * noise[r : r + h, c : c + w, None]
    return np.clip(img, 0, 255).astype(np.uint8)


def _jpeg(rgb: np.ndarray, factors, quality: int = 92) -> bytes:
    params = [cv2.IMWRITE_JPEG_QUALITY, quality, cv2.IMWRITE_JPEG_SAMPLING_FACTOR, FACTORS[factors]]
    ok, buf = cv2.imencode(".jpg", np.ascontiguousarray(rgb[:, :, ::-1]), params)
    assert ok
    return buf.tobytes()


def _decode(data: bytes) -> np.ndarray:
    return cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)[:, :, ::-1].copy()


def _chroma(rgb: np.ndarray) -> np.ndarray:
    return cv2.cvtColor(np.ascontiguousarray(rgb), cv2.COLOR_RGB2YCrCb)[..., 1:].astype(np.float64)


@pytest.mark.parametrize("factors", [(2, 2), (2, 1), (1, 1)])
def test_subsampling_is_read_from_the_frame_header(tmp_path, factors):
    p = tmp_path / "a.jpg"
    p.write_bytes(_jpeg(_scene(0), factors))
    assert jpeg_chroma_subsampling(p) == factors


def test_files_without_subsampled_colour_read_none(tmp_path):
    rgb = _scene(1)
    png = tmp_path / "a.jpg"  # a PNG whatever its name
    png.write_bytes(cv2.imencode(".png", rgb)[1].tobytes())
    grey = tmp_path / "g.jpg"
    grey.write_bytes(cv2.imencode(".jpg", rgb[..., 0])[1].tobytes())
    cut = tmp_path / "cut.jpg"
    cut.write_bytes(_jpeg(rgb, (2, 2))[:20])  # the header ends before the frame
    for p in (png, grey, cut, tmp_path / "missing.jpg"):
        assert jpeg_chroma_subsampling(p) is None, p.name


@pytest.mark.parametrize("seed", [2, 3, 4])
@pytest.mark.parametrize("factors", [(2, 2), (2, 1)])
def test_colour_edges_come_back_and_flat_colour_stays(seed, factors):
    rgb = _scene(seed)
    decoded = _decode(_jpeg(rgb, factors))
    restored = restore_chroma(decoded, factors)
    true_c, dec_c, res_c = _chroma(rgb), _chroma(decoded), _chroma(restored)
    # pixels within 2 of a colour edge of the original (its chroma changes there)
    sobel = lambda a, dx, dy: np.abs(cv2.Sobel(a, cv2.CV_64F, dx, dy))  # noqa: E731
    grad = sum(sobel(true_c[..., k], 1, 0) + sobel(true_c[..., k], 0, 1) for k in range(2))
    edge = cv2.dilate((grad > 60).astype(np.uint8), np.ones((5, 5), np.uint8)) > 0
    err_dec = np.abs(dec_c - true_c).sum(-1)
    err_res = np.abs(res_c - true_c).sum(-1)
    assert edge.mean() > 0.05
    # the smear along the outlines shrinks by half at least
    assert err_res[edge].mean() < 0.5 * err_dec[edge].mean()
    # away from the edges the colour is not made worse
    assert err_res[~edge].mean() < err_dec[~edge].mean() + 1.0
    # the luma is the decoder's (within the rounding of the conversions)
    y = lambda a: cv2.cvtColor(np.ascontiguousarray(a), cv2.COLOR_RGB2YCrCb)[..., 0].astype(int)  # noqa: E731
    assert np.abs(y(restored) - y(decoded)).max() <= 2


def test_full_resolution_colour_is_left_alone_and_bad_input_is_named():
    rgb = _scene(5)
    assert restore_chroma(rgb, (1, 1)) is rgb
    with pytest.raises(InputError, match="uint8 RGB"):
        restore_chroma(rgb[..., 0], (2, 2))
    with pytest.raises(InputError, match="uint8 RGB"):
        restore_chroma(rgb.astype(np.uint16), (2, 2))
    with pytest.raises(InputError, match="subsampling"):
        restore_chroma(rgb, (0, 2))
    with pytest.raises(InputError, match="subsampling"):
        restore_chroma(rgb, "2x2")
    with pytest.raises(InputError, match="file path"):
        jpeg_chroma_subsampling(None)
