/* Part of the multibin elevation-mapping library. */
#pragma once

#include <array>
#include <cmath>
#include <map>
#include <string>

#include "multibin/io/OptionsFwd.h"
#include "multibin/sensors/RangeSigmaCurve.h"

namespace multibin::sensors {

/** The two standard deviations of a point measured along a ray [m]: along it and across it. The
 * depth, lidar and stereo-cloud models differ only in these (RayModel.h). */
struct RaySigmas {
    double axial_m = 0;
    double lateral_m = 0;
};

/** Pitched 2D laser scanner (Hokuyo URG-04LX) model options. */
struct LaserModelOptions {
    RangeSigmaCurve rangeSigma;  //!< sigma_r(r) (key `laser_range_sigma_coeffs = c0 c1 c2`)
    /** AGC voltage per sensor label (key `laser_agc = LABEL:value[,LABEL:value...]`) [raw units
     * of eq 1]. A label without an entry gets no intensity check. */
    std::map<std::string, double> agcByLabel;
    double minRestoredIntensity =
        100.0;  //!< eq 1 threshold on Ires (key `laser_min_restored_intensity`)
    double intensityCheckRange_m = 1.0;  //!< only readings closer than this are checked [m]
    bool mixedPixelFilter = true;        //!< key `laser_mixed_pixel_filter`
    /** Range jump separating two clusters of consecutive beams [m] (key
     * `laser_mixed_pixel_jump_m`).
     */
    double mixedPixelJump_m = 0.03;
    /** A cluster of at most this many beams whose range lies between its two neighbouring
     * clusters is a mixed measurement (key `laser_mixed_pixel_max_beams`). */
    int mixedPixelMaxBeams = 2;
    bool continuity = true;  //!< eq 14 gate on (key `laser_continuity`)
    double continuitySigmas =
        3.0;  //!< Delta_zmax covers this many sigmas (key `laser_continuity_sigmas`)
    /** Correlation of the pose errors of consecutive scans, 0 = independent, 1 = identical (key
     * `laser_continuity_pose_correlation`). */
    double continuityPoseCorrelation = 0.0;
    /** Height variation of the terrain inside a cell that the gate must allow [m] (key
     * `laser_continuity_allowance_m`). */
    double continuityAllowance_m = 0.01;
    /** Scans further apart in time are not consecutive: no gate [s] (key
     * `laser_continuity_max_dt_s`). */
    double continuityMaxDt_s = 1.0;
    /** Eq 13's Delta_max for this model's points [m] (key `laser_max_elevation_uncertainty_m`): a
     * point counts if 3 sigma_z <= it. 0: the map's max_elevation_uncertainty_m
     * (doc/sensor-reach.md). */
    double maxElevationUncertainty_m = 0;
};

/** Stereo camera (STOC-style) model options. */
struct StereoModelOptions {
    /** Standard deviations of fx, fy, cx, cy [px], k1, k2, p1, p2, k3 [-] of each camera, in the
     * order of cv::calibrateCamera's stdDeviationsIntrinsics (keys `stereo_left_intrinsics_sigma`,
     * `stereo_right_intrinsics_sigma`). */
    std::array<double, 9> leftIntrinsicsSigma{0.5,   0.5,    0.5,    0.5, 0.002,
                                              0.002, 0.0002, 0.0002, 0.0};
    std::array<double, 9> rightIntrinsicsSigma{0.5,   0.5,    0.5,    0.5, 0.002,
                                               0.002, 0.0002, 0.0002, 0.0};
    /** Right camera relative to the left: rotation vector [rad] and translation [m] sigmas (key
     * `stereo_extrinsics_sigma = s_rx s_ry s_rz s_tx s_ty s_tz`). */
    std::array<double, 6> extrinsicsSigma{0.0005, 0.0005, 0.0005, 0.0005, 0.0005, 0.0005};
    double matchingSigma_px =
        0.25;  //!< matching noise per image [px] (key `stereo_matching_sigma_px`)
    /** A point cloud of a stereo rig (CObservationPointCloud with the stereo model) has no
     * pixels: its covariance is eq 10 with matching noise only, for a rig of this focal length
     * [px] and baseline [m] (keys `stereo_cloud_focal_length_px`, `stereo_cloud_baseline_m`). */
    double cloudFocalLength_px = 500.0;
    double cloudBaseline_m = 0.09;
    /** The ray sigmas of a point of a stereo cloud as a function of its range r [m] (RayModel.h):
     * eq 10 with matching noise only, r taken as the depth: r^2 sqrt(2) sigma_m / (f b) along
     * the ray, r sigma_m / f across it. */
    auto raySigmas() const {
        const double f = cloudFocalLength_px, sm = matchingSigma_px;
        return [axialPerR2 = std::sqrt(2.0) * sm / (f * cloudBaseline_m), sm, f](double range_m) {
            return RaySigmas{axialPerR2 * range_m * range_m, range_m * sm / f};
        };
    }
    int subsample = 2;        //!< use every n-th pixel in u and v (key `stereo_subsample`)
    double minDepth_m = 0.2;  //!< nearer points are out of the horopter (key `stereo_min_depth_m`)

