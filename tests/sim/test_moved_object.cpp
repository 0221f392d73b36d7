/* A moved object, end to end: terrain-sim's pitched URG-04LX on its walking robot passes a 0.15 m
 * box twice along the same line; the box is there on the first pass and gone on the second. With
 * the map's default options, the DEM users read (dem_get_z after dem_update_map(), and the cell
 * values the mapper's rasters export) must return to the ground over the box's footprint and one
 * cell around it, the cells its faces crossed included (doc/dual-grid.md, "Moved objects"). */
#include <gtest/gtest.h>
#include <mrpt/maps/CHeightGridMap2D.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimplePointsMap.h>

#include <cmath>
#include <cstdio>

#include "LaserSim.h"
#include "Scenario.h"
#include "Trajectory.h"

using namespace terrain_sim;

namespace {

/** The scene: gently rolling ground, sampled every 4 mm, with (or without) a 0.15 m cube whose
 * near corner is at (0.605, y0_m): its edges cut cells of the default 20 mm grid, and its faces
 * are met at grazing angles by the beams that pass beside it. */
struct MovedBox {
    double y0_m;
    static constexpr double kX0_m = 0.605, kSide_m = 0.15, kHeight_m = 0.15;

    static double ground(double x, double y) {
        return 0.008 * std::sin(2.1 * x + 0.4) * std::cos(1.7 * y) + 0.004 * std::sin(5.3 * y);
    }
    bool inBox(double x, double y) const {
        return x >= kX0_m && x <= kX0_m + kSide_m && y >= y0_m && y <= y0_m + kSide_m;
    }
    Terrain terrain(bool box) const {
        constexpr double spacing = 0.004, x0 = -1.0, y0 = -1.0;
        const int nx = int(3.0 / spacing) + 1, ny = int(2.0 / spacing) + 1;
        Eigen::MatrixXf h(ny, nx);
        for (int r = 0; r < ny; ++r)
            for (int k = 0; k < nx; ++k) {
                const double x = x0 + spacing * k, y = y0 + spacing * r;
                h(r, k) = float(box && inBox(x, y) ? kHeight_m : ground(x, y));
            }
        return Terrain::fromSamples(h, x0, y0, spacing);
    }
};

/** One pass of terrain-sim's walking robot (its hexapod walk along y = 0 from x = -0.6 to 1.3,
 * with its gait, pose errors and pose covariances drawn from `seed`) with the laser seeing `seen`;
 * the points also go into MRPT's mean height grid. */
void walkPast(mrpt::maps::CMultiBinElevationMap& map, mrpt::maps::CHeightGridMap2D& mrptMean,
              const Terrain& walkedOn, const Terrain& seen, uint64_t seed) {
    TrajectoryOptions opts;
    opts.startX_m = -0.6;
    opts.endMargin_m = 1.3;  // no tiles: the walk ends at x = endMargin_m
    std::mt19937_64 rng(seed);
    const std::vector<Frame> frames = walkTrajectory(walkedOn, opts, rng);
    const SurfaceTexture texture(seen, seed, 0);
    const LaserSim laser(LaserConfig{}, seen, texture, seed);
    for (const Frame& f : frames) {
        const auto scan = laser.scan(f.truth, syntheticStamp(f.t_s), rng);
        map.insertObservation(*scan, f.estimate);
        mrpt::maps::CSimplePointsMap points;
        points.insertionOptions.minDistBetweenLaserPoints = 0;
        points.loadFromRangeScan(*scan, f.estimate.mean);
        mrpt::maps::CHeightGridMap2D_Base::TPointInsertParams ip;
        for (size_t k = 0; k < points.size(); k++) {
            float x, y, z;
            points.getPoint(k, x, y, z);
            mrptMean.insertIndividualPoint(x, y, z, ip);
        }
    }
}

struct FootprintError {
    double dem_m = 0, raster_m = 0, mrptMean_m = 0;  // RMSE from the ground
    size_t cells = 0, unknown = 0;
};

/** RMSE from the ground over the cells whose centres lie within the box's footprint grown by one
 * cell: dem_get_z at the cell centres after dem_update_map(), the cell value the rasters export
 * (cellElevation), and MRPT's mean height grid at the same cells. */
FootprintError footprintError(mrpt::maps::CMultiBinElevationMap& map,
                              const mrpt::maps::CHeightGridMap2D& mrptMean, const MovedBox& box) {
    map.dem_update_map();
    const double cell = map.dem_get_resolution();
    FootprintError e;
    double sumDem = 0, sumRaster = 0, sumMrpt = 0;
    const int ix0 = int(std::floor(box.kX0_m / cell)) - 1;
    const int ix1 = int(std::floor((box.kX0_m + box.kSide_m) / cell)) + 1;
    const int iy0 = int(std::floor(box.y0_m / cell)) - 1;
    const int iy1 = int(std::floor((box.y0_m + box.kSide_m) / cell)) + 1;
    for (int ix = ix0; ix <= ix1; ix++)
        for (int iy = iy0; iy <= iy1; iy++) {
            const double x = (ix + 0.5) * cell, y = (iy + 0.5) * cell;
            const double truth = MovedBox::ground(x, y);
            double z, zr, s;
            const auto* m = mrptMean.cellByPos(x, y);
            if (!map.dem_get_z(x, y, z) ||
                map.cellElevation(x, y, zr, s) == multibin::HeightSource::Unknown || !m ||
                m->w == 0) {
                e.unknown++;
                continue;
            }
            sumDem += (z - truth) * (z - truth);
            sumRaster += (zr - truth) * (zr - truth);
            sumMrpt += (m->h - truth) * (m->h - truth);
            e.cells++;
        }
    const double n = double(std::max<size_t>(e.cells, 1));
    e.dem_m = std::sqrt(sumDem / n);
    e.raster_m = std::sqrt(sumRaster / n);
    e.mrptMean_m = std::sqrt(sumMrpt / n);
    return e;
}

class MovedObject : public ::testing::TestWithParam<double> {};

}  // namespace

