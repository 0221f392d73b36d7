/* Part of the multibin elevation-mapping library.
 * CMultiBinElevationMap: 3D visualization with stock mrpt::opengl classes only, so a saved
 * .3Dscene opens in programs that do not load this library. */
#include <mrpt/img/CImage.h>
#include <mrpt/math/geometry.h>
#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/CMesh.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CPointCloudColoured.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/opengl/CText.h>
#include "CMultiBinElevationMap_impl.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <vector>

#include "multibin/io/MapLayerFiles.h"
#include "multibin/map/TerrainView.h"

#include "multibin/io/EsriAsciiGrid.h"
#include "multibin/io/FiniteSamples.h"

using namespace mrpt::maps;

namespace multibin {
namespace {

using Layer = CMultiBinElevationMap::RasterLayer;
using HS = CMultiBinElevationMap::HeightSource;

}  // namespace

MapLayer layerShownBy(SceneColouring c) {
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

const char* sceneColouringName(SceneColouring c) { return mapLayerName(layerShownBy(c)); }

namespace {

/** The rasters a view is drawn from: the heights and the colouring layer (one raster when they
 * are the same), block-reduced to at most kPreviewMaxSide_px a side, relative to the map
 * origin. */
std::vector<EsriAsciiGrid> viewRasters(const TiledRaster& heights, const TiledRaster& values,
                                       Layer shown) {
    // Read tile by tile, one vertex per cell up to kPreviewMaxSide_px a side, else per block.
    // Coloured by height (the default), the two rasters are one: reduced once.
    const bool one = &heights == &values && layerBlockReduce(shown) == BlockReduce::Mean;
    std::vector<TiledRaster> layers{heights};
    if (!one) layers.push_back(values);
    for (TiledRaster& t : layers) t.originX_m = t.originY_m = 0;
    const CellWindow box = knownWindow(layers[0], 1);
    std::vector<BlockReduce> how{BlockReduce::Mean};
    if (!one) how.push_back(layerBlockReduce(shown));
    return blockReduced(layers, box, blockFactorFor(box, kPreviewMaxSide_px), how);
}

/** The height range of the known cells and the range the colours span. */
struct ViewRanges {
    float zLo_m = 0, zHi_m = 0, lo = 0, hi = 0;
    float span() const { return hi > lo ? hi - lo : 1.f; }
};

ViewRanges viewRanges(const EsriAsciiGrid& heights, const EsriAsciiGrid& values,
                      SceneColouring colouring) {
    ViewRanges r;
    r.zLo_m = std::numeric_limits<float>::infinity(), r.zHi_m = -r.zLo_m;
    std::vector<float> known;
    // The known cells in memory order (the rasters are column-major, mostly NaN).
    forEachFinite(heights.heights_m.data(), size_t(heights.heights_m.size()), [&](size_t i) {
        const float h = heights.heights_m.data()[i], v = values.heights_m.data()[i];
        r.zLo_m = std::min(r.zLo_m, h), r.zHi_m = std::max(r.zHi_m, h);
        if (std::isfinite(v)) known.push_back(v);
    });
    if (known.empty()) return r;
    r.lo = *std::min_element(known.begin(), known.end());
    // Heights span their whole range (as the previews); sigma and certainty are skewed (a few
    // cells far above the rest), so their colours span up to the 98th percentile.
    auto at = known.begin() + std::ptrdiff_t(colouring == SceneColouring::Height
                                                 ? known.size() - 1
                                                 : known.size() * 98 / 100);
    std::nth_element(known.begin(), at, known.end());
    r.hi = *at;
    return r;
}

mrpt::img::TColor toColor(const std::array<uint8_t, 3>& rgb) {
    return mrpt::img::TColor(rgb[0], rgb[1], rgb[2]);
}

/** The colour of a known cell's value: its category, or the layer's colour map (the previews'). */
mrpt::img::TColor cellColour(float v, SceneColouring colouring, const ColourLut& lut,
                             const ViewRanges& r) {
    if (colouring != SceneColouring::Source) return toColor(colourAt(lut, (v - r.lo) / r.span()));
    for (const RasterCategory& k : heightSourceCategories())
        if (int(std::lround(v)) == k.value) return toColor({k.rgb[0], k.rgb[1], k.rgb[2]});
    return mrpt::img::TColor(128, 128, 128);
}

/** Vertices [x0, x1] x [y0, y1] (inclusive). */
struct Box {
    int x0, y0, x1, y1;
};

/** The box of the quads of four known vertices with their lower corner in [x0, x1) x [y0, y1)
 * (empty: x1 < x0). A mesh draws a quad only between four known vertices: a mesh over this box
 * draws what one over the range draws, with fewer masked vertices to build, serialize and
 * compress (on a 2D laser's map, most known cells lie on thin walls, in no quad: loneCells()
 * draws them). */
Box quadBox(const EsriAsciiGrid& heights, int x0, int y0, int x1, int y1) {
    Box b{x1 + 1, y1 + 1, x0 - 1, y0 - 1};
    const size_t rows = size_t(heights.rows());
    for (int ix = x0; ix < x1; ix++) {
        const float* h = heights.heights_m.data() + size_t(ix) * rows;  // column ix
        const float* right = h + rows;                                  // column ix + 1
        forEachFinite(h + y0, size_t(y1 - y0), [&](size_t k) {
            const size_t iy = size_t(y0) + k;
            if (!std::isfinite(h[iy + 1]) || !std::isfinite(right[iy]) ||
                !std::isfinite(right[iy + 1]))
                return;
            b = {std::min(b.x0, ix), std::min(b.y0, int(iy)), std::max(b.x1, ix + 1),
                 std::max(b.y1, int(iy) + 1)};
        });
    }
    return b;
}

/** The side of the terrain's meshes [raster cells]: one per tile holding a known cell, so the
 * scene's size (and the cost of building and saving it) follows the data, not its bounding box. */
constexpr int kSceneTile_cells = 64;

/** The terrain: CMeshes over tiles of kSceneTile_cells x kSceneTile_cells cells of the raster,
 * those holding a quad of four known cells, each over its quads' box (quadBox()); a tile has one
 * row and column of vertices more where the raster goes on, so the quads between tiles are
 * drawn. Z(i, j) with i along x and j along y, vertices at cell
 * centres; the texture has one texel per vertex (the image's rows follow i, its columns j). A
 * raster of at most kSceneTile_cells + 1 vertices a side is one mesh. */
std::vector<mrpt::opengl::CMesh::Ptr> terrainMeshes(const EsriAsciiGrid& heights,
                                                    const EsriAsciiGrid& values,
                                                    SceneColouring colouring, const ViewRanges& r) {
    const int nx = heights.cols(), ny = heights.rows();
    const ColourLut lut = colourLut(layerPreviewStyle(layerShownBy(colouring)).colormap);
    const auto known = [&](int ix, int iy) { return std::isfinite(heights.heights_m(iy, ix)); };
    std::vector<mrpt::opengl::CMesh::Ptr> meshes;
    for (int y0 = 0; y0 < ny - 1; y0 += kSceneTile_cells)
        for (int x0 = 0; x0 < nx - 1; x0 += kSceneTile_cells) {
            const int tx1 = x0 + std::min(kSceneTile_cells, nx - 1 - x0);
            const int ty1 = y0 + std::min(kSceneTile_cells, ny - 1 - y0);
            const Box b = quadBox(heights, x0, y0, tx1, ty1);
            if (b.x1 < b.x0) continue;
            const int mx = b.x1 - b.x0 + 1, my = b.y1 - b.y0 + 1;
            mrpt::math::CMatrixDynamic<float> Z(mx, my), mask(mx, my);
            mrpt::img::CImage texture(my, mx, mrpt::img::CH_RGB);
            for (int i = 0; i < mx; i++) {
                // Texel row i written in place (B, G, R as CImage::setPixel stores them):
                // setPixel checks and converts per texel.
                uint8_t* texel = texture.ptrLine<uint8_t>(unsigned(i));
                for (int j = 0; j < my; j++, texel += 3) {
                    const int ix = b.x0 + i, iy = b.y0 + j;
                    const float h = heights.heights_m(iy, ix), v = values.heights_m(iy, ix);
                    Z(i, j) = known(ix, iy) ? h : r.zLo_m;
                    mask(i, j) = known(ix, iy) ? 1.f : 0.f;
                    const mrpt::img::TColor c = known(ix, iy) && std::isfinite(v)
                                                    ? cellColour(v, colouring, lut, r)
                                                    : mrpt::img::TColor(128, 128, 128);
                    texel[0] = c.B, texel[1] = c.G, texel[2] = c.R;
                }
            }
            auto mesh = mrpt::opengl::CMesh::Create();
            mesh->setName("CMultiBinElevationMap");
            const double cs = heights.cellsize_m;
            mesh->setGridLimits(
                heights.xllcenter_m + b.x0 * cs, heights.xllcenter_m + (b.x0 + mx - 1) * cs,
                heights.yllcenter_m + b.y0 * cs, heights.yllcenter_m + (b.y0 + my - 1) * cs);
            mesh->assignImageAndZ(texture, Z);
            mesh->setMask(mask);
            meshes.push_back(mesh);
        }
    return meshes;
}

/** The known cells the meshes do not draw (they draw a quad only between four known vertices:
 * a cell with no such quad around it, on a thin wall or alone, would not show), as points of
 * their colour, 2 pixels wide at any distance. */
mrpt::opengl::CPointCloudColoured::Ptr loneCells(const EsriAsciiGrid& heights,
                                                 const EsriAsciiGrid& values,
                                                 SceneColouring colouring, const ViewRanges& r) {
    const int nx = heights.cols(), ny = heights.rows();
    auto known = [&](int ix, int iy) {
        return ix >= 0 && iy >= 0 && ix < nx && iy < ny && std::isfinite(heights.heights_m(iy, ix));
    };
    auto inAQuad = [&](int ix, int iy) {
        for (int qx = ix - 1; qx <= ix; qx++)
            for (int qy = iy - 1; qy <= iy; qy++)
                if (known(qx, qy) && known(qx + 1, qy) && known(qx, qy + 1) &&
                    known(qx + 1, qy + 1))
                    return true;
        return false;
    };
    const ColourLut lut = colourLut(layerPreviewStyle(layerShownBy(colouring)).colormap);
    auto points = mrpt::opengl::CPointCloudColoured::Create();
    points->setName("cells outside the mesh");
    points->setPointSize(2);
    // The known cells in memory order (column-major, mostly NaN).
    forEachFinite(heights.heights_m.data(), size_t(heights.heights_m.size()), [&](size_t i) {
        const int ix = int(i / size_t(ny)), iy = int(i % size_t(ny));
        if (inAQuad(ix, iy)) return;
        const float v = values.heights_m.data()[i];
        const mrpt::img::TColor c =
            std::isfinite(v) ? cellColour(v, colouring, lut, r) : mrpt::img::TColor(128, 128, 128);
        points->push_back(float(heights.xllcenter_m + ix * heights.cellsize_m),
                          float(heights.yllcenter_m + iy * heights.cellsize_m),
                          heights.heights_m.data()[i], c.R / 255.f, c.G / 255.f, c.B / 255.f);
    });
    return points;
}

mrpt::opengl::CText::Ptr label(const std::string& text, const mrpt::math::TPoint3D& at,
                               mrpt::img::TColor colour = mrpt::img::TColor(30, 30, 30)) {
    auto t = mrpt::opengl::CText::Create(text);
    t->setLocation(at);
    t->setColor_u8(colour);
    return t;
}

/** Scale: a grid of nice spacing just under the lowest cell, its spacing written beside it. */
void addScaleGrid(const EsriAsciiGrid& heights, float zLo_m, mrpt::opengl::CSetOfObjects& into) {
    const double xSpan = heights.xMax_m() - heights.xllcenter_m,
                 ySpan = heights.yMax_m() - heights.yllcenter_m;
    const double step = niceStep(std::max(xSpan, ySpan) / 8);
    const double x0 = std::floor(heights.xllcenter_m / step) * step,
                 y0 = std::floor(heights.yllcenter_m / step) * step;
    const double x1 = std::ceil(heights.xMax_m() / step) * step,
                 y1 = std::ceil(heights.yMax_m() / step) * step;
    auto grid = mrpt::opengl::CGridPlaneXY::Create(x0, x1, y0, y1, zLo_m - 0.01, step);
    grid->setName("grid");
    grid->setColor_u8(mrpt::img::TColor(90, 90, 90));
    into.insert(grid);
    char buf[64];
    std::snprintf(buf, sizeof buf, "grid: %g m", step);
    into.insert(label(buf, {x0, y0 - 0.5 * step, zLo_m}));
}

/** Where the legend is: its lower-left corner and axes (x right, y up, z towards the camera). */
struct LegendFrame {
    mrpt::poses::CPose3D pose;
    double width_m = 0, height_m = 0;
};

/** The legend's frame: beside the map on the default view's right, facing that view, its height
 * a fixed share of the map's extent (so it reads the same on a 1 m and a 40 m map once framed). */
LegendFrame legendFrame(const EsriAsciiGrid& heights, const ViewRanges& r) {
    const TerrainViewDirection d;
    const double xSpan = heights.xMax_m() - heights.xllcenter_m,
                 ySpan = heights.yMax_m() - heights.yllcenter_m;
    const double halfDiagonal_m = 0.5 * std::hypot(xSpan, ySpan);
    LegendFrame f;
    f.height_m = halfDiagonal_m;
    f.width_m = 0.07 * f.height_m;
    const mrpt::math::TPoint3D centre(0.5 * (heights.xllcenter_m + heights.xMax_m()),
                                      0.5 * (heights.yllcenter_m + heights.yMax_m()),
                                      0.5 * (r.zLo_m + r.zHi_m));
    const mrpt::math::TPoint3D corner =
        centre + d.right() * (1.1 * halfDiagonal_m) - d.up() * (0.5 * f.height_m);
    f.pose = mrpt::poses::CPose3D::FromRotationAndTranslation(
        d.axes(), mrpt::math::CVectorFixedDouble<3>({corner.x, corner.y, corner.z}));
    return f;
}

/** The colour bar: a CMesh of 2 x 64 vertices in the legend's plane, the layer's colour map from
 * its low end (bottom) to its high end (top), unlit so its colours are the map's. One more row of
 * vertices at each end, masked out, keeps the renderer's texture wrap (the top colour blended with
 * the bottom one) off the drawn bar. */
mrpt::opengl::CMesh::Ptr colourBar(const LegendFrame& f, SceneColouring colouring) {
    constexpr int kSteps = 64, kRows = kSteps + 2;
    const double step_m = f.height_m / (kSteps - 1);
    const ColourLut lut = colourLut(layerPreviewStyle(layerShownBy(colouring)).colormap);
    mrpt::math::CMatrixDynamic<float> Z(2, kRows), mask(2, kRows);
    Z.setZero(), mask.fill(1.f);
    mrpt::img::CImage texture(kRows, 2, mrpt::img::CH_RGB);
    for (int i = 0; i < 2; i++) {
        mask(i, 0) = mask(i, kRows - 1) = 0.f;
        for (int j = 0; j < kRows; j++) {
            const int k = std::clamp(j - 1, 0, kSteps - 1);
            texture.setPixel(j, i, toColor(colourAt(lut, float(k) / (kSteps - 1))));
        }
    }
    auto bar = mrpt::opengl::CMesh::Create();
    bar->setName("colour bar");
    bar->setGridLimits(0.0, f.width_m, -step_m, f.height_m + step_m);
    bar->assignImageAndZ(texture, Z);
    bar->setMask(mask);
    bar->enableLight(false);
    bar->setPose(f.pose);
    return bar;
}

/** The labels' format: three decimals, more when five labels over [lo, hi] would repeat one. */
std::string valueFormat(SceneColouring colouring, const ViewRanges& r) {
    if (colouring == SceneColouring::Certainty) return "%.0f";
    const double step = (r.hi - r.lo) / 4;
    const int decimals = step > 0 ? std::clamp(int(std::ceil(-std::log10(step))) + 1, 3, 6) : 3;
    return "%." + std::to_string(decimals) + "f m";
}

/** A colour bar with five values and the layer's name, or the categories of the source layer,
 * as CText labels (drawn upright, facing the screen, at a fixed size in pixels). */
void addLegend(const LegendFrame& f, SceneColouring colouring, const ViewRanges& r,
               mrpt::opengl::CSetOfObjects& into) {
    auto at = [&](double right_m, double up_m) {
        return f.pose.composePoint(mrpt::math::TPoint3D(right_m, up_m, 0));
    };
    if (colouring == SceneColouring::Source) {
        double up_m = f.height_m;
        for (const RasterCategory& k : heightSourceCategories()) {
            into.insert(label(k.name, at(0, up_m), toColor({k.rgb[0], k.rgb[1], k.rgb[2]})));
            up_m -= 0.12 * f.height_m;
        }
        return;
    }
    into.insert(colourBar(f, colouring));
    const std::string format = valueFormat(colouring, r);
    char buf[64];
    for (int k = 0; k <= (r.hi > r.lo ? 4 : 0); k++) {  // one label for a single value
        std::snprintf(buf, sizeof buf, format.c_str(), r.lo + (r.hi - r.lo) * k / 4.0);
        into.insert(label(buf, at(1.5 * f.width_m, f.height_m * k / 4.0)));
    }
    std::snprintf(buf, sizeof buf, "%s%s", sceneColouringName(colouring),
                  colouring == SceneColouring::Certainty ? " c [-]" : " [m]");
    into.insert(label(buf, at(0, 1.08 * f.height_m)));
}

}  // namespace

mrpt::math::CMatrixDouble33 TerrainViewDirection::axes() const {
    mrpt::math::CMatrixDouble33 R;
    const mrpt::math::TVector3D r = right(), u = up(), n = towardsCamera();
    for (int i = 0; i < 3; i++) R(i, 0) = r[i], R(i, 1) = u[i], R(i, 2) = n[i];
    return R;
}

mrpt::math::TVector3D TerrainViewDirection::towardsCamera() const {
    const double a = mrpt::DEG2RAD(azimuth_deg), e = mrpt::DEG2RAD(elevation_deg);
    return {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
}
mrpt::math::TVector3D TerrainViewDirection::right() const {
    const double a = mrpt::DEG2RAD(azimuth_deg);
    return {-std::sin(a), std::cos(a), 0};
}
mrpt::math::TVector3D TerrainViewDirection::up() const {
    return mrpt::math::crossProduct3D(towardsCamera(), right());
}

void buildTerrainView(const CMultiBinElevationMap& map, SceneColouring colouring,
                      mrpt::opengl::CSetOfObjects& out) {
    // Coloured by height, the heights are read once and serve as both rasters (viewRasters()).
    const Layer shown = layerShownBy(colouring);
    const std::vector<TiledRaster> layers =
        knownLayers(map, shown == Layer::Height ? std::vector<Layer>{Layer::Height}
                                                : std::vector<Layer>{Layer::Height, shown});
    buildTerrainView(layers.front(), layers.back(), map.mapOrigin(), colouring, out);
}

void buildTerrainView(const TiledRaster& heightLayer, const TiledRaster& shownLayer,
                      const mrpt::math::TPoint2D& origin, SceneColouring colouring,
                      mrpt::opengl::CSetOfObjects& out) {
    const std::vector<EsriAsciiGrid> rasters =
        viewRasters(heightLayer, shownLayer, layerShownBy(colouring));
    const EsriAsciiGrid &heights = rasters.front(), &values = rasters.back();
    if (heights.cols() < 2 || heights.rows() < 2) return;
    // Built relative to the map origin and placed at it, so the view's floats stay small at
    // georeferenced coordinates.
    auto placed = mrpt::opengl::CSetOfObjects::Create();
    placed->setName("map origin");
    placed->setLocation(origin.x, origin.y, 0);
    const bool atZero = origin.x == 0 && origin.y == 0;
    mrpt::opengl::CSetOfObjects& into = atZero ? out : *placed;

    const ViewRanges r = viewRanges(heights, values, colouring);
    for (const auto& mesh : terrainMeshes(heights, values, colouring, r)) into.insert(mesh);
    if (auto lone = loneCells(heights, values, colouring, r); lone->size() > 0) into.insert(lone);
    addScaleGrid(heights, r.zLo_m, into);
    addLegend(legendFrame(heights, r), colouring, r, into);
    if (!atZero) out.insert(placed);
}

TerrainCamera frameTerrainView(const mrpt::math::TBoundingBox& box, double aspect) {
    const TerrainViewDirection d;
    TerrainCamera cam;
    cam.target = 0.5 * (box.min + box.max);
    // The nearest distance at which every corner of the box is inside 90 % of the field of view:
    // a corner q (from the target) at depth distance - q.n needs |q.up| <= tan(fov/2) depth.
    const double t = 0.9 * std::tan(mrpt::DEG2RAD(0.5 * d.fov_deg));
    double distance_m = 0;
    for (int k = 0; k < 8; k++) {
        const mrpt::math::TPoint3D c((k & 1) ? box.max.x : box.min.x,
                                     (k & 2) ? box.max.y : box.min.y,
                                     (k & 4) ? box.max.z : box.min.z);
        const mrpt::math::TVector3D q = c - cam.target;
        const double depth =
            q.x * d.towardsCamera().x + q.y * d.towardsCamera().y + q.z * d.towardsCamera().z;
        const double up = std::abs(q.x * d.up().x + q.y * d.up().y + q.z * d.up().z);
        const double side = std::abs(q.x * d.right().x + q.y * d.right().y);
        distance_m = std::max({distance_m, depth + up / t, depth + side / (t * aspect)});
    }
    cam.distance_m = std::max(distance_m, 0.1);
    return cam;
}

void frameTerrainScene(mrpt::opengl::COpenGLScene& scene) {
    auto view = scene.getViewport("main");
    if (!view || view->size() == 0) return;
    // The text labels' boxes are their anchor points: the margin of 90 % keeps them on screen.
    const TerrainCamera cam = frameTerrainView(view->getBoundingBox(), kTerrainViewAspect);
    const TerrainViewDirection d;
    mrpt::opengl::CCamera& c = view->getCamera();
    c.setPointingAt(cam.target);
    c.setZoomDistance(float(cam.distance_m));
    c.setAzimuthDegrees(float(d.azimuth_deg));
    c.setElevationDegrees(float(d.elevation_deg));
    c.setProjectiveFOVdeg(float(d.fov_deg));
    // SceneViewer3D starts from this camera (instead of its fixed 20 m from the origin).
    scene.enableFollowCamera(true);
    // A light background: the labels are dark, as on the PNG previews.
    view->setCustomBackgroundColor(mrpt::img::TColorf(0.93f, 0.93f, 0.93f));
}

}  // namespace multibin

void CMultiBinElevationMap::getVisualizationInto(mrpt::opengl::CSetOfObjects& outObj) const {
    prepareForReading();
    const multibin::MapLock::Shared lock(m_impl->lock);
    if (!genericMapParams.enableSaveAs3DObject) return;
    multibin::buildTerrainView(*this,
                               insertionOptions.render.color_by_sigma
                                   ? multibin::SceneColouring::Sigma
                                   : multibin::SceneColouring::Height,
                               outObj);
}
