"""QGIS layers <-> plain core records.

The one place where the project's vector schemas live:

* **Camera layer** (PointZ, projection centres, world CRS): ``name``, ``camera``,
  ``path``, ``x``, ``y``, ``z``, ``omega``, ``phi``, ``kappa`` (degrees, see
  :mod:`truortho.core.geometry`), ``fx``, ``width``, ``height``.
* **Footprint layer** (PolygonZ at one height): ``name``, ``camera``, ``height``.
* **GCP layer** (Point or PointZ): ``name`` (text, unique), ``role`` (``gcp`` or
  ``check``; empty = ``gcp``), height from the geometry's Z or a ``z`` field,
  optional sigmas in metres ``sigma_xy`` and ``sigma_z`` (or ``sigma_x``,
  ``sigma_y``, ``sigma_z``).
* **Observation table** (no geometry): ``gcp`` (name), ``image`` (image name),
  ``x``, ``y`` (pixels; (0, 0) = centre of the top-left pixel, x right, y down); optional
  ``sigma_x``, ``sigma_y`` or ``sigma`` (pixels): the measurement's weight in the bundle.
"""

from __future__ import annotations

import math

from qgis.core import (
    QgsCoordinateReferenceSystem,
    QgsCoordinateTransform,
    QgsFeature,
    QgsField,
    QgsFields,
    QgsGeometry,
    QgsLineString,
    QgsPoint,
    QgsPolygon,
    QgsProcessingException,
)
from qgis.PyQt.QtCore import QVariant

from ..core.geometry.rotation import matrix_to_opk
from ..core.orientation import GCP, Orientation, isotropic_sigma
from .i18n import tr

GCP_REQUIRED_FIELDS = ("name",)
OBSERVATION_FIELDS = ("gcp", "image", "x", "y")
#: optional standard deviations of a measurement, pixels (detecttargets writes sigma_x, sigma_y)
OBSERVATION_SIGMA_FIELDS = ("sigma", "sigma_x", "sigma_y")


def qgs_crs(text: str | None) -> QgsCoordinateReferenceSystem:
    """A QGIS CRS from the orientation's CRS text (authority code or WKT); invalid if None."""
    if not text:
        return QgsCoordinateReferenceSystem()
    crs = QgsCoordinateReferenceSystem(text)
    if not crs.isValid():
        crs = QgsCoordinateReferenceSystem.fromWkt(text)
    if not crs.isValid():
        raise QgsProcessingException(tr("QGIS cannot read the CRS {!r}").format(text[:80]))
    return crs


def crs_text(crs: QgsCoordinateReferenceSystem) -> str | None:
    """Authority code when QGIS knows one, else WKT2; None for an invalid CRS."""
    if not crs.isValid():
        return None
    auth = crs.authid()
    if auth and ":" in auth and not auth.upper().startswith("USER"):
        return auth
    return crs.toWkt(QgsCoordinateReferenceSystem.WKT2_2019)


def _field(name: str, kind) -> QgsField:
    return QgsField(name, kind)


# ------------------------------------------------------------------- cameras


def camera_fields() -> QgsFields:
    fields = QgsFields()
    for name in ("name", "camera", "path"):
        fields.append(_field(name, QVariant.String))
    for name in ("x", "y", "z", "omega", "phi", "kappa", "fx"):
        fields.append(_field(name, QVariant.Double))
    for name in ("width", "height"):
        fields.append(_field(name, QVariant.Int))
    return fields


def camera_features(orientation: Orientation, fields: QgsFields):
    """One PointZ feature per image at its projection centre (world CRS)."""
    centres = orientation.world_centers()
    for im, c in zip(orientation.images, centres, strict=True):
        cam = orientation.camera_of(im)
        o, p, k = matrix_to_opk(im.R, degrees=True)
        f = QgsFeature(fields)
        f.setGeometry(QgsGeometry(QgsPoint(float(c[0]), float(c[1]), float(c[2]))))
        f.setAttributes(
            [
                im.name,
                im.camera,
                im.path,
                float(c[0]),
                float(c[1]),
                float(c[2]),
                float(o),
                float(p),
                float(k),
                cam.fx,
                cam.width,
                cam.height,
            ]
        )
        yield f


def footprint_fields() -> QgsFields:
    fields = QgsFields()
    fields.append(_field("name", QVariant.String))
    fields.append(_field("camera", QVariant.String))
    fields.append(_field("height", QVariant.Double))
    return fields


def footprint_feature(name: str, camera: str, ring_world, height: float, fields: QgsFields) -> QgsFeature:
    xs = [float(v) for v in ring_world[:, 0]] + [float(ring_world[0, 0])]
    ys = [float(v) for v in ring_world[:, 1]] + [float(ring_world[0, 1])]
    zs = [float(height)] * len(xs)
    poly = QgsPolygon(QgsLineString(xs, ys, zs))
    f = QgsFeature(fields)
    f.setGeometry(QgsGeometry(poly))
    f.setAttributes([name, camera, float(height)])
    return f


# ---------------------------------------------------------------------- GCPs


