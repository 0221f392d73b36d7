/* The options protocol (multibin/io/OptionKeys.h): every options struct lists its keys once, and
 * reading, writing and checking follow that list. These tests check the parts a struct's own
 * tests do not: renamed keys still read under their old names, every key written reads back to
 * the same options, and a value set in code is refused by the same rule as one read from a file. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/TMetricMapInitializer.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "multibin/io/ErrorMessage.h"
#include "multibin/io/OptionKeys.h"

namespace {
using Map = mrpt::maps::CMultiBinElevationMap;

/** The ini text of insertion options as saveToConfigFile writes them (section "i"). */
std::string savedText(const Map::TInsertionOptions& o) {
    mrpt::config::CConfigFileMemory out;
    o.saveToConfigFile(out, "i");
    std::string text;
    out.getContent(text);
    return text;
}

Map::TInsertionOptions loadInsertion(const std::string& body) {
    mrpt::config::CConfigFileMemory ini("[i]\n" + body + "\n");
    Map::TInsertionOptions o;
    o.loadFromConfigFile(ini, "i");
    return o;
}

/** Old name, new name, a value that differs from the default. */
struct Renamed {
    const char* oldName;
    const char* newName;
    const char* value;
};
const std::vector<Renamed> kRenamed = {
    {"fill_median_window", "fill_median_window_cells", "7"},
    {"fill_support_margin", "fill_support_margin_cells", "6"},
    {"fill_min_width", "fill_min_width_cells", "1.5"},
    {"fill_sigma_floor", "fill_sigma_floor_m", "0.003"},
    {"laser_intensity_check_range", "laser_intensity_check_range_m", "1.5"},
    {"laser_mixed_pixel_jump", "laser_mixed_pixel_jump_m", "0.05"},
    {"laser_continuity_allowance", "laser_continuity_allowance_m", "0.02"},
    {"laser_continuity_max_dt", "laser_continuity_max_dt_s", "2"},
    {"stereo_matching_sigma", "stereo_matching_sigma_px", "0.4"},
    {"stereo_min_depth", "stereo_min_depth_m", "0.3"},
    {"stereo_halo_jump", "stereo_halo_jump_px", "4"},
    {"stereo_halo_radius", "stereo_halo_radius_px", "5"},
    {"stereo_near_cluster_max_area", "stereo_near_cluster_max_area_px", "300"},
    {"stereo_near_cluster_step", "stereo_near_cluster_step_px", "3"},
    {"stereo_near_cluster_jump", "stereo_near_cluster_jump_px", "3"},
    {"stereo_cloud_focal_length", "stereo_cloud_focal_length_px", "600"},
    {"stereo_cloud_baseline", "stereo_cloud_baseline_m", "0.12"},
    {"lidar_angular_sigma", "lidar_angular_sigma_rad", "0.002"},
    {"lidar_beam_divergence", "lidar_beam_divergence_rad", "0.004"},
    {"depth_axial_sigma", "depth_axial_sigma_m", "0.002"},
    {"depth_axial_sigma_quadratic", "depth_axial_sigma_quadratic_per_m", "0.003"},
    {"depth_axial_offset", "depth_axial_offset_m", "0.5"},
    {"depth_lateral_sigma", "depth_lateral_sigma_rad", "0.002"},
    {"visibility_margin", "visibility_margin_m", "0.03"},
    {"range_sigma", "range_sigma_m", "0.02"},
};
}  // namespace

// A key renamed to carry its unit still reads under its old name, to the same options as the new
// name; the options save under the new name only; both names at once is an error naming both.
TEST(OptionKeys, EveryRenamedKeyReadsUnderItsOldNameAndSavesUnderItsNewOne) {
    const std::string defaults = savedText(Map::TInsertionOptions{});
    for (const auto& r : kRenamed) {
        SCOPED_TRACE(r.newName);
        const std::string viaOld =
            savedText(loadInsertion(std::string(r.oldName) + " = " + r.value));
        const std::string viaNew =
            savedText(loadInsertion(std::string(r.newName) + " = " + r.value));
        EXPECT_EQ(viaOld, viaNew);
        EXPECT_NE(viaNew, defaults) << "the value did not change the options";
        EXPECT_NE(viaNew.find(std::string(r.newName) + " "), std::string::npos);
        EXPECT_EQ(viaNew.find(std::string(r.oldName) + " "), std::string::npos);
        try {
            loadInsertion(std::string(r.oldName) + " = " + r.value + "\n" + r.newName + " = " +
                          r.value);
            ADD_FAILURE() << "both names accepted";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find(r.oldName), std::string::npos) << e.what();
        }
    }
}

