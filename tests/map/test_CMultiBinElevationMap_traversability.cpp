/* CMultiBinElevationMap's traversability: options, live update, MRPT planning inputs. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CMultiMetricMap.h>
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CObservationPointCloud.h>

#include <cmath>
#include <random>

#include "multibin/traversability/TerrainFeatures.h"

using mrpt::maps::CMultiBinElevationMap;
using namespace multibin;

namespace {
/** A map of [0, 0.6] x [0, 0.4] m, 2 cm cells, with 16 points per cell of z = f(x, y) + noise. */
template <typename F>
CMultiBinElevationMap mapOf(F f, double sigma_m = 0.002, unsigned seed = 1) {
    CMultiBinElevationMap::TCreationOptions c;
    c.resolution_m = 0.02;
    c.grow = false;
    c.min_x = c.min_y = 0;
    c.max_x = 0.6, c.max_y = 0.4;
    c.origin_auto = false;
    CMultiBinElevationMap map(c);
    PointsWithCov pts;
    std::mt19937 rng(seed);
    std::normal_distribution<double> n01;
    for (double y = 0.0025; y < 0.4; y += 0.005)
        for (double x = 0.0025; x < 0.6; x += 0.005) {
            PointWithCov p;
            p.point_m = Eigen::Vector3f(float(x), float(y), float(f(x, y) + sigma_m * n01(rng)));
            p.cov_m2 = {1e-8f, 0, 0, 1e-8f, 0, float(sigma_m * sigma_m)};
            pts.push_back(p);
        }
    map.insertPoints(pts);
    return map;
}
}  // namespace

TEST(TraversabilityOptions, ReadStrictlyFromTheMapsIniSection) {
    const std::string ini =
        "[map]\nmultiBinElevationMap_count = 1\n"
        "[map_multiBinElevationMap_00_creationOpts]\nresolution = 0.02\n"
        "[map_multiBinElevationMap_00_traversabilityOpts]\nradius_m = 0.08\nmax_step_m = 0.1\n"
        "max_slope_deg = 20\nmax_roughness_m = 0.03\nfoot_radius_m = 0.03\n";
    mrpt::maps::TSetOfMetricMapInitializers inits;
    inits.loadFromConfigFile(mrpt::config::CConfigFileMemory(ini), "map");
    mrpt::maps::CMultiMetricMap mm;
    mm.setListOfMaps(inits);
    const auto map = mm.mapByClass<CMultiBinElevationMap>();
    ASSERT_TRUE(map);
    EXPECT_EQ(map->traversabilityOptions.radius_m, 0.08);
    EXPECT_EQ(map->traversabilityOptions.max_step_m, 0.1);
    EXPECT_EQ(map->traversabilityOptions.max_slope_deg, 20);
    EXPECT_EQ(map->traversabilityOptions.max_roughness_m, 0.03);
    EXPECT_EQ(map->traversabilityOptions.foothold.radius_m, 0.03);

    const auto errorOf = [](const std::string& text) -> std::string {
        try {
            mrpt::maps::TSetOfMetricMapInitializers i;
            i.loadFromConfigFile(mrpt::config::CConfigFileMemory(text), "map");
        } catch (const std::exception& e) {
            return e.what();
        }
        return "";
    };
    const std::string head =
        "[map]\nmultiBinElevationMap_count = 1\n"
        "[map_multiBinElevationMap_00_traversabilityOpts]\n";
    const std::string unknown = errorOf(head + "max_step = 0.1\n");
    EXPECT_NE(unknown.find("max_step"), std::string::npos) << unknown;
    EXPECT_NE(unknown.find("traversabilityOpts"), std::string::npos) << unknown;
    const std::string negative = errorOf(head + "max_step_m = -0.1\n");
    EXPECT_NE(negative.find("max_step_m"), std::string::npos) << negative;
    EXPECT_NE(negative.find("positive"), std::string::npos) << negative;
    const std::string misspelt = errorOf(
        "[map]\nmultiBinElevationMap_count = 1\n"
        "[map_multiBinElevationMap_00_traversabilityOpt]\n");
    EXPECT_NE(misspelt.find("unknown section"), std::string::npos) << misspelt;
}

TEST(TraversabilityMap, ATiltedPlaneHasItsSlopeAndIsUntraversableBeyondTheLimit) {
    const double a = 25.0 * M_PI / 180;
    CMultiBinElevationMap map = mapOf([&](double x, double) { return std::tan(a) * x; });
    map.traversabilityOptions.max_slope_deg = 30;
    traversability::TraversabilityLayers t = map.traversabilityLayers();
    const size_t c = t.lattice.index(15, 10);
    EXPECT_NEAR(t.slope_deg[c], 25.0, 1.0);
    EXPECT_LT(t.untraversable[c], 0.05);
    map.traversabilityOptions.max_slope_deg = 20;
    t = map.traversabilityLayers();
    EXPECT_GT(t.untraversable[c], 0.95);
}

