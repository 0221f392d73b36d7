/* Small rasters and Gaussian surfaces for the gap-filling unit tests. */
#pragma once

#include <random>
#include <vector>

#include "multibin/fill/GaussianSurface.h"
#include "multibin/fill/HeightRaster.h"

namespace fill_test {

using multibin::fill::GaussianSurface;
using multibin::fill::GaussianTerm;
using multibin::fill::HeightRaster;
using multibin::fill::SurfaceSample;

/** A raster with every cell measured from f(ix, iy) [m], sigma s [m]. */
template <class F>
inline HeightRaster rasterFrom(int n, F f, float s = 0.002f) {
    HeightRaster r(n, n, 0.015);
    for (int iy = 0; iy < n; iy++)
        for (int ix = 0; ix < n; ix++) r.setMeasured(ix, iy, float(f(ix, iy)), s);
    return r;
}

inline void hide(HeightRaster& r, int x0, int y0, int w, int h) {
    for (int iy = y0; iy < y0 + h; iy++)
        for (int ix = x0; ix < x0 + w; ix++) r.setUnknown(ix, iy);
}

/** Samples of a sum of Gaussians on a side x side area with a hole, plus noise. */
inline std::vector<SurfaceSample> gaussianSamples(const std::vector<GaussianTerm>& terms, double c0,
                                                  int side, double noise_m, unsigned seed) {
    GaussianSurface truth;
    truth.c0_m = c0;
    truth.terms = terms;
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0.0, noise_m);
    std::vector<SurfaceSample> s;
    for (int j = 0; j < side; j++)
        for (int i = 0; i < side; i++)
            if (!(i >= 10 && i < 14 && j >= 10 && j < 14))
                s.push_back({i, j, truth(i, j) + n(rng), noise_m});
    return s;
}

inline GaussianTerm term(double c, double a1, double a2, double width_cells) {
    const double l = -0.5 / (width_cells * width_cells);
    return GaussianTerm{c, l, a1, l, a2};
}

}  // namespace fill_test
