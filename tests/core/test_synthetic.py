"""Tests of the synthetic scene generator (truortho.core.synthetic)."""

from __future__ import annotations

import json
import math
import time

import numpy as np
import pytest

from truortho.core.errors import InputError
from truortho.core.geometry import pixel_to_ray, project_points
from truortho.core.orientation import Orientation
from truortho.core.synthetic import GROUND, ROOF, WALL, SceneConfig, cast_rays, make_scene, srgb_to_lab
from truortho.core.synthetic.texture import GROUND_RGB, ROOF_RGB, WALL_RGB


@pytest.fixture(scope="module")
def scene():
    t0 = time.perf_counter()
    s = make_scene(SceneConfig(seed=1))
    print(
        f"\nsynthetic scene: {len(s.images)} images {s.camera.width}x{s.camera.height}, "
        f"render {s.render_seconds:.2f} s, total {time.perf_counter() - t0:.2f} s (incl. JIT on first use)"
    )
    return s


def _small(seed=5, **kw):
    return SceneConfig(
        seed=seed,
        image_size=(160, 120),
        focal_px=200.0,
        n_buildings=3,
        n_oblique=1,
        n_gcps=4,
        min_gcp_views=2,
        grid_margin=150.0,
        **kw,
    )


def test_determinism():
    a = make_scene(_small(noise_sigma=2.0))
    b = make_scene(_small(noise_sigma=2.0))
    assert len(a.images) == len(b.images) > 0
    for x, y in zip(a.images, b.images, strict=True):
        assert x.dtype == np.uint8 and x.shape == (120, 160, 3)
        assert np.array_equal(x, y)
    assert a.orientation.to_dict() == b.orientation.to_dict()
    c = make_scene(_small(seed=6, noise_sigma=2.0))
    assert not np.array_equal(a.images[0], c.images[0])


def test_image_sink_receives_the_same_images_and_keeps_none():
    a = make_scene(_small(noise_sigma=2.0))
    got = {}
    b = make_scene(_small(noise_sigma=2.0), image_sink=lambda k, im, rgb: got.__setitem__(k, (im.name, rgb)))
    assert b.images == [] and sorted(got) == list(range(len(a.images)))
    for k, x in enumerate(a.images):
        assert got[k][0] == a.orientation.images[k].name
        assert np.array_equal(got[k][1], x)
    assert a.orientation.to_dict() == b.orientation.to_dict()


def test_skipped_images_leave_the_others_unchanged():
    """A resumed render (skip_image) draws the skipped images' random numbers all the same: the images
    it renders equal those of a full render, the skipped ones reach the sink as None."""
    a = make_scene(_small(noise_sigma=2.0))
    got = {}
    make_scene(
        _small(noise_sigma=2.0),
        image_sink=lambda k, im, rgb: got.__setitem__(k, rgb),
        skip_image=lambda k, im: k % 2 == 0,
    )
    assert sorted(got) == list(range(len(a.images)))
    for k, x in enumerate(a.images):
        assert (got[k] is None) if k % 2 == 0 else np.array_equal(got[k], x)
    with pytest.raises(InputError, match="skip_image needs an image_sink"):
        make_scene(_small(), skip_image=lambda k, im: True)


def test_block_layout(scene):
    o = scene.orientation
    assert o.crs == "EPSG:32632"
    assert np.allclose(o.offset, [500000.0, 5600000.0, 0.0])
    assert [im.name for im in o.images] == [f"img_{k:03d}.png" for k in range(len(o.images))]
    assert len(o.cameras) == 1 and scene.camera.has_distortion
    assert 12 <= len(o.images) <= 20 and len(o.images) - scene.n_nadir == 4
    nadir = o.images[: scene.n_nadir]
    assert all(im.R[2, 2] < -0.99 for im in nadir)  # looking down
    # kappa flips between strips: image x axes of the first and the last image are opposite
    assert nadir[0].R[0] @ nadir[-1].R[0] < -0.95
    for im in o.images[scene.n_nadir :]:
        tilt = math.degrees(math.acos(-im.R[2, 2]))
        assert 35 <= tilt <= 45


