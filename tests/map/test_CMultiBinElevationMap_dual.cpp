/* Tests of the moving grids: circular-buffer scrolling, local/global write-back and fusion. */
#include <gtest/gtest.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CObservationPointCloud.h>

#include <map>
#include <random>

#include "multibin/grid/BinGrid.h"
#include "multibin/map/MapInternals.h"

using namespace multibin;
using mrpt::maps::CMultiBinElevationMap;

TEST(Scrolling, ThousandRandomMovesKeepEveryCellInsideBitIdentical) {
    BinGrid g(0.1);
    g.reset(0.1, CellWindow{0, 0, 40, 30});
    BinUpdateParams p;
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> h(-0.3, 0.3);
    std::uniform_int_distribution<int> step(-7, 7);
    // Reference: the bins each cell should hold, by world cell index.
    std::map<std::pair<int, int>, std::vector<Bin>> reference;
    auto fillWindow = [&]() {
        const CellWindow& w = g.window();
        for (int iy = w.iy0; iy < w.iy0 + w.ny; iy++)
            for (int ix = w.ix0; ix < w.ix0 + w.nx; ix++) {
                if (reference.count({ix, iy})) continue;  // keep the cells already there
                PointWithCov pt;
                pt.point_m = Eigen::Vector3f(float(g.cellCenter_m(ix)), float(g.cellCenter_m(iy)),
                                             float(h(rng)));
                pt.cov_m2 = {1e-6f, 0, 0, 1e-6f, 0, 1e-4f};
                g.insertPoints({pt}, p);
                auto& bins = reference[{ix, iy}];
                g.forEachBin(ix, iy, [&](const Bin& b) { bins.push_back(b); });
            }
    };
    fillWindow();
    size_t checkedCells = 0;
    for (int move = 0; move < 1000; move++) {
        const CellWindow w = g.window();
        const int nx0 = w.ix0 + step(rng), ny0 = w.iy0 + step(rng);
        size_t leavers = 0;
        g.moveWindowTo(nx0, ny0, [&](int ix, int iy) {
            leavers++;
            reference.erase({ix, iy});
        });
        // Cells outside the new window are gone from the reference; the others must be intact.
        for (auto it = reference.begin(); it != reference.end();) {
            if (!g.window().contains(it->first.first, it->first.second))
                it = reference.erase(it);
            else
                ++it;
        }
        for (const auto& [cell, bins] : reference) {
            std::vector<Bin> now;
            g.forEachBin(cell.first, cell.second, [&](const Bin& b) { now.push_back(b); });
            ASSERT_EQ(now.size(), bins.size());
            for (size_t k = 0; k < bins.size(); k++) {
                // Bit-identical payload (the pool link `next` may differ).
                EXPECT_EQ(std::memcmp(&now[k], &bins[k], sizeof(BinEstimate)), 0);
            }
            checkedCells++;
        }
        if (move % 10 == 0) fillWindow();  // new data in the entering cells now and then
    }
    EXPECT_GT(checkedCells, 100000u);
    EXPECT_EQ(g.binCount(), [&] {
        size_t n = 0;
        for (const auto& [cell, bins] : reference) n += bins.size();
        return n;
    }());
}

namespace {
mrpt::obs::CObservationPointCloud::Ptr cloudAt(double x, double y, double z, int n,
                                               const std::string& label) {
    auto obs = mrpt::obs::CObservationPointCloud::Create();
    obs->sensorLabel = label;
    auto pts = mrpt::maps::CSimplePointsMap::Create();
    for (int i = 0; i < n; i++) pts->insertPoint(float(x), float(y), float(z));
    obs->pointcloud = pts;
    return obs;
}
CMultiBinElevationMap dualMap() {
    CMultiBinElevationMap::TCreationOptions c;
    c.dual_grid = true;
    CMultiBinElevationMap map(c);
    // Point clouds use the depth-camera model: make it a constant 10 mm along the ray.
    map.insertionOptions.sensors.depth.axialSigma0_m = 0.01;
    map.insertionOptions.sensors.depth.axialSigmaQuadratic_per_m = 0.0;
    map.insertionOptions.height_sigma_floor_m = 0.0;  // compare raw Kalman variances
    map.insertionOptions.default_pose_sigmas = {0, 0, 0, 0, 0, 0};
    return map;
}
mrpt::poses::CPose3DPDFGaussian exactPose(double x, double y) {
    mrpt::poses::CPose3DPDFGaussian p;
    p.mean = mrpt::poses::CPose3D(x, y, 0, 0, 0, 0);
    p.cov.setZero();
    return p;
}
}  // namespace

