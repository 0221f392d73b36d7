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
 * (stereo_texture_min_std_grey, stereo_texture_radius_px), MEU (max_elevation_uncertainty_m), MAXR
 * (max_range_m); FULL (stereo_sgbm_full_width); DEM=1 scores the DEM with filled cells; DUMP=FILE
 * writes the cells; NAIVE_FULL=1 gives the naive pipeline the library's full-width matching too
 * (stereo_naive.h).
 * `--disparity-errors PREFIX` (a scenario WITH disparity images: the true disparity plus
 * N(0, 0.25 px)) prints SGBM's disparity against it, split by the texture filter's criterion
 * (textured pixels of the leftmost numDisparities columns, matched thanks to
 * stereo_sgbm_full_width, apart). */
#include <cstdio>
#include <cstdlib>
#include <string>

#include "../sensors/stereo_naive.h"

namespace {
/** SGBM (library defaults) against the simulator's disparity image, textured and textureless
 * pixels apart (local grey std over 5 x 5 at or above / below stereo_texture_min_std_grey), the
 * textured ones of the leftmost numDisparities columns apart too. */
int disparityErrors(const std::string& prefix) {
    mrpt::maps::CSimpleMap sm;
    mrpt::io::CFileGZInputStream f(prefix + ".simplemap");
    mrpt::serialization::archiveFrom(f) >> sm;
    const multibin::sensors::StereoModelOptions opts;
    struct Acc {
        size_t n = 0, gross = 0;
        double sumSq = 0, sum = 0;
        size_t frac[10] = {};
    } acc[3];  // textured, textureless, textured in the leftmost numDisparities columns
    for (size_t i = 0; i < sm.size(); i++)
        for (const auto& obs : *std::get<1>(sm.get(i))) {
            auto st = std::dynamic_pointer_cast<mrpt::obs::CObservationStereoImages>(obs);
            if (!st || !st->hasImageDisparity) continue;
            const auto sim = multibin::sensors::decodeDisparityImage(st->imageDisparity);
            const auto sgbm =
                multibin::sensors::computeDisparitySGBM(st->imageLeft, st->imageRight, opts);
            auto flat = sgbm;  // valid where the texture filter would keep the pixel
            multibin::sensors::removeTextureless(flat, st->imageLeft, opts);
            for (int v = 0; v < sgbm.height; v++)
                for (int u = 0; u < sgbm.width; u++) {
                    if (!sgbm.valid(u, v) || !sim.valid(u, v)) continue;
                    const bool band = u < opts.numDisparitiesFor(sgbm.width);
                    Acc& a = acc[!flat.valid(u, v) ? 1 : band ? 2 : 0];
                    const double e = sgbm.at(u, v) - sim.at(u, v);
                    a.n++;
                    if (std::abs(e) > 2) {
                        a.gross++;
                        continue;
                    }
                    a.sum += e;
                    a.sumSq += e * e;
                    const double d = sgbm.at(u, v);
                    a.frac[std::min(9, int(10 * (d - std::floor(d))))]++;
                }
        }
    const char* names[3] = {"textured", "textureless", "left band"};
    for (int k = 0; k < 3; k++) {
        const Acc& a = acc[k];
        const double m = double(a.n - a.gross);
        std::printf(
            "%-11s px %8zu  > 2 px %5.2f %%  within 2 px: mean %+.3f px  RMS %.3f px  "
            "sub-pixel fraction deciles:",
            names[k], a.n, 100.0 * double(a.gross) / double(a.n), a.sum / m,
            std::sqrt(a.sumSq / m));
        for (size_t c : a.frac) std::printf(" %.3f", double(c) / m);
        std::printf("\n");
    }
    return 0;
}
}  // namespace

int main(int argc, char** argv) {
    if (argc == 3 && std::string(argv[1]) == "--disparity-errors") return disparityErrors(argv[2]);
    if (argc < 2) {
        std::fprintf(
            stderr,
            "usage: %s [--area XMIN,XMAX,YMIN,YMAX] PREFIX [PREFIX...] (terrain-sim outputs)\n",
            argv[0]);
        return 2;
    }
    std::printf("%-28s %7s %9s %9s %7s %10s %10s %9s %9s %9s\n", "scenario", "common", "naive mm",
                "map mm", "gain", "naive cov", "map cov", "naive 3cm", "map 3cm", "map 3sig");
    stereo_naive::Area area;
    for (int i = 1; i < argc; i++) {
        if (std::string(argv[i]) == "--area" && i + 1 < argc) {
            if (std::sscanf(argv[++i], "%lf,%lf,%lf,%lf", &area.xMin_m, &area.xMax_m, &area.yMin_m,
                            &area.yMax_m) != 4) {
                std::fprintf(stderr, "--area: expected XMIN,XMAX,YMIN,YMAX [m], got '%s'\n",
                             argv[i]);
                return 2;
            }
            continue;
        }
        const auto s = stereo_naive::compare(
            argv[i],
            [](auto& o) {
                auto& so = o.sensors.stereo;
                if (auto e = std::getenv("HALO")) so.halo.enabled = std::atoi(e);
                if (auto e = std::getenv("NC")) so.nearCluster.enabled = std::atoi(e);
                if (auto e = std::getenv("SUB")) so.subsample = std::atoi(e);
                if (auto e = std::getenv("SIG")) so.matchingSigma_px = std::atof(e);
                if (auto e = std::getenv("HJ")) so.halo.jump_px = std::atof(e);
                if (auto e = std::getenv("TEX")) so.texture.minStd_grey = std::atof(e);
                if (auto e = std::getenv("TEXR")) so.texture.radius_px = std::atoi(e);
                if (auto e = std::getenv("FULL")) so.sgbmFullWidth = std::atoi(e);
                if (auto e = std::getenv("UNIQ")) so.sgbmUniquenessRatio = std::atoi(e);
                if (auto e = std::getenv("D12")) so.sgbmDisp12MaxDiff = std::atoi(e);
                if (auto e = std::getenv("BLOCK")) so.sgbmBlockSize = std::atoi(e);
                if (auto e = std::getenv("SPW")) so.sgbmSpeckleWindowSize = std::atoi(e);
                if (auto e = std::getenv("MODE")) so.sgbmMode = e;
                if (auto e = std::getenv("NCA")) so.nearCluster.maxArea_px = std::atoi(e);
                if (auto e = std::getenv("HR")) so.halo.radius_px = std::atoi(e);
                if (auto e = std::getenv("MEU")) o.max_elevation_uncertainty_m = std::atof(e);
                if (auto e = std::getenv("MAXR")) o.max_range_m = std::atof(e);
            },
            area);
        std::printf("%-28s %7zu %9.2f %9.2f %6.1f%% %10.3f %10.3f %9.3f %9.3f %8.1f%%\n", argv[i],
                    s.commonCells, 1e3 * s.naiveRmse_m(), 1e3 * s.mapRmse_m(),
                    100 * (1 - s.mapRmse_m() / s.naiveRmse_m()), s.naiveCoverage(), s.mapCoverage(),
                    s.naiveGoodCoverage(), s.mapGoodCoverage(), 100 * s.mapWithin3());
    }
    return 0;
}