def test_gcp_observations_reproject(scene):
    gcps = scene.orientation.gcps
    assert len(gcps) == 9
    assert sum(g.role == "check" for g in gcps) == 2
    assert any(g.name == "gcp_roof" for g in gcps)
    n_obs = 0
    for g in gcps:
        assert len(g.observations) >= 2
        P = g.xyz - scene.offset
        for name, u, v in g.observations:
            im = scene.orientation.image(name)
            uv = project_points(P[None], im.R, im.C, scene.camera)[0]
            assert np.hypot(uv[0] - u, uv[1] - v) < 1e-6
            n_obs += 1
        # every image that sees the point is listed
        seen = [im.name for im in scene.orientation.images if scene.visibility(g.xyz, im.name)[0][0]]
        assert seen == [o[0] for o in g.observations]
    # ground GCPs lie on the surface
    for g in gcps:
        assert abs(scene.height(g.xyz[None, :2])[0] - g.xyz[2]) < 1e-9
    assert n_obs > 20


def test_roof_pixel_has_roof_texture(scene):
    b_idx = next(k for k, b in enumerate(scene.surface.buildings) if b.roof == "flat" and not b.tower)
    b = scene.surface.buildings[b_idx]
    P = np.array([b.center[0] + 0.3, b.center[1] - 0.2, b.eave_top]) + scene.offset
    for i in range(scene.n_nadir):
        vis, uv, _ = scene.visibility(P, i)
        if vis[0]:
            break
    else:
        pytest.fail("the roof point is seen by no nadir image")
    px = np.round(uv[0])
    hit, mat, bid = scene.cast(i, px[None])
    assert mat[0] == ROOF and bid[0] == b_idx
    assert abs(hit[0, 2] - (b.eave_top + scene.offset[2])) < 1e-6
    truth_rgb = scene.colour(hit, ROOF, b_idx)[0]
    r = scene.render(i, supersample=1)
    c, rr = int(px[0]), int(px[1])
    assert np.abs(r.colour[rr, c] - truth_rgb).max() < 1e-5
    # the radiometric image differs only by gain, offset, vignetting and noise
    rad = scene.radiometry[i]
    assert np.all(np.abs(rad.gain - 1) < 0.5)
    img = scene.images[i][rr, c].astype(float)
    expected = (truth_rgb * rad.gain + rad.offset) * 255
    assert np.abs(img - expected).max() < 0.2 * 255 * rad.vignetting + 6 * rad.noise_sigma + 1
    # and the roof texture is distinct from the wall and the ground at the same place
    lab = srgb_to_lab(truth_rgb)
    assert np.linalg.norm(lab - srgb_to_lab(scene.colour(hit, WALL, b_idx)[0])) > 10
    assert np.linalg.norm(lab - srgb_to_lab(scene.colour(hit, GROUND, -1)[0])) > 10


def test_occlusion_behind_tower(scene):
    k_tower = next(k for k, b in enumerate(scene.surface.buildings) if b.tower)
    tower = scene.surface.buildings[k_tower]
    for i in range(scene.n_nadir, len(scene.orientation.images)):
        im = scene.image(i)
        M = np.array([tower.center[0], tower.center[1], tower.base + 0.5 * (tower.eave_top - tower.base)])
        d = (M - im.C) / np.linalg.norm(M - im.C)
        # continue the ray beyond the far side of the tower down to the ground
        start = M + d * (tower.radius + 0.5) / np.hypot(d[0], d[1])
        t, mat, _ = cast_rays(scene.surface, start, d[None])
        if mat[0] != GROUND:
            continue
        G = start + t[0] * d + scene.offset
        vis, uv, hit_dist = scene.visibility(G, i)
        assert not vis[0]
        assert hit_dist[0] < np.linalg.norm(G - scene.offset - im.C) - 1.0
        # the front wall point on the same ray is visible
        Wp = scene.cast(i, uv)[0]
        assert scene.visibility(Wp, i)[0][0]
        # the pixel shows the tower (wall), not the ground
        px = np.round(uv[0])
        hit, mat, bid = scene.cast(i, px[None])
        assert mat[0] == WALL and bid[0] == k_tower
        r = scene.render(i, supersample=1)
        c, rr = int(px[0]), int(px[1])
        assert r.material[rr, c] == WALL and r.building[rr, c] == k_tower
        assert np.abs(r.colour[rr, c] - scene.colour(hit, WALL, k_tower)[0]).max() < 1e-5
        assert r.depth[rr, c] < np.linalg.norm(G - scene.offset - im.C) * 0.95
        return
    pytest.fail("no oblique image sees ground behind the tower")