def gcp_fields() -> QgsFields:
    fields = QgsFields()
    fields.append(_field("name", QVariant.String))
    fields.append(_field("role", QVariant.String))
    for name in ("z", "sigma_xy", "sigma_z"):
        fields.append(_field(name, QVariant.Double))
    return fields


def gcp_feature(g: GCP, fields: QgsFields, sigma_xy: float | None, sigma_z: float | None) -> QgsFeature:
    sxy = float(g.sigma[0]) if g.sigma is not None else sigma_xy
    sz = float(g.sigma[2]) if g.sigma is not None else sigma_z
    f = QgsFeature(fields)
    f.setGeometry(QgsGeometry(QgsPoint(float(g.xyz[0]), float(g.xyz[1]), float(g.xyz[2]))))
    f.setAttributes([g.name, g.role, float(g.xyz[2]), sxy, sz])
    return f


def observation_fields() -> QgsFields:
    fields = QgsFields()
    fields.append(_field("gcp", QVariant.String))
    fields.append(_field("image", QVariant.String))
    fields.append(_field("x", QVariant.Double))
    fields.append(_field("y", QVariant.Double))
    return fields


def observation_features(gcps, fields: QgsFields):
    for g in gcps:
        for image, x, y in g.observations:
            f = QgsFeature(fields)
            f.setAttributes([g.name, image, float(x), float(y)])
            yield f


def _value(feature: QgsFeature, name: str):
    v = feature[name]
    if v is None or (hasattr(v, "isNull") and v.isNull()):
        return None
    return v


def _number(value, what: str) -> float | None:
    if value is None or value == "":
        return None
    try:
        f = float(value)
    except (TypeError, ValueError):
        raise QgsProcessingException(tr("{}: expected a number, got {!r}").format(what, value)) from None
    if not math.isfinite(f):
        raise QgsProcessingException(tr("{}: expected a finite number, got {!r}").format(what, value))
    return f


def _require_fields(layer, required, what: str) -> None:
    names = [f.name().lower() for f in layer.fields()]
    missing = [r for r in required if r not in names]
    if missing:
        raise QgsProcessingException(
            tr("{} layer {!r} lacks the field(s) {}; expected fields: {}").format(
                what, layer.name(), ", ".join(missing), ", ".join(required)
            )
        )


def _field_name(layer, name: str) -> str | None:
    for f in layer.fields():
        if f.name().lower() == name:
            return f.name()
    return None


def read_gcp_layer(
    layer,
    target_crs: QgsCoordinateReferenceSystem | None,
    transform_context,
    default_sigma_xy: float | None = None,
    default_sigma_z: float | None = None,
) -> list[GCP]:
    """GCP records from a point layer, reprojected to ``target_crs`` when it differs.

    Raises ``QgsProcessingException`` naming the layer, the feature and the
    field for missing fields, missing names, duplicates, bad roles or a
    missing height.
    """
    if layer is None:
        return []
    _require_fields(layer, GCP_REQUIRED_FIELDS, tr("GCP"))
    name_f = _field_name(layer, "name")
    role_f = _field_name(layer, "role")
    z_f = _field_name(layer, "z")
    sx_f = _field_name(layer, "sigma_x") or _field_name(layer, "sigma_xy")
    sy_f = _field_name(layer, "sigma_y") or _field_name(layer, "sigma_xy")
    sz_f = _field_name(layer, "sigma_z")
    transform = None
    if (
        target_crs is not None
        and target_crs.isValid()
        and layer.crs().isValid()
        and layer.crs() != target_crs
    ):
        transform = QgsCoordinateTransform(layer.crs(), target_crs, transform_context)
    gcps: list[GCP] = []
    seen: set[str] = set()
    for feat in layer.getFeatures():
        fid = feat.id()
        name = _value(feat, name_f)
        if name is None or str(name).strip() == "":
            raise QgsProcessingException(
                tr("GCP layer {!r}: feature {} has no name").format(layer.name(), fid)
            )
        name = str(name).strip()
        if name in seen:
            raise QgsProcessingException(
                tr("GCP layer {!r}: the name {!r} appears twice").format(layer.name(), name)
            )
        seen.add(name)
        geom = feat.geometry()
        if geom is None or geom.isEmpty():
            raise QgsProcessingException(
                tr("GCP layer {!r}: GCP {!r} has no geometry").format(layer.name(), name)
            )
        pt = geom.constGet()
        if hasattr(pt, "x") and not hasattr(pt, "numGeometries"):
            x, y = pt.x(), pt.y()
            z = pt.z() if pt.is3D() else None
        else:
            raise QgsProcessingException(
                tr("GCP layer {!r}: GCP {!r} is not a single point").format(layer.name(), name)
            )
        if z is None or (isinstance(z, float) and math.isnan(z)):
            z = _number(_value(feat, z_f), f"GCP {name!r} field z") if z_f else None
        if z is None:
            raise QgsProcessingException(
                tr("GCP layer {!r}: GCP {!r} has no height: use PointZ geometries or a 'z' field").format(
                    layer.name(), name
                )
            )
        if transform is not None:
            p = transform.transform(x, y)  # planimetric; heights are kept as given
            x, y = p.x(), p.y()
        role = str(_value(feat, role_f) or "gcp").strip().lower() if role_f else "gcp"
        if role in ("control", "gcp", ""):
            role = "gcp"
        elif role in ("check", "checkpoint", "check point"):
            role = "check"
        else:
            raise QgsProcessingException(
                tr("GCP layer {!r}: GCP {!r} has role {!r}; expected 'gcp' or 'check'").format(
                    layer.name(), name, role
                )
            )
        sx = _number(_value(feat, sx_f), f"GCP {name!r} sigma") if sx_f else None
        sy = _number(_value(feat, sy_f), f"GCP {name!r} sigma") if sy_f else None
        sz = _number(_value(feat, sz_f), f"GCP {name!r} sigma_z") if sz_f else None
        sx = sx if sx is not None else default_sigma_xy
        sy = sy if sy is not None else default_sigma_xy
        sz = sz if sz is not None else default_sigma_z
        sigma = None
        if None not in (sx, sy, sz):
            if min(sx, sy, sz) <= 0:  # type: ignore[type-var]
                raise QgsProcessingException(tr("GCP {!r}: sigmas must be positive").format(name))
            sigma = [sx, sy, sz]
        gcps.append(GCP(name, [x, y, float(z)], role, sigma))
    return gcps


