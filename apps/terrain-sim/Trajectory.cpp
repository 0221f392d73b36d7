/* Part of the multibin elevation-mapping library: terrain-sim. */
#include "Trajectory.h"

#include <cmath>
#include <stdexcept>

namespace terrain_sim {

mrpt::math::CMatrixDouble66 PoseErrorModel::covariance(int k) const {
    mrpt::math::CMatrixDouble66 C;
    C.setZero();
    for (int i = 0; i < 6; ++i) C(i, i) = sigma0[i] * sigma0[i] + k * sigmaStep[i] * sigmaStep[i];
    return C;
}

PoseErrorModel mockupErrorModel() {
    PoseErrorModel m;
    m.sigma0 = {0.0005, 0.0005, 0.0005, 0.0005, 0.0005, 0.0005};
    return m;
}

PoseErrorModel walkErrorModel() {
    PoseErrorModel m;
    m.sigma0 = {0.004, 0.004, 0.003, 0.006, 0.004, 0.004};
    m.sigmaStep = {0.001, 0.001, 0.0005, 0.001, 0.0007, 0.0007};
    m.correctionPeriod_s = 2.0;
    return m;
}

void applyPoseErrors(std::vector<Frame>& frames, const PoseErrorModel& model,
                     const TrajectoryOptions& o, std::mt19937_64& rng) {
    const double rate_hz = o.laserRate_hz;
    std::normal_distribution<double> gauss(0.0, 1.0);
    const int period = model.correctionPeriod_s > 0
                           ? std::max(1, int(std::lround(model.correctionPeriod_s * rate_hz)))
                           : 1;
    std::array<double, 6> e{};
    for (size_t k = 0; k < frames.size(); ++k) {
        const int since = static_cast<int>(k % period);
        if (since == 0)
            for (int i = 0; i < 6; ++i) e[i] = o.poseErrorScale * model.sigma0[i] * gauss(rng);
        else
            for (int i = 0; i < 6; ++i) e[i] += o.poseErrorScale * model.sigmaStep[i] * gauss(rng);
        const auto& p = frames[k].truth;
        frames[k].estimate.mean =
            mrpt::poses::CPose3D(p.x() + e[0], p.y() + e[1], p.z() + e[2], p.yaw() + e[3],
                                 p.pitch() + e[4], p.roll() + e[5]);
        frames[k].estimate.cov = model.covariance(since);
    }
}

namespace {

int stereoEvery(const TrajectoryOptions& o) {
    if (!(o.laserRate_hz > 0) || !(o.stereoRate_hz > 0))
        throw std::invalid_argument("trajectory: rates must be positive");
    return std::max(1, int(std::lround(o.laserRate_hz / o.stereoRate_hz)));
}

}  // namespace

mrpt::poses::CPose3D hexapodPose(const Terrain& terrain, double x, double y, double yaw,
                                 double ph) {
    // Foot positions of the hexapod in the body frame [m]: front, middle, rear pairs.
    const double feet[6][2] = {{0.18, 0.16},  {0.0, 0.2},  {-0.18, 0.16},
                               {0.18, -0.16}, {0.0, -0.2}, {-0.18, -0.16}};
    auto footHeight = [&](double fx, double fy) {  // mean over the foot's 4 cm contact patch
        double s = 0;
        for (int i = -1; i <= 1; ++i)
            for (int j = -1; j <= 1; ++j) s += terrain.height(fx + 0.02 * i, fy + 0.02 * j);
        return s / 9;
    };
    double hf[6], mean = 0;
    for (int i = 0; i < 6; ++i) {
        const double fx = x + feet[i][0] * std::cos(yaw) - feet[i][1] * std::sin(yaw);
        const double fy = y + feet[i][0] * std::sin(yaw) + feet[i][1] * std::cos(yaw);
        hf[i] = footHeight(fx, fy);
        mean += hf[i] / 6;
    }
    const double front = 0.5 * (hf[0] + hf[3]), rear = 0.5 * (hf[2] + hf[5]);
    const double leftH = (hf[0] + hf[1] + hf[2]) / 3, rightH = (hf[3] + hf[4] + hf[5]) / 3;
    // MRPT: positive pitch is nose down, positive roll lifts the left side.
    const double pitch = -std::atan2(front - rear, 0.36) + 0.005 * std::sin(2 * ph);
    const double roll = std::atan2(leftH - rightH, 0.347) + 0.008 * std::sin(ph);
    const double z = mean + 0.004 * std::abs(std::sin(ph));
    return mrpt::poses::CPose3D(x, y, z, yaw, pitch, roll);
}

std::vector<Frame> mockupTrajectory(const Terrain& terrain, const TrajectoryOptions& o,
                                    std::mt19937_64& rng) {
    if (!(o.mockupStep_m > 0)) throw std::invalid_argument("mockup: step must be positive");
    const double endX = terrain.tilesX() * terrain.tileSide_m() - 0.3;
    const int every = stereoEvery(o);
    std::vector<Frame> frames;
    for (int k = 0;; ++k) {
        const double x = o.startX_m + k * o.mockupStep_m;
        if (x > endX + 1e-9 || (o.maxFrames > 0 && k >= o.maxFrames)) break;
        Frame f;
        f.t_s = k / o.laserRate_hz;
        f.truth = mrpt::poses::CPose3D(x, 0, terrain.meanTileHeight_m(), 0, 0, 0);
        f.stereo = k % every == 0;
        frames.push_back(f);
    }
    applyPoseErrors(frames, mockupErrorModel(), o, rng);
    return frames;
}

std::vector<Frame> walkTrajectory(const Terrain& terrain, const TrajectoryOptions& o,
                                  std::mt19937_64& rng) {
    if (!(o.walkSpeed_mps > 0)) throw std::invalid_argument("walk: speed must be positive");
    const double endX = terrain.tilesX() * terrain.tileSide_m() + o.endMargin_m;
    const int every = stereoEvery(o);
    std::vector<Frame> frames;
    for (int k = 0;; ++k) {
        const double t = k / o.laserRate_hz;
        const double x = o.startX_m + o.walkSpeed_mps * t;
        if (x > endX + 1e-9 || (o.maxFrames > 0 && k >= o.maxFrames)) break;
        const double ph = 2 * M_PI * t / o.gaitPeriod_s;
        const double y = 0.006 * std::sin(ph), yaw = 0.01 * std::sin(ph);
        Frame f;
        f.t_s = t;
        f.truth = hexapodPose(terrain, x, y, yaw, ph);
        f.stereo = k % every == 0;
        frames.push_back(f);
    }
    applyPoseErrors(frames, walkErrorModel(), o, rng);
    return frames;
}

}  // namespace terrain_sim
