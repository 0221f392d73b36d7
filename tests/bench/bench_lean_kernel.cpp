/* Part of the multibin elevation-mapping library: benchmarks.
 *
 * A lean reference kernel of the insertion's arithmetic, to say how far the map's insertion path
 * is from what the hardware allows (issue "insertion at the speed of the hardware"). The same
 * 2 M points, in scan order (pitched 683-beam scans of a walking robot), go through:
 *
 * - BM_LeanKernelInOrderScatter / BM_LeanKernelInterleavedScatter: per scan, what depends only on
 * the pose and the sensor is precomputed (rotation, translation, the pose covariance's quadratic
 * form in the point); per point: transform, height variance = z-z entry of J_R C_R J_R^T + J_S C_S
 * J_S^T for a range-only sensor model, the eq 13 gate, and an information-form Kalman update of one
 *   of 8 fixed bin slots per cell of a 133 x 133 grid. The point stage runs over
 *   each scan in structure-of-arrays form, vectorised (omp simd; target_clones
 *   for AVX-512, AVX2 and baseline with runtime dispatch: one binary for all three). The survivors
 * are scattered in scan order or four ways interleaved (independent store-to-load chains);
 * - BM_LeanKernelFullBinState: the same point stage with what the map keeps per bin updated per
 *   point in fixed 64-byte slots (height sums, certainty, count, the plane moments by the
 *   library's addPlanePoint, the least pose code, the cell's highest height): what the method's
 *   per-bin state costs at best;
 * - BM_MapInsertSensorPoints: the map's insertion core (BinGrid::insertSensorPoints with a
 *   PosePropagator per scan): the full method (multi-bin choice, certainty, eq 13 and 14 gates,
 *   visibility index, exact 3x3 propagation);
 * - BM_MrptHeightGridMean: MRPT's CHeightGridMap2D::insertIndividualPoint (a plain running mean,
 *   no uncertainty) over the same points in the map frame.
 *
 * Before timing, the kernel's height variance is checked against the library's propagation
 * (PosePropagator, the z-z entry, within 1e-3 relative: float arithmetic) and the two scatter
 * orders against each other. */
#include <benchmark/benchmark.h>
#include <mrpt/maps/CHeightGridMap2D.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "multibin/geometry/PosePropagation.h"
#include "multibin/grid/BinGrid.h"
#include "multibin/grid/BinUpdate.h"

using namespace multibin;

