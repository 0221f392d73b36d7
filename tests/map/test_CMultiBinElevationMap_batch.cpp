/* The batch height query, CMultiBinElevationMap::heights(), answers what height() answers point
 * by point, bit for bit: on the shipped mock-up map (measured, filled and unknown cells, points
 * on cell borders, outside the window and not finite, in shuffled order), on a dual grid, with
 * the `nearest` query, and on an empty map. */
#include <gtest/gtest.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CObservationPointCloud.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "../common/mockup_map.h"
#include "multibin/grid/BinGrid.h"
#include "multibin/grid/CellSurface.h"
#include "multibin/map/MapInternals.h"

namespace {
using Map = mrpt::maps::CMultiBinElevationMap;
using Source = Map::HeightSource;

uint64_t bits(double v) {
    uint64_t b;
    std::memcpy(&b, &v, sizeof b);
    return b;
}

/** heights() over the points against height() at each; counts the answers by source. */
void expectBatchAsSingle(const Map& map, const std::vector<double>& x, const std::vector<double>& y,
                         size_t counts[5]) {
    std::vector<Map::HeightAnswer> batch(x.size());
    map.heights(x.data(), y.data(), x.size(), batch.data());
    std::fill(counts, counts + 5, 0);
    size_t mismatches = 0;
    for (size_t i = 0; i < x.size(); i++) {
        const Map::HeightAnswer single = map.height(x[i], y[i]);
        counts[int(single.source)]++;
        const bool same = single.source == batch[i].source &&
                          bits(single.height_m) == bits(batch[i].height_m) &&
                          bits(single.sigma_m) == bits(batch[i].sigma_m);
        if (!same && mismatches++ < 5)
            ADD_FAILURE() << "point " << i << " (" << x[i] << ", " << y[i] << "): height() "
                          << single.height_m << " +- " << single.sigma_m << " source "
                          << int(single.source) << ", heights() " << batch[i].height_m << " +- "
                          << batch[i].sigma_m << " source " << int(batch[i].source);
    }
    EXPECT_EQ(mismatches, 0u) << "of " << x.size() << " points";
}

/** Points over [x0, x1] x [y0, y1] and beyond: uniform (a tenth outside), on cell borders
 * (x, y or both a whole number of cells from `border0`), a regular grid in row order, and not
 * finite; shuffled. */
void queryPoints(double x0, double x1, double y0, double y1, double cell_m, double border0_m,
                 size_t n, std::vector<double>& x, std::vector<double>& y) {
    std::mt19937 rng(11);
    const double margin_m = 0.05 * (x1 - x0);
    std::uniform_real_distribution<double> ux(x0 - margin_m, x1 + margin_m),
        uy(y0 - margin_m, y1 + margin_m);
    auto onBorder = [&](double v) {
        return border0_m + std::round((v - border0_m) / cell_m) * cell_m;
    };
    for (size_t i = 0; i < n; i++) {
        double xi = ux(rng), yi = uy(rng);
        if (i % 8 == 1) xi = onBorder(xi);
        if (i % 8 == 2) yi = onBorder(yi);
        if (i % 8 == 3) xi = onBorder(xi), yi = onBorder(yi);
        x.push_back(xi);
        y.push_back(yi);
    }
    for (double yi = y0; yi < y1; yi += 7.3 * cell_m)  // rows of points 0.4 cells apart
        for (double xi = x0; xi < x1 && x.size() < 2 * n; xi += 0.4 * cell_m) {
            x.push_back(xi);
            y.push_back(yi);
        }
    const double nan = std::numeric_limits<double>::quiet_NaN(),
                 inf = std::numeric_limits<double>::infinity();
    for (const auto& [xi, yi] :
         {std::pair{nan, y0}, {x0, nan}, {inf, y1}, {-inf, -inf}, {1e12, 0.5 * (y0 + y1)}})
        x.push_back(xi), y.push_back(yi);
    std::vector<size_t> order(x.size());
    for (size_t i = 0; i < order.size(); i++) order[i] = i;
    std::shuffle(order.begin(), order.end(), rng);
    std::vector<double> xs, ys;
    for (const size_t i : order) xs.push_back(x[i]), ys.push_back(y[i]);
    x.swap(xs);
    y.swap(ys);
}

}  // namespace

TEST(BatchQuery, MockupMapAnswersAsHeightBitForBit) {
    const auto maps = test_maps::mockupMaps();
    const Map& map = *maps->mapByClass<Map>();
    std::vector<double> x, y;
    const double cell_m = map.creationOptions.resolution_m;
    // Cell borders in the pose frame: whole cells from the map origin.
    queryPoints(map.getXMin(), map.getXMax(), map.getYMin(), map.getYMax(), cell_m,
                map.mapOrigin().x, 20000, x, y);
    size_t counts[5];
    expectBatchAsSingle(map, x, y, counts);
    // The comparison covers every kind of answer.
    EXPECT_GT(counts[int(Source::Measured)], 2000u);
    EXPECT_GT(counts[int(Source::FilledMedian)] + counts[int(Source::FilledSurface)], 200u);
    EXPECT_GT(counts[int(Source::Unknown)], 2000u);

    // The `nearest` query (each cell's value): the same answers as its height().
    Map nearest = map;
    nearest.insertionOptions.query.height_query =
        Map::TInsertionOptions::TQueryOptions::HeightQuery::Nearest;
    expectBatchAsSingle(nearest, x, y, counts);
    EXPECT_GT(counts[int(Source::Measured)], 2000u);
}

