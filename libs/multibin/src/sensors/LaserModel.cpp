/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/LaserModel.h"
#include "multibin/sensors/ObservationChecks.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

#include "multibin/geometry/PosePropagation.h"
#include "multibin/util/VectorClones.h"

namespace multibin::sensors {

double restoredIntensity(double rawIntensity, double agcVoltage) {
    return std::sqrt(std::max(0.0, rawIntensity) * 1023.0 / agcVoltage);
}

std::vector<bool> findMixedPixels(const std::vector<float>& ranges_m,
                                  const LaserModelOptions& opts) {
    const size_t n = ranges_m.size();
    std::vector<bool> mixed(n, false);
    auto finiteRange = [&](size_t i) { return std::isfinite(ranges_m[i]); };
    size_t i = 0;
    while (i < n) {
        if (!finiteRange(i)) {
            i++;
            continue;
        }
        // Cluster [i, j): consecutive returns with small range steps.
        size_t j = i + 1;
        while (j < n && finiteRange(j) &&
               std::abs(ranges_m[j] - ranges_m[j - 1]) <= opts.mixedPixelJump_m)
            j++;
        const size_t size = j - i;
        // Both sides must be known beams (a return or "no return"); scan ends are not edges.
        if (size <= size_t(opts.mixedPixelMaxBeams) && i > 0 && j < n) {
            const double before = ranges_m[i - 1], after = ranges_m[j];  // +inf = no return
            const double lo = std::min(before, after), hi = std::max(before, after);
            bool between = true;
            for (size_t k = i; k < j; k++)
                between = between && ranges_m[k] > lo + opts.mixedPixelJump_m &&
                          ranges_m[k] < hi - opts.mixedPixelJump_m;
            // A surface seen at a grazing angle has steps larger than the jump between every
            // pair of beams, but a steady slope of range: a cluster that continues the trend of
            // the two beams before it, or of the two after it, is a surface, not an edge.
            const bool trendBefore =
                i >= 2 && std::abs(ranges_m[i] - (2.0 * ranges_m[i - 1] - ranges_m[i - 2])) <=
                              opts.mixedPixelJump_m;
            const bool trendAfter =
                j + 1 < n && std::abs(ranges_m[j - 1] - (2.0 * ranges_m[j] - ranges_m[j + 1])) <=
                                 opts.mixedPixelJump_m;
            if (between && !trendBefore && !trendAfter)
                for (size_t k = i; k < j; k++) mixed[k] = true;
        }
        i = j;
    }
    return mixed;
}

namespace {
/** The unit beam directions (cos a_i, sin a_i, 0) of a scan, a_i = getScanAngle(i): the same for
 * every scan of one laser, so they are cached per thread and rebuilt when the beam count, the
 * aperture or the scanning direction change (the sine and cosine were 5 % of a scan). */
const std::vector<Eigen::Vector3f>& beamDirections(const mrpt::obs::CObservation2DRangeScan& scan) {
    struct Cache {
        size_t beams = 0;
        float aperture = 0;
        uint8_t rightToLeft = 0;
        bool built = false;
        std::vector<Eigen::Vector3f> directions;
    };
    thread_local Cache cache;
    const size_t n = scan.getScanSize();
    // The scanning direction's byte, not the bool: a corrupt file can hold any byte there, and
    // loading it as a bool is undefined (MRPT's getScanAngle reads it itself; the same byte gives
    // the same angles).
    uint8_t rightToLeft;
    static_assert(sizeof(scan.rightToLeft) == 1, "a bool of one byte");
    std::memcpy(&rightToLeft, &scan.rightToLeft, 1);
    if (!cache.built || cache.beams != n || !(cache.aperture == scan.aperture) ||
        cache.rightToLeft != rightToLeft) {
        cache.directions.resize(n);
        for (size_t i = 0; i < n; i++) {
            const float a = scan.getScanAngle(i);
            cache.directions[i] = Eigen::Vector3f(std::cos(a), std::sin(a), 0.f);
        }
        cache.beams = n;
        cache.aperture = scan.aperture;
        cache.rightToLeft = rightToLeft;
        cache.built = true;
    }
    return cache.directions;
}
}  // namespace

void laserScanToPoints(const mrpt::obs::CObservation2DRangeScan& scan,
                       const LaserModelOptions& opts, double minRange_m, double maxRange_m,
                       PointsWithCov& out, LaserStats& stats) {
    const size_t n = scan.getScanSize();
    out.clear();
    out.reserve(n);
    stats.beams += n;
    // The beam angles derive from the aperture: a corrupt one refuses the scan whole.
    if (const std::string why = apertureProblem(scan); !why.empty()) {
        stats.badAperture += n;
        throw std::invalid_argument(why);
    }

    // Ranges for the mixed-pixel clustering: +inf = no return, NaN = unusable reading.
    std::vector<float> ranges(n);
    // getScanRange() returns a reference into the scan's contiguous range vector.
    const float* scanRanges = n > 0 ? &scan.getScanRange(0) : nullptr;
    for (size_t i = 0; i < n; i++) {
        const float r = scanRanges[i];
        if (!std::isfinite(r))
            ranges[i] = std::numeric_limits<float>::quiet_NaN();
        else if (!scan.getScanRangeValidity(i) || r >= scan.maxRange || r <= 0)
            ranges[i] = std::numeric_limits<float>::infinity();
        else
            ranges[i] = r;
    }
    const std::vector<bool> mixed =
        opts.mixedPixelFilter ? findMixedPixels(ranges, opts) : std::vector<bool>(n, false);

    const std::vector<Eigen::Vector3f>& directions = beamDirections(scan);
    const auto agc = opts.agcByLabel.find(scan.sensorLabel);
    const bool checkIntensity = scan.hasIntensity() && agc != opts.agcByLabel.end();
    for (size_t i = 0; i < n; i++) {
        const float r = ranges[i];
        if (std::isnan(r)) {
            stats.notFinite++;
            continue;
        }
        if (std::isinf(r)) {
            stats.noReturn++;
            continue;
        }
        if (r < minRange_m || r > maxRange_m) {
            stats.outOfRange++;
            continue;
        }
        if (checkIntensity && r < opts.intensityCheckRange_m &&
            restoredIntensity(scan.getScanIntensity(i), agc->second) < opts.minRestoredIntensity) {
            stats.lowIntensity++;
            continue;
        }
        if (mixed[i]) {
            stats.mixedPixel++;
            continue;
        }
        const Eigen::Vector3f& dir = directions[i];
        out.push_back({dir * r, rangeOnlyCovariance(dir, float(opts.rangeSigma(r)))});
        stats.kept++;
    }
}

namespace {
/** What continuityBound_m's per-point term needs, by value. */
struct ContinuityTerms {
    double zRow[3];  //!< row 2 of the sensor-to-map rotation
    RangeSigmaCurve rangeSigma;
    double previous[10], current[10];  //!< the poses' height-variance polynomials
    double rho;                        //!< correlation of the two poses' errors
};

/** 2 sigma_zr^2 + sigma_zp^2 of each of `n` points (continuityBound_m's) into `out`; 0 for a
 * point at range 0 (or NaN). Branch-free, so it vectorises (the maximum is taken after: GCC 12
 * does not vectorise a floating-point max reduction without -ffast-math). */
MULTIBIN_VECTOR_CLONES
void differenceVariances(const ContinuityTerms& t, const double* xs, const double* ys,
                         const double* zs, size_t n, double* out) {
    for (size_t i = 0; i < n; i++) {
        const double x = xs[i], y = ys[i], z = zs[i];
        const double range = std::sqrt(x * x + y * y + z * z);
        const double along = t.zRow[0] * (x / range) + t.zRow[1] * (y / range) +
                             t.zRow[2] * (z / range);  // e_z . d in the map
        const double sZr = t.rangeSigma(range) * std::abs(along);
        const double sa2 = PosePropagator::heightVariancePolynomial(t.previous, x, y, z);
        const double sb2 = PosePropagator::heightVariancePolynomial(t.current, x, y, z);
        const double d2 = sa2 + sb2 - 2 * t.rho * std::sqrt(sa2 * sb2);
        const double v = 2 * sZr * sZr + (d2 > 0 ? d2 : 0.0);
        out[i] = range > 0 ? v : 0.0;
    }
}
}  // namespace

double continuityBound_m(const PointsWithCov& sensorPoints, const mrpt::poses::CPose3D& sensorPose,
                         const mrpt::poses::CPose3DPDFGaussian& previousRobotPose,
                         const mrpt::poses::CPose3DPDFGaussian& currentRobotPose,
                         const LaserModelOptions& opts) {
    if (sensorPoints.empty()) return std::numeric_limits<double>::infinity();
    // The pose terms are the z-z entries of J_R C J_R^T, which the propagators hold as
    // polynomials in the sensor-frame point: no Jacobian and no 6x6 product per point.
    ContinuityTerms t;
    const PosePropagator prev(previousRobotPose, sensorPose), cur(currentRobotPose, sensorPose);
    std::copy_n(prev.poseHeightVarianceCoefficients(), 10, t.previous);
    std::copy_n(cur.poseHeightVarianceCoefficients(), 10, t.current);
    const auto& Rs = sensorPose.getRotationMatrix();
    const auto& Rr = currentRobotPose.mean.getRotationMatrix();
    // Height component of a sensor-frame direction in the map: row 2 of Rr * Rs.
    for (int c = 0; c < 3; c++)
        t.zRow[c] = Rr(2, 0) * Rs(0, c) + Rr(2, 1) * Rs(1, c) + Rr(2, 2) * Rs(2, c);
    t.rangeSigma = opts.rangeSigma;
    t.rho = opts.continuityPoseCorrelation;

    double worst2 = 0;
    constexpr size_t kBlock = 256;
    alignas(64) double x[kBlock], y[kBlock], z[kBlock], v[kBlock];
    for (size_t begin = 0; begin < sensorPoints.size(); begin += kBlock) {
        const size_t n = std::min(kBlock, sensorPoints.size() - begin);
        gatherPositions(sensorPoints.data() + begin, n, x, y, z);
        differenceVariances(t, x, y, z, n, v);
        for (size_t i = 0; i < n; i++) worst2 = std::max(worst2, v[i]);
    }
    return opts.continuitySigmas * std::sqrt(worst2) + opts.continuityAllowance_m;
}

}  // namespace multibin::sensors
