/* Part of the multibin elevation-mapping library. */
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "multibin/io/EsriAsciiGrid.h"

namespace multibin {

/** A block of a raster's samples: rows [row0, row0 + rows), columns [col0, col0 + cols). */
struct RasterBox {
    int row0 = 0, col0 = 0, rows = 0, cols = 0;
    bool empty() const { return rows <= 0 || cols <= 0; }
};

/** The bounding box of the raster's known (finite) samples grown by `margin_cells` on every side
 * and clipped to the raster; empty when no sample is known. Exports cover this box, not the
 * whole grown window, so a sparse map cannot write hundreds of MB of NODATA. */
RasterBox knownBox(const EsriAsciiGrid& raster, int margin_cells);

/** The samples of `raster` inside `box`, with the georeference moved accordingly. */
EsriAsciiGrid cropRaster(const EsriAsciiGrid& raster, const RasterBox& box);

/** The ESRI world file (.tfw) that places an image of the raster (north up, one pixel per
 * sample) in the map frame [m]. */
std::string worldFileText(const EsriAsciiGrid& raster);
/** The same from the pixel size and the centre of the upper-left pixel [m]. */
std::string worldFileText(double pixel_m, double upperLeftCenterX_m, double upperLeftCenterY_m);

/** The raster as a triangle mesh in ASCII PLY: one vertex per known sample at its cell centre
 * (x, y, height) [m], two triangles per 2x2 block of known samples (one where exactly three are
 * known). */
std::string meshPlyText(const EsriAsciiGrid& raster);

/** 1, 2 or 5 times a power of ten, the smallest at or above `rough` (> 0): tick and grid
 * spacings [m]. */
double niceStep(double rough);

/** A category of a categorical layer: its value, name and colour (R, G, B). */
struct RasterCategory {
    int value;
    std::string name;
    uint8_t rgb[3];
};

/** How encodePreviewPng() draws a layer. */
struct PreviewStyle {
    std::string title;  //!< e.g. "height [m]"
    /** Continuous layers: OpenCV colormap (cv::COLORMAP_*), bar labelled with `valueFormat`. */
    int colormap = 16;  // cv::COLORMAP_VIRIDIS
    std::string valueFormat = "%.3f";
    /** Categorical layers: a legend of swatches replaces the colour bar. Samples with other
     * values are drawn as unknown. */
    std::vector<RasterCategory> categories;
    /** A line under the title, e.g. "1 pixel = 8 x 8 cells (mean)" for a downsampled raster. */
    std::string note;
};

/** The 256 colours (R, G, B) of an OpenCV colour map (cv::COLORMAP_*, a PreviewStyle's
 * `colormap`): the one lookup of the PNG previews and the 3D view, so both draw a normalized value
 * in the same colour. */
using ColourLut = std::array<std::array<uint8_t, 3>, 256>;
ColourLut colourLut(int colormap);

/** The colour of a normalized value t (0 = low end, 1 = high end; clamped) in `lut`. */
inline const std::array<uint8_t, 3>& colourAt(const ColourLut& lut, float t) {
    const int k = int(t * 255.f + 0.5f);
    return lut[size_t(k < 0 ? 0 : k > 255 ? 255 : k)];
}

/** The longest side of encodePreviewPng()'s map panel [px]: rasters beyond it are given
 * downsampled (blockReduced(), TiledRaster.h). Encoding costs about 100 instructions a pixel:
 * 1024 keeps three previews of a long route's box (mostly unknown) to a million pixels each. */
constexpr int kPreviewMaxSide_px = 1024;

/** A PNG preview of a raster layer: north up, x and y axes with ticks in metres, a scale bar, a
 * colour bar (or a categorical legend) and unknown cells in a grey that no colormap uses. The
 * map panel is about 600 px on its long side for small rasters (whole pixels per sample), one
 * pixel per sample for larger ones; throws std::invalid_argument for a raster longer than
 * kPreviewMaxSide_px. */
std::vector<uint8_t> encodePreviewPng(const EsriAsciiGrid& raster, const PreviewStyle& style);

/** The grey of unknown cells in encodePreviewPng() (R, G, B). */
constexpr uint8_t kUnknownGrey[3] = {200, 200, 200};

/** Writes meshPlyText() to `path` through writeFileAtomically(); errors name the file. */
void saveMeshPly(const EsriAsciiGrid& raster, const std::string& path);

}  // namespace multibin
