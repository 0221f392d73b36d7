/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/HeightRaster.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "multibin/fill/detail/ResultSetup.h"

namespace multibin::fill {

using detail::kNaN;

HeightRaster::HeightRaster(const Lattice& l)
    : lattice(l),
      height_m(size_t(std::max(l.nx(), 0)) * size_t(std::max(l.ny(), 0)), kNaN),
      sigma_m(height_m.size(), kNaN),
      certainty(height_m.size(), 0.0f) {}

HeightRaster::HeightRaster(int nx_, int ny_, double cellSize)
    : HeightRaster(Lattice{cellSize, CellWindow{0, 0, nx_, ny_}}) {}

bool HeightRaster::isMeasured(size_t k) const {
    return certainty[k] > 0 && std::isfinite(height_m[k]) && std::isfinite(sigma_m[k]) &&
           sigma_m[k] > 0;
}

void HeightRaster::setMeasured(int ix, int iy, float h, float s, float c) {
    const size_t k = index(ix, iy);
    height_m[k] = h;
    sigma_m[k] = s;
    certainty[k] = c > 0 ? c : 1.0f;
}

void HeightRaster::setUnknown(int ix, int iy) {
    const size_t k = index(ix, iy);
    height_m[k] = kNaN;
    sigma_m[k] = kNaN;
    certainty[k] = 0;
}

void HeightRaster::validate() const {
    auto bad = [](const std::string& field, const std::string& what) {
        throw std::invalid_argument("HeightRaster." + field + ": " + what);
    };
    if (nx() < 0 || ny() < 0) bad("lattice.window.nx/ny", "must be >= 0");
    if (!(cellSize_m() > 0) || !std::isfinite(cellSize_m()))
        bad("lattice.cellSize_m", "must be positive [m]");
    const size_t n = size();
    if (height_m.size() != n)
        bad("height_m", "has " + std::to_string(height_m.size()) +
                            " values, expected nx * ny = " + std::to_string(n));
    if (sigma_m.size() != n) bad("sigma_m", "size differs from nx * ny");
    if (certainty.size() != n) bad("certainty", "size differs from nx * ny");
}

namespace detail {

FillResult initResult(const HeightRaster& r, std::vector<char>& measured) {
    FillResult out;
    out.lattice = r.lattice;
    out.height_m.assign(r.size(), kNaN);
    out.sigma_m.assign(r.size(), kNaN);
    out.source.assign(r.size(), HeightSource::Unknown);
    measured.assign(r.size(), 0);
    for (size_t k = 0; k < r.size(); k++)
        if (r.isMeasured(k)) {
            measured[k] = 1;
            out.height_m[k] = r.height_m[k];
            out.sigma_m[k] = r.sigma_m[k];
            out.source[k] = HeightSource::Measured;
        }
    return out;
}

void countSources(FillResult& out) {
    // Cells per HeightSource value (0 .. 4, the numbers of its raster layer; 5: any other).
    std::array<size_t, 6> cells{};
    for (auto src : out.source) cells[std::min<size_t>(size_t(src), 5)]++;
    auto& s = out.stats;
    s.measured = cells[size_t(HeightSource::Measured)];
    s.median = cells[size_t(HeightSource::FilledMedian)];
    s.harmonic = cells[size_t(HeightSource::FilledHarmonic)];
    s.gaussian = cells[size_t(HeightSource::FilledSurface)] + s.harmonic;
    s.unfilled = cells[size_t(HeightSource::Unknown)] + cells[5];
}

}  // namespace detail
}  // namespace multibin::fill
