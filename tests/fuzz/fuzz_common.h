/* Helpers shared by the libFuzzer targets: a byte reader and the map invariants every target
 * checks after each input (see doc/reliability.md). */
#pragma once

#include <mrpt/io/CMemoryStream.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/serialization/CArchive.h>

#include "multibin/io/ErrorMessage.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>
#include "multibin/grid/BinGrid.h"
#include "multibin/map/MapInternals.h"

namespace fuzz {

/** Takes little-endian values off the front of the input; zeros once it runs out. */
class ByteReader {
public:
    ByteReader(const uint8_t* data, size_t size) : m_data(data), m_size(size) {}
    size_t remaining() const { return m_size - m_pos; }
    template <typename T>
    T take() {
        T v{};
        const size_t n = std::min(sizeof(T), remaining());
        std::memcpy(&v, m_data + m_pos, n);
        m_pos += n;
        return v;
    }
    /** An integer in [lo, hi]. */
    int takeInt(int lo, int hi) { return lo + int(take<uint16_t>() % uint32_t(hi - lo + 1)); }
    /** Any float bit pattern (NaN, inf, denormals included) when `raw`, else one in [lo, hi]. */
    float takeFloat(float lo, float hi, bool raw) {
        if (raw) return take<float>();
        return lo + (hi - lo) * float(take<uint16_t>()) / 65535.f;
    }

private:
    const uint8_t* m_data;
    size_t m_size;
    size_t m_pos = 0;
};

/** With FUZZ_DEBUG set, prints why an input was rejected (for corpus maintenance). */
inline void debugRejected(const std::exception& e) {
    static const bool on = std::getenv("FUZZ_DEBUG") != nullptr;
    if (on) std::fprintf(stderr, "rejected: %s\n", multibin::oneLineMessage(e).c_str());
}

[[noreturn]] inline void fail(const char* what) {
    std::fprintf(stderr, "fuzz invariant violated: %s\n", what);
    std::abort();
}

/** The map's bytes as CArchive writes them (for "unchanged by a rejected input"). */
inline std::vector<uint8_t> serialize(const mrpt::maps::CMultiBinElevationMap& map) {
    mrpt::io::CMemoryStream mem;
    auto arch = mrpt::serialization::archiveFrom(mem);
    arch << map;
    const auto* p = static_cast<const uint8_t*>(mem.getRawBufferData());
    return std::vector<uint8_t>(p, p + mem.getTotalBytesCount());
}

/** Every bin of both grids: finite height, finite variance >= 0, certainty >= 0, and the winning
 * bin's sigma (what getHeight() reports) finite and >= 0. */
inline void checkInvariants(const mrpt::maps::CMultiBinElevationMap& map) {
    // Over the stored bins, tile by tile: a window grown by a far pose is mostly empty.
    for (const multibin::BinGrid* g :
         {&multibin::MapInternals::grid(map), &multibin::MapInternals::localGrid(map)})
        g->store().forEachStoredBin([&](int ix, int iy, const multibin::Bin& b) {
            if (!g->window().contains(ix, iy)) fail("bin outside the window");
            if (!std::isfinite(b.height_m)) fail("bin height not finite");
            if (!(b.variance_m2 >= 0) || !std::isfinite(b.variance_m2))
                fail("bin variance negative or not finite");
            if (!(b.certainty >= 0) || !std::isfinite(b.certainty))
                fail("bin certainty negative or not finite");
        });
}

}  // namespace fuzz