namespace {

constexpr int kBeams = 683;            // URG-04LX
constexpr size_t kPoints = 2'000'000;  // about 2 928 scans
constexpr int kGridCells = 133;        // 2 m at 15 mm
constexpr double kCell_m = 0.015;
constexpr int kBinsPerCell = 8;  // fixed slots: bin n lives in slot n mod 8
constexpr double kBinHeight_m = 0.05;
constexpr double kMaxUncertainty_m = 0.1;  // Delta_max of eq 13
constexpr double kGridOrigin_m = -1.0;     // the grid covers [-1, 1) m on both axes

/** Range sigma of the lean sensor model [m]: about 1 mm at 0.1 m to 4.5 mm at 1 m. */
inline float rangeSigma_m(float r_m) { return 0.0006f + 0.0039f * r_m; }

/** One scan: its sensor-frame points (structure of arrays) and the pose PDF it was taken from. */
struct Scan {
    std::vector<float> x, y, z;  //!< sensor frame [m]
    mrpt::poses::CPose3DPDFGaussian robotPose;
};

const mrpt::poses::CPose3D kLaserOnRobot(0.1, 0, 0.26, 0, 0.785, 0);  // pitched 45 deg down

/** Scans of a robot walking along x over a rough floor, pitched laser: kPoints points. */
std::vector<Scan> makeScans() {
    std::mt19937 rng(7);
    std::normal_distribution<float> rough(0.f, 0.01f);
    std::vector<Scan> scans;
    size_t total = 0;
    for (int k = 0; total < kPoints; k++) {
        Scan s;
        const double x = -0.6 + 0.0004 * k;
        s.robotPose.mean =
            mrpt::poses::CPose3D(x, 0.05 * std::sin(0.01 * k), 0.0, 0.02, 0.01, -0.01);
        s.robotPose.cov.setZero();
        const double sig[6] = {0.01, 0.01, 0.005, 0.005, 0.005, 0.005};
        for (int i = 0; i < 6; i++) s.robotPose.cov(i, i) = sig[i] * sig[i];
        s.robotPose.cov(0, 4) = s.robotPose.cov(4, 0) = 0.3 * sig[0] * sig[4];
        for (int b = 0; b < kBeams && total < kPoints; b++, total++) {
            const float a = float(-2.0944 + 4.1888 * b / (kBeams - 1));  // 240 deg
            // The pitched plane meets the floor at 0.26 / sin(45 deg) = 0.37 m straight ahead.
            const float r = 0.37f / std::max(0.2f, std::cos(a)) * (1.f + rough(rng));
            s.x.push_back(r * std::cos(a));
            s.y.push_back(r * std::sin(a));
            s.z.push_back(0.f);
        }
        scans.push_back(std::move(s));
    }
    return scans;
}

/** What depends only on the pose and the sensor, once per scan. The map-frame height variance
 * of a sensor-frame point p (range r, unit direction p / r) is
 *   pose part   j(p)^T C_R j(p), j = the z row of J_R = a + B q, q = R_s p + t_s (robot frame),
 *               i.e. a quadratic form p^T Q p + 2 b^T p + c;
 *   sensor part sigma_r(r)^2 (m_z . p / r)^2, m_z the z row of the sensor-to-map rotation. */
struct ScanConstants {
    float r[9], t[3];     //!< sensor to map: rotation (row-major) and translation [m]
    float q[6], b[3], c;  //!< pose quadratic form: Q (xx xy xz yy yz zz), b, c
};

ScanConstants precompute(const Scan& s) {
    ScanConstants k;
    const mrpt::poses::CPose3D sensorInMap = s.robotPose.mean + kLaserOnRobot;
    const Eigen::Matrix3d R = sensorInMap.getRotationMatrix().asEigen();
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) k.r[3 * i + j] = float(R(i, j));
    }
    k.t[0] = float(sensorInMap.x());
    k.t[1] = float(sensorInMap.y());
    k.t[2] = float(sensorInMap.z());
    // z row of J_R (x, y, z, yaw, pitch, roll; R = Rz(yaw) Ry(pitch) Rx(roll)) at robot-frame q:
    // (0, 0, 1, 0, dRz/dpitch . q, dRz/droll . q).
    const double p = s.robotPose.mean.pitch(), ro = s.robotPose.mean.roll();
    const Eigen::RowVector3d dPitch(-std::cos(p), -std::sin(p) * std::sin(ro),
                                    -std::sin(p) * std::cos(ro));
    const Eigen::RowVector3d dRoll(0, std::cos(p) * std::cos(ro), -std::cos(p) * std::sin(ro));
    const Eigen::Matrix3d Rs = kLaserOnRobot.getRotationMatrix().asEigen();
    const Eigen::Vector3d ts(kLaserOnRobot.x(), kLaserOnRobot.y(), kLaserOnRobot.z());
    // j = a + B q, q = Rs p + ts  =>  j = (a + B ts) + (B Rs) p.
    Eigen::Matrix<double, 6, 3> B = Eigen::Matrix<double, 6, 3>::Zero();
    B.row(4) = dPitch;
    B.row(5) = dRoll;
    Eigen::Matrix<double, 6, 1> a = Eigen::Matrix<double, 6, 1>::Zero();
    a(2) = 1;
    const Eigen::Matrix<double, 6, 1> a0 = a + B * ts;
    const Eigen::Matrix<double, 6, 3> B0 = B * Rs;
    const Eigen::Matrix<double, 6, 6> C = s.robotPose.cov.asEigen();
    const Eigen::Matrix3d Q = B0.transpose() * C * B0;
    const Eigen::Vector3d bv = B0.transpose() * C * a0;
    k.q[0] = float(Q(0, 0));
    k.q[1] = float(Q(0, 1));
    k.q[2] = float(Q(0, 2));
    k.q[3] = float(Q(1, 1));
    k.q[4] = float(Q(1, 2));
    k.q[5] = float(Q(2, 2));
    for (int i = 0; i < 3; i++) k.b[i] = float(bv(i));
    k.c = float(a0.dot(C * a0));
    return k;
}

