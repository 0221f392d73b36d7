/* Test data for gap filling: the shared LittleDog boards resampled to the map cell size, with
 * measurement noise on the known cells and gaps hidden by hand. Used by the unit tests, the
 * comparison program and the benchmark. Boards: kuindersma/drake (BSD-3-Clause), see
 * rawlogs/terrain/README.md. */
#pragma once

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "multibin/eval/Evaluation.h"
#include "multibin/fill/HeightRaster.h"
#include "multibin/io/EsriAsciiGrid.h"

namespace multibin::filltest {

/** A board resampled by cell means: truth(ix, iy) is the mean of the source samples whose
 * centres fall in the cell (only cells fully covered by the board are kept). */
struct Board {
    std::string name;
    int n = 0;  //!< cells per side
    double cell_m = 0;
    std::vector<double> truth_m;  //!< n x n, index iy * n + ix
    double at(int ix, int iy) const { return truth_m[size_t(iy) * size_t(n) + size_t(ix)]; }
};

inline const std::vector<std::string>& boardNames() {
    static const std::vector<std::string> names{"B", "X1", "W", "AC", "CC", "CD"};
    return names;
}

inline Board loadBoard(const std::string& sharedDir, const std::string& name, double cell_m) {
    const auto g = EsriAsciiGrid::load(sharedDir + "/terrain/littledog/" + name + ".asc");
    Board b;
    b.name = name;
    b.cell_m = cell_m;
    const int side = std::min(g.rows(), g.cols());
    b.n = int(std::floor(side * g.cellsize_m / cell_m));
    std::vector<double> sum(size_t(b.n) * size_t(b.n), 0.0), cnt(sum.size(), 0.0);
    for (int r = 0; r < side; r++)
        for (int c = 0; c < side; c++) {
            const int ix = int((c + 0.5) * g.cellsize_m / cell_m);
            const int iy = int((r + 0.5) * g.cellsize_m / cell_m);
            if (ix >= b.n || iy >= b.n || !std::isfinite(g.heights_m(r, c))) continue;
            sum[size_t(iy) * size_t(b.n) + size_t(ix)] += g.heights_m(r, c);
            cnt[size_t(iy) * size_t(b.n) + size_t(ix)]++;
        }
    b.truth_m.resize(sum.size());
    for (size_t k = 0; k < sum.size(); k++) b.truth_m[k] = sum[k] / cnt[k];
    return b;
}

/** Every board at 15 mm cells (cell means), loaded once from the reference data in dataDir. */
inline const std::vector<Board>& boardsAt15mm(const std::string& dataDir) {
    static const std::vector<Board> b = [&] {
        std::vector<Board> v;
        for (const auto& n : boardNames()) v.push_back(loadBoard(dataDir, n, 0.015));
        return v;
    }();
    return b;
}

/** A side x side crop of a board at (x0, y0), every cell measured: height = truth + N(0, s^2),
 * s drawn per cell uniformly in [sigmaLo_m, sigmaHi_m] and stored as the cell's sigma. */
inline fill::HeightRaster noisyCrop(const Board& b, int x0, int y0, int side, unsigned seed,
                                    double sigmaLo_m = 0.002, double sigmaHi_m = 0.004) {
    if (x0 < 0 || y0 < 0 || x0 + side > b.n || y0 + side > b.n)
        throw std::invalid_argument("noisyCrop: crop outside board " + b.name);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> sig(sigmaLo_m, sigmaHi_m);
    std::normal_distribution<double> unit(0.0, 1.0);
    fill::HeightRaster r(side, side, b.cell_m);
    for (int iy = 0; iy < side; iy++)
        for (int ix = 0; ix < side; ix++) {
            const double s = sig(rng);
            r.setMeasured(ix, iy, float(b.at(x0 + ix, y0 + iy) + s * unit(rng)), float(s));
        }
    return r;
}

inline void hideBox(fill::HeightRaster& r, int x0, int y0, int w, int h) {
    for (int iy = y0; iy < y0 + h; iy++)
        for (int ix = x0; ix < x0 + w; ix++)
            if (r.inside(ix, iy)) r.setUnknown(ix, iy);
}

/** An n x n raster tiled from the boards (board (tx + ty) mod 6 at tile (tx, ty)), every cell
 * measured with noise as in noisyCrop: a mock-up larger than one board (at 15 mm, n = 133 is the
 * 2 x 2 m local grid). */
inline fill::HeightRaster tiledRaster(const std::vector<Board>& boards, int n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> sig(0.002, 0.004);
    std::normal_distribution<double> unit(0.0, 1.0);
    const int t = boards[0].n;
    fill::HeightRaster r(n, n, boards[0].cell_m);
    for (int iy = 0; iy < n; iy++)
        for (int ix = 0; ix < n; ix++) {
            const Board& b = boards[size_t((ix / t + iy / t) % int(boards.size()))];
            const double s = sig(rng);
            r.setMeasured(ix, iy, float(b.at(ix % t, iy % t) + s * unit(rng)), float(s));
        }
    return r;
}

/** One hidden square gap on one board crop. */
struct GapCase {
    int board = 0;                 //!< index into the loaded boards
    int gx = 0, gy = 0, size = 0;  //!< gap corner and side, in crop cells
    unsigned noiseSeed = 0;
};

constexpr int kCropSide = 35;   //!< crop side [cells]: small enough for MRPT's GMRF solver
constexpr int kCropOffset = 2;  //!< crop corner on the board [cells]

/** `perSize` random placements of each gap size on each board; gaps stay `margin` cells away
 * from the crop border so their support areas lie inside the crop. */
inline std::vector<GapCase> makeGapCases(int boards, const std::vector<int>& sizes, int perSize,
                                         int margin, unsigned seed) {
    std::mt19937 rng(seed);
    std::vector<GapCase> cases;
    for (int b = 0; b < boards; b++)
        for (int s : sizes)
            for (int p = 0; p < perSize; p++) {
                std::uniform_int_distribution<int> pos(margin, kCropSide - margin - s);
                GapCase c;
                c.board = b;
                c.size = s;
                c.gx = pos(rng);
                c.gy = pos(rng);
                c.noiseSeed = unsigned(rng());
                cases.push_back(c);
            }
    return cases;
}

/** The crop of a case with its gap hidden. */
inline fill::HeightRaster caseRaster(const std::vector<Board>& boards, const GapCase& c) {
    auto r = noisyCrop(boards[size_t(c.board)], kCropOffset, kCropOffset, kCropSide, c.noiseSeed);
    hideBox(r, c.gx, c.gy, c.size, c.size);
    return r;
}

inline double caseTruth(const std::vector<Board>& boards, const GapCase& c, int ix, int iy) {
    return boards[size_t(c.board)].at(kCropOffset + ix, kCropOffset + iy);
}

/** Calls fn(k, truth_m) for every filled cell k of `fill` that has a ground truth: the ESRI raster
 * at `truthPath` averaged onto a lattice of the fill's cell size (eval::groundTruthOnLattice),
 * matched at that lattice's cell centres. */
template <class Fn>
void forEachFilledCellWithTruth(const fill::FillResult& fill, const std::string& truthPath,
                                Fn&& fn) {
    Lattice lattice;
    const auto truth = eval::groundTruthOnLattice(EsriAsciiGrid::load(truthPath),
                                                  fill.lattice.cellSize_m, lattice);
    for (int row = 0; row < lattice.ny(); row++)
        for (int col = 0; col < lattice.nx(); col++) {
            int c, r;
            const float t = truth(row, col);
            if (!std::isfinite(t) ||
                !fill.lattice.cellOf(lattice.cellCenterX_m(col), lattice.cellCenterY_m(row), c, r))
                continue;
            const size_t k = fill.index(c, r);
            if (fill.isFilled(k)) fn(k, double(t));
        }
}

}  // namespace multibin::filltest
