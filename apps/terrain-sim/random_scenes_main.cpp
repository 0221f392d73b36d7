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
    "  tuning boards B, X1, W; scoring boards AC, CC, CD (doc/independent-evaluation.md)\n"
    "  --ini: map options from FILE's section " kInsertSection " over the defaults\n";

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

}  // namespace

int main(int argc, char** argv) {
    std::string boards = "scoring", noise = "matched", dir = "rawlogs/terrain/littledog", ini;
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
    std::printf("\n| quantity | bound | scenes | median | 90th pct | worst | failing scenes |\n");
    std::printf("| --- | --- | ---: | ---: | ---: | ---: | --- |\n");
    for (const Quantity* q : {&object, &mrptObject, &noObject, &seenAgain, &staticRatio,
                              &staticMrpt, &filled, &query, &queryFloor}) {
        std::string fails;
        for (const auto& f : q->failing) fails += (fails.empty() ? "" : " ") + f;
        std::printf("| %s | %s | %zu | %.3g | %.3g | %.3g | %zu: %s |\n", q->name, q->bound,
                    q->values.size(), percentile(q->values, 0.5), percentile(q->values, 0.9),
                    percentile(q->values, 1.0), q->failing.size(), fails.c_str());
    }
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