/** The grid of the lean kernel: 8 fixed bin slots per cell, information form (no divide in the
 * update: 1 / variance is computed in the vectorised point stage). */
struct LeanGrid {
    std::vector<float> information, weightedHeight, certainty;  //!< per slot
    LeanGrid()
        : information(size_t(kGridCells) * kGridCells * kBinsPerCell, 0.f),
          weightedHeight(information.size(), 0.f),
          certainty(information.size(), 0.f) {}
};

/** Point stage of one scan: slot (or -1 when a gate or the grid refuses the point), weight
 * 1/var and weight * height. The loop is compiled for
 * AVX-512, AVX2 and baseline (runtime dispatch). */
constexpr float kInvCell = float(1.0 / kCell_m), kInvBin = float(1.0 / kBinHeight_m);
constexpr float kMaxVariance_m2 = float(kMaxUncertainty_m * kMaxUncertainty_m / 9.0);
constexpr float kOrigin_m = float(kGridOrigin_m);
/** What the full-state kernel's scatter needs of a point besides slot and weights: its height,
 * its offset from its cell's centre [m] and the code of its pose part of the height variance. */
struct FullPointOutputs {
    float* height_m;
    float* dx_m;
    float* dy_m;
    uint8_t* poseCode;
};

/** One point of the point stage (inlined into the loops); `full`, if given, also gets what the
 * full bin state needs. */
__attribute__((always_inline)) inline void pointStage(const ScanConstants& k, const float* x,
                                                      const float* y, const float* z, int i,
                                                      int32_t* slot, float* weight,
                                                      float* weightedZ,
                                                      const FullPointOutputs* full = nullptr) {
    const float px = x[i], py = y[i], pz = z[i];
    const float mx = k.r[0] * px + k.r[1] * py + k.r[2] * pz + k.t[0];
    const float my = k.r[3] * px + k.r[4] * py + k.r[5] * pz + k.t[1];
    const float dz = k.r[6] * px + k.r[7] * py + k.r[8] * pz;
    const float mz = dz + k.t[2];
    const float r2 = px * px + py * py + pz * pz;
    const float r = std::sqrt(r2);
    const float sr = 0.0006f + 0.0039f * r;
    const float quad = k.q[0] * px * px + k.q[3] * py * py + k.q[5] * pz * pz +
                       2.f * (k.q[1] * px * py + k.q[2] * px * pz + k.q[4] * py * pz) +
                       2.f * (k.b[0] * px + k.b[1] * py + k.b[2] * pz) + k.c;
    const float var = quad + sr * sr * dz * dz / r2;
    const float fx = (mx - kOrigin_m) * kInvCell, fy = (my - kOrigin_m) * kInvCell;
    const int ix = int(fx), iy = int(fy);
    const float fb = mz * kInvBin;
    const int nbTrunc = int(fb);
    const int nb = nbTrunc - int(fb < float(nbTrunc));  // floor without a libm call
    const int ok = int(var <= kMaxVariance_m2) & int(fx >= 0.f) & int(fy >= 0.f) &
                   int(ix < kGridCells) & int(iy < kGridCells);
    const float w = 1.f / var;
    slot[i] = ((iy * kGridCells + ix) * kBinsPerCell + (nb & (kBinsPerCell - 1)) + 1) * ok - 1;
    weight[i] = w;
    weightedZ[i] = w * mz;
    if (full) {
        full->height_m[i] = mz;
        full->dx_m[i] = (fx - float(ix) - 0.5f) * float(kCell_m);
        full->dy_m[i] = (fy - float(iy) - 0.5f) * float(kCell_m);
        full->poseCode[i] = poseSigmaCode(quad);
    }
}

__attribute__((target_clones("avx512f", "avx2", "default"))) void pointStageSimd(
    const ScanConstants& k, const float* __restrict x, const float* __restrict y,
    const float* __restrict z, int n, int32_t* __restrict slot, float* __restrict weight,
    float* __restrict weightedZ) {
#pragma omp simd
    for (int i = 0; i < n; i++) pointStage(k, x, y, z, i, slot, weight, weightedZ);
}

