/* Part of the multibin elevation-mapping library: evaluation against ground truth (eq 17). */
#include "multibin/eval/Evaluation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

namespace multibin::eval {

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

int floorIndex(double coord_m, double cellSize_m) {
    return static_cast<int>(std::floor(coord_m / cellSize_m));
}
}  // namespace

Lattice subLattice(const Lattice& lattice, const std::vector<double>& area_m) {
    if (area_m.size() != 4 || !(area_m[0] < area_m[1]) || !(area_m[2] < area_m[3]))
        throw std::invalid_argument("evaluation area: expected xmin < xmax, ymin < ymax [m]");
    // Cell k's centre (k + 0.5) s lies in [lo, hi] for ceil(lo/s - 0.5) <= k <= floor(hi/s - 0.5).
    const double s = lattice.cellSize_m;
    const auto first = [s](double lo) { return int(std::ceil(lo / s - 0.5)); };
    const auto last = [s](double hi) { return int(std::floor(hi / s - 0.5)); };
    Lattice sub = lattice;
    sub.window.ix0 = std::max(lattice.window.ix0, first(area_m[0]));
    sub.window.iy0 = std::max(lattice.window.iy0, first(area_m[2]));
    sub.window.nx =
        std::min(lattice.window.ix0 + lattice.window.nx - 1, last(area_m[1])) - sub.window.ix0 + 1;
    sub.window.ny =
        std::min(lattice.window.iy0 + lattice.window.ny - 1, last(area_m[3])) - sub.window.iy0 + 1;
    if (sub.window.nx <= 0 || sub.window.ny <= 0)
        throw std::invalid_argument("evaluation area: no cell of the ground truth lies inside it");
    return sub;
}

CellArray groundTruthOnLattice(const EsriAsciiGrid& truth, double cellSize_m, Lattice& latticeOut) {
    if (!(cellSize_m > 0)) throw std::invalid_argument("ground truth: cell size must be > 0");
    if (truth.rows() == 0 || truth.cols() == 0)
        throw std::invalid_argument("ground truth: the raster is empty");
    // Refuse before allocating (16 bytes per cell below): 2 x 2 truth cells of 150 m took 10 GB.
    // 2.5e7 cells (0.4 GB) hold 100 m x 100 m at 2 cm, beyond any evaluation scenario.
    const double nx = std::floor(truth.xMax_m() / cellSize_m) -
                      std::floor(truth.xllcenter_m / cellSize_m) + 1,
                 ny = std::floor(truth.yMax_m() / cellSize_m) -
                      std::floor(truth.yllcenter_m / cellSize_m) + 1;
    constexpr double kMaxCells = 2.5e7;
    if (!(nx * ny <= kMaxCells)) {
        std::ostringstream os;
        os << "ground truth: its extent on the map's " << cellSize_m << " m cells is " << nx
           << " x " << ny << " cells (" << nx * ny * 16 / 1e9 << " GB), more than the " << kMaxCells
           << " cells allowed";
        throw std::invalid_argument(os.str());
    }
    Lattice& L = latticeOut;
    L.cellSize_m = cellSize_m;
    L.window.ix0 = floorIndex(truth.xllcenter_m, cellSize_m);
    L.window.iy0 = floorIndex(truth.yllcenter_m, cellSize_m);
    L.window.nx = floorIndex(truth.xMax_m(), cellSize_m) - L.window.ix0 + 1;
    L.window.ny = floorIndex(truth.yMax_m(), cellSize_m) - L.window.iy0 + 1;

    Eigen::ArrayXXd sum = Eigen::ArrayXXd::Zero(L.window.ny, L.window.nx);
    Eigen::ArrayXXi count = Eigen::ArrayXXi::Zero(L.window.ny, L.window.nx);
    for (int r = 0; r < truth.rows(); r++)
        for (int c = 0; c < truth.cols(); c++) {
            const float h = truth.heights_m(r, c);
            if (!std::isfinite(h)) continue;
            int col, row;
            if (!L.cellOf(truth.xllcenter_m + c * truth.cellsize_m,
                          truth.yllcenter_m + r * truth.cellsize_m, col, row))
                continue;
            sum(row, col) += h;
            count(row, col)++;
        }
    CellArray out(L.window.ny, L.window.nx);
    for (int r = 0; r < L.window.ny; r++)
        for (int c = 0; c < L.window.nx; c++)
            out(r, c) = count(r, c) > 0 ? float(sum(r, c) / count(r, c)) : kNaN;
    return out;
}

