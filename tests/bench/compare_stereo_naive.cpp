/* The map on stereo alone against the naive pipeline (OpenCV SGBM with the library's default
 * parameters, triangulate every pixel, MRPT CHeightGridMap2D mean at the same cell size), scored
 * on the cells both hold against the ground truth. Scenarios are terrain-sim outputs (SGBM is
 * run on the rendered pairs whether or not they carry a disparity image), e.g. the scoring boards:
 *   L=rawlogs/terrain/littledog
 *   build/apps/terrain-sim/terrain-sim --scenario mockup --terrain $L/AC.asc,$L/CC.asc,$L/CD.asc \
 *       --tiles 4x3 --seed 7 --no-disparity --out build/stereo/score
 *   build/tests/bench/compare_stereo_naive build/stereo/score [more prefixes...]
 * Prints one table row per scenario (doc/sensor-models.md, "Stereo against the naive pipeline").
 * For experiments, environment variables override the map's options: HALO, NC (0/1 filters), SUB
 * (stereo_subsample), SIG (stereo_matching_sigma_px), HJ (stereo_halo_jump_px), TEX, TEXR
 * (stereo_texture_min_std_grey, stereo_texture_radius_px), MEU (max_elevation_uncertainty_m);
 * DEM=1 scores the DEM with filled cells; DUMP=FILE writes the cells (stereo_naive.h). */
#include <cstdio>
#include <cstdlib>

#include "../sensors/stereo_naive.h"

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s PREFIX [PREFIX...] (terrain-sim outputs)\n", argv[0]);
        return 2;
    }
    std::printf("%-28s %7s %9s %9s %7s %10s %10s %9s\n", "scenario", "common", "naive mm", "map mm",
                "gain", "naive cov", "map cov", "map 3sig");
    for (int i = 1; i < argc; i++) {
        const auto s = stereo_naive::compare(argv[i], [](auto& o) {
            auto& so = o.sensors.stereo;
            if (auto e = std::getenv("HALO")) so.haloFilter = std::atoi(e);
            if (auto e = std::getenv("NC")) so.nearClusterFilter = std::atoi(e);
            if (auto e = std::getenv("SUB")) so.subsample = std::atoi(e);
            if (auto e = std::getenv("SIG")) so.matchingSigma_px = std::atof(e);
            if (auto e = std::getenv("HJ")) so.haloJump_px = std::atof(e);
            if (auto e = std::getenv("TEX")) so.textureMinStd_grey = std::atof(e);
            if (auto e = std::getenv("TEXR")) so.textureRadius_px = std::atoi(e);
            if (auto e = std::getenv("MEU")) o.max_elevation_uncertainty_m = std::atof(e);
        });
        std::printf("%-28s %7zu %9.2f %9.2f %6.1f%% %10.3f %10.3f %8.1f%%\n", argv[i],
                    s.commonCells, 1e3 * s.naiveRmse_m(), 1e3 * s.mapRmse_m(),
                    100 * (1 - s.mapRmse_m() / s.naiveRmse_m()), s.naiveCoverage(), s.mapCoverage(),
                    100 * s.mapWithin3());
    }
    return 0;
}