/** The same with the full bin state's outputs. */
__attribute__((target_clones("avx512f", "avx2", "default"))) void pointStageFullSimd(
    const ScanConstants& k, const float* __restrict x, const float* __restrict y,
    const float* __restrict z, int n, int32_t* __restrict slot, float* __restrict weight,
    float* __restrict weightedZ, const FullPointOutputs& full) {
    const FullPointOutputs out = full;  // a copy: no aliasing with the arrays
#pragma omp simd
    for (int i = 0; i < n; i++) pointStage(k, x, y, z, i, slot, weight, weightedZ, &out);
}

/** A bin slot with everything the map keeps per bin, in one cache line as the map's Bin: the
 * height in information form, certainty, point count, the plane moments (the library's
 * addPlanePoint) and the least pose code. */
struct FullSlot {
    float information = 0, weightedHeight = 0, certainty = 0;
    uint32_t points = 0;
    PlaneMoments plane;
    uint8_t poseCode = 0;
};
static_assert(sizeof(FullSlot) <= 64, "one cache line, as the map's Bin");

/** The full-state kernel's grid: 8 fixed slots per cell and, per cell, the highest height (the
 * visibility index's bound). */
struct FullGrid {
    std::vector<FullSlot> slots{size_t(kGridCells) * kGridCells * kBinsPerCell};
    std::vector<float> cellMax_m =
        std::vector<float>(size_t(kGridCells) * kGridCells, -std::numeric_limits<float>::max());
};

/** One point into its slot, per point (no runs), in scan order. */
void scatterFull(FullGrid& g, const int32_t* slot, const float* w, const float* wz,
                 const float* height_m, const float* dx_m, const float* dy_m,
                 const uint8_t* poseCode, int n) {
    for (int i = 0; i < n; i++) {
        if (slot[i] < 0) continue;
        FullSlot& b = g.slots[size_t(slot[i])];
        b.information += w[i];
        b.weightedHeight += wz[i];
        b.certainty += 1.f;
        b.points++;
        addPlanePoint(b.plane, dx_m[i], dy_m[i], height_m[i], w[i]);
        b.poseCode = leastPoseSigmaCode(b.poseCode, poseCode[i]);
        float& top = g.cellMax_m[size_t(slot[i]) / kBinsPerCell];
        top = std::max(top, height_m[i]);
    }
}

inline void scatterOne(LeanGrid& g, int32_t s, float w, float wz) {
    if (s < 0) return;
    g.information[size_t(s)] += w;
    g.weightedHeight[size_t(s)] += wz;
    g.certainty[size_t(s)] += 1.f;
}

/** Scatter in point order (one store-to-load chain through repeated slots). */
void scatterInOrder(LeanGrid& g, const int32_t* slot, const float* w, const float* wz, int n) {
    for (int i = 0; i < n; i++) scatterOne(g, slot[i], w[i], wz[i]);
}

/** Scatter four ways interleaved: points i, i + n/4, i + n/2, i + 3n/4 together, which rarely
 * share a bin (consecutive points of a scan do), so the four chains run in parallel. The sum per
 * slot is the same up to float rounding order. */
void scatterInterleaved(LeanGrid& g, const int32_t* slot, const float* w, const float* wz, int n) {
    const int q = n / 4;
    for (int i = 0; i < q; i++) {
        scatterOne(g, slot[i], w[i], wz[i]);
        scatterOne(g, slot[i + q], w[i + q], wz[i + q]);
        scatterOne(g, slot[i + 2 * q], w[i + 2 * q], wz[i + 2 * q]);
        scatterOne(g, slot[i + 3 * q], w[i + 3 * q], wz[i + 3 * q]);
    }
    for (int i = 4 * q; i < n; i++) scatterOne(g, slot[i], w[i], wz[i]);
}

struct Prepared {
    std::vector<Scan> scans = makeScans();
    std::vector<ScanConstants> constants;
    Prepared() {
        for (const Scan& s : scans) constants.push_back(precompute(s));
    }
};
const Prepared& prepared() {
    static const Prepared p;
    return p;
}

