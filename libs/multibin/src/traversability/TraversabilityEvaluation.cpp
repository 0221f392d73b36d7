/* Part of the multibin elevation-mapping library. */
#include "multibin/traversability/TraversabilityEvaluation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace multibin::traversability {

std::vector<int8_t> truthClasses(const EsriAsciiGrid& truth, const Lattice& lattice,
                                 const TraversabilityOptions& o,
                                 std::vector<DiscFeatures>* features) {
    std::vector<int8_t> out(lattice.cellCount(), -1);
    if (features) features->assign(lattice.cellCount(), DiscFeatures{NAN, NAN, NAN});
    const double d = truth.cellsize_m, r = o.radius_m;
    const int reach = int(std::ceil(r / d));
    for (int row = 0; row < lattice.ny(); row++)
        for (int col = 0; col < lattice.nx(); col++) {
            const double x = lattice.cellCenterX_m(col), y = lattice.cellCenterY_m(row);
            const int c0 = int(std::lround((x - truth.xllcenter_m) / d));
            const int r0 = int(std::lround((y - truth.yllcenter_m) / d));
            DiscAccumulator acc;
            size_t inDisc = 0;
            for (int rr = r0 - reach; rr <= r0 + reach; rr++)
                for (int cc = c0 - reach; cc <= c0 + reach; cc++) {
                    const double dx = truth.xllcenter_m + cc * d - x;
                    const double dy = truth.yllcenter_m + rr * d - y;
                    if (dx * dx + dy * dy > r * r) continue;
                    inDisc++;
                    if (rr < 0 || cc < 0 || rr >= truth.rows() || cc >= truth.cols()) continue;
                    const float h = truth.heights_m(rr, cc);
                    if (std::isfinite(h)) acc.add(dx, dy, h);
                }
            DiscFeatures f;
            if (double(acc.count()) < o.min_known_fraction * double(inDisc) || !acc.features(f))
                continue;
            if (features) (*features)[lattice.index(col, row)] = f;
            out[lattice.index(col, row)] = f.step_m > o.max_step_m ||
                                           f.slope_deg > o.max_slope_deg ||
                                           f.roughness_m > o.max_roughness_m;
        }
    return out;
}

SurfaceSamples cellHeightSamples(const Lattice& lattice, const std::vector<float>& height_m) {
    SurfaceSamples s(lattice, 1);
    for (size_t k = 0; k < height_m.size(); k++) {
        s.height_m[k] = height_m[k];
        s.sigma_m[k] = std::isfinite(height_m[k]) ? 0.f : NAN;
    }
    return s;
}

ClassifierScore scoreProbabilities(const std::vector<float>& p, const std::vector<int8_t>& truth) {
    ClassifierScore s;
    std::array<double, 10> sumP{}, sumTruth{};
    for (size_t k = 0; k < truth.size() && k < p.size(); k++) {
        if (truth[k] < 0) continue;
        s.truthCells++;
        if (!std::isfinite(p[k])) continue;
        s.scored++;
        const bool bad = truth[k] == 1, predicted = p[k] > 0.5f;
        s.truePositive += bad && predicted, s.falsePositive += !bad && predicted;
        s.falseNegative += bad && !predicted, s.trueNegative += !bad && !predicted;
        const int b = std::min(9, int(p[k] * 10));
        s.reliability[size_t(b)].cells++;
        sumP[size_t(b)] += p[k], sumTruth[size_t(b)] += bad;
    }
    const auto ratio = [](double a, double b) { return b > 0 ? a / b : 0.0; };
    s.precision = ratio(double(s.truePositive), double(s.truePositive + s.falsePositive));
    s.recall = ratio(double(s.truePositive), double(s.truePositive + s.falseNegative));
    s.f1 = ratio(2 * s.precision * s.recall, s.precision + s.recall);
    s.coverage = ratio(double(s.scored), double(s.truthCells));
    for (size_t b = 0; b < 10; b++) {
        ReliabilityBin& r = s.reliability[b];
        if (r.cells == 0) continue;
        r.meanProbability = sumP[b] / double(r.cells);
        r.observed = sumTruth[b] / double(r.cells);
        s.ece += double(r.cells) / double(s.scored) * std::abs(r.meanProbability - r.observed);
    }
    return s;
}

std::string scoresJson(const std::map<std::string, ClassifierScore>& scores,
                       const std::vector<std::string>& order, const TraversabilityOptions& o) {
    std::ostringstream j;
    j << "{\n  \"limits\": {\"radius_m\": " << o.radius_m << ", \"max_step_m\": " << o.max_step_m
      << ", \"max_slope_deg\": " << o.max_slope_deg
      << ", \"max_roughness_m\": " << o.max_roughness_m << "},\n  \"methods\": {";
    const char* sep = "\n";
    for (const std::string& name : order) {
        const ClassifierScore& s = scores.at(name);
        j << sep << "    \"" << name << "\": {\"truth_cells\": " << s.truthCells
          << ", \"scored\": " << s.scored << ", \"coverage\": " << s.coverage
          << ", \"precision\": " << s.precision << ", \"recall\": " << s.recall
          << ", \"f1\": " << s.f1 << ", \"ece\": " << s.ece << ", \"tp\": " << s.truePositive
          << ", \"fp\": " << s.falsePositive << ", \"fn\": " << s.falseNegative
          << ", \"tn\": " << s.trueNegative << ", \"reliability\": [";
        for (size_t b = 0; b < 10; b++)
            j << (b ? ", " : "") << "{\"cells\": " << s.reliability[b].cells
              << ", \"mean_p\": " << s.reliability[b].meanProbability
              << ", \"observed\": " << s.reliability[b].observed << "}";
        j << "]}";
        sep = ",\n";
    }
    j << "\n  }\n}\n";
    return j.str();
}

std::string scoresTable(const std::map<std::string, ClassifierScore>& scores,
                        const std::vector<std::string>& order) {
    std::ostringstream t;
    char line[256];
    // Indented, as the evaluation's per-area lines: tools that read the height table's rows by
    // their method names (compare-baseline.sh) skip these.
    t << "  method                 precision  recall      F1     ECE  coverage   cells\n";
    for (const std::string& name : order) {
        const ClassifierScore& s = scores.at(name);
        std::snprintf(line, sizeof line, "  %-22s %9.3f %7.3f %7.3f %7.3f %9.3f %7zu\n",
                      name.c_str(), s.precision, s.recall, s.f1, s.ece, s.coverage, s.scored);
        t << line;
    }
    if (order.empty()) return t.str();
    const ClassifierScore& s = scores.at(order.front());
    t << "reliability of " << order.front() << " (P in deciles: cells, mean P, observed):\n";
    for (size_t b = 0; b < 10; b++) {
        std::snprintf(line, sizeof line, "  %.1f-%.1f %8zu %7.3f %7.3f\n", 0.1 * double(b),
                      0.1 * double(b + 1), s.reliability[b].cells, s.reliability[b].meanProbability,
                      s.reliability[b].observed);
        t << line;
    }
    return t.str();
}

}  // namespace multibin::traversability