def _roof_height(b, xy):
    u, v = b.to_uv(xy)[0]
    a, w = b.half_size
    prof = {
        "flat": 0.0,
        "gable": 1 - abs(v) / w,
        "hip": min(1 - abs(v) / w, (a - abs(u)) / w),
        "shed": (v + w) / (2 * w),
    }[b.roof]
    return b.eave_top + b.ridge * prof


def test_dsm_building_heights(scene):
    res = 0.25
    dsm, gt = scene.dsm(res)
    x0, r, _, y1, _, mr = gt
    assert r == res and mr == -res and dsm.dtype == np.float32
    assert (x0, y1) == (scene.extent_world()[0], scene.extent_world()[3])
    assert dsm.shape == (400, 480)
    shapes = set()
    for b in scene.surface.buildings:
        col = int((b.center[0] + scene.offset[0] - x0) // res)
        row = int((y1 - (b.center[1] + scene.offset[1])) // res)
        xy = np.array([[x0 + (col + 0.5) * res, y1 - (row + 0.5) * res]]) - scene.offset[:2]
        expected = _roof_height(b, xy) + scene.offset[2]
        assert abs(dsm[row, col] - expected) < 1e-3
        assert dsm[row, col] > scene.surface.terrain(xy)[0] + 3.0
        shapes.add(b.roof)
    assert shapes == {"flat", "gable", "hip", "shed"}
    tower = next(b for b in scene.surface.buildings if b.tower)
    assert tower.top - tower.base >= 30
    # walls are vertical: the DSM jumps by the wall height within one cell across a footprint edge
    edge_mid = tower.from_uv([[tower.half_size[0] - 1e-3, 0.0], [tower.half_size[0] + 1e-3, 0.0]])
    h, bid = scene.surface.height(edge_mid)
    assert bid[0] >= 0 and bid[1] == -1 and h[0] - h[1] > 25


def test_orthophoto_is_vertical_view(scene):
    ortho, gt = scene.orthophoto(0.5)
    assert ortho.dtype == np.uint8 and ortho.shape == (200, 240, 3)
    rgbf, _ = scene.orthophoto(0.5, as_uint8=False)
    x0, res, _, y1, _, _ = gt
    # a cell on the tower roof has the tower roof colour
    tower_k = next(k for k, b in enumerate(scene.surface.buildings) if b.tower)
    tw = scene.surface.buildings[tower_k]
    col = int((tw.center[0] + scene.offset[0] - x0) // res)
    row = int((y1 - (tw.center[1] + scene.offset[1])) // res)
    P = np.array([x0 + (col + 0.5) * res, y1 - (row + 0.5) * res, tw.eave_top + scene.offset[2]])
    assert np.allclose(rgbf[row, col], scene.colour(P, ROOF, tower_k)[0], atol=1e-6)


def test_base_colours_are_far_apart():
    groups = [np.array(GROUND_RGB), np.array(ROOF_RGB), np.array(WALL_RGB)]
    labs = [srgb_to_lab(g) for g in groups]
    for i in range(3):
        for j in range(i + 1, 3):
            d = np.linalg.norm(labs[i][:, None, :] - labs[j][None, :, :], axis=2)
            assert d.min() > 25


def test_pixel_rays_hit_where_points_project(scene):
    # ray casting and projection agree: the hit of a pixel's ray projects back onto the pixel
    rng = np.random.default_rng(0)
    for i in (0, scene.n_nadir):
        im = scene.image(i)
        uv = rng.uniform([0, 0], [scene.camera.width - 1, scene.camera.height - 1], (200, 2))
        hit, mat, _ = scene.cast(i, uv)
        ok = mat >= 0
        back = project_points(hit[ok] - scene.offset, im.R, im.C, scene.camera)
        assert np.abs(back - uv[ok]).max() < 1e-5
        C, d = pixel_to_ray(uv[ok], im.R, im.C, scene.camera)
        dist = np.linalg.norm(hit[ok] - scene.offset - C, axis=1)
        assert np.all(scene.visibility(hit[ok], i, tol=1e-4)[0])
        assert np.all(dist > 50)


def test_write(scene, tmp_path):
    out = scene.write(tmp_path / "ds")
    o = Orientation.load(out / "orientation.json")
    assert len(o.images) == len(scene.images)
    o.check_images_exist()
    import cv2

    img = cv2.imread(str(out / "img_003.png"), cv2.IMREAD_COLOR)[:, :, ::-1]
    assert np.array_equal(img, scene.images[3])
    lines = (out / "gcp_list.txt").read_text().splitlines()
    assert lines[0] == "EPSG:32632"
    assert len(lines) - 1 == sum(len(g.observations) for g in scene.orientation.gcps)
    f = lines[1].split()
    g = scene.orientation.gcps[0]
    assert np.allclose([float(v) for v in f[:3]], g.xyz, atol=1e-5) and f[5] == g.observations[0][0]
    rasterio = pytest.importorskip("rasterio")
    with rasterio.open(out / "dsm.tif") as ds:
        assert ds.crs.to_epsg() == 32632 and ds.nodata == -9999
        assert ds.transform.c == scene.extent_world()[0] and ds.transform.f == scene.extent_world()[3]
        dsm = ds.read(1)
    assert np.array_equal(dsm, scene.dsm(scene.config.gsd)[0])
    with rasterio.open(out / "ortho.tif") as ds:
        assert ds.count == 3 and ds.nodata == 0 and ds.crs.to_epsg() == 32632
    assert not [p for p in out.iterdir() if ".tmp" in p.name]


def test_invalid_config():
    with pytest.raises(InputError, match="extent"):
        SceneConfig(extent=(0.0, 0.0, 5.0, 5.0))
    with pytest.raises(InputError, match="forward_overlap"):
        SceneConfig(forward_overlap=1.2)
    with pytest.raises(InputError, match="could not place"):
        make_scene(SceneConfig(extent=(0.0, 0.0, 30.0, 30.0), n_buildings=20))


def test_harder_appearance_options(tmp_path):
    """Shadows (images and truth alike), JPEG artefacts, low-contrast roofs and facade windows."""
    plain = make_scene(_small(noise_sigma=0.0, vignetting=0.0, gain_sigma=0.0, offset_sigma=0.0))
    hard = make_scene(
        _small(
            noise_sigma=0.0,
            vignetting=0.0,
            gain_sigma=0.0,
            offset_sigma=0.0,
            jpeg_quality=60,
            shadow_strength=0.5,
            sun_elevation_deg=30.0,
            roof_contrast=(0.0, 0.0),
            facade_windows=True,
        )
    )
    # the same cameras; a JPEG block's images are JPEG files (img_NNN.jpg), the plain one's PNGs
    assert [im.name for im in hard.orientation.images] == [
        im.name[:-4] + ".jpg" for im in plain.orientation.images
    ]
    as_png = json.dumps(hard.orientation.to_dict()).replace(".jpg", ".png")
    assert as_png == json.dumps(plain.orientation.to_dict())
    # truth orthophoto: shadowed cells are exactly half as bright, lit cells unchanged
    a, _ = plain.orthophoto(0.5, as_uint8=False)
    b, _ = hard.orthophoto(0.5, as_uint8=False)
    ratio = b.sum(-1) / np.maximum(a.sum(-1), 1e-9)
    lit = np.isclose(ratio, 1.0, atol=1e-6)
    dark = np.isclose(ratio, 0.5, atol=1e-6)
    assert 0.05 < dark.mean() < 0.6 and (lit | dark).mean() > 0.7
    X, Y = np.meshgrid(np.arange(a.shape[1]), np.arange(a.shape[0]))
    _, bid = hard.surface.height(np.column_stack([
        hard.extent_world()[0] - hard.offset[0] + (X.ravel() + 0.5) * 0.5,
        hard.extent_world()[3] - hard.offset[1] - (Y.ravel() + 0.5) * 0.5]))  # fmt: skip
    roofs = (bid >= 0).reshape(a.shape[:2])
    # ground: only lit or shadowed; roofs also lose their texture (contrast 0) and are uniform
    assert roofs.any() and (lit | dark)[~roofs].all()
    for b_id in np.unique(bid[bid >= 0]):
        cells = (bid.reshape(a.shape[:2]) == b_id) & lit
        if cells.sum() > 4:
            assert b[cells].std(axis=0).max() < 1e-6  # a uniform roof (no texture)
    # images: JPEG changes the digital numbers a little, not the content
    rendered = hard.render(0, radiometry=True)
    assert np.array_equal(rendered, hard.images[0])
    noise_free = hard.render(0)
    ref = np.round(noise_free.colour * 255)
    diff = np.abs(hard.images[0].astype(float) - ref)
    assert 0.2 < diff.mean() < 15.0  # quality 60 on a fine texture
    assert np.corrcoef(hard.images[0].ravel(), ref.ravel())[0, 1] > 0.9
    # write() stores the JPEG files as they are: decoded, they are the scene's images
    import cv2

    folder = tmp_path / "hard"
    hard.write(folder)
    assert len(hard.jpeg_files) == len(hard.images)
    first = folder / hard.orientation.images[0].name
    assert first.read_bytes()[:2] == b"\xff\xd8" and first.read_bytes() == hard.jpeg_files[0]
    assert np.array_equal(cv2.imread(str(first), cv2.IMREAD_COLOR)[:, :, ::-1], hard.images[0])
    assert not plain.jpeg_files
    # windows: wall pixels of the hard scene hold many very dark pixels, the plain scene's none
    wall = noise_free.material == WALL
    if wall.sum() > 50:
        assert (noise_free.colour[wall].max(-1) < 0.2).mean() > 0.05


def test_sun_vector_points_to_the_sun():
    from truortho.core.synthetic.render import sun_vector

    s = sun_vector(90.0, 30.0, 0.4)  # east, 30 degrees up
    assert np.allclose(s, [math.cos(math.radians(30)), 0.0, 0.5, 0.4], atol=1e-12)
    with pytest.raises(InputError, match="jpeg_quality"):
        _small(jpeg_quality=101)
    with pytest.raises(InputError, match="shadow_strength"):
        _small(shadow_strength=1.5)


def _radiometry_reference(colour, camera, radiometry):
    """The vectorised formula of the module docstring, as numpy evaluates it."""
    H, W = colour.shape[:2]
    xs, ys = np.meshgrid(np.arange(W) - camera.cx, np.arange(H) - camera.cy)
    corner = max(
        np.hypot(cx, cy)
        for cx in (-0.5 - camera.cx, W - 0.5 - camera.cx)
        for cy in (-0.5 - camera.cy, H - 0.5 - camera.cy)
    )
    vig = 1.0 - radiometry.vignetting * (np.hypot(xs, ys) / corner) ** 2
    val = (colour.astype(np.float64) * radiometry.gain + radiometry.offset) * vig[:, :, None] * 255.0
    if radiometry.noise_sigma > 0:
        val += np.random.default_rng(radiometry.noise_seed).normal(0.0, radiometry.noise_sigma, val.shape)
    return np.clip(np.round(val), 0, 255).astype(np.uint8)


@pytest.mark.parametrize("noise", [0.0, 2.5])
def test_apply_radiometry_equals_the_vectorised_formula(noise):
    """The compiled pass gives exactly the digital numbers of the formula (values below 0 and above
    1, an off-centre principal point, exact halves rounded to even)."""
    from truortho.core.synthetic.cameras import make_camera
    from truortho.core.synthetic.render import Radiometry, apply_radiometry

    rng = np.random.default_rng(5)
    cam = make_camera(203, 151, 180.0, (3.3, -2.1))
    colour = rng.uniform(-0.1, 1.1, (151, 203, 3)).astype(np.float32)
    rad = Radiometry(np.array([1.05, 0.93, 1.2]), np.array([0.01, -0.02, 0.0]), 0.3, noise, 77)
    assert np.array_equal(apply_radiometry(colour, cam, rad), _radiometry_reference(colour, cam, rad))
    # DNs exactly half-way (offsets x / 255 with x = 126.5, 127.5, 2.5) are rounded to even, as
    # np.round does (half up would give 127, 128, 3)
    flat = make_camera(8, 1, 8.0)
    halves = Radiometry(np.ones(3), np.array([126.5, 127.5, 2.5]) / 255.0, 0.0, 0.0, 0)
    dn = apply_radiometry(np.zeros((1, 8, 3), np.float32), flat, halves)
    assert (dn == np.array([126, 128, 2], np.uint8)).all()
    plain = Radiometry(np.ones(3), np.zeros(3), 0.0, 0.0, 0)
    with pytest.raises(InputError, match="apply_radiometry"):
        apply_radiometry(np.zeros((4, 4)), flat, plain)


def test_crop_fields_look_different_from_every_direction():
    """In a field the ground's colour depends on the direction the photo looks from (the stalk layer
    is crossed elsewhere by each ray); outside one, and with no fields at all, it does not."""
    from truortho.core.synthetic.texture import _colour, _field, palette, texture_params

    pal = palette(1)
    seed = 3
    fields = texture_params(seed, 0.15, 5, 2.6, crop_share=0.5, crop_height=0.3)
    none = texture_params(seed, 0.15, 5, 2.6)
    rng = np.random.default_rng(0)
    pts = rng.uniform(0.0, 200.0, (400, 2))
    inside = np.array([_field(x, y, seed, 0.5) for x, y in pts])
    assert 0.2 < inside.mean() < 0.8  # about the share asked for, in patches
    views = [(0.0, 0.0), (0.4, 0.1), (-0.3, 0.5)]  # horizontal travel per metre up: nadir, obliques

    def colours(tex, x, y):
        return np.array([_colour(x, y, 10.0, GROUND, -1, pal, tex, vx, vy) for vx, vy in views])

    changed = [np.abs(colours(fields, x, y) - colours(fields, x, y)[0]).max() > 1e-3 for x, y in pts]
    changed = np.array(changed)
    assert changed[inside].mean() > 0.2  # some stalk or soil point differs from another view
    assert not changed[~inside].any()
    for x, y in pts[:50]:
        c = colours(none, x, y)
        assert np.array_equal(c, np.repeat(c[:1], len(views), axis=0))
    # a field is nearly uniform straw: little contrast, whatever the view
    field_rgb = np.array([colours(fields, x, y) for x, y in pts[inside]]).reshape(-1, 3)
    assert field_rgb.std(axis=0).max() < 0.05
    with pytest.raises(InputError, match="crop_share"):
        SceneConfig(crop_share=1.5)
    with pytest.raises(InputError, match="crop_height"):
        SceneConfig(crop_height=-0.1)


def test_optics_blur_softens_the_images_only():
    """The optics' point spread removes fine detail from the photos and keeps their mean; the
    geometry and the truth do not change."""
    kw = dict(noise_sigma=0.0, vignetting=0.0, gain_sigma=0.0, offset_sigma=0.0, jpeg_quality=0)
    sharp = make_scene(_small(**kw))
    soft = make_scene(_small(optics_blur=1.5, **kw))
    a = sharp.images[0].astype(float)
    b = soft.images[0].astype(float)
    assert abs(a.mean() - b.mean()) < 1.0
    hf = [np.abs(np.diff(x, axis=1)).mean() for x in (a, b)]
    assert hf[1] < 0.6 * hf[0]
    assert np.array_equal(soft.render(0, radiometry=True), soft.images[0])
    assert json.dumps(soft.orientation.to_dict()) == json.dumps(sharp.orientation.to_dict())
    ta, _ = sharp.orthophoto(0.5, as_uint8=False)
    tb, _ = soft.orthophoto(0.5, as_uint8=False)
    assert np.array_equal(ta, tb)
    with pytest.raises(InputError, match="optics_blur"):
        SceneConfig(optics_blur=-1.0)


def test_crop_heights_and_their_inputs():
    """The stalk layer's height per cell: crop_height in the fields, 0 on roofs, elsewhere and in a
    scene without fields; bad inputs of the helpers say what was expected."""
    from truortho.core.synthetic.scene import optics_blur
    from truortho.core.synthetic.texture import field_mask

    kw = dict(noise_sigma=0.0, jpeg_quality=0)
    crops = make_scene(_small(crop_share=0.5, crop_height=0.4, **kw))
    h = crops.crop_heights(0.5)
    rgb, _ = crops.orthophoto(0.5)
    assert h.shape == rgb.shape[:2]
    assert set(np.unique(h)) <= {0.0, 0.4} and 0.1 < (h > 0).mean() < 0.9
    assert not make_scene(_small(**kw)).crop_heights(0.5).any()
    with pytest.raises(InputError, match="field_mask"):
        field_mask(np.zeros((3, 3)), 1, 0.5)
    with pytest.raises(InputError, match="share"):
        field_mask(np.zeros((3, 2)), 1, 1.5)
    with pytest.raises(InputError, match="sigma"):
        optics_blur(np.zeros((4, 4, 3)), float("nan"))
    with pytest.raises(InputError, match="colours"):
        optics_blur(np.zeros((4, 4)), 1.0)
