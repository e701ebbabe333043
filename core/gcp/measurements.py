"""Image measurements of ground control points: the model behind the GCP panel.

QGIS-free. A :class:`MeasurementSet` holds the GCPs (:class:`GroundPoint`), the
images of one folder (:class:`Photo`) and at most one measurement per GCP and
image (:class:`Measurement`). Changes go through :meth:`MeasurementSet.place`,
:meth:`~MeasurementSet.delete` and :meth:`~MeasurementSet.replace_all`, which
validate first and are recorded on an undo/redo stack.

Given an orientation, :func:`predict` projects every GCP into every oriented
image with the camera model of :mod:`truortho.core.geometry.camera` and keeps
the projections that fall in the frame, in front of the camera and inside the
field where the distortion model is invertible.

Files
-----
* **Observation table** (CSV, UTF-8, comma separated, header line)::

      gcp,image,x,y,sigma_x,sigma_y,source

  ``gcp``, ``image``, ``x``, ``y`` are required (the fields the Processing
  algorithms read from an observation table); ``sigma_x``, ``sigma_y`` (pixels,
  may be empty) and ``source`` are optional. A ``.csvt`` sidecar gives OGR the
  column types, so QGIS opens the table with numeric ``x``/``y``.
* **ODM** ``gcp_list.txt`` through :mod:`truortho.core.formats.gcplist`.

Pixels: ``(x, y)`` = (column, row) of the image as stored, the centre of the
top-left pixel is (0, 0); an image of ``W x H`` pixels spans
``[-0.5, W - 0.5] x [-0.5, H - 0.5]`` (:mod:`truortho.core.geometry`).
Every file is written to a temporary file and renamed, so a failed save leaves
the previous file as it was.
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..errors import FormatError, InputError
from ..orientation import GCP, Orientation, atomic_write_text, isotropic_sigma

#: Where a measurement came from.
SOURCES = ("manual", "predicted", "detected", "refined")
#: State of one GCP x image cell.
NONE, PREDICTED, MEASURED = "none", "predicted", "measured"
#: Image file extensions listed from a folder (case-insensitive).
IMAGE_EXTENSIONS = (".jpg", ".jpeg", ".png", ".tif", ".tiff", ".jp2", ".bmp")
#: Columns of the observation table; the first four are required.
CSV_FIELDS = ("gcp", "image", "x", "y", "sigma_x", "sigma_y", "source")
_CSVT = '"String","String","Real","Real","Real","Real","String"\n'


@dataclass(frozen=True)
class GroundPoint:
    """A GCP or check point.

    Attributes
    ----------
    name : str
    xyz : (3,) tuple of float
        World coordinates in ``crs`` (metres for projected CRSs).
    crs : str or None
        CRS text (``EPSG:nnnn``, WKT or PROJ); None = the orientation's CRS.
    check : bool
        A check point (not used as control).
    """

    name: str
    xyz: tuple[float, float, float]
    crs: str | None = None
    check: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip() or self.name != self.name.strip():
            raise InputError(f"GCP name {self.name!r}: expected a non-empty name without surrounding blanks")
        xyz = tuple(float(v) for v in np.asarray(self.xyz, dtype=np.float64).reshape(-1))
        if len(xyz) != 3 or not all(math.isfinite(v) for v in xyz):
            raise InputError(f"GCP {self.name!r}: coordinates must be 3 finite numbers, got {self.xyz!r}")
        object.__setattr__(self, "xyz", xyz)


@dataclass(frozen=True)
class Photo:
    """An image of the folder: file name, full path and stored size in pixels."""

    name: str
    path: str
    width: int
    height: int

    def contains(self, x: float, y: float) -> bool:
        """True when pixel ``(x, y)`` lies on the image (``[-0.5, W - 0.5] x [-0.5, H - 0.5]``)."""
        return -0.5 <= x <= self.width - 0.5 and -0.5 <= y <= self.height - 0.5


@dataclass(frozen=True)
class Measurement:
    """One image measurement of one GCP.

    Attributes
    ----------
    gcp, image : str
        GCP name and image file name.
    x, y : float
        Pixel position (centre of the top-left pixel = (0, 0)).
    sigma_x, sigma_y : float or None
        Standard deviations in pixels; None = the adjustment's default.
    source : str
        One of :data:`SOURCES`.
    """

    gcp: str
    image: str
    x: float
    y: float
    sigma_x: float | None = None
    sigma_y: float | None = None
    source: str = "manual"


@dataclass(frozen=True)
class Prediction:
    """Where a GCP is expected in an image: pixel ``(x, y)`` and its depth in metres."""

    gcp: str
    image: str
    x: float
    y: float
    depth: float


# ---------------------------------------------------------------------- images


def list_images(folder: str | os.PathLike) -> list[Photo]:
    """The images directly inside ``folder`` (sorted by name) with their stored sizes.

    Raises
    ------
    InputError
        ``folder`` is not a folder or holds no image.
    FormatError
        An image file cannot be read.
    """
    from ..imagery import image_info

    p = Path(folder)
    if not p.is_dir():
        raise InputError(f"image folder {str(p)!r} is not a folder")
    photos = []
    for entry in sorted(p.iterdir(), key=lambda e: e.name):
        if entry.is_file() and entry.suffix.lower() in IMAGE_EXTENSIONS and not entry.name.startswith("."):
            info = image_info(entry)
            photos.append(Photo(entry.name, str(entry), info.width, info.height))
    if not photos:
        raise InputError(f"image folder {str(p)!r} holds no image ({', '.join(IMAGE_EXTENSIONS)})")
    return photos


# ---------------------------------------------------------------------- prediction


def _orientation_image_names(orientation: Orientation) -> dict[str, int]:
    """Image file name -> index in the orientation (by name, else by the base name of its path)."""
    out: dict[str, int] = {}
    for i, im in enumerate(orientation.images):
        out.setdefault(im.name, i)
    for i, im in enumerate(orientation.images):
        base = os.path.basename((im.path or im.name).replace("\\", "/"))
        out.setdefault(base, i)
    return out


def _world_in(orientation: Orientation, gcps: Sequence[GroundPoint]) -> np.ndarray:
    """(N, 3) GCP coordinates in the orientation's CRS (plan reprojected, heights kept)."""
    from ..geometry.frame import parse_crs, transform_points

    xyz = np.array([g.xyz for g in gcps], dtype=np.float64).reshape(-1, 3)
    target = orientation.crs
    for crs in {g.crs for g in gcps if g.crs}:
        if target is None:
            raise InputError(
                f"the GCPs are in {crs[:40]!r} but the orientation has no CRS: their image positions "
                "cannot be predicted"
            )
        src, dst = parse_crs(crs), parse_crs(target)
        if src.equals(dst, ignore_axis_order=True):
            continue
        rows = [i for i, g in enumerate(gcps) if g.crs == crs]
        moved = transform_points(xyz[rows], src, dst)
        xyz[rows, :2] = moved[:, :2]
    return xyz


