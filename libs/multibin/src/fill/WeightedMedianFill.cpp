/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/WeightedMedianFill.h"

#include <algorithm>
#include <cmath>

#include "multibin/fill/detail/MedianFiller.h"
#include "multibin/fill/detail/ResultSetup.h"

namespace multibin::fill {

double medianSkeletonWeight(int di, int dj) { return std::sqrt(double(di * di + dj * dj)); }

namespace detail {

MedianFiller::MedianFiller(const HeightRaster& r, const FillOptions& o) : m_r(r), m_o(o) {
    const int half = o.medianWindow_cells / 2;
    for (int dj = -half; dj <= half; dj++)
        for (int di = -half; di <= half; di++)
            if (di || dj)
                m_offsets.push_back(
                    {di, dj, dj * std::ptrdiff_t(r.nx()) + di, medianSkeletonWeight(di, dj)});
    m_half = half;
}

bool MedianFiller::fillCell(int ix, int iy, FillResult& out, const std::vector<char>& usable) {
    m_vals.clear();
    double wSum = 0;
    // Away from the border the whole window is inside: no per-neighbour bounds check.
    const bool interior =
        ix >= m_half && iy >= m_half && ix < m_r.nx() - m_half && iy < m_r.ny() - m_half;
    const std::ptrdiff_t centre = std::ptrdiff_t(m_r.index(ix, iy));
    for (const auto& o : m_offsets) {
        if (!interior && !m_r.inside(ix + o.di, iy + o.dj)) continue;
        const size_t k = size_t(centre + o.linear);
        if (!usable[k]) continue;
        // Insertion into a sorted list: at most window^2 - 1 values, cheaper than a sort.
        const Sample v{out.height_m[k], out.sigma_m[k], float(o.w)};
        size_t at = m_vals.size();
        m_vals.push_back(v);
        while (at > 0 && m_vals[at - 1].h > v.h) {
            m_vals[at] = m_vals[at - 1];
            at--;
        }
        m_vals[at] = v;
        wSum += o.w;
    }
    if (int(m_vals.size()) < m_o.medianMinKnown) return false;
    double acc = 0, med = m_vals.back().h;
    for (const auto& s : m_vals) {
        acc += s.w;
        if (acc >= 0.5 * wSum) {
            med = s.h;
            break;
        }
    }
    double sigma;
    if (m_o.sigmaModel == FillSigmaModel::Paper) {
        double ws = 0;
        for (const auto& s : m_vals) ws += s.w * s.s;
        sigma = ws / wSum;
    } else {
        // Neighbour noise plus the local spread of heights about the median: a cell on a
        // step edge gets a large sigma, one on a flat plate stays near the sensor noise.
        double var = 0, spread = 0;
        for (const auto& s : m_vals) {
            var += s.w * s.s * s.s;
            spread += s.w * (s.h - med) * (s.h - med);
        }
        var /= wSum;
        spread /= wSum;
        sigma = std::sqrt(var + m_o.medianSigmaGain * m_o.medianSigmaGain * spread);
        sigma = std::max(sigma, m_o.sigmaFloor_m);
    }
    const size_t k = m_r.index(ix, iy);
    out.height_m[k] = float(med);
    out.sigma_m[k] = float(sigma);
    out.source[k] = HeightSource::FilledMedian;
    return true;
}

int MedianFiller::fillRepeated(const std::vector<int>& cells, FillResult& out,
                               std::vector<char>& usable) {
    std::vector<int> todo = cells, next, filledNow;
    int filled = 0;
    while (!todo.empty()) {
        next.clear();
        filledNow.clear();
        for (int k : todo) {
            if (fillCell(k % m_r.nx(), k / m_r.nx(), out, usable))
                filledNow.push_back(k);
            else
                next.push_back(k);
        }
        if (filledNow.empty()) break;
        for (int k : filledNow) usable[size_t(k)] = 1;  // data for the next pass only
        filled += int(filledNow.size());
        todo.swap(next);
    }
    return filled;
}

}  // namespace detail

FillResult weightedMedianFill(const HeightRaster& r, const FillOptions& o, bool repeat) {
    r.validate();
    o.validate();
    std::vector<char> usable;
    FillResult out = detail::initResult(r, usable);
    detail::MedianFiller median(r, o);
    std::vector<int> gaps;
    for (size_t k = 0; k < r.size(); k++)
        if (!usable[k]) gaps.push_back(int(k));
    if (repeat)
        median.fillRepeated(gaps, out, usable);
    else
        for (int k : gaps) median.fillCell(k % r.nx(), k / r.nx(), out, usable);
    detail::countSources(out);
    return out;
}

}  // namespace multibin::fill