// What saveToConfigFile writes, loadFromConfigFile reads back to the same options, for options
// far from the defaults (every struct of the insertion options touched).
TEST(OptionKeys, SavedOptionsReadBackToTheSameText) {
    Map::TInsertionOptions a;
    a.certainty_increment = 2.5f;
    a.default_pose_sigmas = {0.1, 0.2, 0.3, 0.01, 0.02, 0.03};
    a.sensor_labels = {"LASER", "STEREO"};
    a.render.colormap = mrpt::img::cmHOT;
    a.visibility.margin_m = 0.031;
    a.fill.residualModel = multibin::fill::ResidualModel::Biharmonic;
    a.fill.sigmaFloor_m = 0.0041;
    a.sensors.stereo.sgbmMode = "hh";
    a.sensors.lidar = multibin::sensors::LidarModelOptions::forSensor("os1");
    a.sensors.lidar.angularSigma_rad = 0.0021;
    a.sensors.modelByLabel = {{"VELO", multibin::sensors::SensorModelKind::lidar}};
    const std::string text = savedText(a);
    mrpt::config::CConfigFileMemory ini(text);
    Map::TInsertionOptions b;
    b.loadFromConfigFile(ini, "i");
    EXPECT_EQ(savedText(b), text);
    EXPECT_EQ(b.sensors.lidar.sensor, "os1");
    EXPECT_DOUBLE_EQ(b.sensors.lidar.angularSigma_rad, 0.0021);  // the key overrides the preset
    EXPECT_EQ(b.fill.residualModel, multibin::fill::ResidualModel::Biharmonic);
}

// A value set in code breaks the same rule as one read from a file: validate() names the key and
// the rule. Enum choices set to a value outside their words are refused too.
TEST(OptionKeys, ValuesSetInCodeAreCheckedByTheKeysRules) {
    const auto expectRefused = [](const Map::TInsertionOptions& o, const std::string& key,
                                  const std::string& rule) {
        try {
            o.validate();
            ADD_FAILURE() << key << ": accepted";
        } catch (const std::invalid_argument& e) {
            const std::string msg = e.what();
            EXPECT_NE(msg.find("'" + key + "'"), std::string::npos) << msg;
            EXPECT_NE(msg.find(rule), std::string::npos) << msg;
        }
    };
    Map::TInsertionOptions o;
    EXPECT_NO_THROW(o.validate());
    o.fill.medianWindow_cells = 4;
    expectRefused(o, "fill_median_window_cells", "odd number from 3 to 15 (cells)");
    o = {};
    o.sensors.stereo.halo.jump_px = 0;
    expectRefused(o, "stereo_halo_jump_px", "positive and finite (px)");
    o = {};
    o.sensors.depth.axialOffset_m = std::numeric_limits<double>::infinity();
    expectRefused(o, "depth_axial_offset_m", ">= 0 and finite (m)");
    o = {};
    o.default_pose_sigmas[3] = -1;
    expectRefused(o, "default_pose_sigmas", ">= 0");
    o = {};
    o.fill.residualModel = static_cast<multibin::fill::ResidualModel>(9);
    expectRefused(o, "fill_residual_model", "kriging, harmonic, biharmonic");
    o = {};
    o.sensors.stereo.sgbmMode = "fast";
    expectRefused(o, "stereo_sgbm_mode", "sgbm_3way");
    o = {};
    o.render.colormap = mrpt::img::cmNONE;
    expectRefused(o, "colormap", "jet");
}

// The rules' texts, which are the error messages.
TEST(OptionKeys, RuleTextsSayTheRule) {
    EXPECT_EQ(multibin::positive("m").text(), "must be positive and finite (m), at most 1e+10 m");
    EXPECT_EQ(multibin::atLeast(1).text(), "must be >= 1 and finite, at most 1e+09");
    EXPECT_EQ(multibin::between(0, 1).text(), "must be from 0 to 1");
    EXPECT_EQ(multibin::oddBetween(3, 15, "cells").text(),
              "must be an odd number from 3 to 15 (cells)");
    EXPECT_EQ(multibin::finite("m").text(), "must be finite (m), within +-1e+10 m");
    EXPECT_FALSE(multibin::oddBetween(3, 15).holds(4));
    EXPECT_TRUE(multibin::oddBetween(3, 15).holds(15));
    EXPECT_FALSE(multibin::positive().holds(0));
    EXPECT_FALSE(multibin::atLeast(0).holds(std::nan("")));
}

// A rule broken in an ini file reaches the user whole, through MRPT's map initializers (as
// observations2map and elevation-mapper load maps): file, section, key, rule and unit. Before,
// MRPT's exception wrapper cut the message at the ']' of "[m]", and the user saw "error: ".
TEST(OptionKeys, BrokenRulesReachTheUserWholeThroughMrptsInitializers) {
    const std::string dir = std::string(MULTIBIN_BINARY_DIR) + "/test_option_keys";
    std::filesystem::create_directories(dir);
    for (const std::string key :
         {"fill_median_window_cells = 4", "visibility_margin_m = -1", "stereo_halo_jump_px = 0",
          "fill_pso_particles = 0", "visibility_certainty_share = 1.5"}) {
        SCOPED_TRACE(key);
        const std::string path = dir + "/broken.ini";
        std::ofstream(path) << "[map]\nmultiBinElevationMap_count = 1\n"
                            << "[map_multiBinElevationMap_00_insertOpts]\n"
                            << key << "\n";
        try {
            mrpt::config::CConfigFile ini(path);
            mrpt::maps::TSetOfMetricMapInitializers inits;
            inits.loadFromConfigFile(ini, "map");
            ADD_FAILURE() << "accepted";
        } catch (const std::exception& e) {
            const std::string msg = multibin::oneLineMessage(e);
            for (const std::string& word :
                 {path, std::string("map_multiBinElevationMap_00_insertOpts"),
                  key.substr(0, key.find(' ')), std::string("must be")})
                EXPECT_NE(msg.find(word), std::string::npos) << "'" << word << "' not in: " << msg;
        }
    }
}