TEST(TraversabilityMap, TheLiveUpdateEqualsAFullRecompute) {
    CMultiBinElevationMap map =
        mapOf([](double x, double y) { return 0.03 * std::sin(20 * x + 10 * y); });
    (void)map.traversabilityLayers();
    // New points on a box in one corner, then the layers updated where the map changed.
    PointsWithCov pts;
    for (double y = 0.0025; y < 0.1; y += 0.005)
        for (double x = 0.0025; x < 0.1; x += 0.005) {
            PointWithCov p;
            p.point_m = Eigen::Vector3f(float(x), float(y), 0.15f);
            p.cov_m2 = {1e-8f, 0, 0, 1e-8f, 0, 4e-6f};
            pts.push_back(p);
        }
    map.insertPoints(pts);
    const traversability::TraversabilityLayers live = map.traversabilityLayers();
    const CMultiBinElevationMap copy = map;  // a copy computes its layers afresh
    const traversability::TraversabilityLayers full = copy.traversabilityLayers();
    ASSERT_EQ(live.size(), full.size());
    int differ = 0, changedFromBefore = 0;
    for (size_t k = 0; k < live.size(); k++) {
        const bool same =
            (std::isnan(live.untraversable[k]) && std::isnan(full.untraversable[k])) ||
            (live.untraversable[k] == full.untraversable[k] && live.step_m[k] == full.step_m[k] &&
             live.foothold[k] == full.foothold[k]);
        differ += !same;
        changedFromBefore += live.untraversable[k] > 0.5;
    }
    EXPECT_EQ(differ, 0);
    EXPECT_GT(changedFromBefore, 10);  // the box's edge is a step
}

TEST(TraversabilityMap, OccupancyGridPointsAndFoothold) {
    // A box 0.1 m high on x > 0.3: its edge untraversable, the rest free.
    CMultiBinElevationMap map = mapOf([](double x, double) { return x > 0.3 ? 0.1 : 0.0; });
    mrpt::maps::COccupancyGridMap2D grid;
    map.getAsOccupancyGrid(grid);
    EXPECT_NEAR(grid.getResolution(), 0.02, 1e-6);
    EXPECT_NEAR(grid.getXMin(), 0.0, 1e-4);
    EXPECT_NEAR(grid.getXMax(), 0.6, 1e-4);
    // MRPT's cells hold P(free).
    EXPECT_GT(grid.getPos(0.1, 0.2), 0.95f);
    EXPECT_LT(grid.getPos(0.31, 0.2), 0.05f);
    EXPECT_GT(grid.getPos(0.5, 0.2), 0.95f);
    EXPECT_NEAR(grid.getPos(0.7, 0.2), 0.5f, 0.01f);  // outside: not in the grid

    mrpt::maps::CSimplePointsMap pts;
    map.getUntraversablePoints(pts);
    ASSERT_GT(pts.size(), 20u);
    for (size_t i = 0; i < pts.size(); i++) {
        float x, y, z;
        pts.getPoint(i, x, y, z);
        EXPECT_NEAR(x, 0.3, 0.07) << i;
    }
    const auto f = map.bestFoothold(0.3, 0.2, 0.1);
    ASSERT_TRUE(f.found);
    EXPECT_GT(f.probability, 0.9);
    EXPECT_GT(std::abs(f.x_m - 0.3), 0.03);  // away from the edge
    EXPECT_NEAR(f.z_m, f.x_m > 0.3 ? 0.1 : 0.0, 0.01);
    EXPECT_FALSE(map.bestFoothold(2.0, 2.0, 0.1).found);
}

TEST(TraversabilityMap, TheLiveUpdateAfterTheWindowGrewEqualsAFullRecompute) {
    // Point clouds seen from a robot at the origin: the map grows to cover each.
    CMultiBinElevationMap map;
    const auto cloud = [](double x0, double z) {
        auto obs = mrpt::obs::CObservationPointCloud::Create();
        obs->sensorLabel = "CLOUD";
        auto pts = mrpt::maps::CSimplePointsMap::Create();
        for (double y = -0.15; y < 0.15; y += 0.005)
            for (double x = x0; x < x0 + 0.3; x += 0.005)
                pts->insertPoint(float(x), float(y), float(z + 0.2 * (x - x0)));
        obs->pointcloud = pts;
        return obs;
    };
    const mrpt::poses::CPose3D robot;
    ASSERT_TRUE(map.insertObservation(*cloud(0.2, 0.0), robot));
    const auto before = map.traversabilityLayers();
    ASSERT_TRUE(map.insertObservation(*cloud(3.0, 0.1), robot));
    const auto live = map.traversabilityLayers();
    ASSERT_FALSE(live.lattice == before.lattice);  // the window grew
    const CMultiBinElevationMap copy = map;        // a copy computes its layers afresh
    const auto full = copy.traversabilityLayers();
    ASSERT_EQ(live.size(), full.size());
    int differ = 0, known = 0;
    for (size_t k = 0; k < live.size(); k++) {
        differ +=
            !((std::isnan(live.untraversable[k]) && std::isnan(full.untraversable[k])) ||
              (live.untraversable[k] == full.untraversable[k] && live.step_m[k] == full.step_m[k]));
        known += live.known(k);
    }
    EXPECT_EQ(differ, 0);
    EXPECT_GT(known, 200);
}
