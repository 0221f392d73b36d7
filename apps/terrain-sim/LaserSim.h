/* Part of the multibin elevation-mapping library: terrain-sim. */
#pragma once

#include "SensorErrors.h"
#include "SurfaceTexture.h"
#include "Terrain.h"

#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/poses/CPose3D.h>
#include <multibin/sensors/RangeSigmaCurve.h>

#include <random>
#include <string>
#include <vector>

namespace terrain_sim {

/** The pitched Hokuyo URG-04LX of the Messor rig (paper Fig. 1). */
struct LaserConfig {
    std::string label = "LASER";
    int beams = 683;
    double aperture_rad = 240.0 * M_PI / 180.0;
    double minRange_m = 0.02;
    double maxRange_m = 4.0;
    /** Laser on the robot: 0.26 m above the robot frame origin (the ground), pitched 45 deg down
     * (MRPT's positive pitch turns +x towards -z). */
    mrpt::poses::CPose3D pose{0.0, 0.0, 0.26, 0.0, 45.0 * M_PI / 180.0, 0.0};
    multibin::sensors::RangeSigmaCurve sigma;  //!< range noise sigma_r(r) [m]
    double surfaceBiasMax_m = 0.004;           //!< per-surface range bias, uniform in +-this [m]
    double agc = 512;  //!< AGC voltage value v_AGC of eq 1 (written to the ini)
    /** Restored intensity model: Ires = 1023 * albedo * sqrt(cos(incidence)). */
    double dropoutRestored = 60;      //!< Ires below this: no return
    double darkRestored = 100;        //!< Ires below this (and >= dropout): unreliable range
    double darkExtraSigma_m = 0.015;  //!< extra noise of unreliable (dark) returns [m]
    double darkBias_m = 0.02;         //!< extra range bias of unreliable (dark) returns [m]
    double mixedJump_m = 0.03;        //!< neighbour range jump that marks a depth edge [m]
    double mixedProbability = 0.5;    //!< chance that the far beam at an edge is a mixed pixel
    // Errors the library's laser model does not describe (off by default, doc/terrain-sim.md).
    ErrorShape errors;            //!< heavy tails and gross outliers of the range
    double rangeBias0_m = 0.0;    //!< extra range bias b0 + b1 r, the same on every surface [m]
    double rangeBiasSlope = 0.0;  //!< b1 [m/m]
    double pitchError_rad = 0.0;  //!< true mounting pitch minus the written `pose` pitch [rad]

    /** The pose the beams are really cast from: `pose` with the mounting pitch error. The scan
     * keeps `pose` as its sensorPose, so the map is not told. */
    mrpt::poses::CPose3D truePose() const;
};

/** What really happened to one beam (for tests and statistics). */
struct BeamTruth {
    double trueRange_m = 0;  //!< exact range to the surface (inf: none within maxRange)
    int surface = -1;        //!< surface id hit (-1: none)
    double restored = 0;     //!< restored intensity Ires of eq 1
    bool dropout = false;    //!< no return because the surface is too dark
    bool dark = false;       //!< returned, but Ires < darkRestored
    bool mixed = false;      //!< mixed pixel: a range between foreground and background
    bool outlier = false;    //!< gross error: true range times U(1 - span, 1 + span)
};

/** Simulates scans of the URG-04LX over a terrain. */
class LaserSim {
public:
    LaserSim(const LaserConfig& cfg, const Terrain& terrain, const SurfaceTexture& texture,
             uint64_t seed);

    /** One scan from the robot at `robot` (map frame). Noise is drawn from `rng`. */
    mrpt::obs::CObservation2DRangeScan::Ptr scan(const mrpt::poses::CPose3D& robot,
                                                 mrpt::Clock::time_point stamp,
                                                 std::mt19937_64& rng,
                                                 std::vector<BeamTruth>* truth = nullptr) const;

    /** The range bias [m] of surface `id` (drawn once from the seed). */
    double surfaceBias_m(int id) const { return bias_.at(id); }
    /** Beam direction in the laser frame for beam k (angle -aperture/2 + k step). */
    Eigen::Vector3d beamDirection(int k) const;
    const LaserConfig& config() const { return cfg_; }

private:
    LaserConfig cfg_;
    const Terrain* terrain_;
    const SurfaceTexture* texture_;
    std::vector<double> bias_;
};

}  // namespace terrain_sim