TEST(DualGrid, RoutesBySensorAndFusesWithoutCountingTwice) {
    CMultiBinElevationMap map = dualMap();
    // Laser-like data (local grid): 4 points 1 m below the sensor, straight down, sigma 10 mm.
    const auto laser = cloudAt(0.0, 0.0, -1.0, 4, "LASER");
    laser->sensorPose = mrpt::poses::CPose3D(0.5123, 0.3071, 1.0, 0, 0, 0);
    ASSERT_TRUE(map.insertObservation(*laser, exactPose(0, 0)));
    EXPECT_FALSE(multibin::MapInternals::localGrid(map).empty());
    EXPECT_TRUE(multibin::MapInternals::grid(map).empty());
    double h, sLocal;
    ASSERT_TRUE(map.cellHeight(0.5123, 0.3071, h, sLocal));
    EXPECT_NEAR(sLocal, 0.01 / 2, 1e-4);  // 4 independent points

    // Scroll the spot out of the local grid (written back to the global grid) and back in.
    map.recenter(4.0, 0.0);
    EXPECT_FALSE(multibin::MapInternals::grid(map).empty());

    double hBack, sBack;
    ASSERT_TRUE(map.cellHeight(0.5123, 0.3071, hBack, sBack));
    EXPECT_NEAR(sBack, sLocal, 1e-6);
    map.recenter(0.0, 0.0);
    ASSERT_TRUE(map.cellHeight(0.5123, 0.3071, hBack, sBack));
    EXPECT_NEAR(hBack, h, 1e-6);
    EXPECT_NEAR(sBack, sLocal, 1e-6) << "a re-entering local cell must not count its data twice";

    // Stereo data (global grid) at the same place: 1 point, sigma 10 mm. The fused sigma is that of
    // 5 independent points: smaller than either grid alone, and no smaller.
    const auto stereo = cloudAt(0.0, 0.0, -1.0, 1, "STEREO");
    stereo->sensorPose = mrpt::poses::CPose3D(0.5123, 0.3071, 1.0, 0, 0, 0);
    ASSERT_TRUE(map.insertObservation(*stereo, exactPose(0, 0)));
    double sFused;
    ASSERT_TRUE(map.cellHeight(0.5123, 0.3071, h, sFused));
    EXPECT_LE(sFused, sLocal);
    EXPECT_NEAR(sFused, 0.01 / std::sqrt(5.0), 1e-4);
}

TEST(DualGrid, GridsFollowTheRobot) {
    CMultiBinElevationMap map = dualMap();
    const auto laser = cloudAt(0.0, 0.0, -1.0, 1, "LASER");
    laser->sensorPose = mrpt::poses::CPose3D(0, 0, 1.0, 0, 0, 0);
    for (double x = 0.0123; x <= 20.0; x += 0.5)
        map.insertObservation(*laser, exactPose(x, 0.0123));
    // The local grid is 2 m around the robot, centred on its last position, x = 19.5123; the
    // global one covers 10 m around every position along the route.
    EXPECT_NEAR(0.5 * (multibin::MapInternals::localGrid(map).window().ix0 * 0.015 +
                       (multibin::MapInternals::localGrid(map).window().ix0 +
                        multibin::MapInternals::localGrid(map).window().nx) *
                           0.015),
                19.5123, 0.02);
    double h, s;
    EXPECT_TRUE(map.cellHeight(16.0123, 0.0123, h, s));  // written back, in the global grid
    EXPECT_TRUE(map.cellHeight(0.5123, 0.0123, h, s));   // the start: the global grid keeps it
    EXPECT_FALSE(map.cellHeight(0.5123, 3.0, h, s));     // never seen
    EXPECT_LE(multibin::MapInternals::grid(map).window().ix0 * 0.05, -5.0 + 0.1);
    EXPECT_GE((multibin::MapInternals::grid(map).window().ix0 +
               multibin::MapInternals::grid(map).window().nx) *
                  0.05,
              19.5 + 5.0 - 0.1);
    EXPECT_TRUE(map.cellHeight(19.5123, 0.0123, h, s));  // in the local grid
    EXPECT_LE(multibin::MapInternals::localGrid(map).binCount(), 3u);
}
