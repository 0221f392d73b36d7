/* The 3D terrain view (multibin::buildTerrainView, CMultiBinElevationMap::getVisualizationInto)
 * as MRPT 2.5's renderer draws it: every colouring shows a spread of colours over the terrain
 * (MRPT 2.5.8 draws a CMesh's per-vertex colours as one colour), unknown cells are left out, a
 * legend is in the scene, and the saved .3Dscene loads and renders without an assertion
 * (color_by_sigma used to write a texture of the wrong size). */
#include <gtest/gtest.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/opengl/CColorBar.h>
#include <mrpt/opengl/CFBORender.h>
#include <mrpt/opengl/CMesh.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CText.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>

#include "multibin/map/TerrainView.h"

namespace fs = std::filesystem;
using mrpt::maps::CMultiBinElevationMap;
using multibin::SceneColouring;

namespace {

/** A 1 x 0.6 m ramp (height 0.2 x [m]) whose point sigma grows with x and whose points per cell
 * grow with y, so height, sigma and certainty all vary; a 4 x 4 cell hole in it is filled by the
 * weighted median (source: measured and filled). */
CMultiBinElevationMap& rampMap() {
    static std::unique_ptr<CMultiBinElevationMap> map;
    if (map) return *map;
    map = std::make_unique<CMultiBinElevationMap>();
    map->creationOptions.resolution_m = 0.02;
    map->setCreationOptions(map->creationOptions);
    map->insertionOptions.height_sigma_floor_m = 0.0005;
    mrpt::maps::CHeightGridMap2D_Base::TPointInsertParams p;
    for (int i = 0; i < 50; i++)
        for (int j = 0; j < 30; j++) {
            if (i >= 23 && i < 27 && j >= 13 && j < 17) continue;  // the hole
            const double x = 0.01 + 0.02 * i, y = 0.01 + 0.02 * j;
            p.pt_z_std = 0.001 + 0.01 * x;
            for (int k = 0; k <= j / 6; k++) map->insertIndividualPoint(x, y, 0.2 * x, p);
        }
    map->dem_update_map();
    return *map;
}

/** The number of 30-degree hue sectors that hold at least `minShare` of the saturated pixels
 * (saturation > 0.35, value > 0.2) of an RGB image, and how many such pixels there are. Grey
 * background, grid and text do not count. */
std::pair<int, size_t> hueSectors(const mrpt::img::CImage& img, double minShare = 0.01) {
    std::map<int, size_t> sectors;
    size_t saturated = 0;
    for (int y = 0; y < int(img.getHeight()); y++)
        for (int x = 0; x < int(img.getWidth()); x++) {
            // CImage keeps colour pixels as OpenCV does: B, G, R.
            const double b = img.at<uint8_t>(x, y, 0) / 255.0, g = img.at<uint8_t>(x, y, 1) / 255.0,
                         r = img.at<uint8_t>(x, y, 2) / 255.0;
            const double mx = std::max({r, g, b}), mn = std::min({r, g, b}), d = mx - mn;
            if (mx < 0.2 || d / mx < 0.35) continue;
            double h = mx == r   ? std::fmod((g - b) / d, 6.0)
                       : mx == g ? (b - r) / d + 2
                                 : (r - g) / d + 4;
            if (h < 0) h += 6;
            sectors[int(h * 60.0 / 30.0) % 12]++;
            saturated++;
        }
    int n = 0;
    for (const auto& [s, count] : sectors)
        if (count >= minShare * double(saturated)) n++;
    return {n, saturated};
}

/** The terrain mesh of a view. */
mrpt::opengl::CMesh::Ptr meshOf(const mrpt::opengl::CSetOfObjects& view) {
    for (const auto& o : view)
        if (auto m = std::dynamic_pointer_cast<mrpt::opengl::CMesh>(o)) return m;
    return {};
}

/** Renders `scene` from above (centre of the ramp); nullopt when no OpenGL (EGL) is available.
 * One renderer (one EGL context) for the whole program: MRPT's objects keep their OpenGL buffers
 * in the context that first drew them. */
std::optional<mrpt::img::CImage> renderFromAbove(const mrpt::opengl::COpenGLScene& scene) {
    static std::unique_ptr<mrpt::opengl::CFBORender> render;
    static bool unavailable = false;
    if (unavailable) return std::nullopt;
    try {
        if (!render)
            render = std::make_unique<mrpt::opengl::CFBORender>(
                mrpt::opengl::CFBORender::Parameters(400, 300));
    } catch (const std::exception& e) {
        std::cerr << "no offscreen OpenGL: " << e.what() << "\n";
        unavailable = true;
        return std::nullopt;
    }
    auto& cam = render->getCamera(scene);
    cam.setPointingAt(0.5, 0.3, 0.1);
    cam.setZoomDistance(1.4);
    cam.setAzimuthDegrees(-90);
    cam.setElevationDegrees(70);
    mrpt::img::CImage img;
    render->render_RGB(scene, img);
    return img;
}

}  // namespace

class TerrainView : public ::testing::TestWithParam<SceneColouring> {};

