/* Part of the multibin elevation-mapping library: terrain-sim. */
#pragma once

#include "Terrain.h"

#include <mrpt/math/CMatrixFixed.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>

#include <array>
#include <random>
#include <vector>

namespace terrain_sim {

/** One sensory frame of a scenario: when, where the robot truly is, what the estimator says. */
struct Frame {
    double t_s = 0;                            //!< time since the start [s]
    mrpt::poses::CPose3D truth;                //!< true robot pose in the map frame
    mrpt::poses::CPose3DPDFGaussian estimate;  //!< estimated pose: truth + drawn error, with cov
    bool stereo = false;                       //!< a stereo frame is taken here
};

/** Pose-error model, in MRPT's (x y z yaw pitch roll) order [m m m rad rad rad].
 * The covariance after a correction is diag(sigma0^2); each laser period adds diag(sigmaStep^2)
 * (a random walk, as a visual tracker drifts) until the next correction, every
 * correctionPeriod_s, where the error is drawn afresh from diag(sigma0^2). With sigmaStep = 0 the
 * errors are independent draws from diag(sigma0^2) per frame. */
struct PoseErrorModel {
    std::array<double, 6> sigma0{};
    std::array<double, 6> sigmaStep{};
    double correctionPeriod_s = 0;
    /** The covariance after k steps since a correction. */
    mrpt::math::CMatrixDouble66 covariance(int stepsSinceCorrection) const;
};

struct TrajectoryOptions {
    double laserRate_hz = 10;
    double stereoRate_hz = 1;
    double mockupStep_m = 0.01;  //!< mockup: the rig advances this much per laser scan
    double walkSpeed_mps = 0.1;  //!< walk: mean forward speed
    double gaitPeriod_s = 1.0;   //!< walk: tripod gait cycle
    double startX_m = -0.5;      //!< first robot x [m]
    double endMargin_m = 0.1;    //!< walk ends this far beyond the tiles [m]; mockup: stops
                                 //!< 0.3 m before their far edge
    int maxFrames = 0;           //!< if > 0, stop after this many frames (tests, previews)
    /** Scale of the drawn pose errors: 1, or 0 for exact poses (`--noise exact`; the written
     * covariances unchanged, the draws still made). */
    double poseErrorScale = 1.0;
};

/** The paper's mock-up set-up: the rig held by an industrial arm at constant height above the
 * mean tile height, level, moved along +x in equal steps towards and over the terrain. */
PoseErrorModel mockupErrorModel();
/** A visual tracker's drifting pose error between corrections (walk). */
PoseErrorModel walkErrorModel();

/** Draws the model's pose errors along the frames (scaled by opts.poseErrorScale) and fills
 * each frame's estimate (truth + error) and covariance. */
void applyPoseErrors(std::vector<Frame>& frames, const PoseErrorModel& model,
                     const TrajectoryOptions& opts, std::mt19937_64& rng);

/** The hexapod's body pose standing at (x, y) [m] with heading yaw [rad] at gait phase ph
 * [rad]: height, pitch and roll follow the terrain under its six feet, with the gait's bob and
 * rocking on top (the walk's body model). */
mrpt::poses::CPose3D hexapodPose(const Terrain& terrain, double x_m, double y_m, double yaw_rad,
                                 double ph_rad);

std::vector<Frame> mockupTrajectory(const Terrain& terrain, const TrajectoryOptions& opts,
                                    std::mt19937_64& rng);
/** A hexapod walk along y = 0 in +x: body height, pitch and roll follow the terrain under the
 * six feet, with tripod-gait sway (y, z, yaw, roll) on top. */
std::vector<Frame> walkTrajectory(const Terrain& terrain, const TrajectoryOptions& opts,
                                  std::mt19937_64& rng);

}  // namespace terrain_sim
