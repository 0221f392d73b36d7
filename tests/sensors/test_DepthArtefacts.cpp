/* Depth-frame artefacts (multibin/sensors/DepthArtefacts.h): flying pixels between foreground and
 * background and the frame's border are removed before the points are made, and counted. */
#include <gtest/gtest.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <cmath>
#include <map>
#include <vector>

#include "mrpt_datasets.h"
#include "multibin/sensors/DepthArtefacts.h"
#include "multibin/sensors/DepthModel.h"

using namespace multibin::sensors;
using multibin::PointsWithCov;

namespace {
constexpr int kRows = 120, kCols = 160;
constexpr double kFocal_px = 150;

/** A synthetic frame of points with pixel indices: a wall 2 m ahead, a 40 x 40 px box 1.2 m
 * ahead in the middle, one flying pixel at 1.6 m on each row of the box's left edge, and a
 * border column of garbage depths (0.5 m) at column 0. Returns the frame and its true labels. */
mrpt::obs::CObservation3DRangeScan frame(std::vector<DepthPixel>& truth) {
    mrpt::obs::CObservation3DRangeScan scan;
    scan.sensorLabel = "DEPTH";
    scan.hasPoints3D = true;
    scan.cameraParams.ncols = kCols;
    scan.cameraParams.nrows = kRows;
    truth.assign(size_t(kRows * kCols), DepthPixel::Keep);
    for (int r = 0; r < kRows; r++)
        for (int c = 0; c < kCols; c++) {
            const bool box = r >= 40 && r < 80 && c >= 60 && c < 100;
            float depth = box ? 1.2f : 2.0f;
            DepthPixel label = DepthPixel::Keep;
            if (r >= 40 && r < 80 && c == 59) depth = 1.6f, label = DepthPixel::FlyingPixel;
            if (c == 0) depth = 0.5f, label = DepthPixel::FrameBorder;
            truth[size_t(r * kCols + c)] = label;
            scan.points3D_x.push_back(depth);  // +x forward
            scan.points3D_y.push_back(float(-(c - kCols / 2) * depth / kFocal_px));
            scan.points3D_z.push_back(float(-(r - kRows / 2) * depth / kFocal_px));
            scan.points3D_idxs_x.push_back(uint16_t(c));
            scan.points3D_idxs_y.push_back(uint16_t(r));
        }
    return scan;
}
}  // namespace

// Every injected flying pixel and the border column are removed and counted as such; of the
// true wall and box pixels, only the rims at the box's edges go (the filter takes both sides of
// a jump: at most 2 x 4 x 40 + corners of the 16 000), none elsewhere.
TEST(DepthArtefacts, SyntheticFrameFlyingPixelsAndBorderAreRemovedAndCounted) {
    std::vector<DepthPixel> truth;
    const auto scan = frame(truth);
    DepthModelOptions opts;
    opts.borderWidth_px = 1;
    PointsWithCov pts;
    DepthStats stats;
    depthScanToPoints(scan, opts, 0.02, 10, pts, stats);
    EXPECT_EQ(stats.points, size_t(kRows * kCols));
    EXPECT_EQ(stats.points, stats.flyingPixel + stats.frameBorder + stats.kept + stats.outOfRange +
                                stats.notFinite);
    EXPECT_EQ(stats.frameBorder, size_t(2 * kCols + 2 * (kRows - 2)));  // one pixel all round
    size_t flyingLeft = 0, wallOrBoxLost = 0;
    std::vector<float> depth(truth.size());
    for (size_t i = 0; i < depth.size(); i++) depth[i] = scan.points3D_x[i];
    const auto marks = depthArtefacts(depth, kRows, kCols, opts);
    for (size_t i = 0; i < truth.size(); i++) {
        if (truth[i] == DepthPixel::FlyingPixel) flyingLeft += marks[i] == DepthPixel::Keep;
        if (truth[i] == DepthPixel::Keep && marks[i] == DepthPixel::FlyingPixel) wallOrBoxLost++;
    }
    EXPECT_EQ(flyingLeft, 0u);
    EXPECT_LE(wallOrBoxLost, 2u * 4u * 40u + 8u);
    EXPECT_GT(stats.flyingPixel, 40u);
    // Off: nothing removed, nothing counted.
    opts.flyingPixel.enabled = false;
    opts.borderWidth_px = 0;
    DepthStats off;
    depthScanToPoints(scan, opts, 0.02, 10, pts, off);
    EXPECT_EQ(off.flyingPixel + off.frameBorder, 0u);
    EXPECT_EQ(off.kept, size_t(kRows * kCols));
}