    /** @name OpenCV StereoSGBM, used when the observation has no disparity image (keys
     * `stereo_sgbm_*`). p1/p2 = 0 means OpenCV's usual 8 and 32 * block_size^2. @{ */
    int sgbmMinDisparity = 0;
    /** The number of disparities searched for an image `width_px` wide. */
    int numDisparitiesFor(int width_px) const;
    /** Multiple of 16; 0 = from the image width: width / 4 rounded down to a multiple of 16,
     * between 16 and 256 (OpenCV leaves the leftmost minDisparity + numDisparities columns
     * without a disparity unless sgbmFullWidth). */
    int sgbmNumDisparities = 0;
    /** Match the leftmost columns too: the pair is padded on the left (edge columns repeated)
     * by minDisparity + numDisparities before SGBM and cropped after; a match whose right pixel
     * falls outside the right image is dropped (key `stereo_sgbm_full_width`;
     * doc/sensor-models.md, "Stereo against the naive pipeline"). */
    bool sgbmFullWidth = true;
    int sgbmBlockSize = 5;  //!< odd
    int sgbmP1 = 0, sgbmP2 = 0;
    int sgbmDisp12MaxDiff = 1;
    int sgbmUniquenessRatio = 15;
    int sgbmSpeckleWindowSize = 200;
    int sgbmSpeckleRange = 2;            //!< [px of disparity]
    std::string sgbmMode = "sgbm_3way";  //!< sgbm, hh, sgbm_3way or hh4
    /** @} */

    /** Halo filter: pixels on the near side of a disparity jump larger than jump_px, within
     * radius_px of it (keys `stereo_halo_filter`, `stereo_halo_jump_px`,
     * `stereo_halo_radius_px`). */
    struct HaloFilter {
        bool enabled = true;
        double jump_px = 3.0;
        int radius_px = 4;
    } halo;
    /** Near-cluster filter: connected regions (neighbours within step_px of disparity) of fewer
     * than maxArea_px pixels that are nearer than their surroundings by more than jump_px (keys
     * `stereo_near_cluster_filter`, `stereo_near_cluster_max_area_px`,
     * `stereo_near_cluster_step_px`, `stereo_near_cluster_jump_px`). */
    struct NearClusterFilter {
        bool enabled = true;
        int maxArea_px = 400;
        double step_px = 2.0;
        double jump_px = 2.0;
    } nearCluster;
    /** SGBM only: pixels whose left-image grey standard deviation over a radius_px window is
     * below minStd_grey have no match of their own (SGBM's smoothing carries a neighbour's
     * disparity into them) and are removed; minStd_grey 0 turns it off (keys
     * `stereo_texture_min_std_grey`, `stereo_texture_radius_px`; doc/sensor-models.md). */
    struct TextureFilter {
        double minStd_grey = 1.5;
        int radius_px = 2;
    } texture;
    /** Eq 13's Delta_max for this model's points [m] (key `stereo_max_elevation_uncertainty_m`): a
     * point counts if 3 sigma_z <= it. 0: the map's max_elevation_uncertainty_m
     * (doc/sensor-reach.md). */
    double maxElevationUncertainty_m = 0;
};

/** Structured-light depth camera model (Nguyen, Izadi, Lovell 2012):
 * sigma_axial(z) = axialSigma0 + axialSigmaQuadratic (z - axialOffset)^2 along the ray,
 * sigma_lateral(z) = lateralSigma_rad * z across it, z the range of the point. */
struct DepthModelOptions {
    double axialSigma0_m = 0.0012;              //!< key `depth_axial_sigma_m` [m]
    double axialSigmaQuadratic_per_m = 0.0019;  //!< key `depth_axial_sigma_quadratic_per_m` [m/m^2]
    double axialOffset_m = 0.4;                 //!< key `depth_axial_offset_m` [m]
    double lateralSigma_rad = 0.0014;  //!< key `depth_lateral_sigma_rad` [rad] (0.8 px at 580 px)
    /** The error the points of one frame share, which averaging them does not shrink
     * (doc/sensor-models.md): the depth quantisation of a structured-light camera, one step of
     * quantisationStep_per_m r^2 (disparity step / (focal length x baseline): 1/8 px / (580 px x
     * 7.5 cm) for a Kinect; key `depth_quantisation_step_per_m` [1/m]), a uniform error of sd
     * step / sqrt(12) over the patch a step covers; plus a calibration error of sd
     * frameSigmaRelative r (key `depth_frame_sigma_relative` [-]). Both 0: points independent. */
    double quantisationStep_per_m = 0.003;
    double frameSigmaRelative = 0.005;
    /** Depth-frame artefacts (DepthArtefacts.h; frames with a pixel grid only, not point
     * clouds): flying pixels within radius_px of a jump between neighbouring pixels larger than
     * jumpRelative x the nearer depth (keys `depth_flying_pixel_filter`,
     * `depth_flying_pixel_jump_relative`, `depth_flying_pixel_radius_px`), and the frame's
     * border of borderWidth_px (key `depth_border_px`). */
    struct FlyingPixelFilter {
        bool enabled = true;
        double jumpRelative = 0.05;
        int radius_px = 1;
    } flyingPixel;
    int borderWidth_px = 0;
    /** Eq 13's Delta_max for this model's points [m] (key `depth_max_elevation_uncertainty_m`): a
     * point counts if 3 sigma_z <= it. 0: the map's max_elevation_uncertainty_m
     * (doc/sensor-reach.md). */
    double maxElevationUncertainty_m = 0;

