/* Stereo alone (SGBM on rendered pairs over the scoring boards AC, CC, CD) against the naive
 * pipeline (stereo_naive.h): issue 18's bound, at least 20 % lower RMSE on the cells both hold
 * with at least the naive coverage, guarded with a margin (measured: 30.3 % lower, coverage
 * 0.639 against 0.554; doc/sensor-models.md). Two controls show what the guard catches: without
 * the texture filter the map is under 20 % better (SGBM carries the boards' disparities over
 * textureless ground), and without matching the leftmost columns it covers less than the naive
 * pipeline. */
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "stereo_naive.h"

TEST(StereoNaive, MapBeatsTheNaivePipelineOnRenderedRockBoards) {
    const std::filesystem::path dir = std::filesystem::path(MULTIBIN_BINARY_DIR) / "stereo_naive";
    std::filesystem::create_directories(dir);
    const std::string L = MULTIBIN_SOURCE_DIR "/rawlogs/terrain/littledog/";
    const std::string prefix = (dir / "score").string();
    const std::string cmd = std::string(TERRAIN_SIM_EXE) + " --scenario mockup --terrain " + L +
                            "AC.asc," + L + "CC.asc," + L +
                            "CD.asc --tiles 4x3 --seed 7 --no-disparity --out " + prefix +
                            " > /dev/null";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;

    const stereo_naive::Area boards{0, 2.43, -0.91, 0.91};  // the 4 x 3 tiles of 0.607 m
    const auto on = stereo_naive::compare(
        prefix, [](auto&) {}, boards);
    const auto noTexture = stereo_naive::compare(
        prefix, [](auto& o) { o.sensors.stereo.texture.minStd_grey = 0; }, boards);
    const auto narrow = stereo_naive::compare(
        prefix, [](auto& o) { o.sensors.stereo.sgbmFullWidth = false; }, boards);
    for (const auto* s : {&on, &noTexture, &narrow})
        std::printf(
            "common %zu  naive %.2f mm  map %.2f mm  gain %.1f %%  coverage naive %.3f map %.3f  "
            "within 3 sigma %.1f %%\n",
            s->commonCells, 1e3 * s->naiveRmse_m(), 1e3 * s->mapRmse_m(),
            100 * (1 - s->mapRmse_m() / s->naiveRmse_m()), s->naiveCoverage(), s->mapCoverage(),
            100 * s->mapWithin3());
    // The bound (gain >= 20 %, coverage >= naive) with a margin: gain over 23 % (measured 30.3),
    // coverage over 1.05 times the naive one (measured 1.15), more cells within 3 cm of the
    // truth, and sigmas that stay honest (measured 91.1 % within 3 sigma).
    EXPECT_LT(on.mapRmse_m(), 0.77 * on.naiveRmse_m());
    EXPECT_GT(on.mapCoverage(), 1.05 * on.naiveCoverage());
    EXPECT_GT(on.mapGood, on.naiveGood);
    EXPECT_GT(on.mapWithin3(), 0.88);
    // Controls: each would fail the bound (measured: gain 14.8 %; coverage 0.516 against 0.554).
    EXPECT_GT(noTexture.mapRmse_m(), 0.8 * noTexture.naiveRmse_m());
    EXPECT_LT(narrow.mapCoverage(), narrow.naiveCoverage());
}