RawPointGrid::RawPointGrid(const Lattice& lattice)
    : m_lattice(lattice),
      m_sum_m(Eigen::ArrayXXd::Zero(lattice.window.ny, lattice.window.nx)),
      m_count(Eigen::ArrayXXi::Zero(lattice.window.ny, lattice.window.nx)) {}

void RawPointGrid::addPoint(double x_m, double y_m, double z_m) {
    int col, row;
    if (!std::isfinite(z_m) || !m_lattice.cellOf(x_m, y_m, col, row)) return;
    m_sum_m(row, col) += z_m;
    m_count(row, col)++;
}

CellArray RawPointGrid::heights_m() const {
    CellArray out(m_lattice.window.ny, m_lattice.window.nx);
    for (int r = 0; r < m_lattice.window.ny; r++)
        for (int c = 0; c < m_lattice.window.nx; c++)
            out(r, c) = m_count(r, c) > 0 ? float(m_sum_m(r, c) / m_count(r, c)) : kNaN;
    return out;
}

SquaredError meanSquaredError(const CellArray& estimate_m, const CellArray& truth_m,
                              const Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>* mask) {
    if (estimate_m.rows() != truth_m.rows() || estimate_m.cols() != truth_m.cols())
        throw std::invalid_argument("meanSquaredError: estimate and truth differ in size");
    SquaredError e;
    double sum = 0;
    for (Eigen::Index r = 0; r < truth_m.rows(); r++)
        for (Eigen::Index c = 0; c < truth_m.cols(); c++) {
            if (mask && !(*mask)(r, c)) continue;
            const float h = estimate_m(r, c), t = truth_m(r, c);
            if (!std::isfinite(h) || !std::isfinite(t)) continue;
            sum += double(h - t) * double(h - t);
            e.cells++;
        }
    e.mse_m2 = e.cells ? sum / double(e.cells) : std::numeric_limits<double>::quiet_NaN();
    return e;
}

double performanceIndex(const SquaredError& method, const SquaredError& raw) {
    if (raw.cells == 0 || !(raw.mse_m2 > 0) || method.cells == 0)
        return std::numeric_limits<double>::quiet_NaN();
    return method.mse_m2 / raw.mse_m2;
}

