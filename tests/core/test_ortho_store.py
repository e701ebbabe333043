"""The decoded-image store of the mosaic (core/ortho/mosaic.py: ImageStore)."""

from __future__ import annotations

import pickle
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from truortho.core.errors import FormatError
from truortho.core.imagery import level_size
from truortho.core.ortho import mosaic
from truortho.core.ortho.mosaic import ImageStore


def _store(n=3, max_bytes=1 << 30):
    paths = [f"img{i}.png" for i in range(n)]
    return ImageStore(paths, [(40, 30)] * n, 3, "uint8", max_bytes, windowed=False)


def test_images_decode_in_parallel_and_once_each(monkeypatch):
    barrier = threading.Barrier(2, timeout=10)
    calls: list[str] = []

    def decode(path, size, level):
        calls.append(path)
        if path in ("img0.png", "img1.png"):
            barrier.wait()  # both decodes must be running at once, else this times out
        w, h = level_size(size, level)
        return np.full((h, w, 3), int(path[3]), np.uint8)

    monkeypatch.setattr(mosaic, "read_image_level", decode)
    store = _store()
    with ThreadPoolExecutor(2) as pool:
        a, b = pool.map(store.get, [0, 1])
    assert a[0, 0, 0] == 0 and b[0, 0, 0] == 1 and store.reads == 2
    # eight threads asking for one image: one decode, the same array for all
    with ThreadPoolExecutor(8) as pool:
        got = list(pool.map(store.get, [2] * 8))
    assert calls.count("img2.png") == 1 and all(g is got[0] for g in got) and store.reads == 3
    # a level is decoded on its own (JPEGs at the reduced scale) and cached alone
    half = store.get(2, 1)
    assert half.shape == (15, 20, 3) and store.reads == 4 and store.get(2, 1) is half
    assert store.get(0) is a and not store._pending
    copy = pickle.loads(pickle.dumps(store))
    assert copy.reads == 4 and not copy._cache and not copy._pending


def test_a_failed_decode_raises_in_every_waiting_thread_and_can_be_retried(monkeypatch):
    gate = threading.Event()
    state = {"fail": True}

    def decode(path, size, level):
        gate.wait(5)
        if state["fail"]:
            return np.zeros((size[1], size[0]), np.uint8)  # one band where the block has three
        return np.zeros((size[1], size[0], 3), np.uint8)

    monkeypatch.setattr(mosaic, "read_image_level", decode)
    store = _store()
    with ThreadPoolExecutor(4) as pool:
        futures = [pool.submit(store.get, 0) for _ in range(4)]
        gate.set()
        for f in futures:
            with pytest.raises(FormatError, match="1 band"):
                f.result()
    assert not store._pending and not store._cache
    state["fail"] = False
    assert store.get(0).shape == (30, 40, 3)


def test_the_cache_stays_within_its_bound(monkeypatch):
    monkeypatch.setattr(mosaic, "read_image_level", lambda p, s, lv: np.zeros((s[1], s[0], 3), np.uint8))
    store = _store(n=5, max_bytes=2 * 40 * 30 * 3)
    for i in range(5):
        store.get(i)
    assert len(store._cache) == 2 and store._bytes <= store.max_bytes and store.reads == 5
    assert list(store._cache) == [(3, 0), (4, 0)]


def test_subsampled_jpeg_colour_is_restored_at_full_resolution_only(tmp_path):
    import cv2

    from truortho.core.chroma import jpeg_chroma_subsampling, restore_chroma
    from truortho.core.errors import InputError

    rng = np.random.default_rng(7)
    rgb = np.zeros((48, 64, 3), np.uint8)
    rgb[:] = (90, 110, 80)
    rgb[10:30, 12:40] = (230, 30, 40)  # a red roof on grey-green ground
    rgb = np.clip(rgb + rng.normal(0, 4, rgb.shape), 0, 255).astype(np.uint8)
    path = tmp_path / "a.jpg"
    path.write_bytes(cv2.imencode(".jpg", rgb[:, :, ::-1], [cv2.IMWRITE_JPEG_QUALITY, 92])[1].tobytes())
    sub = jpeg_chroma_subsampling(path)
    assert sub == (2, 2)  # OpenCV's default, as most cameras write
    plain = ImageStore([str(path)], [(64, 48)], 3, "uint8", windowed=False)
    store = ImageStore([str(path)], [(64, 48)], 3, "uint8", windowed=False, chroma=[sub])
    assert np.array_equal(store.get(0), restore_chroma(plain.get(0), sub))
    assert not np.array_equal(store.get(0), plain.get(0))
    assert np.array_equal(store.get(0, 1), plain.get(0, 1))  # a reduced level is left as decoded
    copy = pickle.loads(pickle.dumps(store))
    assert copy.chroma == [sub] and np.array_equal(copy.get(0), store.get(0))
    with pytest.raises(InputError, match="chroma"):
        ImageStore([str(path)], [(64, 48)], 3, "uint8", chroma=[sub, None])
