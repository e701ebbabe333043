"""Sensible styles for TruOrtho products when Processing loads them into the project.

Algorithms call :func:`style_on_load` for each raster/point-cloud output; when the
algorithm runs from the GUI (or the model builder), Processing loads the output
on completion and the post-processor styles it: a hillshade for DSMs, RGB with
alpha for orthophotos, a red mask for occlusion, a colour ramp for confidence, RGB
for point clouds. Headless runs (``qgis_process``) load nothing, so nothing happens.

Post-processors must outlive ``processAlgorithm`` (Processing only keeps a raw
pointer): they are kept in a module-level registry.
"""

from __future__ import annotations

from qgis.core import (
    QgsBilinearRasterResampler,
    QgsColorRampShader,
    QgsContrastEnhancement,
    QgsHillshadeRenderer,
    QgsMultiBandColorRenderer,
    QgsPalettedRasterRenderer,
    QgsProcessingLayerPostProcessorInterface,
    QgsRasterBandStats,
    QgsRasterLayer,
    QgsRasterShader,
    QgsSingleBandPseudoColorRenderer,
    QgsStyle,
)
from qgis.PyQt.QtGui import QColor

from .i18n import tr

KINDS = ("dsm", "ortho", "occlusion", "confidence", "index", "pointcloud")


def apply_style(layer, kind: str) -> bool:
    """Style a loaded layer as a TruOrtho product of ``kind``; False when the layer does not fit."""
    if kind not in KINDS:
        raise ValueError(f"unknown style kind {kind!r}; expected one of {KINDS}")
    if kind == "pointcloud":
        return _style_point_cloud(layer)
    if not isinstance(layer, QgsRasterLayer) or not layer.isValid():
        return False
    provider = layer.dataProvider()
    if kind == "dsm":
        renderer = QgsHillshadeRenderer(provider, 1, 315.0, 45.0)
        renderer.setMultiDirectional(True)
        layer.setRenderer(renderer)
        # zoomed in, shade the DSM's own cells and interpolate the shading: with the default
        # nearest-neighbour resampling the renderer gets repeated rows and columns, whose zero
        # gradients draw a grid of flat lines across the hillshade
        layer.resampleFilter().setZoomedInResampler(QgsBilinearRasterResampler())
    elif kind == "ortho":
        if layer.bandCount() < 3:
            return False
        renderer = QgsMultiBandColorRenderer(provider, 1, 2, 3)
        if layer.bandCount() >= 4:
            renderer.setAlphaBand(4)
        if provider.dataType(1) != 1:  # not Byte: stretch each band to its range
            for band, setter in (
                (1, renderer.setRedContrastEnhancement),
                (2, renderer.setGreenContrastEnhancement),
                (3, renderer.setBlueContrastEnhancement),
            ):
                stats = provider.bandStatistics(band, QgsRasterBandStats.Min | QgsRasterBandStats.Max)
                ce = QgsContrastEnhancement(provider.dataType(band))
                ce.setContrastEnhancementAlgorithm(QgsContrastEnhancement.StretchToMinimumMaximum)
                ce.setMinimumValue(stats.minimumValue)
                ce.setMaximumValue(stats.maximumValue)
                setter(ce)
        layer.setRenderer(renderer)
    elif kind == "occlusion":
        classes = [QgsPalettedRasterRenderer.Class(1, QColor(220, 30, 30, 200), tr("seen by no image"))]
        layer.setRenderer(QgsPalettedRasterRenderer(provider, 1, classes))
    elif kind in ("confidence", "index"):
        stats = provider.bandStatistics(1, QgsRasterBandStats.Min | QgsRasterBandStats.Max)
        ramp = QgsStyle.defaultStyle().colorRamp("Viridis" if kind == "confidence" else "Spectral")
        fn = QgsColorRampShader(stats.minimumValue, stats.maximumValue, ramp)
        fn.classifyColorRamp(8 if kind == "confidence" else 12)
        shader = QgsRasterShader()
        shader.setRasterShaderFunction(fn)
        layer.setRenderer(QgsSingleBandPseudoColorRenderer(provider, 1, shader))
    layer.triggerRepaint()
    return True


def _style_point_cloud(layer) -> bool:
    try:
        from qgis.core import QgsPointCloudLayer, QgsPointCloudRgbRenderer
    except ImportError:  # QGIS without point cloud support
        return False
    if not isinstance(layer, QgsPointCloudLayer) or not layer.isValid():
        return False
    attrs = {a.name().lower() for a in layer.attributes().attributes()}
    if not {"red", "green", "blue"} <= attrs:
        return False
    renderer = QgsPointCloudRgbRenderer()
    renderer.setRedAttribute("Red")
    renderer.setGreenAttribute("Green")
    renderer.setBlueAttribute("Blue")
    layer.setRenderer(renderer)
    layer.triggerRepaint()
    return True


class _StylePostProcessor(QgsProcessingLayerPostProcessorInterface):
    def __init__(self, kind: str) -> None:
        super().__init__()
        self.kind = kind

    def postProcessLayer(self, layer, context, feedback):  # noqa: N802 - QGIS API
        apply_style(layer, self.kind)


_KEEP: list[_StylePostProcessor] = []


def style_on_load(context, output_path: str, kind: str, name: str | None = None) -> None:
    """If Processing will load ``output_path`` into the project, style it as ``kind`` (and name it)."""
    if not output_path or not context.willLoadLayerOnCompletion(output_path):
        return
    details = context.layerToLoadOnCompletionDetails(output_path)
    if name:
        details.name = name
    post = _StylePostProcessor(kind)
    _KEEP.append(post)
    del _KEEP[:-64]  # bounded: only the latest runs need their post-processors
    details.setPostProcessor(post)
