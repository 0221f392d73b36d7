/* The 3D terrain view (multibin::buildTerrainView, CMultiBinElevationMap::getVisualizationInto)
 * as MRPT 2.5's renderer draws it: every colouring shows a spread of colours over the terrain
 * (MRPT 2.5.8 draws a CMesh's per-vertex colours as one colour), unknown cells are left out, a
 * legend is in the scene, and the saved .3Dscene loads and renders without an assertion
 * (color_by_sigma used to write a texture of the wrong size). */
#include <gtest/gtest.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
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
#include <set>

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
    // Known cells only: the ramp's 50 x 30 cells (hole filled); the mesh spans their box, not
    // the 1-cell margin around them (masked vertices draw nothing).
    EXPECT_EQ(mask.sum(), 50.f * 30.f);
    EXPECT_EQ(mask.rows() * mask.cols(), 50 * 30);

    const auto [sectors, saturated] = hueSectors(texture, 0.005);
    if (colouring == SceneColouring::Source)
        EXPECT_GE(sectors, 2) << "measured and filled cells in distinct colours";
    else
        EXPECT_GE(sectors, 4) << "colours of " << multibin::sceneColouringName(colouring);

    size_t bars = 0, texts = 0;
    for (const auto& o : view) {
        bars += std::dynamic_pointer_cast<mrpt::opengl::CMesh>(o) && o->getName() == "colour bar";
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
    map.insertionOptions.render.color_by_sigma = true;
    mrpt::opengl::COpenGLScene scene;
    auto view = mrpt::opengl::CSetOfObjects::Create();
    map.getVisualizationInto(*view);
    map.insertionOptions.render.color_by_sigma = false;
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

namespace {

/** A square map of `side_m` (50 x 50 cells) on a slope rising 10 % of the side along x. */
std::unique_ptr<CMultiBinElevationMap> squareMap(double side_m) {
    auto map = std::make_unique<CMultiBinElevationMap>();
    map->creationOptions.resolution_m = side_m / 50;
    map->setCreationOptions(map->creationOptions);
    map->insertionOptions.fill.enabled = false;
    map->insertionOptions.max_elevation_uncertainty_m = 10;
    mrpt::maps::CHeightGridMap2D_Base::TPointInsertParams p;
    p.pt_z_std = 0.001;
    for (int i = 0; i < 50; i++)
        for (int j = 0; j < 50; j++) {
            const double x = (i + 0.5) * side_m / 50, y = (j + 0.5) * side_m / 50;
            map->insertIndividualPoint(x, y, 0.1 * x, p);
        }
    map->dem_update_map();
    return map;
}

/** An object of a view by name (searched in placed sets too). */
mrpt::opengl::CRenderizable::Ptr byName(const mrpt::opengl::CSetOfObjects& view,
                                        const std::string& name) {
    for (const auto& o : view) {
        if (o->getName() == name) return o;
        if (auto set = std::dynamic_pointer_cast<mrpt::opengl::CSetOfObjects>(o))
            if (auto found = byName(*set, name)) return found;
    }
    return {};
}

/** The screen of an orbit camera as MRPT's COpenGLViewport places it (eye at azimuth and
 * elevation around the target, z up): normalized device coordinates of a point (-1..1 on each
 * axis is in view) for a window of width/height `aspect`. */
struct OrbitScreen {
    Eigen::Vector3d eye, right, up, forward;
    double tanHalfFov, aspect;
    OrbitScreen(const mrpt::opengl::CCamera& c, double aspect_) : aspect(aspect_) {
        const double a = mrpt::DEG2RAD(c.getAzimuthDegrees()),
                     e = mrpt::DEG2RAD(c.getElevationDegrees());
        const Eigen::Vector3d target(c.getPointingAtX(), c.getPointingAtY(), c.getPointingAtZ());
        eye =
            target + c.getZoomDistance() * Eigen::Vector3d(std::cos(e) * std::cos(a),
                                                           std::cos(e) * std::sin(a), std::sin(e));
        forward = (target - eye).normalized();
        right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
        up = right.cross(forward);
        tanHalfFov = std::tan(mrpt::DEG2RAD(0.5 * c.getProjectiveFOVdeg()));
    }
    Eigen::Vector2d ndc(const Eigen::Vector3d& p) const {
        const Eigen::Vector3d q = p - eye;
        const double depth = q.dot(forward);
        return {q.dot(right) / (depth * tanHalfFov * aspect), q.dot(up) / (depth * tanHalfFov)};
    }
};

}  // namespace

// The legend of a 1 m and a 40 m map, seen from SceneViewer3D's default direction (azimuth and
// elevation 45 degrees): the colour bar's plane faces the camera (its normal along the view
// direction, its long side along the screen's up), so its value labels read upright and the low
// value is at the bottom; the bar is as tall as half the map's diagonal, 40 times taller on the
// 40 m map. It used to lie flat, a fixed 1 m tall once saved, its labels upside down from there.
TEST(TerrainViewLegend, FacesTheDefaultCameraAndScalesWithTheMap) {
    const Eigen::Vector3d towardsCamera(0.5, 0.5, std::sqrt(0.5));  // azimuth, elevation 45 deg
    const Eigen::Vector3d screenUp = Eigen::Vector3d(-0.5, -0.5, std::sqrt(0.5));
    std::map<double, double> barHeight_m;
    for (const double side_m : {1.0, 40.0}) {
        const auto map = squareMap(side_m);
        mrpt::opengl::CSetOfObjects view;
        multibin::buildTerrainView(*map, SceneColouring::Height, view);
        const auto bar = std::dynamic_pointer_cast<mrpt::opengl::CMesh>(byName(view, "colour bar"));
        ASSERT_TRUE(bar) << side_m << " m map";
        const Eigen::Matrix3d R = bar->getPoseRef().getRotationMatrix().asEigen();
        EXPECT_GT(R.col(2).dot(towardsCamera), 0.999) << "the bar faces the camera";
        EXPECT_GT(R.col(1).dot(screenUp), 0.999) << "its long side is the screen's up";

        // The value labels, bottom to top along the screen's up, read low to high.
        std::vector<std::pair<double, double>> upAndValue;
        for (const auto& o : view)
            if (auto t = std::dynamic_pointer_cast<mrpt::opengl::CText>(o)) {
                double v = 0;
                if (std::sscanf(t->getString().c_str(), "%lf m", &v) != 1) continue;
                const auto p = t->getPoseRef().translation();
                upAndValue.emplace_back(Eigen::Vector3d(p.x, p.y, p.z).dot(screenUp), v);
            }
        ASSERT_EQ(upAndValue.size(), 5u) << "five value labels";
        std::sort(upAndValue.begin(), upAndValue.end());
        for (size_t k = 1; k < upAndValue.size(); k++)
            EXPECT_GT(upAndValue[k].second, upAndValue[k - 1].second);
        // The labels span the bar: as tall as half the view's diagonal (the known cells and a
        // margin of one cell), as seen by the default camera (the bar faces it).
        barHeight_m[side_m] = upAndValue.back().first - upAndValue.front().first;
        EXPECT_NEAR(barHeight_m[side_m], 0.5 * std::hypot(side_m, side_m) * 51 / 50, 1e-3 * side_m);
        EXPECT_NEAR(upAndValue.front().second, 0.1 * 0.5 * side_m / 50, 0.002 * side_m);
        EXPECT_NEAR(upAndValue.back().second, 0.1 * 49.5 * side_m / 50, 0.002 * side_m);
    }
    EXPECT_NEAR(barHeight_m[40.0] / barHeight_m[1.0], 40.0, 1e-6);
}

// The saved scene of a 1 m and a 40 m map (saveMetricMapRepresentationToFile, as MRPT's tools
// write it) opens framed: SceneViewer3D follows its camera (followCamera), and from it every
// corner of the map's box and the colour bar's ends are inside a 4:3 window, the map spanning at
// least 40 % of the window's width. It used to open at SceneViewer3D's fixed 20 m from the
// origin: a 40 m map showed in fragments, a 1 m map as a speck.
TEST(TerrainViewCamera, SavedSceneFramesTheMapOnItsDefaultCamera) {
    const fs::path dir = fs::path(MULTIBIN_BINARY_DIR) / "test_terrain_view";
    fs::create_directories(dir);
    for (const double side_m : {1.0, 40.0}) {
        const auto map = squareMap(side_m);
        const std::string prefix = (dir / ("square_" + std::to_string(int(side_m)))).string();
        map->saveMetricMapRepresentationToFile(prefix);
        mrpt::opengl::COpenGLScene scene;
        ASSERT_TRUE(scene.loadFromFile(prefix + ".3Dscene"));
        EXPECT_TRUE(scene.followCamera()) << "SceneViewer3D takes the scene's camera";
        const OrbitScreen screen(scene.getViewport("main")->getCamera(), 4.0 / 3.0);
        EXPECT_NEAR(screen.forward.dot(Eigen::Vector3d(-0.5, -0.5, -std::sqrt(0.5))), 1.0, 1e-6)
            << "the default direction, which the legend faces";
        double xLo = 1e9, xHi = -1e9;
        for (int k = 0; k < 8; k++) {
            const Eigen::Vector3d corner((k & 1) ? side_m : 0.0, (k & 2) ? side_m : 0.0,
                                         (k & 4) ? 0.1 * side_m : 0.0);
            const Eigen::Vector2d p = screen.ndc(corner);
            EXPECT_LE(p.cwiseAbs().maxCoeff(), 1.0) << side_m << " m map, corner " << k;
            xLo = std::min(xLo, p.x()), xHi = std::max(xHi, p.x());
        }
        EXPECT_GE(xHi - xLo, 0.4 * 2) << side_m << " m map: the map fills the view";
        const auto view = scene.getByClass<mrpt::opengl::CSetOfObjects>();
        ASSERT_TRUE(view);
        const auto bar =
            std::dynamic_pointer_cast<mrpt::opengl::CMesh>(byName(*view, "colour bar"));
        ASSERT_TRUE(bar);
        const double step_m = (bar->getyMax() - bar->getyMin()) / 65;  // 2 masked rows
        for (const double up : {bar->getyMin() + step_m, bar->getyMax() - step_m}) {
            const auto e = bar->getPoseRef().composePoint(mrpt::math::TPoint3D(0, up, 0));
            EXPECT_LE(screen.ndc({e.x, e.y, e.z}).cwiseAbs().maxCoeff(), 1.0) << "the legend";
        }
    }
}

// The PNG preview and the 3D view draw a value in the same colour: every colour of the height
// scene's known texels is a colour of elevation_height.png (both written by
// saveMetricMapRepresentationToFile, both spanning the heights' whole range). The scene used to
// be in jet, the previews in viridis.
TEST(TerrainViewColours, SceneAndPreviewShareTheColourMap) {
    const fs::path dir = fs::path(MULTIBIN_BINARY_DIR) / "test_terrain_view";
    fs::create_directories(dir);
    const std::string prefix = (dir / "colours").string();
    rampMap().saveMetricMapRepresentationToFile(prefix);
    mrpt::img::CImage preview;
    ASSERT_TRUE(preview.loadFromFile(prefix + "_height.png"));
    std::set<std::array<int, 3>> previewColours;
    for (int y = 0; y < int(preview.getHeight()); y++)
        for (int x = 0; x < int(preview.getWidth()); x++)
            previewColours.insert({preview.at<uint8_t>(x, y, 2), preview.at<uint8_t>(x, y, 1),
                                   preview.at<uint8_t>(x, y, 0)});  // B, G, R
    mrpt::opengl::COpenGLScene scene;
    ASSERT_TRUE(scene.loadFromFile(prefix + ".3Dscene"));
    const auto mesh = meshOf(*scene.getByClass<mrpt::opengl::CSetOfObjects>());
    ASSERT_TRUE(mesh);
    mrpt::math::CMatrixFloat mask;
    mesh->getMask(mask);
    const mrpt::img::CImage& texture = mesh->getTextureImage();
    std::set<std::array<int, 3>> sceneColours;
    size_t missing = 0;
    for (int r = 0; r < int(texture.getHeight()); r++)
        for (int c = 0; c < int(texture.getWidth()); c++) {
            if (mask(r, c) == 0) continue;
            const std::array<int, 3> rgb{texture.at<uint8_t>(c, r, 2), texture.at<uint8_t>(c, r, 1),
                                         texture.at<uint8_t>(c, r, 0)};
            sceneColours.insert(rgb);
            missing += previewColours.count(rgb) == 0;
        }
    EXPECT_GE(sceneColours.size(), 20u) << "the ramp spreads over the colour map";
    EXPECT_EQ(missing, 0u) << "known texels in a colour the preview does not use";
}
