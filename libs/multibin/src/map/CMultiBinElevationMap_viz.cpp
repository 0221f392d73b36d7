/* Part of the multibin elevation-mapping library.
 * CMultiBinElevationMap: 3D visualization with stock mrpt::opengl classes only, so a saved
 * .3Dscene opens in programs that do not load this library. */
#include <mrpt/img/CImage.h>
#include <mrpt/opengl/CColorBar.h>
#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/CMesh.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/opengl/CText.h>
#include "CMultiBinElevationMap_impl.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <vector>

#include "multibin/io/MapLayerFiles.h"
#include "multibin/map/TerrainView.h"

#include "multibin/io/EsriAsciiGrid.h"

using namespace mrpt::maps;

namespace multibin {
namespace {

using Layer = CMultiBinElevationMap::RasterLayer;
using HS = CMultiBinElevationMap::HeightSource;

Layer layerOf(SceneColouring c) {
    switch (c) {
        case SceneColouring::Sigma:
            return Layer::Sigma;
        case SceneColouring::Certainty:
            return Layer::Certainty;
        case SceneColouring::Source:
            return Layer::Source;
        default:
            return Layer::Height;
    }
}

}  // namespace

const std::vector<RasterCategory>& heightSourceCategories() {
    // tab10's blue, orange and green: distinct, and none is the grey of unknown cells.
    static const std::vector<RasterCategory> categories{
        {int(HS::Measured), "measured", {31, 119, 180}},
        {int(HS::FilledMedian), "filled: median", {255, 127, 14}},
        {int(HS::FilledSurface), "filled: surface", {44, 160, 44}}};
    return categories;
}

SceneColouring sceneColouringFromName(const std::string& name) {
    for (const SceneColouring c : {SceneColouring::Height, SceneColouring::Sigma,
                                   SceneColouring::Certainty, SceneColouring::Source})
        if (name == sceneColouringName(c)) return c;
    throw std::invalid_argument("unknown scene colouring '" + name +
                                "' (known: height, sigma, certainty, source)");
}

const char* sceneColouringName(SceneColouring c) {
    switch (c) {
        case SceneColouring::Sigma:
            return "sigma";
        case SceneColouring::Certainty:
            return "certainty";
        case SceneColouring::Source:
            return "source";
        default:
            return "height";
    }
}

void buildTerrainView(const CMultiBinElevationMap& map, SceneColouring colouring,
                      mrpt::opengl::CSetOfObjects& out) {
    // Built relative to the map origin and placed at it, so the view's floats stay small at
    // georeferenced coordinates.
    const mrpt::math::TPoint2D origin = map.mapOrigin();
    // Read tile by tile, one vertex per cell up to 2048 a side, else per block.
    std::vector<TiledRaster> layers = tiledLayers(map, {Layer::Height, layerOf(colouring)});
    for (TiledRaster& t : layers) t.originX_m = t.originY_m = 0;
    auto placed = mrpt::opengl::CSetOfObjects::Create();
    placed->setName("map origin");
    placed->setLocation(origin.x, origin.y, 0);
    const bool atZero = origin.x == 0 && origin.y == 0;
    mrpt::opengl::CSetOfObjects& into = atZero ? out : *placed;
    const CellWindow box = knownWindow(layers[0], 1);
    const std::vector<EsriAsciiGrid> blocks =
        blockReduced(layers, box, blockFactorFor(box, kPreviewMaxSide_px),
                     {BlockReduce::Mean, layerBlockReduce(layerOf(colouring))});
    const EsriAsciiGrid &heights = blocks[0], &values = blocks[1];
    const int nx = heights.cols(), ny = heights.rows();
    if (nx < 2 || ny < 2) return;

    float zLo = std::numeric_limits<float>::infinity(), zHi = -zLo;
    std::vector<float> known;
    for (int r = 0; r < ny; r++)
        for (int c = 0; c < nx; c++) {
            const float h = heights.heights_m(r, c), v = values.heights_m(r, c);
            if (!std::isfinite(h)) continue;
            zLo = std::min(zLo, h), zHi = std::max(zHi, h);
            if (std::isfinite(v)) known.push_back(v);
        }
    float lo = 0, hi = 0;
    if (!known.empty()) {
        lo = *std::min_element(known.begin(), known.end());
        // Heights span their whole range; sigma and certainty are skewed (a few cells far
        // above the rest), so their colours span up to the 98th percentile.
        auto at = known.begin() + std::ptrdiff_t(colouring == SceneColouring::Height
                                                     ? known.size() - 1
                                                     : known.size() * 98 / 100);
        std::nth_element(known.begin(), at, known.end());
        hi = *at;
    }
    const float span = hi > lo ? hi - lo : 1.f;
    const mrpt::img::TColormap cmap = map.insertionOptions.colormap;

    // CMesh: Z(i, j) with i along x and j along y, vertices at cell centres; its texture has one
    // texel per vertex (the image's rows follow i, its columns j).
    mrpt::math::CMatrixDynamic<float> Z(nx, ny), mask(nx, ny);
    mrpt::img::CImage texture(ny, nx, mrpt::img::CH_RGB);
    for (int ix = 0; ix < nx; ix++)
        for (int iy = 0; iy < ny; iy++) {
            const float h = heights.heights_m(iy, ix), v = values.heights_m(iy, ix);
            const bool known = std::isfinite(h);
            Z(ix, iy) = known ? h : zLo;
            mask(ix, iy) = known ? 1.f : 0.f;
            mrpt::img::TColor colour(128, 128, 128);
            if (known && std::isfinite(v)) {
                if (colouring == SceneColouring::Source) {
                    for (const RasterCategory& k : heightSourceCategories())
                        if (int(std::lround(v)) == k.value)
                            colour = mrpt::img::TColor(k.rgb[0], k.rgb[1], k.rgb[2]);
                } else {
                    float R, G, B;
                    mrpt::img::colormap(cmap, (v - lo) / span, R, G, B);
                    colour =
                        mrpt::img::TColor(uint8_t(255 * R), uint8_t(255 * G), uint8_t(255 * B));
                }
            }
            texture.setPixel(iy, ix, colour);
        }
    auto mesh = mrpt::opengl::CMesh::Create();
    mesh->setName("CMultiBinElevationMap");
    mesh->setGridLimits(heights.xllcenter_m, heights.xMax_m(), heights.yllcenter_m,
                        heights.yMax_m());
    mesh->assignImageAndZ(texture, Z);
    mesh->setMask(mask);
    into.insert(mesh);

    // Scale: a grid of nice spacing just under the lowest cell, its spacing written beside it.
    const double xSpan = heights.xMax_m() - heights.xllcenter_m,
                 ySpan = heights.yMax_m() - heights.yllcenter_m;
    const double step = niceStep(std::max(xSpan, ySpan) / 8);
    const double x0 = std::floor(heights.xllcenter_m / step) * step,
                 y0 = std::floor(heights.yllcenter_m / step) * step;
    const double x1 = std::ceil(heights.xMax_m() / step) * step,
                 y1 = std::ceil(heights.yMax_m() / step) * step;
    auto grid = mrpt::opengl::CGridPlaneXY::Create(x0, x1, y0, y1, zLo - 0.01, step);
    grid->setName("grid");
    grid->setColor_u8(mrpt::img::TColor(90, 90, 90));
    into.insert(grid);
    char buf[96];
    std::snprintf(buf, sizeof buf, "grid: %g m", step);
    auto gridLabel = mrpt::opengl::CText::Create(buf);
    gridLabel->setLocation(x0, y0 - 0.5 * step, zLo);
    gridLabel->setColor_u8(mrpt::img::TColor(40, 40, 40));
    into.insert(gridLabel);

    // Legend beside the map (+x side), centred on it in y.
    const double legendH = std::max(step, 0.4 * ySpan);
    const double lx = x1 + 0.2 * step, ly = 0.5 * (y0 + y1) - 0.5 * legendH;
    if (colouring == SceneColouring::Source) {
        double y = ly + legendH;
        for (const RasterCategory& k : heightSourceCategories()) {
            auto t = mrpt::opengl::CText::Create(k.name);
            t->setLocation(lx, y, zHi);
            t->setColor_u8(mrpt::img::TColor(k.rgb[0], k.rgb[1], k.rgb[2]));
            into.insert(t);
            y -= 0.1 * legendH;
        }
    } else {
        const char* unit = colouring == SceneColouring::Certainty ? " c [-]" : "";
        const std::string format =
            colouring == SceneColouring::Certainty ? "%.0f" : std::string("%.3f m");
        auto bar = mrpt::opengl::CColorBar::Create(cmap, 0.1 * legendH, legendH, 0.f, 1.f, lo, hi,
                                                   format, float(0.035 * legendH));
        bar->setName("colour bar");
        bar->setLocation(lx, ly, zHi);
        into.insert(bar);
        std::snprintf(buf, sizeof buf, "%s%s", sceneColouringName(colouring), unit);
        auto title = mrpt::opengl::CText::Create(buf);
        title->setLocation(lx, ly - 0.1 * legendH, zHi);  // under the bar: its drawn height varies
        title->setColor_u8(mrpt::img::TColor(40, 40, 40));
        into.insert(title);
    }
    if (!atZero) out.insert(placed);
}

}  // namespace multibin

void CMultiBinElevationMap::getVisualizationInto(mrpt::opengl::CSetOfObjects& outObj) const {
    prepareForReading();
    const multibin::MapLock::Shared lock(m_impl->lock);
    if (!genericMapParams.enableSaveAs3DObject) return;
    multibin::buildTerrainView(*this,
                               insertionOptions.color_by_sigma ? multibin::SceneColouring::Sigma
                                                               : multibin::SceneColouring::Height,
                               outObj);
}