def predict(
    orientation: Orientation, gcps: Sequence[GroundPoint], photos: Sequence[Photo] | None = None
) -> list[Prediction]:
    """Pixel positions of GCPs in the oriented images that see them.

    Parameters
    ----------
    orientation : Orientation
        Cameras and exterior orientations (local frame, :mod:`truortho.core.geometry`).
    gcps : sequence of GroundPoint
        World coordinates; reprojected in plan to the orientation's CRS when theirs differs.
    photos : sequence of Photo, optional
        When given, only images of this list (matched by file name) are predicted, and the
        frame test uses the stored size of the file (which must equal the camera's).

    Returns
    -------
    list of Prediction
        One per GCP and image where the GCP is in front of the camera (depth > 0), inside
        the frame ``[-0.5, W - 0.5] x [-0.5, H - 0.5]`` and where the distortion model
        maps back to the same ray (a strong distortion folds far-away points into the frame;
        those are dropped). Ordered by GCP, then by image as in the orientation.

    Raises
    ------
    InputError
        No CRS to reproject the GCPs into; an image whose file size differs from its camera.
    """
    from ..geometry.camera import project_points, undistort_points

    if not gcps:
        return []
    local = orientation.frame.to_local(_world_in(orientation, gcps))
    index = _orientation_image_names(orientation)
    if photos is None:
        targets = [(im.name, i) for i, im in enumerate(orientation.images)]
        sizes: dict[str, tuple[int, int]] = {}
    else:
        targets = [(p.name, index[p.name]) for p in photos if p.name in index]
        sizes = {p.name: (p.width, p.height) for p in photos}
    found: list[list[Prediction]] = [[] for _ in gcps]
    for name, i in targets:
        im = orientation.images[i]
        cam = orientation.camera_of(im)
        w, h = sizes.get(name, (cam.width, cam.height))
        if (w, h) != (cam.width, cam.height):
            raise InputError(
                f"image {name!r} is {w} x {h} pixels but its camera {cam.id!r} in the orientation is "
                f"{cam.width} x {cam.height}: the orientation does not belong to these images"
            )
        uv, depth = project_points(local, im.R, im.C, cam, return_depth=True)
        ok = (depth > 0) & np.all(np.isfinite(uv), axis=1)
        ok &= (uv[:, 0] >= -0.5) & (uv[:, 0] <= w - 0.5) & (uv[:, 1] >= -0.5) & (uv[:, 1] <= h - 0.5)
        if cam.has_distortion and np.any(ok):
            cam_xyz = (local[ok] - im.C) @ im.R.T
            norm = cam_xyz[:, :2] / cam_xyz[:, 2:3]
            back = undistort_points(uv[ok], cam)
            tol = 1e-6 * (1.0 + np.abs(norm))
            same = np.all(np.abs(back - norm) <= tol, axis=1)
            ok[np.flatnonzero(ok)[~same]] = False
        for k in np.flatnonzero(ok):
            found[k].append(Prediction(gcps[k].name, name, float(uv[k, 0]), float(uv[k, 1]), float(depth[k])))
    return [p for per_gcp in found for p in per_gcp]


