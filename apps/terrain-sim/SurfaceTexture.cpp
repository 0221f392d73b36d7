/* Part of the multibin elevation-mapping library: terrain-sim. */
#include "SurfaceTexture.h"

#include <algorithm>
#include <cmath>

namespace terrain_sim {

uint64_t hash64(uint64_t x) {
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
}

namespace {
/** Uniform in [0, 1) from a hash. */
double unit(uint64_t h) { return (h >> 11) * (1.0 / 9007199254740992.0); }
}  // namespace

SurfaceTexture::SurfaceTexture(const Terrain& terrain, uint64_t seed, int darkPatches)
    : terrain_(&terrain), seed_(hash64(seed ^ 0x7e47u)) {
    tint_.resize(terrain.surfaceCount());
    for (size_t s = 0; s < tint_.size(); ++s) tint_[s] = 0.8 + 0.3 * unit(hash64(seed_ + 101 * s));
    const double L = terrain.tileSide_m();
    for (int k = 0; k < darkPatches && terrain.tilesX() > 0; ++k) {
        const uint64_t h = hash64(seed_ + 7919 * (k + 1));
        Disc d;
        d.x_m = unit(h) * terrain.tilesX() * L;
        d.y_m = (unit(hash64(h)) - 0.5) * terrain.tilesY() * L;
        d.radius_m = 0.03 + 0.03 * unit(hash64(h + 1));
        dark_.push_back(d);
    }
}

double SurfaceTexture::valueNoise(double x_m, double y_m, double scale_m, uint64_t octave) const {
    const double fx = x_m / scale_m, fy = y_m / scale_m;
    const double ix = std::floor(fx), iy = std::floor(fy);
    double u = fx - ix, v = fy - iy;
    u = u * u * (3 - 2 * u);  // smoothstep: continuous gradient, no lattice creases
    v = v * v * (3 - 2 * v);
    auto at = [&](double a, double b) {
        const uint64_t key = (static_cast<uint64_t>(static_cast<int64_t>(a)) * 0x1f1f1f1fULL) ^
                             (static_cast<uint64_t>(static_cast<int64_t>(b)) * 0x9e3779b1ULL);
        return unit(hash64(seed_ ^ hash64(key + 0x51ed27u * octave)));
    };
    return (1 - u) * (1 - v) * at(ix, iy) + u * (1 - v) * at(ix + 1, iy) +
           (1 - u) * v * at(ix, iy + 1) + u * v * at(ix + 1, iy + 1);
}

bool SurfaceTexture::isDark(double x_m, double y_m) const {
    if (terrain_->surfaceId(x_m, y_m) == 0) return false;  // paint only on the boards
    for (const auto& d : dark_) {
        const double dx = x_m - d.x_m, dy = y_m - d.y_m;
        if (dx * dx + dy * dy <= d.radius_m * d.radius_m) return true;
    }
    return false;
}

double SurfaceTexture::albedo(double x_m, double y_m) const {
    const int s = terrain_->surfaceId(x_m, y_m);
    if (s == 0) return 0.5 + 0.004 * (2 * valueNoise(x_m, y_m, 0.02, 9) - 1);
    if (isDark(x_m, y_m)) return kDarkAlbedo;
    const double n = 0.4 * valueNoise(x_m, y_m, 0.006, 1) + 0.3 * valueNoise(x_m, y_m, 0.012, 2) +
                     0.2 * valueNoise(x_m, y_m, 0.024, 3) + 0.1 * valueNoise(x_m, y_m, 0.048, 4);
    // n concentrates around 0.5 (sum of octaves): stretch to use the range.
    const double a = 0.55 + 1.3 * (n - 0.5);
    return std::clamp(tint_[s] * a, 0.2, 0.95);
}

}  // namespace terrain_sim