std::map<std::string, MethodScore> scoreMethods(const CellArray& truth_m,
                                                const std::vector<MethodEstimate>& methods) {
    std::map<std::string, const MethodEstimate*> byName;
    for (const auto& m : methods) {
        if (m.height_m.rows() != truth_m.rows() || m.height_m.cols() != truth_m.cols())
            throw std::invalid_argument("evaluation: method '" + m.name +
                                        "' does not cover the evaluation lattice");
        byName[m.name] = &m;
    }
    // Cells every whole-area method covers (and the truth knows): the shared PI.
    Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> shared = truth_m.isFinite();
    for (const auto& m : methods)
        if (m.coversWholeArea) shared = shared && m.height_m.isFinite();

    const size_t truthCells = size_t(truth_m.isFinite().count());
    std::map<std::string, MethodScore> scores;
    for (const auto& m : methods) {
        const std::string& baseName = m.baseline.empty() ? m.name : m.baseline;
        const auto base = byName.find(baseName);
        if (base == byName.end())
            throw std::invalid_argument("evaluation: method '" + m.name + "' names baseline '" +
                                        baseName + "', which is not evaluated");
        MethodScore s;
        const SquaredError own = meanSquaredError(m.height_m, truth_m);
        // A crop-only method is compared with its raw map over its crop only, for PI and for
        // the shared cells.
        using Mask = Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>;
        Mask crop, sharedInCrop;
        if (!m.coversWholeArea) {
            crop = m.height_m.isFinite();
            sharedInCrop = shared && crop;
        }
        const Mask* rawCells = m.coversWholeArea ? nullptr : &crop;
        const Mask* sharedCells = m.coversWholeArea ? &shared : &sharedInCrop;
        const SquaredError raw = meanSquaredError(base->second->height_m, truth_m, rawCells);
        s.validCells = own.cells;
        s.rmse_m = std::sqrt(own.mse_m2);
        s.pi = performanceIndex(own, raw);
        s.piShared =
            performanceIndex(meanSquaredError(m.height_m, truth_m, sharedCells),
                             meanSquaredError(base->second->height_m, truth_m, sharedCells));
        s.coverage = truthCells ? double(own.cells) / double(truthCells) : 0.0;
        if (m.sigma_m.size() > 0) {
            // Share of the cells (of `only`, if given) where h and the truth are finite whose
            // error is within 3 sigma; `cells` receives their count.
            auto within3Sigma = [&](const Mask* only, size_t& cells) {
                size_t inside = 0;
                cells = 0;
                for (Eigen::Index r = 0; r < truth_m.rows(); r++)
                    for (Eigen::Index c = 0; c < truth_m.cols(); c++) {
                        const float h = m.height_m(r, c), t = truth_m(r, c);
                        if (!std::isfinite(h) || !std::isfinite(t) || (only && !(*only)(r, c)))
                            continue;
                        cells++;
                        if (std::abs(h - t) <= 3.f * m.sigma_m(r, c)) inside++;
                    }
                return cells ? double(inside) / double(cells) : 0.0;
            };
            size_t cells = 0;
            s.within3Sigma = within3Sigma(nullptr, cells);
            const auto twin = byName.find(m.filledFrom);
            if (!m.filledFrom.empty() && twin != byName.end()) {
                const Mask filledOnly = !twin->second->height_m.isFinite();
                s.within3SigmaFilledOnly = within3Sigma(&filledOnly, s.filledOnlyCells);
                s.rmseFilledOnly_m =
                    std::sqrt(meanSquaredError(m.height_m, truth_m, &filledOnly).mse_m2);
            }
        }
        s.insert_s = m.insert_s;
        s.fill_s = m.fill_s;
        scores[m.name] = s;
    }
    return scores;
}

namespace {
using Mask = Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>;
AreaScores scoreCells(const std::string& name, const CellArray& truth_m,
                      const std::vector<MethodEstimate>& methods, const Mask& cells) {
    AreaScores a;
    a.name = name;
    for (const auto& m : methods) a.errors[m.name] = meanSquaredError(m.height_m, truth_m, &cells);
    return a;
}
}  // namespace

AreaScores scoreArea(const std::string& name, const CellArray& truth_m,
                     const std::vector<MethodEstimate>& methods, const Lattice& lattice,
                     const Lattice& area) {
    Mask mask(lattice.window.ny, lattice.window.nx);
    for (int r = 0; r < lattice.window.ny; r++)
        for (int c = 0; c < lattice.window.nx; c++) {
            const int ix = lattice.window.ix0 + c, iy = lattice.window.iy0 + r;
            mask(r, c) = ix >= area.window.ix0 && ix < area.window.ix0 + area.window.nx &&
                         iy >= area.window.iy0 && iy < area.window.iy0 + area.window.ny;
        }
    AreaScores a = scoreCells(name, truth_m, methods, mask);
    a.area_m = area.area_m();
    return a;
}

AreaScores scoreGapsOf(const std::string& gapsOf, const CellArray& truth_m,
                       const std::vector<MethodEstimate>& methods) {
    for (const auto& m : methods)
        if (m.name == gapsOf)
            return scoreCells(gapsOf + "_gaps", truth_m, methods, !m.height_m.isFinite());
    throw std::invalid_argument("evaluation: no method '" + gapsOf + "' to score the gaps of");
}