TEST(BatchQuery, ACacheNarrowerThanItsQueriesAnswersAsHeightAt) {
    // Slots for 4 columns only and the points in random order: cells evict each other all the
    // time, and every answer is still heightAt's.
    const auto maps = test_maps::mockupMaps();
    const Map& map = *maps->mapByClass<Map>();
    std::vector<double> x, y;
    queryPoints(map.getXMin(), map.getXMax(), map.getYMin(), map.getYMax(),
                map.creationOptions.resolution_m, map.mapOrigin().x, 20000, x, y);
    const multibin::BinUpdateParams params = map.binUpdateParams();
    multibin::HeightAtCache cache(multibin::MapInternals::grid(map), nullptr, params, 0.0);
    size_t known = 0, mismatches = 0;
    for (size_t i = 0; i < x.size(); i++) {
        const double xi = x[i] - map.mapOrigin().x, yi = y[i] - map.mapOrigin().y;
        multibin::CellSurface a, b;
        const bool haveA =
            multibin::heightAt(multibin::MapInternals::grid(map), nullptr, xi, yi, params, true, a);
        const bool haveB = cache.heightAt(xi, yi, true, b);
        known += haveA;
        mismatches += haveA != haveB ||
                      (haveA && (bits(a.height_m) != bits(b.height_m) ||
                                 bits(a.reportedVariance_m2()) != bits(b.reportedVariance_m2())));
    }
    EXPECT_EQ(mismatches, 0u) << "of " << x.size() << " points";
    EXPECT_GT(known, 2000u);
}

TEST(BatchQuery, DualGridAnswersAsHeightBitForBit) {
    Map::TCreationOptions c;
    c.dual_grid = true;
    c.local_size_m = 1.0;
    c.global_size_m = 3.0;
    Map map(c);
    // A rough slope seen by both grids' sensors (LASER: the local grid, STEREO: the global one)
    // from 1 m above (0, 0), the stereo points 1 cm higher: where both grids know a cell they
    // agree or not, by the cell.
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-1.2f, 1.2f);
    std::normal_distribution<float> noise(0.f, 0.003f);
    for (const char* label : {"LASER", "STEREO"}) {
        auto obs = mrpt::obs::CObservationPointCloud::Create();
        obs->sensorLabel = label;
        auto pts = mrpt::maps::CSimplePointsMap::Create();
        const float dz = std::string(label) == "STEREO" ? 0.01f : 0.f;
        for (int i = 0; i < 30000; i++) {
            const float px = u(rng), py = u(rng);
            if (px > 0.3f && py > 0.3f) continue;  // a hole to fill
            pts->insertPoint(px, py, -1.f + 0.2f * px + 0.05f * std::sin(8 * py) + dz + noise(rng));
        }
        obs->pointcloud = pts;
        obs->sensorPose = mrpt::poses::CPose3D(0, 0, 1.0, 0, 0, 0);
        mrpt::poses::CPose3DPDFGaussian pose;
        pose.cov.setZero();
        ASSERT_TRUE(map.insertObservation(*obs, pose));
    }
    map.dem_update_map();
    std::vector<double> x, y;
    const double o_m = map.mapOrigin().x;
    queryPoints(-1.5, 1.5, -1.5, 1.5, c.local_resolution_m, o_m, 5000, x, y);
    size_t counts[5];
    expectBatchAsSingle(map, x, y, counts);
    EXPECT_GT(counts[int(Source::Measured)], 1000u);
    EXPECT_GT(counts[int(Source::Unknown)], 100u);
}

TEST(BatchQuery, EmptyMapAndBadInput) {
    const Map map;
    const std::vector<double> x{0.0, 1.0, -2.0}, y{0.0, 0.5, 3.0};
    std::vector<Map::HeightAnswer> out(3);
    map.heights(x.data(), y.data(), 3, out.data());
    for (const auto& a : out) {
        EXPECT_EQ(a.source, Source::Unknown);
        EXPECT_TRUE(std::isnan(a.height_m) && std::isnan(a.sigma_m));
    }
    map.heights(nullptr, nullptr, 0, nullptr);  // nothing to answer
    try {
        map.heights(x.data(), nullptr, 3, out.data());
        FAIL() << "a null y_m was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("heights: x_m, y_m and out must not be null"),
                  std::string::npos)
            << e.what();
    }
}
