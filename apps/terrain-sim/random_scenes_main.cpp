/* random-scenes: maps N random scenes (RandomScene.h) with the library's default options and
 * prints, per quantity of issue 38, the distribution over the scenes (median, 90th percentile,
 * worst) and the scenes that fail its bound (doc/random-scenes.md). */
#include "RandomScene.h"
#include "RandomSceneScore.h"

#include <mrpt/config/CConfigFile.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/system/filesystem.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

using namespace terrain_sim;

namespace {

#define kInsertSection "[MappingApplication_multiBinElevationMap_00_insertOpts]"
const char* kUsage =
    "usage: random-scenes [--boards tuning|scoring] [--seeds FIRST-LAST] "
    "[--noise matched|independent|exact] [--board-dir DIR] [--ini FILE]\n"
    "                     [--sensor laser|stereo] [--cells FILE]\n"
    "  tuning boards B, X1, W; scoring boards AC, CC, CD (doc/independent-evaluation.md)\n"
    "  --ini: map options from FILE's section " kInsertSection
    " over the defaults\n"
    "  --sensor stereo: stereo only, the map against the naive pipeline; --cells: the cells\n"
    "    on the boards either holds (seed x y truth map sigma naive [m], nan: none) into FILE\n";

struct Quantity {
    const char* name;
    const char* bound;  // the bound, as text
    std::vector<double> values;
    std::vector<std::string> failing;
};

double percentile(std::vector<double> v, double q) {
    if (v.empty()) return NAN;
    std::sort(v.begin(), v.end());
    const size_t k = std::min(v.size() - 1, size_t(std::ceil(q * v.size())) - (q > 0 ? 1 : 0));
    return v[k];
}

void record(Quantity& q, double value, bool fails, uint64_t seed) {
    if (!std::isfinite(value)) return;
    q.values.push_back(value);
    if (fails) q.failing.push_back(std::to_string(seed));
}

std::string joined(const std::vector<std::string>& v) {
    std::string out;
    for (const auto& f : v) out += (out.empty() ? "" : " ") + f;
    return out;
}

void printTable(const std::vector<const Quantity*>& quantities) {
    std::printf("\n| quantity | bound | scenes | median | 90th pct | worst | failing scenes |\n");
    std::printf("| --- | --- | ---: | ---: | ---: | ---: | --- |\n");
    for (const Quantity* q : quantities)
        std::printf("| %s | %s | %zu | %.3g | %.3g | %.3g | %zu: %s |\n", q->name, q->bound,
                    q->values.size(), percentile(q->values, 0.5), percentile(q->values, 0.9),
                    percentile(q->values, 1.0), q->failing.size(), joined(q->failing).c_str());
}

/** `--sensor stereo`: per scene the map and the naive pipeline on the cells both hold, then the
 * distributions of the RMSE ratio and the coverage ratio (issue 38: ratio <= 0.8 in 90 % of the
 * scenes, coverage no lower). */
int runStereo(RandomSceneOptions opts, uint64_t first, uint64_t last,
              const std::function<void(mrpt::maps::CMultiBinElevationMap&)>& configure,
              const std::string& cellsFile) {
    FILE* cells = nullptr;
    if (!cellsFile.empty() && !(cells = std::fopen(cellsFile.c_str(), "w"))) {
        std::fprintf(stderr, "random-scenes: error: cannot write --cells '%s'\n",
                     cellsFile.c_str());
        return 1;
    }
    Quantity ratio{
        "stereo, boards: map RMSE / naive RMSE, cells both hold", "<= 0.8 in 90 %", {}, {}};
    Quantity coverage{"stereo, boards: map coverage / naive coverage", ">= 1", {}, {}};
    Quantity mapMm{"  map RMSE on the cells both hold [mm]", "-", {}, {}};
    Quantity naiveMm{"  naive RMSE on the cells both hold [mm]", "-", {}, {}};
    Quantity far{"  share of the map's squared error in cells > 30 mm off", "-", {}, {}};
    Quantity stepShare{
        "  share of the map's squared error within 2 cells of a step > 0.1 m", "-", {}, {}};
    Quantity offSteps{"stereo, boards: RMSE ratio away from those steps", "-", {}, {}};
    Quantity onSteps{"stereo, boards: RMSE ratio on the cells near those steps", "-", {}, {}};
    Quantity good{"stereo, boards: cells within 30 mm, map / naive", "-", {}, {}};
    Quantity naiveOnly{"  naive-only cells: share of the truth cells", "-", {}, {}};
    Quantity naiveOnlyMm{"  naive-only cells: naive RMSE there [mm]", "-", {}, {}};
    Quantity rasterRatio{"stereo, whole raster (flat margin too): RMSE ratio", "-", {}, {}};
    Quantity rasterCoverage{"stereo, whole raster: coverage ratio", "-", {}, {}};
    std::vector<std::string> failingBoth;
    std::printf(
        "# seed map_mm naive_mm ratio common map_cov naive_cov cov_ratio far_cells far_share "
        "step_share ratio_off_steps ratio_on_steps good_ratio naive_only naive_only_mm "
        "raster_ratio "
        "raster_cov_ratio frames | camera | "
        "scene\n");
    for (uint64_t seed = first; seed <= last; ++seed) {
        opts.seed = seed;
        const RandomScene sc = makeRandomScene(opts);
        const StereoSceneScores s = scoreRandomSceneStereo(sc, configure, cells != nullptr);
        const auto& b = s.boards;
        const double r = b.mapRmse_m() / b.naiveRmse_m();
        const double c = b.mapCoverage() / b.naiveCoverage();
        const double farShare = b.mapFarSumSq_m2 / b.mapSumSq_m2;
        const double stepShare_ = b.mapStepSumSq_m2 / b.mapSumSq_m2;
        const double goodRatio = double(b.mapGood) / double(b.naiveGood);
        const double naiveOnly_mm = 1e3 * std::sqrt(b.naiveOnlySumSq_m2 / b.naiveOnlyCells);
        const double rr = s.raster.mapRmse_m() / s.raster.naiveRmse_m();
        const double rc = s.raster.mapCoverage() / s.raster.naiveCoverage();
        std::printf(
            "%lu %.2f %.2f %.3f %zu %.3f %.3f %.3f %zu %.2f %.2f %.3f %.3f %.3f %zu %.1f %.3f %.3f "
            "%zu "
            "| %.2f m "
            "%.0f deg | "
            "%s\n",
            (unsigned long)seed, 1e3 * b.mapRmse_m(), 1e3 * b.naiveRmse_m(), r, b.commonCells,
            b.mapCoverage(), b.naiveCoverage(), c, b.mapFarCells, farShare, stepShare_,
            b.ratioOffSteps(), b.ratioOnSteps(), goodRatio, b.naiveOnlyCells, naiveOnly_mm, rr, rc,
            s.stereoFrames, sc.stereo.height_m, sc.stereo.pitch_rad * 180 / M_PI,
            sc.describe().c_str());
        std::fflush(stdout);
        for (const auto& cell : s.cells)
            std::fprintf(cells, "%lu %.4f %.4f %.5f %.5f %.5f %.5f\n", (unsigned long)seed, cell[0],
                         cell[1], cell[2], cell[3], cell[4], cell[5]);
        record(ratio, r, !(r <= 0.8), seed);
        record(coverage, c, !(c >= 1), seed);
        if (!(r <= 0.8 && c >= 1)) failingBoth.push_back(std::to_string(seed));
        record(mapMm, 1e3 * b.mapRmse_m(), false, seed);
        record(naiveMm, 1e3 * b.naiveRmse_m(), false, seed);
        record(far, farShare, false, seed);
        record(stepShare, stepShare_, false, seed);
        record(offSteps, b.ratioOffSteps(), false, seed);
        record(onSteps, b.ratioOnSteps(), false, seed);
        record(good, goodRatio, false, seed);
        record(naiveOnly, double(b.naiveOnlyCells) / double(b.truthCells), false, seed);
        record(naiveOnlyMm, naiveOnly_mm, false, seed);
        record(rasterRatio, rr, false, seed);
        record(rasterCoverage, rc, false, seed);
    }
    if (cells) std::fclose(cells);
    printTable({&ratio, &coverage, &mapMm, &naiveMm, &far, &stepShare, &offSteps, &onSteps, &good,
                &naiveOnly, &naiveOnlyMm, &rasterRatio, &rasterCoverage});
    const size_t n = last - first + 1, held = n - failingBoth.size();
    std::printf(
        "\nstereo: %zu of %zu scenes hold both (ratio <= 0.8 and coverage no lower; bound: 90 "
        "%%): %s; failing: %s\n",
        held, n, 10 * held >= 9 * n ? "met" : "NOT met", joined(failingBoth).c_str());
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    std::string boards = "scoring", noise = "matched", dir = "rawlogs/terrain/littledog", ini;
    std::string sensor = "laser", cellsFile;
    uint64_t first = 1000, last = 1049;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        const char* v = i + 1 < argc ? argv[i + 1] : nullptr;
        if (a == "--boards" && v)
            boards = argv[++i];
        else if (a == "--noise" && v)
            noise = argv[++i];
        else if (a == "--board-dir" && v)
            dir = argv[++i];
        else if (a == "--ini" && v)
            ini = argv[++i];
        else if (a == "--sensor" && v)
            sensor = argv[++i];
        else if (a == "--cells" && v)
            cellsFile = argv[++i];
        else if (a == "--seeds" && v && std::sscanf(argv[++i], "%lu-%lu", &first, &last) == 2) {
        } else {
            std::fprintf(stderr, "random-scenes: error: bad argument '%s'\n%s", a.c_str(), kUsage);
            return 1;
        }
    }
    if ((boards != "tuning" && boards != "scoring") ||
        (noise != "matched" && noise != "independent" && noise != "exact") || last < first) {
        std::fprintf(stderr, "random-scenes: error: bad --boards, --noise or --seeds\n%s", kUsage);
        return 1;
    }
    if (sensor != "laser" && sensor != "stereo") {
        std::fprintf(stderr,
                     "random-scenes: error: --sensor must be laser or stereo (got '%s')\n%s",
                     sensor.c_str(), kUsage);
        return 1;
    }
    if (!cellsFile.empty() && sensor != "stereo") {
        std::fprintf(stderr, "random-scenes: error: --cells needs --sensor stereo\n%s", kUsage);
        return 1;
    }
    RandomSceneOptions opts;
    opts.boardNames = boards == "tuning" ? std::vector<std::string>{"B", "X1", "W"}
                                         : std::vector<std::string>{"AC", "CC", "CD"};
    try {
        for (const auto& b : opts.boardNames)
            opts.boards.push_back(multibin::EsriAsciiGrid::load(dir + "/" + b + ".asc"));
    } catch (const std::exception& e) {
        std::fprintf(stderr, "random-scenes: error: %s\n", e.what());
        return 1;
    }
    opts.noise = noise;
    std::function<void(mrpt::maps::CMultiBinElevationMap&)> configure;
    if (!ini.empty()) {
        if (!mrpt::system::fileExists(ini)) {
            std::fprintf(stderr, "random-scenes: error: cannot read --ini '%s'\n", ini.c_str());
            return 1;
        }
        configure = [ini](mrpt::maps::CMultiBinElevationMap& map) {
            const mrpt::config::CConfigFile file(ini);
            std::string section = kInsertSection;
            map.insertionOptions.loadFromConfigFile(file, section.substr(1, section.size() - 2));
        };
    }
    if (sensor == "stereo") {
        std::printf("# random-scenes --sensor stereo --boards %s --noise %s --seeds %lu-%lu%s%s\n",
                    boards.c_str(), noise.c_str(), (unsigned long)first, (unsigned long)last,
                    ini.empty() ? "" : " --ini ", ini.c_str());
        return runStereo(opts, first, last, configure, cellsFile);
    }
    Quantity object{"moved object RMSE, footprint + 1 cell [mm]", "<= 15 mm in 90 %", {}, {}};
    Quantity mrptObject{"  MRPT's mean there [mm]", "-", {}, {}};
    Quantity noObject{"  the map there, the object never there [mm]", "-", {}, {}};
    Quantity seenAgain{"  the cells a later pass saw again [mm]", "<= 15 mm in 90 %", {}, {}};
    // "No worse than without the object": the two runs draw the same noise streams, but a beam
    // that meets the object draws differently from there on, so 2 % is the runs' own spread.
    Quantity staticRatio{"static terrain RMSE, with / without the object", "<= 1.02", {}, {}};
    Quantity staticMrpt{"static terrain cells, RMSE / MRPT's on the same cells", "-", {}, {}};
    Quantity filled{"filled cells in MRPT's gaps, RMSE [mm]", "median <= 20 mm", {}, {}};
    Quantity query{"random query points, RMSE / MRPT's", "<= 0.55 in every scene", {}, {}};
    Quantity queryFloor{"random query points, RMSE / the one-height-per-cell floor", "-", {}, {}};
    // Over the scenes failing the moved-object bound: what the cells there hold (CellKind).
    double failingSq[RandomSceneScores::kCellKinds][2] = {};
    size_t failingCells[RandomSceneScores::kCellKinds][2] = {};
    std::printf("# random-scenes --boards %s --noise %s --seeds %lu-%lu%s%s\n", boards.c_str(),
                noise.c_str(), (unsigned long)first, (unsigned long)last,
                ini.empty() ? "" : " --ini ", ini.c_str());
    std::printf(
        "# seed object_mm mrpt_mm object_noobj_mm object_seen_mm seen_n/cells unknown static_mm "
        "static_noobj_mm static_mrpt_mm "
        "filled_mm "
        "filled_n "
        "query_mm query_mrpt_mm query_floor_mm | scene\n");
    for (uint64_t seed = first; seed <= last; ++seed) {
        opts.seed = seed;
        const RandomScene sc = makeRandomScene(opts);
        const RandomSceneScores s = scoreRandomScene(sc, configure);
        std::printf(
            "%lu %.1f %.1f %.1f %.1f %zu/%zu %zu %.2f %.2f %.2f %.1f %zu %.2f %.2f %.2f | %s\n",
            (unsigned long)seed, 1e3 * s.objectRmse_m, 1e3 * s.objectMrptRmse_m,
            1e3 * s.objectNoObjectRmse_m, 1e3 * s.objectSeenAgainRmse_m, s.objectSeenAgainCells,
            s.objectCells, s.objectUnknown, 1e3 * s.staticRmse_m, 1e3 * s.staticRmseNoObject_m,
            1e3 * s.staticMrptRmse_m, 1e3 * s.filledRmse_m, s.filledCells, 1e3 * s.queryRmse_m,
            1e3 * s.queryMrptRmse_m, 1e3 * s.queryFloorRmse_m, sc.describe().c_str());
        std::fflush(stdout);
        record(object, 1e3 * s.objectRmse_m, s.objectRmse_m > 0.015, seed);
        for (int k = 0; k < RandomSceneScores::kCellKinds && s.objectRmse_m > 0.015; ++k)
            for (int seen : {0, 1}) {
                failingSq[k][seen] += s.objectSquaredError_m2[k][seen];
                failingCells[k][seen] += s.objectCellsOfKind[k][seen];
            }
        record(mrptObject, 1e3 * s.objectMrptRmse_m, false, seed);
        record(noObject, 1e3 * s.objectNoObjectRmse_m, false, seed);
        record(seenAgain, 1e3 * s.objectSeenAgainRmse_m, s.objectSeenAgainRmse_m > 0.015, seed);
        const double ratio = s.staticRmse_m / s.staticRmseNoObject_m;
        record(staticRatio, ratio, ratio > 1.02, seed);
        record(staticMrpt, s.staticRmse_m / s.staticMrptRmse_m, false, seed);
        record(filled, 1e3 * s.filledRmse_m, s.filledRmse_m > 0.020, seed);
        const double q = s.queryRmse_m / s.queryMrptRmse_m;
        record(query, q, q > 0.55, seed);
        record(queryFloor, s.queryRmse_m / s.queryFloorRmse_m, false, seed);
    }
    printTable({&object, &mrptObject, &noObject, &seenAgain, &staticRatio, &staticMrpt, &filled,
                &query, &queryFloor});
    double total = 0;
    for (const auto& kind : failingSq) total += kind[0] + kind[1];
    const char* kinds[] = {"an object bin winning beside a ground bin", "only object bins",
                           "no bin (the fill's value)", "a winning ground bin"};
    std::printf(
        "\nmoved object, the failing scenes' cells: share of the squared error (cells), "
        "all / seen again by a later pass / not\n");
    for (int k = 0; k < RandomSceneScores::kCellKinds; ++k) {
        const double* sq = failingSq[k];
        const size_t* n = failingCells[k];
        auto share = [total](double e) { return total > 0 ? e / total : 0.0; };
        std::printf("| %s | %.2f (%zu) | %.2f (%zu) | %.2f (%zu) |\n", kinds[k],
                    share(sq[0] + sq[1]), n[0] + n[1], share(sq[1]), n[1], share(sq[0]), n[0]);
    }
    return 0;
}
