/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace multibin {

/** Whether any of v[0, n) is finite: the bits of std::isfinite, in one loop without a branch
 * or a comparison (which the compiler vectorises). */
inline bool anyFinite(const float* v, size_t n) {
    constexpr uint32_t kExponent = 0x7f800000u;  // all ones: infinite or NaN
    uint32_t finiteBits = 0;                      // non-zero once an exponent is not all ones
    for (size_t i = 0; i < n; i++) {
        uint32_t bits;
        std::memcpy(&bits, v + i, sizeof bits);
        finiteBits |= (bits & kExponent) ^ kExponent;
    }
    return finiteBits != 0;
}

/** Calls f(i) for every finite v[i], i ascending. A raster of a sparse map is mostly unknown
 * (NaN): a block of 32 samples without a finite one costs one vectorised test. */
template <typename F>
void forEachFinite(const float* v, size_t n, F&& f) {
    constexpr size_t kBlock = 32;
    size_t i = 0;
    for (; i + kBlock <= n; i += kBlock) {
        if (!anyFinite(v + i, kBlock)) continue;
        for (size_t k = i; k < i + kBlock; k++)
            if (std::isfinite(v[k])) f(k);
    }
    for (; i < n; i++)
        if (std::isfinite(v[i])) f(i);
}

}  // namespace multibin