def _observation_sigma(feat, fields: list[str], layer_name: str) -> float | None:
    """Isotropic sigma (px) of one measurement: ``sigma``, or the RMS of ``sigma_x``/``sigma_y``."""
    values = {f.lower(): _number(_value(feat, f), f"observation {feat.id()} {f}") for f in fields}
    if values.get("sigma") is not None:
        s = values["sigma"]
    else:
        s = isotropic_sigma(values.get("sigma_x"), values.get("sigma_y"))
        if s is None:
            return None
    if not s > 0:  # type: ignore[operator]
        raise QgsProcessingException(
            tr("Observation table {!r}, feature {}: sigma must be positive, got {}").format(
                layer_name, feat.id(), s
            )
        )
    return float(s)  # type: ignore[arg-type]


def read_observation_table(layer, gcps: list[GCP], image_names: set[str] | None = None) -> None:
    """Attach image measurements from a table to ``gcps`` (in place).

    Optional ``sigma_x``, ``sigma_y`` (or one ``sigma``) fields in pixels become the
    measurement's weight in the bundle (``GCP.obs_sigma``: one sigma, the RMS of the two);
    empty values leave the adjustment's default. Raises ``QgsProcessingException`` for missing
    fields, an unknown GCP or image name, non-numeric pixel coordinates or a sigma <= 0.
    """
    if layer is None:
        return
    _require_fields(layer, OBSERVATION_FIELDS, tr("Observation"))
    by_name = {g.name: g for g in gcps}
    names = {k: _field_name(layer, k) for k in OBSERVATION_FIELDS}
    sig_f = [f for f in (_field_name(layer, k) for k in OBSERVATION_SIGMA_FIELDS) if f]
    for feat in layer.getFeatures():
        gname = str(_value(feat, names["gcp"]) or "").strip()
        image = str(_value(feat, names["image"]) or "").strip()
        if gname not in by_name:
            raise QgsProcessingException(
                tr("Observation table {!r}, feature {}: unknown GCP {!r}").format(
                    layer.name(), feat.id(), gname
                )
            )
        if image_names is not None and image not in image_names:
            raise QgsProcessingException(
                tr("Observation table {!r}, feature {}: unknown image {!r}").format(
                    layer.name(), feat.id(), image
                )
            )
        x = _number(_value(feat, names["x"]), f"observation {feat.id()} x")
        y = _number(_value(feat, names["y"]), f"observation {feat.id()} y")
        if x is None or y is None:
            raise QgsProcessingException(
                tr("Observation table {!r}, feature {}: x and y are required").format(layer.name(), feat.id())
            )
        by_name[gname].observations.append((image, x, y))
        sigma = _observation_sigma(feat, sig_f, layer.name())
        if sigma is not None:
            by_name[gname].obs_sigma[image] = sigma


def ground_control(gcp_layer, obs_layer, crs, transform_context):
    """GCP records (with their image measurements) from the GCPS layer and the OBSERVATIONS table.

    ``crs``: the requested output CRS (invalid = none); the GCPs are reprojected into it, or it
    becomes the GCP layer's CRS. Returns ``(gcps, crs)``; no layers gives ``([], crs)``.
    Raises ``QgsProcessingException`` when only one of the two layers is given.
    """
    from qgis.core import QgsProcessingException

    if (gcp_layer is None) != (obs_layer is None):
        raise QgsProcessingException(tr("GCPS and OBSERVATIONS must be given together"))
    if gcp_layer is None:
        return [], crs
    if not crs.isValid():
        crs = gcp_layer.crs()
    gcps = read_gcp_layer(gcp_layer, crs, transform_context)
    read_observation_table(obs_layer, gcps, None)
    return gcps, crs
