/* Random scenes, stereo alone (random-scenes --sensor stereo, doc/random-scenes.md): the map on
 * the rendered pairs of a handful of scoring scenes against the naive pipeline (SGBM, every pixel
 * triangulated, MRPT's mean; apps/terrain-sim/NaiveStereo.h), issue 38's bound on the cells both
 * hold. */
#include <gtest/gtest.h>

#include <cstdio>

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

// Issue 38's ratio bound (<= 0.8 x the naive RMSE on the cells both hold) on the first scoring
// scenes, one noise each, with a margin (measured 0.45-0.55 over the 50 scoring scenes); the
// cells held within 30 mm at least the naive pipeline's. The coverage bound (no lower) is not
// met: the map holds 2-5 % fewer cells, which the naive pipeline holds 70-90 mm wrong
// (doc/results/2026-11-28-random-scenes-stereo.md); guarded at today's level.
TEST(RandomScenesStereo, MapBeatsTheNaivePipelineOnAHandfulOfScoringScenes) {
    for (const auto& [seed, noise] : std::vector<std::pair<uint64_t, std::string>>{
             {1000, "matched"}, {1001, "independent"}, {1002, "matched"}}) {
        const RandomScene sc = scoringScene(seed, noise);
        SCOPED_TRACE(sc.describe() + " (" + noise + ")");
        const StereoSceneScores s = scoreRandomSceneStereo(sc);
        const auto& b = s.boards;
        std::printf(
            "seed %lu %s: map %.2f mm naive %.2f mm ratio %.3f (%zu cells) coverage %.3f "
            "/ %.3f within 30 mm %zu / %zu\n",
            (unsigned long)seed, noise.c_str(), 1e3 * b.mapRmse_m(), 1e3 * b.naiveRmse_m(),
            rmseRatio(s), b.commonCells, b.mapCoverage(), b.naiveCoverage(), b.mapGood,
            b.naiveGood);
        ASSERT_GT(b.commonCells, 1000u);
        EXPECT_LT(rmseRatio(s), 0.7);
        EXPECT_GE(b.mapGood, b.naiveGood);
        EXPECT_GT(b.mapCoverage(), 0.9 * b.naiveCoverage());
    }
}

// The check above fails when the naive pipeline stands in for the map: ratio 1, no margin.
TEST(RandomScenesStereo, TheBoundFailsForTheNaivePipelineItself) {
    const StereoSceneScores s =
        scoreRandomSceneStereo(scoringScene(1000, "matched"), {}, false, /*naiveAsMap=*/true);
    EXPECT_NEAR(rmseRatio(s), 1.0, 1e-12);
    EXPECT_FALSE(rmseRatio(s) < 0.7);
}