std::string reportJson(const std::map<std::string, MethodScore>& scores,
                       const std::vector<std::string>& order, const Lattice& lattice,
                       const std::vector<AreaScores>& areas) {
    // NaN is not JSON: unknown values are written as null.
    auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
    nlohmann::ordered_json methods = nlohmann::ordered_json::object();
    for (const std::string& name : order) {
        const auto it = scores.find(name);
        if (it == scores.end()) continue;
        const MethodScore& s = it->second;
        methods[name] = {{"rmse_m", number(s.rmse_m)},
                         {"pi", number(s.pi)},
                         {"pi_shared", number(s.piShared)},
                         {"coverage", number(s.coverage)},
                         {"within_3sigma", s.within3Sigma ? number(*s.within3Sigma) : nullptr},
                         {"insert_s", number(s.insert_s)},
                         {"fill_s", number(s.fill_s)},
                         {"valid_cells", s.validCells}};
        if (s.within3SigmaFilledOnly) {
            methods[name]["within_3sigma_filled_only"] = number(*s.within3SigmaFilledOnly);
            methods[name]["rmse_filled_only_m"] = number(s.rmseFilledOnly_m.value_or(NAN));
            methods[name]["filled_only_cells"] = s.filledOnlyCells;
        }
    }
    nlohmann::ordered_json report = {
        {"methods", methods}, {"cell_size_m", lattice.cellSize_m}, {"area_m", lattice.area_m()}};
    for (const AreaScores& a : areas) {
        nlohmann::ordered_json rmse = nlohmann::ordered_json::object(),
                               cells = nlohmann::ordered_json::object();
        for (const std::string& name : order) {
            const auto it = a.errors.find(name);
            if (it == a.errors.end()) continue;
            rmse[name] = number(std::sqrt(it->second.mse_m2));
            cells[name] = it->second.cells;
        }
        report[a.name] = {{"rmse_m", rmse}, {"cells", cells}};
        if (!a.area_m.empty()) report[a.name]["area_m"] = a.area_m;
    }
    return report.dump(2) + "\n";
}

std::string reportTable(const std::map<std::string, MethodScore>& scores,
                        const std::vector<std::string>& order,
                        const std::vector<AreaScores>& areas) {
    std::ostringstream os;
    char line[256];
    std::snprintf(line, sizeof line, "%-22s %10s %7s %9s %9s %9s %9s %8s\n", "method", "rmse [mm]",
                  "PI", "PI shared", "coverage", "in 3sigma", "insert s", "fill s");
    os << line;
    for (const std::string& name : order) {
        const auto it = scores.find(name);
        if (it == scores.end()) continue;
        const MethodScore& s = it->second;
        char within[32] = "-";
        if (s.within3Sigma) std::snprintf(within, sizeof within, "%.3f", *s.within3Sigma);
        std::snprintf(line, sizeof line, "%-22s %10.2f %7.3f %9.3f %9.3f %9s %9.3f %8.3f\n",
                      name.c_str(), 1000 * s.rmse_m, s.pi, s.piShared, s.coverage, within,
                      s.insert_s, s.fill_s);
        os << line;
    }
    for (const AreaScores& a : areas) {
        if (a.area_m.size() == 4)
            std::snprintf(line, sizeof line, "RMSE [mm] over %s x [%.3f, %.3f] y [%.3f, %.3f] m:\n",
                          a.name.c_str(), a.area_m[0], a.area_m[1], a.area_m[2], a.area_m[3]);
        else
            std::snprintf(line, sizeof line, "RMSE [mm] over %s:\n", a.name.c_str());
        os << line;
        for (const std::string& name : order) {
            const auto it = a.errors.find(name);
            if (it == a.errors.end()) continue;
            std::snprintf(line, sizeof line, "  %-22s %10.2f (%zu cells)\n", name.c_str(),
                          1000 * std::sqrt(it->second.mse_m2), it->second.cells);
            os << line;
        }
    }
    return os.str();
}

}  // namespace multibin::eval