# ---------------------------------------------------------------------- the model


_Key = tuple[str, str]
_Change = tuple[_Key, Measurement | None, Measurement | None]


class MeasurementSet:
    """GCP measurements in the images of one folder, with undo/redo.

    Parameters
    ----------
    gcps : sequence of GroundPoint
        Unique names.
    photos : sequence of Photo
        Unique file names (:func:`list_images`).

    Every change is validated before anything is modified (unknown GCP, image not in the
    folder, a position outside the image, a bad sigma or source raise :class:`InputError`
    and leave the set as it was) and is recorded as one undoable command.
    """

    def __init__(self, gcps: Sequence[GroundPoint], photos: Sequence[Photo]) -> None:
        self._gcps = tuple(gcps)
        self._photos = tuple(photos)
        self._gcp_by = {g.name: g for g in self._gcps}
        self._photo_by = {p.name: p for p in self._photos}
        if len(self._gcp_by) != len(self._gcps):
            raise InputError("GCP names must be unique")
        if len(self._photo_by) != len(self._photos):
            raise InputError("image names must be unique")
        self._data: dict[_Key, Measurement] = {}
        self._predictions: dict[_Key, Prediction] = {}
        self._undo: list[tuple[str, list[_Change]]] = []
        self._redo: list[tuple[str, list[_Change]]] = []
        self.revision = 0  #: increases with every change, undo and redo

    # ------------------------------------------------------------ access
    @property
    def gcps(self) -> tuple[GroundPoint, ...]:
        return self._gcps

    @property
    def photos(self) -> tuple[Photo, ...]:
        return self._photos

    def gcp(self, name: str) -> GroundPoint:
        """The GCP called ``name``; :class:`InputError` naming the known ones otherwise."""
        try:
            return self._gcp_by[name]
        except KeyError:
            known = ", ".join(list(self._gcp_by)[:10]) + (", ..." if len(self._gcp_by) > 10 else "")
            raise InputError(f"unknown GCP {name!r}: it is not in the GCP layer (known: {known})") from None

    def photo(self, name: str) -> Photo:
        """The image file called ``name``; :class:`InputError` otherwise."""
        try:
            return self._photo_by[name]
        except KeyError:
            raise InputError(f"image {name!r} is not in the image folder") from None

    def get(self, gcp: str, image: str) -> Measurement | None:
        return self._data.get((gcp, image))

    def prediction(self, gcp: str, image: str) -> Prediction | None:
        return self._predictions.get((gcp, image))

    def state(self, gcp: str, image: str) -> str:
        """:data:`MEASURED`, :data:`PREDICTED` or :data:`NONE`."""
        if (gcp, image) in self._data:
            return MEASURED
        if (gcp, image) in self._predictions:
            return PREDICTED
        return NONE

    def measurements(self) -> list[Measurement]:
        """All measurements, by GCP then image in the order of the set."""
        gi = {g.name: k for k, g in enumerate(self._gcps)}
        pi = {p.name: k for k, p in enumerate(self._photos)}
        return sorted(self._data.values(), key=lambda m: (gi[m.gcp], pi[m.image]))

    def __len__(self) -> int:
        return len(self._data)

    def images_of(self, gcp: str) -> list[str]:
        """Images where ``gcp`` is measured or predicted, in folder order."""
        return [p.name for p in self._photos if self.state(gcp, p.name) != NONE]

    def counts(self, gcp: str) -> tuple[int, int]:
        """(measured, predicted but not measured) images of ``gcp``."""
        states = [self.state(gcp, p.name) for p in self._photos]
        return states.count(MEASURED), states.count(PREDICTED)

    # ------------------------------------------------------------ predictions
    def set_predictions(self, predictions: Iterable[Prediction]) -> None:
        """Replace the predictions (not an undoable change; unknown GCPs/images are ignored)."""
        self._predictions = {
            (p.gcp, p.image): p for p in predictions if p.gcp in self._gcp_by and p.image in self._photo_by
        }
        self.revision += 1

    def predict_from(self, orientation: Orientation) -> int:
        """Predict every GCP in every image from ``orientation``; returns the number of predictions."""
        self.set_predictions(predict(orientation, self._gcps, self._photos))
        return len(self._predictions)

    # ------------------------------------------------------------ changes
    def validated(self, m: Measurement) -> Measurement:
        """``m`` checked against the set (GCP, image, bounds, sigmas, source), numbers as floats."""
        self.gcp(m.gcp)
        photo = self.photo(m.image)
        try:
            x, y = float(m.x), float(m.y)
        except (TypeError, ValueError):
            raise InputError(f"GCP {m.gcp!r} on {m.image!r}: x and y must be numbers") from None
        if not (math.isfinite(x) and math.isfinite(y)) or not photo.contains(x, y):
            raise InputError(
                f"GCP {m.gcp!r}: pixel ({x:.2f}, {y:.2f}) is outside the image {m.image!r} "
                f"({photo.width} x {photo.height} pixels, x in [-0.5, {photo.width - 0.5}], "
                f"y in [-0.5, {photo.height - 0.5}])"
            )
        sig = []
        for what, s in (("sigma_x", m.sigma_x), ("sigma_y", m.sigma_y)):
            if s is not None:
                s = float(s)
                if not (math.isfinite(s) and s > 0):
                    raise InputError(
                        f"GCP {m.gcp!r} on {m.image!r}: {what} must be a positive number, got {s}"
                    )
            sig.append(s)
        if m.source not in SOURCES:
            raise InputError(
                f"GCP {m.gcp!r} on {m.image!r}: source must be one of {SOURCES}, got {m.source!r}"
            )
        return replace(m, x=x, y=y, sigma_x=sig[0], sigma_y=sig[1])

    def place(
        self,
        gcp: str,
        image: str,
        x: float,
        y: float,
        sigma_x: float | None = None,
        sigma_y: float | None = None,
        source: str = "manual",
    ) -> Measurement:
        """Place (or move) the measurement of ``gcp`` on ``image`` at pixel ``(x, y)``; undoable."""
        m = self.validated(Measurement(gcp, image, x, y, sigma_x, sigma_y, source))
        old = self._data.get((gcp, image))
        label = "move" if old is not None else "place"
        if old != m:
            self._apply(f"{label} {gcp} on {image}", [((gcp, image), old, m)])
        return m

    def delete(self, gcp: str, image: str) -> bool:
        """Remove the measurement of ``gcp`` on ``image``; False when there was none. Undoable."""
        self.gcp(gcp)
        self.photo(image)
        old = self._data.get((gcp, image))
        if old is None:
            return False
        self._apply(f"delete {gcp} on {image}", [((gcp, image), old, None)])
        return True

    def place_many(self, measurements: Iterable[Measurement], label: str = "place") -> int:
        """Place (or move) several measurements as one undoable command; returns how many changed.

        All are validated first: one invalid measurement raises :class:`InputError` and changes nothing.
        """
        new: dict[_Key, Measurement] = {}
        for m in measurements:
            v = self.validated(m)
            new[(v.gcp, v.image)] = v
        changes: list[_Change] = [(k, self._data.get(k), m) for k, m in new.items() if self._data.get(k) != m]
        if changes:
            self._apply(label, changes)
        return len(changes)

    def replace_all(self, measurements: Iterable[Measurement], label: str = "load") -> None:
        """Replace every measurement by ``measurements`` as one undoable command.

        All are validated first; a duplicate (GCP, image) or any invalid one raises
        :class:`InputError` and changes nothing.
        """
        new: dict[_Key, Measurement] = {}
        for m in measurements:
            v = self.validated(m)
            key = (v.gcp, v.image)
            if key in new:
                raise InputError(f"GCP {v.gcp!r} is measured twice on image {v.image!r}")
            new[key] = v
        changes: list[_Change] = [(k, old, new.get(k)) for k, old in self._data.items() if new.get(k) != old]
        changes += [(k, None, m) for k, m in new.items() if k not in self._data]
        if changes:
            self._apply(label, changes)

    def _apply(self, label: str, changes: list[_Change]) -> None:
        self._set(changes, after=True)
        self._undo.append((label, changes))
        self._redo.clear()

    def _set(self, changes: list[_Change], after: bool) -> None:
        for key, before, later in changes:
            value = later if after else before
            if value is None:
                self._data.pop(key, None)
            else:
                self._data[key] = value
        self.revision += 1

    # ------------------------------------------------------------ undo / redo
    @property
    def can_undo(self) -> bool:
        return bool(self._undo)

    @property
    def can_redo(self) -> bool:
        return bool(self._redo)

    def clear_history(self) -> None:
        """Forget the undo/redo stack (the measurements stay)."""
        self._undo.clear()
        self._redo.clear()

    def undo_label(self) -> str | None:
        return self._undo[-1][0] if self._undo else None

    def redo_label(self) -> str | None:
        return self._redo[-1][0] if self._redo else None

    def undo(self) -> bool:
        """Undo the last command; False when there is none."""
        if not self._undo:
            return False
        label, changes = self._undo.pop()
        self._set(changes, after=False)
        self._redo.append((label, changes))
        return True

    def redo(self) -> bool:
        """Redo the last undone command; False when there is none."""
        if not self._redo:
            return False
        label, changes = self._redo.pop()
        self._set(changes, after=True)
        self._undo.append((label, changes))
        return True

    # ------------------------------------------------------------ files
    def to_csv_text(self) -> str:
        """The observation table as CSV text (see the module docstring)."""
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(CSV_FIELDS)
        for m in self.measurements():
            w.writerow([m.gcp, m.image, _num(m.x), _num(m.y), _num(m.sigma_x), _num(m.sigma_y), m.source])
        return buf.getvalue()

    def save_csv(self, path: str | os.PathLike) -> None:
        """Write the observation table (and its ``.csvt`` type sidecar) atomically."""
        text = self.to_csv_text()
        p = Path(path)
        atomic_write_text(p.with_suffix(".csvt"), _CSVT)
        atomic_write_text(p, text)

    def to_gcp_records(self) -> list[GCP]:
        """The measured GCPs as :class:`~truortho.core.orientation.GCP` records (world frame)."""
        by: dict[str, list[tuple[str, float, float]]] = {}
        sigmas: dict[str, dict[str, float]] = {}
        for m in self.measurements():
            by.setdefault(m.gcp, []).append((m.image, m.x, m.y))
            s = isotropic_sigma(m.sigma_x, m.sigma_y)  # refined or detected: the bundle's weight
            if s is not None:
                sigmas.setdefault(m.gcp, {})[m.image] = s
        return [
            GCP(
                g.name,
                np.asarray(g.xyz),
                "check" if g.check else "gcp",
                None,
                by[g.name],
                sigmas.get(g.name, {}),
            )
            for g in self._gcps
            if g.name in by
        ]

    def save_gcp_list(self, path: str | os.PathLike, crs: str | None = None) -> None:
        """Write an ODM ``gcp_list.txt`` (coordinates in the GCPs' CRS, or ``crs`` when they have none)."""
        from ..formats.gcplist import write_gcp_list

        crss = {g.crs for g in self._gcps if g.crs} or ({crs} if crs else set())
        if len(crss) != 1:
            raise InputError(
                "gcp_list.txt needs one CRS for all GCPs; "
                + ("none is known" if not crss else f"the GCPs have {len(crss)} different ones")
            )
        records = self.to_gcp_records()
        if not records:
            raise InputError("no measurement to write: gcp_list.txt needs at least one measured GCP")
        write_gcp_list(crss.pop(), records, path)

    def read_csv(self, path: str | os.PathLike) -> list[Measurement]:
        """Measurements of an observation table CSV, validated against this set (not applied).

        Raises :class:`FormatError` naming the file and line for a missing column, a bad
        number, an unknown GCP, an image not in the folder, a position outside the image or
        a duplicate.
        """
        from ..formats._text import read_text

        text = read_text(path, "observation table")
        rows = csv.reader(io.StringIO(text))
        header = next(rows, None)
        if header is None:
            raise FormatError(path, "empty file: expected a header line 'gcp,image,x,y'")
        cols = {h.strip().lower(): k for k, h in enumerate(header)}
        missing = [c for c in CSV_FIELDS[:4] if c not in cols]
        if missing:
            raise FormatError(
                path, f"missing column(s) {', '.join(missing)}; expected 'gcp,image,x,y'", line=1
            )
        out: list[Measurement] = []
        seen: dict[_Key, int] = {}
        for n, row in enumerate(rows, start=2):
            if not any(c.strip() for c in row):
                continue

            def cell(name: str, row=row) -> str:
                k = cols.get(name)
                return row[k].strip() if k is not None and k < len(row) else ""

            try:
                vals: dict[str, float | None] = {}
                for name in ("x", "y", "sigma_x", "sigma_y"):
                    s = cell(name)
                    if s == "" and name in ("sigma_x", "sigma_y"):
                        vals[name] = None
                        continue
                    try:
                        vals[name] = float(s)
                    except ValueError:
                        raise InputError(f"{name}: expected a number, got {s!r}") from None
                x, y = vals["x"], vals["y"]
                assert x is not None and y is not None
                m = self.validated(
                    Measurement(cell("gcp"), cell("image"), x, y, vals["sigma_x"],
                                vals["sigma_y"], cell("source") or "manual")
                )  # fmt: skip
            except InputError as err:
                raise FormatError(path, str(err), line=n) from None
            key = (m.gcp, m.image)
            if key in seen:
                raise FormatError(
                    path, f"GCP {m.gcp!r} on {m.image!r} again (first on line {seen[key]})", line=n
                )
            seen[key] = n
            out.append(m)
        return out

    def load_csv(self, path: str | os.PathLike) -> int:
        """Replace the measurements by those of a CSV (one undoable command); returns their number."""
        ms = self.read_csv(path)
        self.replace_all(ms, "load table")
        return len(ms)

    def read_gcp_list(self, path: str | os.PathLike) -> list[Measurement]:
        """Measurements of an ODM ``gcp_list.txt`` (GCPs matched by name), validated, not applied."""
        from ..formats.gcplist import read_gcp_list

        _crs, records = read_gcp_list(path)
        out = []
        for g in records:
            for image, x, y in g.observations:
                try:
                    out.append(self.validated(Measurement(g.name, image, x, y)))
                except InputError as err:
                    raise FormatError(path, str(err)) from None
        return out

    def load_gcp_list(self, path: str | os.PathLike) -> int:
        """Replace the measurements by those of a ``gcp_list.txt`` (one undoable command)."""
        ms = self.read_gcp_list(path)
        self.replace_all(ms, "load gcp_list")
        return len(ms)


