/* Random scenes, stereo alone (random-scenes --sensor stereo, doc/random-scenes.md): the map on
 * the rendered pairs of a handful of scoring scenes against the naive pipeline (SGBM, every pixel
 * triangulated, MRPT's mean; apps/terrain-sim/NaiveStereo.h), issue 38's bound on the cells both
 * hold. */
#include <gtest/gtest.h>

#include <cstdio>

#include <mrpt/maps/CMultiBinElevationMap.h>

#include "RandomScene.h"
#include "RandomSceneScore.h"

using namespace terrain_sim;

namespace {

RandomScene scoringScene(uint64_t seed, const std::string& noise) {
    RandomSceneOptions o;
    o.boardNames = {"AC", "CC", "CD"};
    for (const auto& b : o.boardNames)
        o.boards.push_back(multibin::EsriAsciiGrid::load(std::string(MULTIBIN_REFERENCE_DATA_DIR) +
                                                         "/terrain/littledog/" + b + ".asc"));
    o.seed = seed;
    o.noise = noise;
    return makeRandomScene(o);
}

double rmseRatio(const StereoSceneScores& s) {
    return s.boards.mapRmse_m() / s.boards.naiveRmse_m();
}

}  // namespace

// Issue 38's bound, <= 0.8 x the naive RMSE on the cells both hold, per scene on the first four
// scoring scenes (measured: 1000 0.770, 1002 0.761, 1003 0.734 matched; 1001 0.523
// independent); away from the truth's steps, where most of the map's error sits, under 0.6
// (measured 0.32-0.46); the cells held within 30 mm at least the naive pipeline's (1.04-1.08).
// The coverage bound (no lower) is not met: the map holds 1-5 % fewer cells, which the naive
// pipeline holds 65-150 mm wrong (doc/results/2026-11-28-random-scenes-stereo.md); guarded at
// today's level (measured 0.95-0.99 of the naive coverage).
TEST(RandomScenesStereo, MapBeatsTheNaivePipelineOnAHandfulOfScoringScenes) {
    for (const auto& [seed, noise] : std::vector<std::pair<uint64_t, std::string>>{
             {1000, "matched"}, {1001, "independent"}, {1002, "matched"}, {1003, "matched"}}) {
        const RandomScene sc = scoringScene(seed, noise);
        SCOPED_TRACE(sc.describe() + " (" + noise + ")");
        const StereoSceneScores s = scoreRandomSceneStereo(sc);
        const auto& b = s.boards;
        std::printf(
            "seed %lu %s: map %.2f mm naive %.2f mm ratio %.3f (%zu cells; off steps "
            "%.3f) coverage %.3f / %.3f within 30 mm %zu / %zu\n",
            (unsigned long)seed, noise.c_str(), 1e3 * b.mapRmse_m(), 1e3 * b.naiveRmse_m(),
            rmseRatio(s), b.commonCells, b.ratioOffSteps(), b.mapCoverage(), b.naiveCoverage(),
            b.mapGood, b.naiveGood);
        ASSERT_GT(b.commonCells, 2000u);
        EXPECT_LE(rmseRatio(s), 0.8);
        EXPECT_LT(b.ratioOffSteps(), 0.6);
        EXPECT_GE(b.mapGood, b.naiveGood);
        EXPECT_GT(b.mapCoverage(), 0.93 * b.naiveCoverage());
    }
}

// The bound above can fail: with the naive pipeline standing in for the map (ratio 1), and with
// the map's texture filter off (SGBM's matches carried over textureless ground kept; measured
// 1.04 on seed 1000).
TEST(RandomScenesStereo, TheBoundFailsForTheNaivePipelineAndWithoutTheTextureFilter) {
    const RandomScene sc = scoringScene(1000, "matched");
    const StereoSceneScores naive = scoreRandomSceneStereo(sc, {}, false, /*naiveAsMap=*/true);
    EXPECT_NEAR(rmseRatio(naive), 1.0, 1e-12);
    const StereoSceneScores noTexture = scoreRandomSceneStereo(
        sc, [](auto& map) { map.insertionOptions.sensors.stereo.texture.minStd_grey = 0; });
    std::printf("texture filter off: ratio %.3f\n", rmseRatio(noTexture));
    EXPECT_GT(rmseRatio(noTexture), 0.8);
}
