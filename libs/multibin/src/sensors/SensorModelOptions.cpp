/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/SensorModelOptions.h"

#include "multibin/io/NumberText.h"

#include <mrpt/config/CConfigFileBase.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "multibin/io/OptionKeys.h"

namespace multibin::sensors {

namespace {
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
        if (out.count(label)) s.fail(key, "label '" + label + "' is given twice");
        out[label] = parse(label, item.substr(colon + 1));
    }
    return out;
}

std::map<std::string, double> parseAgc(StrictConfigSection& s, const std::string& key) {
    return parseByLabel<double>(s, key, [&](const std::string& label, const std::string& value) {
        double v = 0;
        if (!parseFiniteNumber(value, v))
            s.fail(key, "AGC value of '" + label + "' is not a number: '" + value + "'");
        return v;
    });
}

const OptionNames<std::string> kSgbmModes{
    {"sgbm", "sgbm"}, {"hh", "hh"}, {"sgbm_3way", "sgbm_3way"}, {"hh4", "hh4"}};

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

double SensorModelOptions::maxElevationUncertaintyFor(SensorModelKind kind, double map_m) const {
    const double own_m = kind == SensorModelKind::laser    ? laser.maxElevationUncertainty_m
                         : kind == SensorModelKind::lidar  ? lidar.maxElevationUncertainty_m
                         : kind == SensorModelKind::stereo ? stereo.maxElevationUncertainty_m
                                                           : depth.maxElevationUncertainty_m;
    return own_m > 0 ? own_m : map_m;
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

namespace {
/** A range-sigma curve as the key `key` reads and writes it: "c0 c1 c2". */
auto curveOption(RangeSigmaCurve& curve) {
    return customOption(
        [&curve](StrictConfigSection& s, const std::string& key) {
            std::vector<double> c;
            s.read(key, c, 3);
            curve = RangeSigmaCurve{c[0], c[1], c[2]};
        },
        [] { return std::string(); });
}
std::string curveText(const RangeSigmaCurve& c) {
    return OptionWriter::joined(std::array<double, 3>{c.c0_m, c.c1, c.c2_per_m}, " ");
}
template <class T, class Name>
std::string labelMapText(const std::map<std::string, T>& m, const Name& name) {
    std::vector<std::string> items;
    for (const auto& [label, v] : m) items.push_back(label + ':' + name(v));
    return OptionWriter::joined(items, ",");
}
bool curveHolds(const RangeSigmaCurve& r) {
    return r.c0_m >= 0 && r.c1 >= 0 && r.c2_per_m >= 0 && r.c0_m + r.c1 + r.c2_per_m > 0;
}

/** The stereo model's keys (one list with the others: visitKeys). */
template <class Stereo, class Visit>
void visitStereoKeys(Stereo& stereo, Visit& visit) {
    visit("stereo_left_intrinsics_sigma", stereo.leftIntrinsicsSigma, atLeast(0));
    visit("stereo_right_intrinsics_sigma", stereo.rightIntrinsicsSigma, atLeast(0));
    visit("stereo_extrinsics_sigma", stereo.extrinsicsSigma, atLeast(0));
    visit({"stereo_matching_sigma_px", "stereo_matching_sigma"}, stereo.matchingSigma_px,
          atLeast(0, "px"));
    visit("stereo_subsample", stereo.subsample, atLeast(1, "px"));
    visit({"stereo_min_depth_m", "stereo_min_depth"}, stereo.minDepth_m, atLeast(0, "m"));
    visit("stereo_sgbm_min_disparity", stereo.sgbmMinDisparity);
    visit("stereo_sgbm_num_disparities", stereo.sgbmNumDisparities, atLeast(0));
    visit("stereo_sgbm_full_width", stereo.sgbmFullWidth);
    visit("stereo_sgbm_block_size", stereo.sgbmBlockSize, oddBetween(1, 255));
    visit("stereo_sgbm_p1", stereo.sgbmP1, atLeast(0));
    visit("stereo_sgbm_p2", stereo.sgbmP2, atLeast(0));
    visit("stereo_sgbm_disp12_max_diff", stereo.sgbmDisp12MaxDiff);
    visit("stereo_sgbm_uniqueness_ratio", stereo.sgbmUniquenessRatio, atLeast(0));
    visit("stereo_sgbm_speckle_window_size", stereo.sgbmSpeckleWindowSize, atLeast(0));
    visit("stereo_sgbm_speckle_range", stereo.sgbmSpeckleRange, atLeast(0));
    visit("stereo_sgbm_mode", stereo.sgbmMode, kSgbmModes);
    visit("stereo_halo_filter", stereo.halo.enabled);
    visit({"stereo_halo_jump_px", "stereo_halo_jump"}, stereo.halo.jump_px, positive("px"));
    visit({"stereo_halo_radius_px", "stereo_halo_radius"}, stereo.halo.radius_px, atLeast(1, "px"));
    visit("stereo_near_cluster_filter", stereo.nearCluster.enabled);
    visit({"stereo_near_cluster_max_area_px", "stereo_near_cluster_max_area"},
          stereo.nearCluster.maxArea_px, atLeast(1, "px"));
    visit({"stereo_near_cluster_step_px", "stereo_near_cluster_step"}, stereo.nearCluster.step_px,
          positive("px"));
    visit({"stereo_near_cluster_jump_px", "stereo_near_cluster_jump"}, stereo.nearCluster.jump_px,
          positive("px"));
    visit("stereo_texture_min_std_grey", stereo.texture.minStd_grey, atLeast(0));
    visit("stereo_texture_radius_px", stereo.texture.radius_px, atLeast(1, "px"));
    visit({"stereo_cloud_focal_length_px", "stereo_cloud_focal_length"}, stereo.cloudFocalLength_px,
          positive("px"));
    visit({"stereo_cloud_baseline_m", "stereo_cloud_baseline"}, stereo.cloudBaseline_m,
          positive("m"));
    visit("stereo_max_elevation_uncertainty_m", stereo.maxElevationUncertainty_m, atLeast(0, "m"));
}

/** The sensor-model keys of `o` (a SensorModelOptions or a const one), for the options protocol
 * (multibin/io/OptionKeys.h). Keys with a syntax of their own (curves, label maps, the lidar
 * preset) are custom options: `parse` for reading (unused when writing a const one) and
 * `format` for writing. The lidar preset comes before the lidar keys that override it. */
template <class Options, class Visit>
void visitKeys(Options& o, Visit&& visit) {
    constexpr bool reading = !std::is_const_v<Options>;
    auto& laser = o.laser;
    auto& lidar = o.lidar;
    auto& depth = o.depth;
    const auto custom = [&](const char* key, auto parse, auto format) {
        visit(key, customOption(parse, format));
    };
    // Laser
    custom(
        "laser_range_sigma_coeffs",
        [&](StrictConfigSection& s, const std::string& key) {
            if constexpr (reading) curveOption(laser.rangeSigma).parse(s, key);
        },
        [&] { return curveText(laser.rangeSigma); });
    custom(
        "laser_agc",
        [&](StrictConfigSection& s, const std::string& key) {
            if constexpr (reading) laser.agcByLabel = parseAgc(s, key);
        },
        [&] {
            return labelMapText(laser.agcByLabel, [](double v) {
                return OptionWriter::joined(std::array<double, 1>{v}, "");
            });
        });
    visit("laser_min_restored_intensity", laser.minRestoredIntensity, atLeast(0));
    visit({"laser_intensity_check_range_m", "laser_intensity_check_range"},
          laser.intensityCheckRange_m, atLeast(0, "m"));
    visit("laser_mixed_pixel_filter", laser.mixedPixelFilter);
    visit({"laser_mixed_pixel_jump_m", "laser_mixed_pixel_jump"}, laser.mixedPixelJump_m,
          positive("m"));
    visit("laser_mixed_pixel_max_beams", laser.mixedPixelMaxBeams, atLeast(1));
    visit("laser_continuity", laser.continuity);
    visit("laser_continuity_sigmas", laser.continuitySigmas, positive());
    visit("laser_continuity_pose_correlation", laser.continuityPoseCorrelation, between(0, 1));
    visit({"laser_continuity_allowance_m", "laser_continuity_allowance"},
          laser.continuityAllowance_m, atLeast(0, "m"));
    visit({"laser_continuity_max_dt_s", "laser_continuity_max_dt"}, laser.continuityMaxDt_s,
          positive("s"));
    visit("laser_max_elevation_uncertainty_m", laser.maxElevationUncertainty_m, atLeast(0, "m"));
    visitStereoKeys(o.stereo, visit);
    // Lidar: the sensor's published figures first, then the keys that override them
    custom(
        "lidar_sensor",
        [&](StrictConfigSection& s, const std::string& key) {
            if constexpr (reading) {
                std::string name;
                s.read(key, name);
                try {
                    lidar = LidarModelOptions::forSensor(name);
                } catch (const std::invalid_argument& e) {
                    s.fail(key, e.what());
                }
            }
        },
        [&] { return lidar.sensor; });
    custom(
        "lidar_range_sigma_coeffs",
        [&](StrictConfigSection& s, const std::string& key) {
            if constexpr (reading) curveOption(lidar.rangeSigma).parse(s, key);
        },
        [&] { return curveText(lidar.rangeSigma); });
    visit({"lidar_angular_sigma_rad", "lidar_angular_sigma"}, lidar.angularSigma_rad,
          atLeast(0, "rad"));
    visit({"lidar_beam_divergence_rad", "lidar_beam_divergence"}, lidar.beamDivergence_rad,
          atLeast(0, "rad"));
    visit("lidar_max_elevation_uncertainty_m", lidar.maxElevationUncertainty_m, atLeast(0, "m"));
    custom(
        "sensor_models",
        [&](StrictConfigSection& s, const std::string& key) {
            if constexpr (reading) o.modelByLabel = parseModels(s, key);
        },
        [&] { return labelMapText(o.modelByLabel, sensorModelName); });
    // Depth camera
    visit({"depth_axial_sigma_m", "depth_axial_sigma"}, depth.axialSigma0_m, positive("m"));
    visit({"depth_axial_sigma_quadratic_per_m", "depth_axial_sigma_quadratic"},
          depth.axialSigmaQuadratic_per_m, atLeast(0, "1/m"));
    visit({"depth_axial_offset_m", "depth_axial_offset"}, depth.axialOffset_m, atLeast(0, "m"));
    visit({"depth_lateral_sigma_rad", "depth_lateral_sigma"}, depth.lateralSigma_rad,
          positive("rad"));
    visit("depth_quantisation_step_per_m", depth.quantisationStep_per_m, atLeast(0, "1/m"));
    visit("depth_frame_sigma_relative", depth.frameSigmaRelative, atLeast(0));
    visit("depth_flying_pixel_filter", depth.flyingPixel.enabled);
    visit("depth_flying_pixel_jump_relative", depth.flyingPixel.jumpRelative, positive());
    visit("depth_flying_pixel_radius_px", depth.flyingPixel.radius_px, atLeast(1, "px"));
    visit("depth_border_px", depth.borderWidth_px, atLeast(0, "px"));
    visit("depth_max_elevation_uncertainty_m", depth.maxElevationUncertainty_m, atLeast(0, "m"));
}
}  // namespace

void SensorModelOptions::read(StrictConfigSection& s) {
    visitKeys(*this, OptionReader{s});
    validateAsReadFrom(s, *this);
}

void SensorModelOptions::write(mrpt::config::CConfigFileBase& c, const std::string& sec) const {
    visitKeys(*this, OptionWriter{c, sec});
}

void SensorModelOptions::validate() const {
    const OptionChecker check("CMultiBinElevationMap insertion option");
    visitKeys(*this, check);
    if (!curveHolds(laser.rangeSigma))
        check.fail("laser_range_sigma_coeffs", "need c0, c1, c2 >= 0, not all zero");
    if (!curveHolds(lidar.rangeSigma))
        check.fail("lidar_range_sigma_coeffs", "need c0, c1, c2 >= 0, not all zero");
    for (const auto& [label, v] : laser.agcByLabel)
        if (!(v > 0)) check.fail("laser_agc", "AGC voltage of '" + label + "' must be positive");
    if (stereo.sgbmNumDisparities % 16 != 0)
        check.fail("stereo_sgbm_num_disparities",
                   "must be 0 (automatic) or a positive multiple of 16");
    if (stereo.sgbmP1 > 0 && stereo.sgbmP2 > 0 && stereo.sgbmP2 <= stereo.sgbmP1)
        check.fail("stereo_sgbm_p2", "must be larger than stereo_sgbm_p1");
}

}  // namespace multibin::sensors
