/* Part of the multibin elevation-mapping library: terrain-sim. */
#pragma once

#include "Terrain.h"

#include <cstdint>
#include <vector>

namespace terrain_sim {

/** Deterministic procedural albedo of the terrain surface, in [0, 1].
 *
 * - Boards (tiles): multi-octave value noise (lattice 6, 12, 24, 48 mm) between about 0.25 and
 *   0.85, with a per-tile tint; well textured for stereo matching.
 * - Dark patches (black paint) on the boards: discs of albedo 0.03, radius 3-6 cm; the laser
 *   sees them with low intensity (dropouts, eq 1 rejection).
 * - Flat ground: uniform grey 0.5 with +-0.4 % variation, i.e. textureless for stereo.
 * Everything is a pure function of the seed and (x, y). */
class SurfaceTexture {
public:
    struct Disc {
        double x_m, y_m, radius_m;
    };
    SurfaceTexture(const Terrain& terrain, uint64_t seed, int darkPatches);

    double albedo(double x_m, double y_m) const;
    /** On black paint (only on the boards). */
    bool isDark(double x_m, double y_m) const;
    const std::vector<Disc>& darkPatches() const { return dark_; }

    static constexpr double kDarkAlbedo = 0.03;

private:
    double valueNoise(double x_m, double y_m, double scale_m, uint64_t octave) const;
    const Terrain* terrain_;
    uint64_t seed_;
    std::vector<Disc> dark_;
    std::vector<double> tint_;  // per surface id
};

/** splitmix64: a fast, well-mixed 64-bit hash (deterministic across platforms). */
uint64_t hash64(uint64_t x);

}  // namespace terrain_sim
