/* Stereo alone (SGBM on rendered pairs over the scoring boards AC, CC, CD) against the naive
 * pipeline (stereo_naive.h): the map must be clearly more accurate on the cells both hold. Before
 * the texture filter both were equal (49.4 mm against 49.2 mm, doc/sensor-models.md): SGBM carried
 * the boards' disparities over the textureless ground, points above the ground. */
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

    const auto on = stereo_naive::compare(prefix, [](auto&) {});
    const auto off =
        stereo_naive::compare(prefix, [](auto& o) { o.sensors.stereo.textureMinStd_grey = 0; });
    for (const auto* s : {&off, &on})
        std::printf(
            "common %zu  naive %.2f mm  map %.2f mm  coverage naive %.3f map %.3f  "
            "within 3 sigma %.1f %%\n",
            s->commonCells, 1e3 * s->naiveRmse_m(), 1e3 * s->mapRmse_m(), s->naiveCoverage(),
            s->mapCoverage(), 100 * s->mapWithin3());
    // Without the texture filter the map is no better than the naive pipeline ...
    EXPECT_GT(off.mapRmse_m(), 0.95 * off.naiveRmse_m());
    // ... with it, at least 10 % better on the cells both hold (measured 15 %), and honest.
    EXPECT_LT(on.mapRmse_m(), 0.9 * on.naiveRmse_m());
    EXPECT_LT(on.mapRmse_m(), 0.7 * off.mapRmse_m());
    EXPECT_GT(on.mapWithin3(), 0.9);
}
