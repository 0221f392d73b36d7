/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/obs/CObservationStereoImages.h>
#include <mrpt/obs/obs_frwds.h>

namespace mrpt::obs {
class CObservationPointCloud;  // in mrpt::maps, not in obs_frwds.h
}

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "multibin/geometry/PointsWithCovariance.h"
#include "multibin/sensors/SensorModelOptions.h"
#include "multibin/sensors/SensorStats.h"
#include "multibin/sensors/StereoDisparity.h"

namespace multibin::sensors {

/** Number of calibration parameters: left intrinsics (9), right intrinsics (9), extrinsics (6). */
constexpr int kCalibrationParams = 24;
/** Calibration errors, in the order fx fy cx cy [px] k1 k2 p1 p2 k3 [-] of the left camera, the
 * same of the right camera, then rx ry rz [rad] tx ty tz [m] of the right camera in the left
 * camera frame. */
using CalibrationVector = Eigen::Matrix<double, kCalibrationParams, 1>;

/** Nominal geometry of a RECTIFIED stereo pair (MRPT camera frame: +z forward, +x right, +y down;
 * points are in the left camera frame). Both cameras share fx, fy and cy; the right camera sits
 * at (+baseline_m, 0, 0) of the left one; cx may differ (disparity offset cx - cxRight). */
struct StereoGeometry {
    int width = 0, height = 0;              //!< image size [px]
    double fx = 0, fy = 0, cx = 0, cy = 0;  //!< left rectified camera [px]
    double cxRight = 0;                     //!< right principal point [px]
    double baseline_m = 0;                  //!< [m]

    /** From an observation; throws std::invalid_argument naming the field if the pair is not
     * rectified (distortion, rotation, vertical offset, differing fx/fy/cy) or degenerate. */
    static StereoGeometry fromObservation(const mrpt::obs::CObservationStereoImages& obs);
    bool operator==(const StereoGeometry& o) const;

    /** Eqs 8-9: point [m] (left camera frame) of left pixel (u, v) [px] with disparity d [px]. */
    Eigen::Vector3d triangulate(double u_px, double v_px, double d_px) const;
    /** Jacobian of triangulate() w.r.t. (u, v, d) [m/px]. */
    Eigen::Matrix3d triangulationJacobian(double u_px, double v_px, double d_px) const;

    /** The real (nonlinear) measurement: left pixel u, v and disparity d [px] at which the point
     * `P_m` (left camera frame) is observed when the true calibration is nominal + `delta`:
     * projection through the true distortion model (OpenCV's k1 k2 p1 p2 k3) of each camera, the
     * right camera at its true pose, read with the nominal rectification (an identity for a
     * rectified pair). */
    Eigen::Vector3d observe(const Eigen::Vector3d& P_m, const CalibrationVector& delta) const;
    /** Analytic Jacobian of observe() w.r.t. delta at delta = 0, for the point seen at (u, v, d)
     * (eqs 4-7, linearised at the nominal calibration). Rows u, v, d [px per unit]. */
    Eigen::Matrix<double, 3, kCalibrationParams> calibrationJacobian(double u_px, double v_px,
                                                                     double d_px) const;
};

/** Diagonal calibration covariance (variances) from the option sigmas. */
CalibrationVector calibrationVariances(const StereoModelOptions& opts);

/** What StereoCovarianceTable::appendPoints() did with the pixels it visited. */
struct StereoPixelCounts {
    size_t pixels = 0;       //!< pixels visited (after subsampling)
    size_t noDisparity = 0;  //!< no valid disparity (NaN, or d <= cx - cxRight)
    size_t tooNear = 0;      //!< depth under minDepth_m
    size_t outOfRange = 0;   //!< range outside [minRange_m, maxRange_m]
    size_t kept = 0;         //!< appended as points
    StereoPixelCounts& operator+=(const StereoPixelCounts& o);
};

/** Per-pixel table of the calibration part of the pixel covariance, computed once for a
 * calibration: for each left pixel the 2x2 covariance of (u, v) from the left intrinsics, for each
 * right pixel the variance of u from the right intrinsics and the (depth-independent) variance of
 * u from the extrinsic rotation. The depth-dependent translation part and the matching noise are
 * added per point (a few multiplications). Stored as separate arrays (structure of arrays), so a
 * row of pixels reads contiguous memory. */
class StereoCovarianceTable {
public:
    StereoCovarianceTable(const StereoGeometry& geometry, const StereoModelOptions& opts);

    /** True if the table was built for this geometry and these sigmas. */
    bool matches(const StereoGeometry& geometry, const StereoModelOptions& opts) const;
    const StereoGeometry& geometry() const { return m_geometry; }

    /** Covariance of (u, v, d) [px^2] at left pixel (u, v) with disparity d [px]: calibration
     * (eqs 6-7, the left and right u errors correlated through the shared extrinsics: exact
     * instead of the paper's sigma_d = sigma_ul + sigma_ur bound) plus matching noise
     * 2 sigma_m^2 on d (independent per image). */
    Eigen::Matrix3d pixelCovariance(int u_px, int v_px, double d_px) const;
    /** Eq 10: covariance [m^2] of the triangulated point in the left camera frame. Computed by
     * the same code as appendPoints(). Throws std::out_of_range outside the image. */
    Eigen::Matrix3d pointCovariance(int u_px, int v_px, double d_px) const;

    /** Points [m] (left camera frame, eqs 8-9) with covariances [m^2] (eq 10) of every
     * `step_px`-th pixel in u and v of `disparity` (the table's image size), appended to `out` in
     * raster order. Pixels without a valid disparity, nearer than `minDepth_m` or with a range
     * outside [minRange_m, maxRange_m] are skipped and counted, in that order of tests. No heap
     * allocation per pixel; per row, what depends only on the row is computed once. With
     * `threads` = 2 the process's helper thread computes the lower half of the rows (the same
     * points, in the same order; one thread if the helper is busy). Throws
     * std::invalid_argument if the image size differs from the table's or step_px < 1. */
    StereoPixelCounts appendPoints(const DisparityImage& disparity, int step_px, double minDepth_m,
                                   double minRange_m, double maxRange_m, PointsWithCov& out,
                                   int threads = 1) const;

private:
    StereoGeometry m_geometry;
    CalibrationVector m_var;
    double m_matchingVar_px2 = 0;
    // Per pixel, row-major: left var u, cov uv, var v [px^2]; right var u [px^2] from the
    // intrinsics and the extrinsic rotation.
    std::vector<float> m_luu, m_luv, m_lvv;
    std::vector<double> m_rightVar;
};

/** Points with covariance of a stereo pair in the LEFT camera frame (MRPT camera frame): disparity
 * from the observation's disparity image if present (see decodeDisparityImage()), else OpenCV
 * StereoSGBM; halo and near-cluster filters; every `subsample`-th pixel; eqs 4-10 for the
 * covariance, through `table`: the per-pixel table of this camera that the caller keeps between
 * pairs, (re)built here when the calibration or the sigmas change. What was done with the pixels
 * is added to `stats`; `threads` as for appendPoints(). Throws std::invalid_argument naming the
 * observation if it has neither a disparity image nor a right image, or if the image size
 * differs from its calibration. */
void stereoToPoints(const mrpt::obs::CObservationStereoImages& obs, const StereoModelOptions& opts,
                    double minRange_m, double maxRange_m,
                    std::shared_ptr<const StereoCovarianceTable>& table, PointsWithCov& out,
                    StereoStats& stats, int threads = 1);

}  // namespace multibin::sensors
