/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/DepthModel.h"

#include <mrpt/maps/CPointsMap.h>
#include <mrpt/maps/CSimplePointsMap.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "RayPoint.h"
#include "multibin/sensors/DepthArtefacts.h"
#include "multibin/util/VectorClones.h"

namespace multibin::sensors {

namespace {
void appendPointsMap(const mrpt::maps::CPointsMap& pts, const DepthModelOptions& opts,
                     double minRange_m, double maxRange_m, PointsWithCov& out, DepthStats& stats) {
    stats.points += pts.size();
    count(appendCloudPoints(pts, minRange_m, maxRange_m, opts.raySigmas(), out), stats);
}
}  // namespace

namespace {
/** The 3D points of a frame whose pixels are known (points3D_idxs_x/y), without the artefacts
 * DepthArtefacts.h marks (counted): the arrays to make points from. */
void withoutArtefacts(const mrpt::obs::CObservation3DRangeScan& scan, const DepthModelOptions& opts,
                      std::vector<float>& xs, std::vector<float>& ys, std::vector<float>& zs,
                      DepthStats& stats) {
    const size_t n = scan.points3D_x.size();
    int rows = int(scan.cameraParams.nrows), cols = int(scan.cameraParams.ncols);
    for (size_t i = 0; i < n; i++) {  // pixels beyond the stated size: the grid the indices need
        rows = std::max(rows, int(scan.points3D_idxs_y[i]) + 1);
        cols = std::max(cols, int(scan.points3D_idxs_x[i]) + 1);
    }
    // MRPT's sensor frame looks along +x: x is the depth.
    std::vector<float> depth(size_t(rows) * size_t(cols), 0.f);
    auto pixel = [&](size_t i) {
        return size_t(scan.points3D_idxs_y[i]) * size_t(cols) + scan.points3D_idxs_x[i];
    };
    for (size_t i = 0; i < n; i++)
        if (scan.points3D_x[i] > 0 && std::isfinite(scan.points3D_x[i]))
            depth[pixel(i)] = scan.points3D_x[i];
    const std::vector<DepthPixel> marks = depthArtefacts(depth, rows, cols, opts);
    for (size_t i = 0; i < n; i++) {
        const DepthPixel m = marks[pixel(i)];
        if (m == DepthPixel::FlyingPixel && depth[pixel(i)] > 0) {
            stats.flyingPixel++;
        } else if (m == DepthPixel::FrameBorder && depth[pixel(i)] > 0) {
            stats.frameBorder++;
        } else {
            xs.push_back(scan.points3D_x[i]);
            ys.push_back(scan.points3D_y[i]);
            zs.push_back(scan.points3D_z[i]);
        }
    }
}

/** The range image of a frame without its artefacts (zeroed, counted): a copy holding only what
 * unprojection needs. */
mrpt::obs::CObservation3DRangeScan rangeImageWithoutArtefacts(
    const mrpt::obs::CObservation3DRangeScan& scan, const DepthModelOptions& opts,
    DepthStats& stats) {
    mrpt::obs::CObservation3DRangeScan out;
    out.hasRangeImage = true;
    out.rangeImage = scan.rangeImage;
    out.rangeUnits = scan.rangeUnits;
    out.range_is_depth = scan.range_is_depth;
    out.cameraParams = scan.cameraParams;
    out.sensorPose = scan.sensorPose;
    const int rows = int(scan.rangeImage.rows()), cols = int(scan.rangeImage.cols());
    std::vector<float> depth(size_t(rows) * size_t(cols));
    for (int r = 0; r < rows; r++)
        for (int c = 0; c < cols; c++)
            depth[size_t(r) * size_t(cols) + size_t(c)] =
                float(scan.rangeImage(r, c)) * scan.rangeUnits;
    const std::vector<DepthPixel> marks = depthArtefacts(depth, rows, cols, opts);
    for (int r = 0; r < rows; r++)
        for (int c = 0; c < cols; c++) {
            const DepthPixel m = marks[size_t(r) * size_t(cols) + size_t(c)];
            if (m == DepthPixel::Keep || out.rangeImage(r, c) == 0) continue;
            (m == DepthPixel::FlyingPixel ? stats.flyingPixel : stats.frameBorder)++;
            out.rangeImage(r, c) = 0;
        }
    return out;
}
}  // namespace

void depthScanToPoints(const mrpt::obs::CObservation3DRangeScan& scan,
                       const DepthModelOptions& opts, double minRange_m, double maxRange_m,
                       PointsWithCov& out, DepthStats& stats) {
    out.clear();
    if (scan.hasPoints3D) {
        const size_t nx = scan.points3D_x.size(), ny = scan.points3D_y.size(),
                     nz = scan.points3D_z.size();
        if (nx != ny || nx != nz)
            throw std::invalid_argument(
                "CObservation3DRangeScan '" + scan.sensorLabel +
                "': points3D_x, points3D_y and points3D_z have different sizes (" +
                std::to_string(nx) + ", " + std::to_string(ny) + ", " + std::to_string(nz) + ")");
        stats.points += nx;
        // Without pixel indices the points have no image to find artefacts in.
        if (scan.points3D_idxs_x.size() == nx && scan.points3D_idxs_y.size() == nx && nx > 0) {
            std::vector<float> xs, ys, zs;
            withoutArtefacts(scan, opts, xs, ys, zs, stats);
            count(appendRayPoints(xs.data(), ys.data(), zs.data(), xs.size(), minRange_m,
                                  maxRange_m, opts.raySigmas(), out),
                  stats);
            return;
        }
        count(
            appendRayPoints(scan.points3D_x.data(), scan.points3D_y.data(), scan.points3D_z.data(),
                            nx, minRange_m, maxRange_m, opts.raySigmas(), out),
            stats);
    } else if (scan.hasRangeImage) {
        mrpt::maps::CSimplePointsMap local;
        mrpt::obs::T3DPointsProjectionParams pp;
        pp.takeIntoAccountSensorPoseOnRobot = false;  // sensor frame (+x forward)
        DepthStats removed;
        mrpt::obs::CObservation3DRangeScan filtered =
            rangeImageWithoutArtefacts(scan, opts, removed);
        filtered.unprojectInto(local, pp);
        // The zeroed pixels are not in `local`: seen, and counted as what removed them.
        stats.points += removed.flyingPixel + removed.frameBorder;
        stats.flyingPixel += removed.flyingPixel;
        stats.frameBorder += removed.frameBorder;
        appendPointsMap(local, opts, minRange_m, maxRange_m, out, stats);
    }
}

namespace {
/** Points per block of the covariance pass. */
constexpr size_t kBlock = 256;

/** n s(r)^2 v v^T of each of `count` rays (x, y, z from the sensor [m], `pointsInCell` points in
 * their cell): the six entries into `out`, and whether the ray has a direction (0 < r finite).
 * Branch-free, so it vectorises. */
MULTIBIN_VECTOR_CLONES
void frameSharedTerms(const DepthModelOptions& opts, const double* xs, const double* ys,
                      const double* zs, const uint32_t* pointsInCell, size_t count,
                      double (*out)[kBlock], uint8_t* hasDirection) {
    for (size_t i = 0; i < count; i++) {
        const double x = xs[i], y = ys[i], z = zs[i];
        const double r = std::sqrt(x * x + y * y + z * z);
        const double vx = x / r, vy = y / r, vz = z / r;
        const double s = opts.frameSigma_m(r);
        const double a = double(pointsInCell[i]) * s * s;  // [m^2] along the ray
        out[0][i] = a * vx * vx;
        out[1][i] = a * vx * vy;
        out[2][i] = a * vx * vz;
        out[3][i] = a * vy * vy;
        out[4][i] = a * vy * vz;
        out[5][i] = a * vz * vz;
        hasDirection[i] = uint8_t(int(r > 0) & int(r - r == 0));
    }
}
}  // namespace

void addFrameSharedCovariance(PointsWithCov& mapPoints, const Eigen::Vector3d& sensor_m,
                              const DepthModelOptions& opts,
                              const std::vector<uint32_t>& pointsInCell) {
    if (pointsInCell.size() != mapPoints.size())
        throw std::invalid_argument(
            "addFrameSharedCovariance: " + std::to_string(pointsInCell.size()) +
            " cell counts for " + std::to_string(mapPoints.size()) + " points");
    const size_t n = mapPoints.size();
    // The covariance pass, a block at a time: the terms in arrays (vectorised), then added.
    alignas(64) double x[kBlock], y[kBlock], z[kBlock], term[6][kBlock];
    alignas(64) uint8_t hasDirection[kBlock];
    for (size_t begin = 0; begin < n; begin += kBlock) {
        const size_t m = std::min(kBlock, n - begin);
        gatherPositions(mapPoints.data() + begin, m, x, y, z);
        for (size_t i = 0; i < m; i++) {
            x[i] -= sensor_m.x();
            y[i] -= sensor_m.y();
            z[i] -= sensor_m.z();
        }
        frameSharedTerms(opts, x, y, z, pointsInCell.data() + begin, m, term, hasDirection);
        for (size_t i = 0; i < m; i++) {
            if (!hasDirection[i]) continue;  // the map counts it as it is
            SymmetricCov3& c = mapPoints[begin + i].cov_m2;
            c.xx += float(term[0][i]);
            c.xy += float(term[1][i]);
            c.xz += float(term[2][i]);
            c.yy += float(term[3][i]);
            c.yz += float(term[4][i]);
            c.zz += float(term[5][i]);
        }
    }
}

}  // namespace multibin::sensors
