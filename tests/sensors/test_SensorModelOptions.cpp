/* Sensor-model ini keys: parsing, round trip, errors that name the key. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/maps/CMultiBinElevationMap.h>

#include "multibin/io/StrictConfigSection.h"
#include "multibin/sensors/SensorModelOptions.h"

using multibin::sensors::SensorModelOptions;

namespace {
SensorModelOptions load(const std::string& body) {
    mrpt::config::CConfigFileMemory ini("[s]\n" + body);
    multibin::StrictConfigSection s(ini, "s");
    SensorModelOptions o;
    o.read(s);
    s.finish();
    return o;
}
}  // namespace

TEST(SensorOptions, ReadsContractKeys) {
    const SensorModelOptions o = load(
        "laser_agc = LASER:512, LASER2:300\n"
        "laser_range_sigma_coeffs = 0.001 0.004 0.0005\n"
        "stereo_left_intrinsics_sigma = 1 2 3 4 0.1 0.2 0.3 0.4 0.5\n"
        "stereo_right_intrinsics_sigma = 1 1 1 1 0 0 0 0 0\n"
        "stereo_extrinsics_sigma = 0.001 0.002 0.003 0.004 0.005 0.006\n"
        "stereo_matching_sigma_px = 0.3\n"
        "stereo_sgbm_num_disparities = 64\n"
        "stereo_sgbm_full_width = false\n"
        "depth_axial_sigma_quadratic_per_m = 0.003\n");
    EXPECT_DOUBLE_EQ(o.laser.agcByLabel.at("LASER"), 512);
    EXPECT_DOUBLE_EQ(o.laser.agcByLabel.at("LASER2"), 300);
    EXPECT_DOUBLE_EQ(o.laser.rangeSigma(1.0), 0.001 + 0.004 + 0.0005);
    EXPECT_DOUBLE_EQ(o.stereo.leftIntrinsicsSigma[8], 0.5);
    EXPECT_DOUBLE_EQ(o.stereo.extrinsicsSigma[5], 0.006);
    EXPECT_DOUBLE_EQ(o.stereo.matchingSigma_px, 0.3);
    EXPECT_EQ(o.stereo.sgbmNumDisparities, 64);
    EXPECT_EQ(o.stereo.numDisparitiesFor(1282), 64);
    EXPECT_FALSE(o.stereo.sgbmFullWidth);
    EXPECT_TRUE(SensorModelOptions().stereo.sgbmFullWidth);  // the default
    // Automatic: width / 4 in multiples of 16, within [16, 256].
    const SensorModelOptions autoOpts = load("stereo_sgbm_num_disparities = 0\n");
    EXPECT_EQ(autoOpts.stereo.numDisparitiesFor(1282), 256);  // 320 -> 256
    EXPECT_EQ(autoOpts.stereo.numDisparitiesFor(640), 160);
    EXPECT_EQ(autoOpts.stereo.numDisparitiesFor(320), 80);
    EXPECT_EQ(autoOpts.stereo.numDisparitiesFor(40), 16);
    EXPECT_DOUBLE_EQ(o.depth.axialSigmaQuadratic_per_m, 0.003);
}

TEST(SensorOptions, BadValuesNameTheKey) {
    auto fails = [](const std::string& body, const std::string& key) {
        try {
            load(body);
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
            return;
        }
        ADD_FAILURE() << "accepted: " << body;
    };
    fails("laser_agc = LASER512\n", "laser_agc");
    fails("laser_agc = LASER:abc\n", "laser_agc");
    fails("laser_agc = LASER:-3\n", "laser_agc");
    fails("stereo_extrinsics_sigma = 1 2 3\n", "stereo_extrinsics_sigma");
    fails("stereo_sgbm_num_disparities = 20\n", "stereo_sgbm_num_disparities");
    fails("stereo_sgbm_num_disparities = -16\n", "stereo_sgbm_num_disparities");
    fails("stereo_sgbm_block_size = 4\n", "stereo_sgbm_block_size");
    fails("stereo_sgbm_mode = fast\n", "stereo_sgbm_mode");
    fails("depth_lateral_sigma_rad = 0\n", "depth_lateral_sigma_rad");
    fails("laser_continuity_pose_correlation = 1.5\n", "laser_continuity_pose_correlation");
}

TEST(SensorOptions, MapRoundTripThroughIni) {
    mrpt::maps::CMultiBinElevationMap::TInsertionOptions a;
    a.sensors.laser.agcByLabel = {{"LASER", 512}, {"BACK", 300.5}};
    a.sensors.stereo.extrinsicsSigma = {1e-3, 2e-3, 3e-3, 4e-3, 5e-3, 6e-3};
    a.sensors.stereo.subsample = 3;
    a.sensors.depth.lateralSigma_rad = 0.002;
    mrpt::config::CConfigFileMemory ini;
    a.saveToConfigFile(ini, "ins");
    mrpt::maps::CMultiBinElevationMap::TInsertionOptions b;
    b.loadFromConfigFile(ini, "ins");
    EXPECT_EQ(b.sensors.laser.agcByLabel, a.sensors.laser.agcByLabel);
    EXPECT_EQ(b.sensors.stereo.extrinsicsSigma, a.sensors.stereo.extrinsicsSigma);
    EXPECT_EQ(b.sensors.stereo.subsample, 3);
    EXPECT_DOUBLE_EQ(b.sensors.depth.lateralSigma_rad, 0.002);
    // An unknown sensor key is refused by the map's strict reader.
    mrpt::config::CConfigFileMemory bad("[ins]\nstereo_halo_radios = 3\n");
    EXPECT_THROW(b.loadFromConfigFile(bad, "ins"), std::invalid_argument);
}
