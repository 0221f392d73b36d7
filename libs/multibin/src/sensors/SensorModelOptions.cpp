/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/SensorModelOptions.h"

#include <mrpt/config/CConfigFileBase.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "multibin/io/StrictConfigSection.h"

namespace multibin::sensors {

namespace {
template <size_t N>
void readArray(StrictConfigSection& s, const std::string& key, std::array<double, N>& a) {
    if (!s.has(key)) return;
    std::vector<double> v;
    s.read(key, v, N);
    for (size_t i = 0; i < N; i++) a[i] = v[i];
}

template <typename Seq>
std::string joined(const Seq& v) {
    std::ostringstream os;
    os.precision(17);
    bool first = true;
    for (double x : v) {
        os << (first ? "" : " ") << x;
        first = false;
    }
    return os.str();
}

/** Parses `LABEL:value[,LABEL:value...]` into a map, each value through `parse(label, value)`,
 * which fails the key itself for a bad value. */
template <typename T, typename Parse>
std::map<std::string, T> parseByLabel(StrictConfigSection& s, const std::string& key,
                                      const Parse& parse) {
    std::vector<std::string> items;
    s.read(key, items);
    std::map<std::string, T> out;
    for (const auto& item : items) {
        const auto colon = item.rfind(':');
        if (colon == std::string::npos || colon == 0 || colon + 1 == item.size())
            s.fail(key, "expected LABEL:value, got '" + item + "'");
        const std::string label = item.substr(0, colon);
        out[label] = parse(label, item.substr(colon + 1));
    }
    return out;
}

std::map<std::string, double> parseAgc(StrictConfigSection& s, const std::string& key) {
    return parseByLabel<double>(s, key, [&](const std::string& label, const std::string& value) {
        char* end = nullptr;
        const double v = std::strtod(value.c_str(), &end);
        if (end != value.c_str() + value.size() || !std::isfinite(v))
            s.fail(key, "AGC value of '" + label + "' is not a number: '" + value + "'");
        return v;
    });
}

constexpr std::pair<const char*, SensorModelKind> kModelNames[] = {
    {"laser", SensorModelKind::laser},
    {"lidar", SensorModelKind::lidar},
    {"stereo", SensorModelKind::stereo},
    {"depth", SensorModelKind::depth}};

std::map<std::string, SensorModelKind> parseModels(StrictConfigSection& s, const std::string& key) {
    return parseByLabel<SensorModelKind>(
        s, key, [&](const std::string& label, const std::string& name) {
            for (const auto& [word, kind] : kModelNames)
                if (name == word) return kind;
            s.fail(key, "unknown sensor model '" + name + "' for label '" + label +
                            "': expected laser, lidar, stereo or depth");
        });
}
}  // namespace

const char* sensorModelName(SensorModelKind kind) {
    for (const auto& [word, k] : kModelNames)
        if (k == kind) return word;
    return "?";
}

SensorModelKind SensorModelOptions::modelFor(const std::string& label,
                                             SensorModelKind classDefault) const {
    const auto it = modelByLabel.find(label);
    return it == modelByLabel.end() ? classDefault : it->second;
}

LidarModelOptions LidarModelOptions::forSensor(const std::string& name) {
    // Sources and derivations: doc/sensor-models.md, "Lidar".
    LidarModelOptions o;
    o.sensor = name;
    if (name == "vlp16") {
        o.rangeSigma = {0.03, 0.0, 0.0};  // +-3 cm typical
        o.angularSigma_rad = 0.001;       // 0.2 deg azimuth step / sqrt(12)
        o.beamDivergence_rad = 0.003;     // 3.0 mrad (the larger, horizontal)
    } else if (name == "os1") {
        o.rangeSigma = {0.03, 0.0, 0.0};  // 1 sigma at SNR 100
        o.angularSigma_rad = 0.00017;     // +-0.01 deg angular sampling accuracy
        o.beamDivergence_rad = 0.0039;    // 0.13 deg FWHM -> 1/e^2 full angle
    } else if (name == "utm30lx") {
        o.rangeSigma = {0.03, 0.00067, 0.0};  // +-30 mm to 10 m, +-50 mm at 30 m
        o.angularSigma_rad = 0.0013;          // 0.25 deg step / sqrt(12)
        o.beamDivergence_rad = 0.0;           // not published
    } else {
        throw std::invalid_argument("unknown lidar '" + name + "': expected vlp16, os1 or utm30lx");
    }
    return o;
}

double LidarModelOptions::lateralSigma_m(double range_m) const {
    return range_m * std::sqrt(angularSigma_rad * angularSigma_rad +
                               beamDivergence_rad * beamDivergence_rad / 16.0);
}

int StereoModelOptions::numDisparitiesFor(int width_px) const {
    if (sgbmNumDisparities > 0) return sgbmNumDisparities;
    return std::clamp(width_px / 4 / 16 * 16, 16, 256);
}

void SensorModelOptions::read(StrictConfigSection& s) {
    // Laser
    if (s.has("laser_range_sigma_coeffs")) {
        std::vector<double> c;
        s.read("laser_range_sigma_coeffs", c, 3);
        laser.rangeSigma = RangeSigmaCurve{c[0], c[1], c[2]};
    }
    if (s.has("laser_agc")) laser.agcByLabel = parseAgc(s, "laser_agc");
    s.read("laser_min_restored_intensity", laser.minRestoredIntensity);
    s.read("laser_intensity_check_range", laser.intensityCheckRange_m);
    s.read("laser_mixed_pixel_filter", laser.mixedPixelFilter);
    s.read("laser_mixed_pixel_jump", laser.mixedPixelJump_m);
    s.read("laser_mixed_pixel_max_beams", laser.mixedPixelMaxBeams);
    s.read("laser_continuity", laser.continuity);
    s.read("laser_continuity_sigmas", laser.continuitySigmas);
    s.read("laser_continuity_pose_correlation", laser.continuityPoseCorrelation);
    s.read("laser_continuity_allowance", laser.continuityAllowance_m);
    s.read("laser_continuity_max_dt", laser.continuityMaxDt_s);
    // Stereo
    readArray(s, "stereo_left_intrinsics_sigma", stereo.leftIntrinsicsSigma);
    readArray(s, "stereo_right_intrinsics_sigma", stereo.rightIntrinsicsSigma);
    readArray(s, "stereo_extrinsics_sigma", stereo.extrinsicsSigma);
    s.read("stereo_matching_sigma", stereo.matchingSigma_px);
    s.read("stereo_subsample", stereo.subsample);
    s.read("stereo_min_depth", stereo.minDepth_m);
    s.read("stereo_sgbm_min_disparity", stereo.sgbmMinDisparity);
    s.read("stereo_sgbm_num_disparities", stereo.sgbmNumDisparities);
    s.read("stereo_sgbm_block_size", stereo.sgbmBlockSize);
    s.read("stereo_sgbm_p1", stereo.sgbmP1);
    s.read("stereo_sgbm_p2", stereo.sgbmP2);
    s.read("stereo_sgbm_disp12_max_diff", stereo.sgbmDisp12MaxDiff);
    s.read("stereo_sgbm_uniqueness_ratio", stereo.sgbmUniquenessRatio);
    s.read("stereo_sgbm_speckle_window_size", stereo.sgbmSpeckleWindowSize);
    s.read("stereo_sgbm_speckle_range", stereo.sgbmSpeckleRange);
    s.read("stereo_sgbm_mode", stereo.sgbmMode);
    s.read("stereo_halo_filter", stereo.haloFilter);
    s.read("stereo_halo_jump", stereo.haloJump_px);
    s.read("stereo_halo_radius", stereo.haloRadius_px);
    s.read("stereo_near_cluster_filter", stereo.nearClusterFilter);
    s.read("stereo_near_cluster_max_area", stereo.nearClusterMaxArea_px);
    s.read("stereo_near_cluster_step", stereo.nearClusterStep_px);
    s.read("stereo_near_cluster_jump", stereo.nearClusterJump_px);
    s.read("stereo_cloud_focal_length", stereo.cloudFocalLength_px);
    s.read("stereo_cloud_baseline", stereo.cloudBaseline_m);
    // Lidar: the sensor's published figures first, then the keys that override them
    if (s.has("lidar_sensor")) {
        std::string name;
        s.read("lidar_sensor", name);
        try {
            lidar = LidarModelOptions::forSensor(name);
        } catch (const std::invalid_argument& e) {
            s.fail("lidar_sensor", e.what());
        }
    }
    if (s.has("lidar_range_sigma_coeffs")) {
        std::vector<double> c;
        s.read("lidar_range_sigma_coeffs", c, 3);
        lidar.rangeSigma = RangeSigmaCurve{c[0], c[1], c[2]};
    }
    s.read("lidar_angular_sigma", lidar.angularSigma_rad);
    s.read("lidar_beam_divergence", lidar.beamDivergence_rad);
    if (s.has("sensor_models")) modelByLabel = parseModels(s, "sensor_models");
    // Depth camera
    s.read("depth_axial_sigma", depth.axialSigma0_m);
    s.read("depth_axial_sigma_quadratic", depth.axialSigmaQuadratic_per_m);
    s.read("depth_axial_offset", depth.axialOffset_m);
    s.read("depth_lateral_sigma", depth.lateralSigma_rad);
    validate();
}

void SensorModelOptions::write(mrpt::config::CConfigFileBase& c, const std::string& sec) const {
    const RangeSigmaCurve& r = laser.rangeSigma;
    c.write(sec, "laser_range_sigma_coeffs",
            joined(std::array<double, 3>{r.c0_m, r.c1, r.c2_per_m}));
    std::string agc;
    for (const auto& [label, v] : laser.agcByLabel) {
        std::ostringstream os;
        os.precision(17);
        os << label << ':' << v;
        agc += (agc.empty() ? "" : ",") + os.str();
    }
    c.write(sec, "laser_agc", agc);
    c.write(sec, "laser_min_restored_intensity", laser.minRestoredIntensity);
    c.write(sec, "laser_intensity_check_range", laser.intensityCheckRange_m);
    c.write(sec, "laser_mixed_pixel_filter", laser.mixedPixelFilter);
    c.write(sec, "laser_mixed_pixel_jump", laser.mixedPixelJump_m);
    c.write(sec, "laser_mixed_pixel_max_beams", laser.mixedPixelMaxBeams);
    c.write(sec, "laser_continuity", laser.continuity);
    c.write(sec, "laser_continuity_sigmas", laser.continuitySigmas);
    c.write(sec, "laser_continuity_pose_correlation", laser.continuityPoseCorrelation);
    c.write(sec, "laser_continuity_allowance", laser.continuityAllowance_m);
    c.write(sec, "laser_continuity_max_dt", laser.continuityMaxDt_s);
    c.write(sec, "stereo_left_intrinsics_sigma", joined(stereo.leftIntrinsicsSigma));
    c.write(sec, "stereo_right_intrinsics_sigma", joined(stereo.rightIntrinsicsSigma));
    c.write(sec, "stereo_extrinsics_sigma", joined(stereo.extrinsicsSigma));
    c.write(sec, "stereo_matching_sigma", stereo.matchingSigma_px);
    c.write(sec, "stereo_subsample", stereo.subsample);
    c.write(sec, "stereo_min_depth", stereo.minDepth_m);
    c.write(sec, "stereo_sgbm_min_disparity", stereo.sgbmMinDisparity);
    c.write(sec, "stereo_sgbm_num_disparities", stereo.sgbmNumDisparities);
    c.write(sec, "stereo_sgbm_block_size", stereo.sgbmBlockSize);
    c.write(sec, "stereo_sgbm_p1", stereo.sgbmP1);
    c.write(sec, "stereo_sgbm_p2", stereo.sgbmP2);
    c.write(sec, "stereo_sgbm_disp12_max_diff", stereo.sgbmDisp12MaxDiff);
    c.write(sec, "stereo_sgbm_uniqueness_ratio", stereo.sgbmUniquenessRatio);
    c.write(sec, "stereo_sgbm_speckle_window_size", stereo.sgbmSpeckleWindowSize);
    c.write(sec, "stereo_sgbm_speckle_range", stereo.sgbmSpeckleRange);
    c.write(sec, "stereo_sgbm_mode", stereo.sgbmMode);
    c.write(sec, "stereo_halo_filter", stereo.haloFilter);
    c.write(sec, "stereo_halo_jump", stereo.haloJump_px);
    c.write(sec, "stereo_halo_radius", stereo.haloRadius_px);
    c.write(sec, "stereo_near_cluster_filter", stereo.nearClusterFilter);
    c.write(sec, "stereo_near_cluster_max_area", stereo.nearClusterMaxArea_px);
    c.write(sec, "stereo_near_cluster_step", stereo.nearClusterStep_px);
    c.write(sec, "stereo_near_cluster_jump", stereo.nearClusterJump_px);
    c.write(sec, "stereo_cloud_focal_length", stereo.cloudFocalLength_px);
    c.write(sec, "stereo_cloud_baseline", stereo.cloudBaseline_m);
    c.write(sec, "lidar_sensor", lidar.sensor);
    const RangeSigmaCurve& lr = lidar.rangeSigma;
    c.write(sec, "lidar_range_sigma_coeffs",
            joined(std::array<double, 3>{lr.c0_m, lr.c1, lr.c2_per_m}));
    c.write(sec, "lidar_angular_sigma", lidar.angularSigma_rad);
    c.write(sec, "lidar_beam_divergence", lidar.beamDivergence_rad);
    std::string models;
    for (const auto& [label, kind] : modelByLabel)
        models += (models.empty() ? "" : ",") + label + ':' + sensorModelName(kind);
    c.write(sec, "sensor_models", models);
    c.write(sec, "depth_axial_sigma", depth.axialSigma0_m);
    c.write(sec, "depth_axial_sigma_quadratic", depth.axialSigmaQuadratic_per_m);
    c.write(sec, "depth_axial_offset", depth.axialOffset_m);
    c.write(sec, "depth_lateral_sigma", depth.lateralSigma_rad);
}

void SensorModelOptions::validate() const {
    auto bad = [](const std::string& key, const std::string& what) {
        throw std::invalid_argument("CMultiBinElevationMap insertion option '" + key +
                                    "': " + what);
    };
    const RangeSigmaCurve& r = laser.rangeSigma;
    if (!(r.c0_m >= 0 && r.c1 >= 0 && r.c2_per_m >= 0 && r.c0_m + r.c1 + r.c2_per_m > 0))
        bad("laser_range_sigma_coeffs", "need c0, c1, c2 >= 0, not all zero");
    for (const auto& [label, v] : laser.agcByLabel)
        if (!(v > 0)) bad("laser_agc", "AGC voltage of '" + label + "' must be positive");
    if (!(laser.minRestoredIntensity >= 0)) bad("laser_min_restored_intensity", "must be >= 0");
    if (!(laser.intensityCheckRange_m >= 0)) bad("laser_intensity_check_range", "must be >= 0 [m]");
    if (!(laser.mixedPixelJump_m > 0)) bad("laser_mixed_pixel_jump", "must be positive [m]");
    if (laser.mixedPixelMaxBeams < 1) bad("laser_mixed_pixel_max_beams", "must be >= 1");
    if (!(laser.continuitySigmas > 0)) bad("laser_continuity_sigmas", "must be positive");
    if (!(laser.continuityPoseCorrelation >= 0 && laser.continuityPoseCorrelation <= 1))
        bad("laser_continuity_pose_correlation", "must be in [0, 1]");
    if (!(laser.continuityAllowance_m >= 0)) bad("laser_continuity_allowance", "must be >= 0 [m]");
    if (!(laser.continuityMaxDt_s > 0)) bad("laser_continuity_max_dt", "must be positive [s]");
    for (const auto& [key, a] :
         {std::pair{"stereo_left_intrinsics_sigma", stereo.leftIntrinsicsSigma},
          {"stereo_right_intrinsics_sigma", stereo.rightIntrinsicsSigma}})
        for (double v : a)
            if (!(v >= 0)) bad(key, "standard deviations must be >= 0");
    for (double v : stereo.extrinsicsSigma)
        if (!(v >= 0)) bad("stereo_extrinsics_sigma", "standard deviations must be >= 0");
    if (!(stereo.matchingSigma_px >= 0)) bad("stereo_matching_sigma", "must be >= 0 [px]");
    if (stereo.subsample < 1) bad("stereo_subsample", "must be >= 1 [px]");
    if (!(stereo.minDepth_m >= 0)) bad("stereo_min_depth", "must be >= 0 [m]");
    if (stereo.sgbmNumDisparities < 0 || stereo.sgbmNumDisparities % 16 != 0)
        bad("stereo_sgbm_num_disparities", "must be 0 (automatic) or a positive multiple of 16");
    if (stereo.sgbmBlockSize < 1 || stereo.sgbmBlockSize % 2 == 0)
        bad("stereo_sgbm_block_size", "must be odd and >= 1");
    if (stereo.sgbmP1 < 0 || stereo.sgbmP2 < 0) bad("stereo_sgbm_p1/p2", "must be >= 0");
    if (stereo.sgbmP1 > 0 && stereo.sgbmP2 > 0 && stereo.sgbmP2 <= stereo.sgbmP1)
        bad("stereo_sgbm_p2", "must be larger than stereo_sgbm_p1");
    if (stereo.sgbmMode != "sgbm" && stereo.sgbmMode != "hh" && stereo.sgbmMode != "sgbm_3way" &&
        stereo.sgbmMode != "hh4")
        bad("stereo_sgbm_mode",
            "expected sgbm, hh, sgbm_3way or hh4, got '" + stereo.sgbmMode + "'");
    if (stereo.sgbmUniquenessRatio < 0) bad("stereo_sgbm_uniqueness_ratio", "must be >= 0");
    if (stereo.sgbmSpeckleWindowSize < 0) bad("stereo_sgbm_speckle_window_size", "must be >= 0");
    if (stereo.sgbmSpeckleRange < 0) bad("stereo_sgbm_speckle_range", "must be >= 0");
    if (!(stereo.haloJump_px > 0)) bad("stereo_halo_jump", "must be positive [px]");
    if (stereo.haloRadius_px < 1) bad("stereo_halo_radius", "must be >= 1 [px]");
    if (stereo.nearClusterMaxArea_px < 1) bad("stereo_near_cluster_max_area", "must be >= 1 [px]");
    if (!(stereo.nearClusterStep_px > 0)) bad("stereo_near_cluster_step", "must be positive [px]");
    if (!(stereo.nearClusterJump_px > 0)) bad("stereo_near_cluster_jump", "must be positive [px]");
    if (!(stereo.cloudFocalLength_px > 0))
        bad("stereo_cloud_focal_length", "must be positive [px]");
    if (!(stereo.cloudBaseline_m > 0)) bad("stereo_cloud_baseline", "must be positive [m]");
    const RangeSigmaCurve& lr = lidar.rangeSigma;
    if (!(lr.c0_m >= 0 && lr.c1 >= 0 && lr.c2_per_m >= 0 && lr.c0_m + lr.c1 + lr.c2_per_m > 0))
        bad("lidar_range_sigma_coeffs", "need c0, c1, c2 >= 0, not all zero");
    if (!(lidar.angularSigma_rad >= 0)) bad("lidar_angular_sigma", "must be >= 0 [rad]");
    if (!(lidar.beamDivergence_rad >= 0)) bad("lidar_beam_divergence", "must be >= 0 [rad]");
    if (!(depth.axialSigma0_m > 0)) bad("depth_axial_sigma", "must be positive [m]");
    if (!(depth.axialSigmaQuadratic_per_m >= 0)) bad("depth_axial_sigma_quadratic", "must be >= 0");
    if (!(depth.axialOffset_m >= 0)) bad("depth_axial_offset", "must be >= 0 [m]");
    if (!(depth.lateralSigma_rad > 0)) bad("depth_lateral_sigma", "must be positive [rad]");
}

}  // namespace multibin::sensors