    /** Standard deviation of the error shared by a frame's points at range r [m] along the ray. */
    double frameSigma_m(double r_m) const {
        const double step = quantisationStep_per_m * r_m * r_m, rel = frameSigmaRelative * r_m;
        return std::sqrt(step * step / 12.0 + rel * rel);
    }
    bool sharesFrameError() const { return quantisationStep_per_m > 0 || frameSigmaRelative > 0; }

    double axialSigma_m(double z_m) const {
        const double dz = z_m - axialOffset_m;
        return axialSigma0_m + axialSigmaQuadratic_per_m * dz * dz;
    }
    /** The ray sigmas as a function of range [m] (RayModel.h). */
    auto raySigmas() const {
        return [o = *this](double range_m) {
            return RaySigmas{o.axialSigma_m(range_m), o.lateralSigma_rad * range_m};
        };
    }
};

/** Rotating or 2D lidar model: sigma_r(r) along the beam; across it r * sqrt(sigma_a^2 +
 * delta^2 / 16), sigma_a the beam's angular sigma and delta its full divergence angle (the return
 * comes from anywhere in the footprint, a disc of diameter delta r: per-axis variance
 * (delta r)^2 / 16). Defaults: the VLP-16 figures (doc/sensor-models.md). */
struct LidarModelOptions {
    /** The sensor whose published figures gave the defaults (key `lidar_sensor`: vlp16, os1 or
     * utm30lx; the keys below override them). */
    std::string sensor = "vlp16";
    RangeSigmaCurve rangeSigma{0.03, 0.0, 0.0};  //!< key `lidar_range_sigma_coeffs`
    double angularSigma_rad = 0.001;             //!< key `lidar_angular_sigma_rad` [rad]
    double beamDivergence_rad = 0.003;           //!< key `lidar_beam_divergence_rad` [rad]
    /** Eq 13's Delta_max for this model's points [m] (key `lidar_max_elevation_uncertainty_m`): a
     * point counts if 3 sigma_z <= it. 0: the map's max_elevation_uncertainty_m
     * (doc/sensor-reach.md). */
    double maxElevationUncertainty_m = 0;

    /** The published figures of `name` (vlp16, os1, utm30lx); throws std::invalid_argument for
     * another name. */
    static LidarModelOptions forSensor(const std::string& name);
    /** Standard deviation across the beam at range `range_m` [m]. */
    double lateralSigma_m(double range_m) const;
    /** The ray sigmas as a function of range [m] (RayModel.h); the lateral one is linear in
     * range, so its factor is computed once. */
    auto raySigmas() const {
        return [curve = rangeSigma, lateralPerRange = lateralSigma_m(1.0)](double range_m) {
            return RaySigmas{curve(range_m), lateralPerRange * range_m};
        };
    }
};

/** The noise model a sensor's data get. */
enum class SensorModelKind { laser, lidar, stereo, depth };
/** "laser", "lidar", "stereo", "depth". */
const char* sensorModelName(SensorModelKind kind);

/** Every sensor-model option of CMultiBinElevationMap (ini section `..._insertOpts`). */
struct SensorModelOptions {
    LaserModelOptions laser;
    StereoModelOptions stereo;
    DepthModelOptions depth;
    LidarModelOptions lidar;
    /** The model of each sensor label (key `sensor_models = LABEL:model[,LABEL:model...]`, model
     * laser, lidar, stereo or depth). A label without an entry gets the default of its
     * observation class: laser for CObservation2DRangeScan, stereo for CObservationStereoImages,
     * depth for CObservation3DRangeScan and CObservationPointCloud, lidar for
     * CObservationVelodyneScan and CObservationRotatingScan. */
    std::map<std::string, SensorModelKind> modelByLabel;

    /** The model of data labelled `label`: its entry in modelByLabel, else `classDefault`. */
    SensorModelKind modelFor(const std::string& label, SensorModelKind classDefault) const;
    /** Eq 13's Delta_max [m] for the points of a `kind` model: its own
     * maxElevationUncertainty_m, or `map_m` (the map's) where that is 0. */
    double maxElevationUncertaintyFor(SensorModelKind kind, double map_m) const;

    /** Reads the keys present in `s` (the others keep their value), then validate(). */
    void read(StrictConfigSection& s);
    void write(mrpt::config::CConfigFileBase& target, const std::string& section) const;
    /** Throws std::invalid_argument naming the key of the first bad value. */
    void validate() const;
};

}  // namespace multibin::sensors