void runFullStateKernel(FullGrid& g) {
    const Prepared& p = prepared();
    alignas(64) int32_t slot[kBeams];
    alignas(64) float w[kBeams], wz[kBeams], h[kBeams], dx[kBeams], dy[kBeams];
    alignas(64) uint8_t code[kBeams];
    const FullPointOutputs full{h, dx, dy, code};
    for (size_t k = 0; k < p.scans.size(); k++) {
        const Scan& s = p.scans[k];
        const int n = int(s.x.size());
        pointStageFullSimd(p.constants[k], s.x.data(), s.y.data(), s.z.data(), n, slot, w, wz,
                           full);
        scatterFull(g, slot, w, wz, h, dx, dy, code, n);
    }
}

template <bool kInterleaved>
void runLeanKernel(LeanGrid& g) {
    const Prepared& p = prepared();
    alignas(64) int32_t slot[kBeams];
    alignas(64) float w[kBeams], wz[kBeams];
    for (size_t k = 0; k < p.scans.size(); k++) {
        const Scan& s = p.scans[k];
        const int n = int(s.x.size());
        pointStageSimd(p.constants[k], s.x.data(), s.y.data(), s.z.data(), n, slot, w, wz);
        if (kInterleaved)
            scatterInterleaved(g, slot, w, wz, n);
        else
            scatterInOrder(g, slot, w, wz, n);
    }
}

/** The scans as the map's sensor points: range-only covariance with the same sigma. */
std::vector<PointsWithCov> sensorPointsOfScans() {
    std::vector<PointsWithCov> out;
    for (const Scan& s : prepared().scans) {
        PointsWithCov pts(s.x.size());
        for (size_t i = 0; i < s.x.size(); i++) {
            const Eigen::Vector3f p(s.x[i], s.y[i], s.z[i]);
            pts[i].point_m = p;
            pts[i].cov_m2 = rangeOnlyCovariance(p.normalized(), rangeSigma_m(p.norm()));
        }
        out.push_back(std::move(pts));
    }
    return out;
}

/** Checks before timing: the kernel's variance against the library's z-z entry, and the two
 * scatter orders against each other. Empty if all agree, else what differs. */
std::string checkKernel() {
    const Prepared& p = prepared();
    const auto sensorPoints = sensorPointsOfScans();
    double worstRel = 0;
    for (size_t k = 0; k < p.scans.size(); k += 97) {
        const PosePropagator prop(p.scans[k].robotPose, kLaserOnRobot);
        const Scan& s = p.scans[k];
        int32_t slot[kBeams];
        float w[kBeams], wz[kBeams];
        pointStageSimd(p.constants[k], s.x.data(), s.y.data(), s.z.data(), int(s.x.size()), slot, w,
                       wz);
        for (size_t i = 0; i < s.x.size(); i += 7) {
            const double ref = prop.apply(sensorPoints[k][i]).cov_m2.zz;
            worstRel = std::max(worstRel, std::abs(1.0 / w[i] - ref) / ref);
        }
    }
    if (!(worstRel < 1e-3))
        return "kernel variance differs from the library's z-z entry by " +
               std::to_string(worstRel);
    LeanGrid a, b;
    runLeanKernel<false>(a);
    runLeanKernel<true>(b);
    double worstHeight_m = 0;
    size_t used = 0;
    for (size_t i = 0; i < a.information.size(); i++) {
        if (a.certainty[i] != b.certainty[i]) return "the two scatter orders give other counts";
        if (a.certainty[i] == 0) continue;
        used++;
        worstHeight_m =
            std::max(worstHeight_m, double(std::abs(a.weightedHeight[i] / a.information[i] -
                                                    b.weightedHeight[i] / b.information[i])));
    }
    if (used == 0 || !(worstHeight_m < 1e-5)) return "the two scatter orders give other heights";
    // The full-state kernel sums the same weights in the same order as the in-order scatter, so
    // the same counts, information and heights, and its plane moments' weight is that information
    // again; up to rounding, and for a few points a neighbouring slot: its point stage is another
    // function, which GCC may contract into fused multiply-adds otherwise, so a point on a cell
    // or bin edge may fall on the other side.
    FullGrid f;
    runFullStateKernel(f);
    const auto near = [](float u, float v) {
        return std::abs(u - v) <= 1e-5f * std::max(std::abs(u), std::abs(v));
    };
    size_t differing = 0;
    for (size_t i = 0; i < a.information.size(); i++) {
        const FullSlot& b = f.slots[i];
        if (b.certainty == 0 && a.certainty[i] == 0) continue;
        const double heightDifference_m =
            b.weightedHeight / b.information - a.weightedHeight[i] / a.information[i];
        differing += !(b.certainty == a.certainty[i] && near(b.information, a.information[i]) &&
                       std::abs(heightDifference_m) < 1e-6 && near(b.plane.weight, b.information));
    }
    if (!(differing * 1000 <= used))
        return "the full-state kernel's slots differ from the lean kernel's in " +
               std::to_string(differing) + " of " + std::to_string(used);
    return {};
}