// MRPT's real depth frame (a wall 2.6 m away behind a bookshelf 1.6 m away; the camera's driver
// already dropped most flying pixels: 14 points remain between the two surfaces at an edge, 0.1-
// 0.8 m in front of the wall with the wall 3 px to one side and the shelf 3 px to the other). The
// defaults remove more than half of those and keep every pixel of the clean wall (rows 20-100,
// columns 30-585); the price is the rims of real edges (8 537 of the frame's 273 225 points).
TEST(DepthArtefacts, RealFrameLosesItsFlyingPixelsAndKeepsTheWall) {
    const auto obs = multibin::test::datasetObservations("tests_rgbd.rawlog");
    ASSERT_EQ(obs.size(), 1u);
    const auto scan = std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(obs[0]);
    ASSERT_TRUE(scan && scan->hasPoints3D);
    const int rows = int(scan->cameraParams.nrows), cols = int(scan->cameraParams.ncols);
    std::vector<float> depth(size_t(rows * cols), 0.f);
    for (size_t i = 0; i < scan->points3D_x.size(); i++)
        if (scan->points3D_x[i] > 0)
            depth[size_t(scan->points3D_idxs_y[i]) * size_t(cols) + scan->points3D_idxs_x[i]] =
                scan->points3D_x[i];
    const DepthModelOptions opts;
    const auto marks = depthArtefacts(depth, rows, cols, opts);
    // The wall plane x = a y + b z + c (sensor frame) from the clean wall.
    std::vector<Eigen::Vector3d> wall;
    for (size_t i = 0; i < scan->points3D_x.size(); i++) {
        const int r = scan->points3D_idxs_y[i], c = scan->points3D_idxs_x[i];
        if (scan->points3D_x[i] > 0 && r >= 20 && r <= 100 && c >= 30 && c < 586)
            wall.emplace_back(scan->points3D_x[i], scan->points3D_y[i], scan->points3D_z[i]);
    }
    Eigen::MatrixXd A(Eigen::Index(wall.size()), 3);
    Eigen::VectorXd b(A.rows());
    for (size_t i = 0; i < wall.size(); i++) {
        A.row(Eigen::Index(i)) << wall[i].y(), wall[i].z(), 1.0;
        b(Eigen::Index(i)) = wall[i].x();
    }
    const Eigen::Vector3d pl = A.colPivHouseholderQr().solve(b);
    size_t between = 0, betweenKept = 0, wallPixels = 0, wallKept = 0;
    for (size_t i = 0; i < scan->points3D_x.size(); i++) {
        const int r = scan->points3D_idxs_y[i], c = scan->points3D_idxs_x[i];
        const double x = scan->points3D_x[i];
        if (!(x > 0)) continue;
        const double inFront =
            pl(0) * scan->points3D_y[i] + pl(1) * scan->points3D_z[i] + pl(2) - x;
        const bool kept = marks[size_t(r) * size_t(cols) + size_t(c)] == DepthPixel::Keep;
        if (r >= 20 && r <= 100 && c >= 30 && c < 586) wallPixels++, wallKept += kept;
        // At a depth edge: a neighbour 3 px away on the row lies on the wall, another on the shelf.
        if (inFront > 0.1 && inFront < 0.8 && c >= 3 && c + 3 < cols) {
            const float l = depth[size_t(r) * size_t(cols) + size_t(c - 3)],
                        rr = depth[size_t(r) * size_t(cols) + size_t(c + 3)];
            if (l > 0 && rr > 0 && std::abs(l - rr) > 0.5) between++, betweenKept += kept;
        }
    }
    DepthStats stats;
    PointsWithCov pts;
    depthScanToPoints(*scan, opts, 0.02, 10, pts, stats);
    std::printf(
        "  %zu flying pixels removed; between the surfaces at an edge: %zu, %zu kept; clean wall: "
        "%zu, %zu kept\n",
        stats.flyingPixel, between, betweenKept, wallPixels, wallKept);
    ASSERT_GT(between, 10u);
    EXPECT_LE(double(betweenKept), 0.5 * double(between));
    EXPECT_GE(double(wallKept), 0.99 * double(wallPixels));
    EXPECT_EQ(stats.points, stats.flyingPixel + stats.frameBorder + stats.kept + stats.outOfRange +
                                stats.notFinite);
}