TEST_P(MovedObject, FootprintAndFacesReturnToTheGroundWithDefaultOptions) {
    const MovedBox box{GetParam()};
    const Terrain withBox = box.terrain(true), without = box.terrain(false);
    mrpt::maps::CMultiBinElevationMap map;  // default options (20 mm cells)
    mrpt::maps::CHeightGridMap2D mrptMean(mrpt::maps::CHeightGridMap2D::mrSimpleAverage, -1.0, 2.0,
                                          -1.0, 1.0, map.dem_get_resolution());
    // The robot walks on the ground beside the box (or straddles it): its gait never touches it.
    walkPast(map, mrptMean, without, withBox, 1);
    double z;
    map.dem_update_map();
    ASSERT_TRUE(map.dem_get_z(box.kX0_m + 0.075, box.y0_m + 0.075, z));
    EXPECT_NEAR(z, MovedBox::kHeight_m, 0.01) << "the box is mapped in the first pass";
    walkPast(map, mrptMean, without, without, 2);
    const FootprintError e = footprintError(map, mrptMean, box);
    std::printf(
        "moved box at y0 = %.3f m: footprint + 1 cell, %zu cells (%zu unknown): RMSE from "
        "the ground: DEM %.1f mm, raster %.1f mm, MRPT's mean %.1f mm\n",
        box.y0_m, e.cells, e.unknown, 1e3 * e.dem_m, 1e3 * e.raster_m, 1e3 * e.mrptMean_m);
    EXPECT_EQ(e.unknown, 0u);
    EXPECT_LE(e.dem_m, 0.015) << "dem_get_z";
    EXPECT_LE(e.raster_m, 0.015) << "the rasters' cell values";
}

// The box's near edge beside the walking line on the left (its faces met at grazing angles), on
// the line (the robot straddles it), and farther out on the right.
INSTANTIATE_TEST_SUITE_P(Placements, MovedObject, ::testing::Values(0.247, -0.075, -0.401));