def _num(v: float | None) -> str:
    return "" if v is None else repr(float(v))


# ---------------------------------------------------------------------- refinement


@dataclass(frozen=True)
class RefineReport:
    """Outcome of :func:`refine_gcp`.

    ``refined``: images whose measurement was set (source ``refined``); ``failed``: image ->
    reason for the images left as they were; ``reason``: why nothing was refined ("" = success);
    ``correlation``: image -> normalised cross-correlation at the solution.
    """

    gcp: str
    master: str
    refined: list[str]
    failed: dict[str, str]
    reason: str = ""
    correlation: dict[str, float] | None = None

    def __bool__(self) -> bool:
        return not self.reason and bool(self.refined)


def refine_gcp(
    mset: MeasurementSet,
    orientation: Orientation,
    gcp: str,
    master: str,
    half_size: int = 10,
    config=None,
) -> RefineReport:
    """Measure a GCP in its other images by multi-image least-squares matching from one measurement.

    The patch around the measurement of ``gcp`` on ``master`` is matched into every other image
    where the GCP is measured or predicted, by geometrically constrained matching
    (:func:`truortho.core.gcp.lsm.mgcm`: one object point for all images, collinearity with
    ``orientation``). The object point starts on the master ray at the GCP's height, so an
    orientation whose datum is off (a first run without GCPs, GNSS) still starts every image
    near the point. The new measurements (source ``refined``, sigmas from the adjustment) are
    placed as one undoable command; the master's measurement is not changed.

    Parameters
    ----------
    mset : MeasurementSet
    orientation : Orientation
        Must contain ``master`` and the other images (matched by file name).
    gcp, master : str
        GCP name and the image of the measurement to start from.
    half_size : int
        Template half size in pixels (the template is ``2 half_size + 1`` pixels square).
    config : truortho.core.gcp.lsm.LsmConfig, optional

    Returns
    -------
    RefineReport
        Failure (no texture, no convergence, the point behind a camera) is a report with a
        ``reason``, not an exception; nothing is changed then.

    Raises
    ------
    InputError
        No measurement on ``master``; ``master`` not in the orientation; no other image.
    """
    from ..geometry.camera import pixel_to_ray
    from ..imagery import luminance, read_image
    from .lsm import MgcmView, extract_template, mgcm

    g = mset.gcp(gcp)
    start = mset.get(gcp, master)
    if start is None:
        raise InputError(f"GCP {gcp!r} is not measured on {master!r}: measure it there first")
    index = _orientation_image_names(orientation)
    if master not in index:
        raise InputError(f"image {master!r} is not in the orientation")
    others = [name for name in mset.images_of(gcp) if name != master and name in index]
    if not others:
        raise InputError(f"GCP {gcp!r} is neither measured nor predicted in another oriented image")

    def view(name: str) -> MgcmView:
        im = orientation.images[index[name]]
        grey = luminance(read_image(mset.photo(name).path)).astype(np.float64)
        return MgcmView(grey, im.R, im.C, orientation.camera_of(im), name)

    views = [view(master)] + [view(n) for n in others]
    z = orientation.frame.to_local(_world_in(orientation, [g]))[0, 2]
    origin, d = pixel_to_ray(np.array([[start.x, start.y]]), views[0].R, views[0].C, views[0].camera)
    if not (np.all(np.isfinite(d)) and abs(d[0, 2]) > 1e-9 and (z - origin[2]) / d[0, 2] > 0):
        return RefineReport(gcp, master, [], {}, "the master ray does not reach the GCP's height")
    X0 = origin + (z - origin[2]) / d[0, 2] * d[0]
    try:  # a template off the image or without contrast: a report, not an error
        template = extract_template(views[0].image, start.x, start.y, half_size)
        result = mgcm(template, views, X0, config, master=0)
    except InputError as err:
        return RefineReport(gcp, master, [], {}, str(err))
    if not result.converged:
        return RefineReport(gcp, master, [], {}, result.reason or "no convergence")
    refined: list[Measurement] = []
    failed: dict[str, str] = {}
    corr: dict[str, float] = {}
    for name, r in zip(others, result.views[1:], strict=True):
        corr[name] = float(r.correlation)
        if not r.converged:
            failed[name] = r.reason or "no convergence"
        elif not mset.photo(name).contains(r.x, r.y):
            failed[name] = "outside the image"
        else:
            sx = r.sigma_x if math.isfinite(r.sigma_x) and r.sigma_x > 0 else None
            sy = r.sigma_y if math.isfinite(r.sigma_y) and r.sigma_y > 0 else None
            refined.append(Measurement(gcp, name, r.x, r.y, sx, sy, "refined"))
    mset.place_many(refined, f"refine {gcp} from {master}")
    return RefineReport(gcp, master, [m.image for m in refined], failed, "", corr)