// The view's objects: a textured mesh with one texel per cell, masked where unknown; a colour bar
// (or a categorical legend of texts); the texels of known cells spread over the colours.
TEST_P(TerrainView, MeshTexelsSpreadOverTheColoursAndALegendIsInTheScene) {
    const SceneColouring colouring = GetParam();
    mrpt::opengl::CSetOfObjects view;
    multibin::buildTerrainView(rampMap(), colouring, view);
    const auto mesh = meshOf(view);
    ASSERT_TRUE(mesh);
    mrpt::math::CMatrixFloat mask;
    mesh->getMask(mask);
    const mrpt::img::CImage& texture = mesh->getTextureImage();
    ASSERT_EQ(size_t(mask.rows()), texture.getHeight());
    ASSERT_EQ(size_t(mask.cols()), texture.getWidth());
    // Known cells only: the ramp's 50 x 30 cells (hole filled) plus a 1-cell margin left out.
    EXPECT_EQ(mask.sum(), 50.f * 30.f);
    EXPECT_EQ(mask.rows() * mask.cols(), 52 * 32);

    const auto [sectors, saturated] = hueSectors(texture, 0.005);
    if (colouring == SceneColouring::Source)
        EXPECT_GE(sectors, 2) << "measured and filled cells in distinct colours";
    else
        EXPECT_GE(sectors, 4) << "colours of " << multibin::sceneColouringName(colouring);

    size_t bars = 0, texts = 0;
    for (const auto& o : view) {
        bars += std::dynamic_pointer_cast<mrpt::opengl::CColorBar>(o) != nullptr;
        texts += std::dynamic_pointer_cast<mrpt::opengl::CText>(o) != nullptr;
    }
    if (colouring == SceneColouring::Source)
        EXPECT_GE(texts, 4u) << "three category labels and the grid's spacing";
    else
        EXPECT_EQ(bars, 1u);
}

// The saved .3Dscene loads with MRPT's own loader and renders without an assertion; the rendered
// terrain (the mesh alone, without the legend) shows the colour spread on screen.
TEST_P(TerrainView, SavedSceneLoadsAndRendersInColour) {
    const SceneColouring colouring = GetParam();
    const fs::path dir = fs::path(MULTIBIN_BINARY_DIR) / "test_terrain_view";
    fs::create_directories(dir);
    const fs::path file = dir / (std::string(multibin::sceneColouringName(colouring)) + ".3Dscene");
    {
        mrpt::opengl::COpenGLScene scene;
        auto view = mrpt::opengl::CSetOfObjects::Create();
        multibin::buildTerrainView(rampMap(), colouring, *view);
        scene.insert(view);
        ASSERT_TRUE(scene.saveToFile(file.string()));
    }
    mrpt::opengl::COpenGLScene loaded;
    ASSERT_TRUE(loaded.loadFromFile(file.string()));
    const auto view = loaded.getByClass<mrpt::opengl::CSetOfObjects>();
    ASSERT_TRUE(view);
    const auto mesh = meshOf(*view);
    ASSERT_TRUE(mesh);

    const auto whole = renderFromAbove(loaded);  // every object, legend included
    if (!whole) GTEST_SKIP() << "no offscreen OpenGL context (EGL) on this machine";
    mrpt::opengl::COpenGLScene terrainOnly;
    mrpt::opengl::CSetOfObjects alone;
    multibin::buildTerrainView(rampMap(), colouring, alone);
    terrainOnly.insert(meshOf(alone));
    const auto img = renderFromAbove(terrainOnly);
    ASSERT_TRUE(img);
    const auto [sectors, saturated] = hueSectors(*img);
    EXPECT_GT(saturated, 400 * 300 / 10u) << "the terrain covers a good part of the view";
    if (colouring == SceneColouring::Source)
        EXPECT_GE(sectors, 1);  // measured blue; the 16 filled cells are a small share
    else
        EXPECT_GE(sectors, 4) << "rendered colours of " << multibin::sceneColouringName(colouring);
}

INSTANTIATE_TEST_SUITE_P(EachColouring, TerrainView,
                         ::testing::Values(SceneColouring::Height, SceneColouring::Sigma,
                                           SceneColouring::Certainty, SceneColouring::Source),
                         [](const auto& info) {
                             return std::string(multibin::sceneColouringName(info.param));
                         });

// color_by_sigma = true through the map's own getVisualizationInto(): a scene that loads and
// renders (it used to fail "mask.cols() == cols && mask.rows() == rows" in SceneViewer3D).
TEST(TerrainViewMap, ColorBySigmaWritesASceneThatRenders) {
    CMultiBinElevationMap& map = rampMap();
    map.insertionOptions.color_by_sigma = true;
    mrpt::opengl::COpenGLScene scene;
    auto view = mrpt::opengl::CSetOfObjects::Create();
    map.getVisualizationInto(*view);
    map.insertionOptions.color_by_sigma = false;
    scene.insert(view);
    const fs::path file = fs::path(MULTIBIN_BINARY_DIR) / "test_terrain_view" / "by_sigma.3Dscene";
    fs::create_directories(file.parent_path());
    ASSERT_TRUE(scene.saveToFile(file.string()));
    mrpt::opengl::COpenGLScene loaded;
    ASSERT_TRUE(loaded.loadFromFile(file.string()));
    const auto img = renderFromAbove(loaded);
    if (!img) GTEST_SKIP() << "no offscreen OpenGL context (EGL) on this machine";
    EXPECT_GE(hueSectors(*img).first, 4);
}

// A map that knows no cell gives an empty view, not a mesh of unknown cells.
TEST(TerrainViewMap, EmptyMapGivesNoObjects) {
    CMultiBinElevationMap empty;
    mrpt::opengl::CSetOfObjects view;
    multibin::buildTerrainView(empty, SceneColouring::Height, view);
    EXPECT_EQ(view.size(), 0u);
}