void setCounters(benchmark::State& state) {
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kPoints));
}

}  // namespace

static void BM_LeanKernelInOrderScatter(benchmark::State& state) {
    if (const std::string e = checkKernel(); !e.empty()) {
        state.SkipWithError(e.c_str());
        return;
    }
    LeanGrid g;
    for (auto _ : state) runLeanKernel<false>(g);
    setCounters(state);
}
BENCHMARK(BM_LeanKernelInOrderScatter)->Unit(benchmark::kMillisecond);

static void BM_LeanKernelInterleavedScatter(benchmark::State& state) {
    LeanGrid g;
    for (auto _ : state) runLeanKernel<true>(g);
    setCounters(state);
}
BENCHMARK(BM_LeanKernelInterleavedScatter)->Unit(benchmark::kMillisecond);

/** The lean kernel with the map's whole per-bin state (plane moments, certainty, count, pose
 * code, the cell's highest height) updated per point in fixed 64-byte slots: what the method's
 * state costs at best, against the map's core below. */
static void BM_LeanKernelFullBinState(benchmark::State& state) {
    if (const std::string e = checkKernel(); !e.empty()) {
        state.SkipWithError(e.c_str());
        return;
    }
    FullGrid g;
    for (auto _ : state) runFullStateKernel(g);
    setCounters(state);
}
BENCHMARK(BM_LeanKernelFullBinState)->Unit(benchmark::kMillisecond);

/** Arg: the insertion core's threads (1: the single-core figure the ratio uses; 2: the
 * two-stage pipeline, reported apart). */
static void BM_MapInsertSensorPoints(benchmark::State& state) {
    const auto sensorPoints = sensorPointsOfScans();
    std::vector<PosePropagator> propagators;
    for (const Scan& s : prepared().scans) propagators.emplace_back(s.robotPose, kLaserOnRobot);
    BinUpdateParams params;
    params.binHeight_m = kBinHeight_m;
    params.maxElevationUncertainty_m = kMaxUncertainty_m;
    const int origin = int(std::floor(kGridOrigin_m / kCell_m));
    BinGrid grid(kCell_m);
    grid.reset(kCell_m, CellWindow{origin, origin, kGridCells, kGridCells});
    grid.setInsertionThreads(int(state.range(0)));
    for (auto _ : state) {
        for (size_t k = 0; k < sensorPoints.size(); k++) {
            grid.beginCycle();
            benchmark::DoNotOptimize(
                grid.insertSensorPoints(propagators[k], sensorPoints[k], params));
        }
    }
    setCounters(state);
}
BENCHMARK(BM_MapInsertSensorPoints)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

static void BM_MrptHeightGridMean(benchmark::State& state) {
    std::vector<PointsWithCov> mapPoints;
    const auto sensorPoints = sensorPointsOfScans();
    for (size_t k = 0; k < sensorPoints.size(); k++) {
        mapPoints.emplace_back();
        PosePropagator(prepared().scans[k].robotPose, kLaserOnRobot)
            .apply(sensorPoints[k], mapPoints.back());
    }
    mrpt::maps::CHeightGridMap2D grid(mrpt::maps::CHeightGridMap2D::mrSimpleAverage, kGridOrigin_m,
                                      -kGridOrigin_m, kGridOrigin_m, -kGridOrigin_m, kCell_m);
    mrpt::maps::CHeightGridMap2D_Base::TPointInsertParams ip;
    ip.update_map_after_insertion = false;
    for (auto _ : state)
        for (const auto& scan : mapPoints)
            for (const auto& p : scan)
                grid.insertIndividualPoint(p.point_m.x(), p.point_m.y(), p.point_m.z(), ip);
    setCounters(state);
}
BENCHMARK(BM_MrptHeightGridMean)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
