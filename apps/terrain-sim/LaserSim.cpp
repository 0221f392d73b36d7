/* Part of the multibin elevation-mapping library: terrain-sim. */
#include "LaserSim.h"

#include <algorithm>
#include <cmath>

namespace terrain_sim {

LaserSim::LaserSim(const LaserConfig& cfg, const Terrain& terrain, const SurfaceTexture& texture,
                   uint64_t seed)
    : cfg_(cfg), terrain_(&terrain), texture_(&texture) {
    std::mt19937_64 rng(hash64(seed ^ 0xb1a5u));
    std::uniform_real_distribution<double> u(-cfg.surfaceBiasMax_m, cfg.surfaceBiasMax_m);
    bias_.resize(terrain.surfaceCount());
    for (auto& b : bias_) b = u(rng);
}

mrpt::poses::CPose3D LaserConfig::truePose() const {
    if (pitchError_rad == 0.0) return pose;
    return mrpt::poses::CPose3D(pose.x(), pose.y(), pose.z(), pose.yaw(),
                                pose.pitch() + pitchError_rad, pose.roll());
}

Eigen::Vector3d LaserSim::beamDirection(int k) const {
    const double a = -0.5 * cfg_.aperture_rad + k * cfg_.aperture_rad / (cfg_.beams - 1);
    return {std::cos(a), std::sin(a), 0.0};
}

mrpt::obs::CObservation2DRangeScan::Ptr LaserSim::scan(const mrpt::poses::CPose3D& robot,
                                                       mrpt::Clock::time_point stamp,
                                                       std::mt19937_64& rng,
                                                       std::vector<BeamTruth>* truthOut) const {
    const mrpt::poses::CPose3D sensor = robot + cfg_.truePose();
    const Eigen::Matrix3d R = sensor.getRotationMatrix().asEigen();
    const Eigen::Vector3d o(sensor.x(), sensor.y(), sensor.z());
    const int n = cfg_.beams;
    std::vector<BeamTruth> truth(n);
    std::vector<double> range(n, 0.0);
    std::normal_distribution<double> gauss(0.0, 1.0);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    for (int k = 0; k < n; ++k) {
        const Eigen::Vector3d d = R * beamDirection(k);
        auto& t = truth[k];
        t.trueRange_m = terrain_->castRay(o, d, cfg_.maxRange_m);
        // Draw every beam's noise whether it hits or not: the random stream stays aligned.
        const double z = gauss(rng);
        if (!std::isfinite(t.trueRange_m) || t.trueRange_m < cfg_.minRange_m) continue;
        const Eigen::Vector3d p = o + t.trueRange_m * d;
        t.surface = terrain_->surfaceId(p.x(), p.y());
        const double cosInc = std::abs(terrain_->normal(p.x(), p.y()).dot(d));
        t.restored = 1023.0 * texture_->albedo(p.x(), p.y()) * std::sqrt(cosInc);
        if (t.restored < cfg_.dropoutRestored) {
            t.dropout = true;
            continue;
        }
        const double rt = t.trueRange_m;
        // Optional errors draw from the stream only when on, so matched runs keep their bytes.
        const double scale = cfg_.errors.drawnErrorScale;  // 1: the sum below as it always was
        double r = rt + scale * bias_[t.surface] +
                   scale * cfg_.sigma(rt) * z * cfg_.errors.tailFactor(rng);
        if (cfg_.rangeBias0_m != 0.0 || cfg_.rangeBiasSlope != 0.0)
            r += cfg_.rangeBias0_m + cfg_.rangeBiasSlope * rt;
        double factor = 1.0;
        if (cfg_.errors.drawOutlier(rng, factor)) {
            r = rt * factor;
            t.outlier = true;
        }
        if (t.restored < cfg_.darkRestored && !t.outlier) {
            t.dark = true;
            r += cfg_.errors.drawnErrorScale *
                 (cfg_.darkBias_m + cfg_.darkExtraSigma_m * gauss(rng));
        }
        range[k] = r;
    }
    // Mixed pixels: where neighbouring beams straddle a depth edge, the farther beam's footprint
    // covers both surfaces and its range falls between them.
    // An edge is a jump that the neighbours' trend does not explain (a smooth surface seen at a
    // grazing angle also has large steps between beams, but a steady slope of range).
    auto tr = [&](int k) { return truth[k].trueRange_m; };
    for (int k = 1; k + 2 < n; ++k) {
        const double u = uni(rng), w = uni(rng);
        if (range[k] <= 0 || range[k + 1] <= 0 || !std::isfinite(tr(k - 1)) ||
            !std::isfinite(tr(k + 2)))
            continue;
        const double jump = tr(k + 1) - tr(k);
        const double trend = 0.5 * ((tr(k) - tr(k - 1)) + (tr(k + 2) - tr(k + 1)));
        if (std::abs(jump) < cfg_.mixedJump_m || std::abs(jump - trend) < cfg_.mixedJump_m ||
            u >= cfg_.mixedProbability)
            continue;
        const int far = range[k] > range[k + 1] ? k : k + 1, nearB = far == k ? k + 1 : k;
        if (truth[far].mixed || truth[nearB].mixed) continue;
        range[far] = range[nearB] + (0.2 + 0.6 * w) * (range[far] - range[nearB]);
        truth[far].mixed = true;
    }
    auto obs = mrpt::obs::CObservation2DRangeScan::Create();
    obs->sensorLabel = cfg_.label;
    obs->timestamp = stamp;
    obs->aperture = static_cast<float>(cfg_.aperture_rad);
    obs->rightToLeft = true;
    obs->maxRange = static_cast<float>(cfg_.maxRange_m);
    obs->sensorPose = cfg_.pose;
    obs->stdError = static_cast<float>(cfg_.sigma(1.0));
    obs->beamAperture = static_cast<float>(cfg_.aperture_rad / (n - 1));
    obs->resizeScan(n);
    obs->setScanHasIntensity(true);
    for (int k = 0; k < n; ++k) {
        const bool valid = range[k] >= cfg_.minRange_m && range[k] < cfg_.maxRange_m;
        obs->setScanRange(
            k, valid ? static_cast<float>(range[k]) : static_cast<float>(cfg_.maxRange_m));
        obs->setScanRangeValidity(k, valid);
        // Raw intensity from eq 1 inverted: I = Ires^2 * vAGC / 1023.
        const double I = truth[k].restored * truth[k].restored * cfg_.agc / 1023.0;
        obs->setScanIntensity(k, static_cast<int>(std::lround(std::min(I, 2e9))));
    }
    if (truthOut) *truthOut = std::move(truth);
    return obs;
}

}  // namespace terrain_sim
