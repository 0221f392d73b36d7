/* Part of the multibin elevation-mapping library: terrain-sim. */
#pragma once

#include "SensorErrors.h"
#include "SurfaceTexture.h"
#include "Terrain.h"

#include <mrpt/obs/CObservationStereoImages.h>
#include <mrpt/poses/CPose3D.h>
#include <opencv2/core.hpp>

#include <array>
#include <random>
#include <string>

namespace terrain_sim {

/** The STOC-style stereo camera of the Messor rig (paper Fig. 1), rectified pinhole pair. */
struct StereoConfig {
    std::string label = "STEREO";
    int width_px = 320, height_px = 240;
    double hfov_rad = 60.0 * M_PI / 180.0;  //!< horizontal field of view -> fx = fy
    double baseline_m = 0.09;
    double height_m = 0.48;                  //!< left camera above the robot frame origin
    double pitch_rad = 35.0 * M_PI / 180.0;  //!< optical axis below the horizontal
    double forward_m = 0.05;                 //!< left camera ahead of the robot frame origin
    bool disparity = true;                   //!< also write a STOC-style disparity image
    double pixelNoise_grey = 1.0;            //!< image noise sigma [grey levels]
    double matchingSigma_px = 0.25;          //!< disparity noise of the simulated matcher [px]
    int haloWidth_px = 4;                    //!< foreground fattening at depth edges [px]
    double haloJump_px = 2.0;                //!< disparity jump that makes an edge [px]
    double texturelessStd_grey = 3.0;        //!< 7x7 grey std below which matching fails
    int blobsPerFrame = 2;                   //!< near-camera blobs in textureless areas
    /** Calibration standard deviations written to the ini (contract): cv::calibrateCamera order
     * fx fy cx cy k1 k2 p1 p2 k3 [px px px px - - - - -], extrinsics rx ry rz tx ty tz [rad, m]. */
    std::array<double, 9> intrinsicsSigma{0.4, 0.4, 0.3, 0.3, 0.002, 0.004, 0.0002, 0.0002, 0.005};
    std::array<double, 6> extrinsicsSigma{0.0005, 0.0005, 0.0003, 0.0002, 0.0001, 0.0002};
    // Errors the library's stereo model does not describe (off by default, doc/terrain-sim.md).
    ErrorShape errors;  //!< heavy tails and gross outliers of the matching (disparity image)
    /** Chance that a pixel at a depth edge (a 4-neighbour more than haloJump_px away in true
     * disparity) matches a blend of both sides: d + w (d_neighbour - d), w ~ U(0, 1). */
    double mixedProbability = 0.0;
    /** Calibration errors: the pair is rendered with the true values (nominal + error), the
     * observation and the ini keep the nominal ones, so the map is not told. */
    double baselineError_m = 0.0;
    double cxError_px = 0.0, cyError_px = 0.0;
    /** Errors of the images themselves (for matching on the rendered pair): the right image's
     * rows lie this far below the left's (a rectification error) [px], and its grey levels are
     * the left camera's times this gain (an exposure mismatch). 0 and 1: none. */
    double rightRowError_px = 0.0;
    double rightGain = 1.0;

    double fx_px() const { return 0.5 * width_px / std::tan(0.5 * hfov_rad); }
    double cx_px() const { return 0.5 * (width_px - 1); }
    double cy_px() const { return 0.5 * (height_px - 1); }
    /** Left camera on the robot: +z forward along the pitched axis, +x right, +y down. */
    mrpt::poses::CPose3D leftPose() const;
};

/** A rendered stereo pair with the truth behind it. */
struct StereoRender {
    cv::Mat left, right;    //!< CV_8U grey
    cv::Mat trueDisparity;  //!< CV_32F, left image, fx * B / z_cam [px]; 0 where no surface
    cv::Mat disparity16;    //!< CV_16U, disparity * 16, 0 = invalid (artefacts included)
    /** CV_8U, left image: what the matcher did at each pixel (one of the kinds below). */
    cv::Mat matchKind;
    enum Kind : uint8_t { kNone = 0, kNoise = 1, kHalo = 2, kMixed = 3, kOutlier = 4, kBlob = 5 };
};

class StereoSim {
public:
    StereoSim(const StereoConfig& cfg, const Terrain& terrain, const SurfaceTexture& texture);

    /** Renders both images (and the disparity image if configured) from the robot pose. */
    StereoRender render(const mrpt::poses::CPose3D& robot, std::mt19937_64& rng) const;
    /** The MRPT observation of a render. */
    mrpt::obs::CObservationStereoImages::Ptr observation(const StereoRender& r,
                                                         mrpt::Clock::time_point stamp) const;
    /** Grey level of the surface at a map point with normal n (albedo times Lambert shading). */
    double shade(const Eigen::Vector3d& p, const Eigen::Vector3d& n) const;
    const StereoConfig& config() const { return cfg_; }

private:
    /** Renders one camera (pose in the map frame): grey image (noise-free, CV_64F) and z_cam. */
    void renderView(const mrpt::poses::CPose3D& cam, double rowError_px, cv::Mat& grey,
                    cv::Mat& zcam) const;
    StereoConfig cfg_;
    const Terrain* terrain_;
    const SurfaceTexture* texture_;
};

}  // namespace terrain_sim
