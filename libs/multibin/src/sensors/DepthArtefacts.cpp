/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/DepthArtefacts.h"

#include <algorithm>
#include <cmath>

namespace multibin::sensors {

namespace {
/** A jump between two returns: both valid and apart by more than `relative` x the nearer. */
bool jumps(float a_m, float b_m, double relative) {
    return a_m > 0 && b_m > 0 && std::abs(a_m - b_m) > relative * std::min(a_m, b_m);
}
}  // namespace

std::vector<DepthPixel> depthArtefacts(const std::vector<float>& depth_m, int rows, int cols,
                                       const DepthModelOptions& opts) {
    std::vector<DepthPixel> out(depth_m.size(), DepthPixel::Keep);
    if (rows <= 0 || cols <= 0 || depth_m.size() != size_t(rows) * size_t(cols)) return out;
    auto at = [&](int r, int c) { return size_t(r) * size_t(cols) + size_t(c); };
    const int b = opts.borderWidth_px;
    auto inBorder = [&](int r, int c) { return r < b || c < b || r >= rows - b || c >= cols - b; };
    if (opts.flyingPixel.enabled) {
        // The border goes first: its depths do not make jumps with the pixels inside it.
        auto isJump = [&](int r0, int c0, int r1, int c1) {
            return !inBorder(r0, c0) && !inBorder(r1, c1) &&
                   jumps(depth_m[at(r0, c0)], depth_m[at(r1, c1)], opts.flyingPixel.jumpRelative);
        };
        // Pixels on either side of a jump, then grown by the radius (a square window).
        std::vector<uint8_t> onJump(depth_m.size(), 0);
        for (int r = 0; r < rows; r++)
            for (int c = 0; c < cols; c++) {
                if (c + 1 < cols && isJump(r, c, r, c + 1))
                    onJump[at(r, c)] = onJump[at(r, c + 1)] = 1;
                if (r + 1 < rows && isJump(r, c, r + 1, c))
                    onJump[at(r, c)] = onJump[at(r + 1, c)] = 1;
            }
        const int k = std::max(0, opts.flyingPixel.radius_px - 1);
        for (int r = 0; r < rows; r++)
            for (int c = 0; c < cols; c++) {
                if (!onJump[at(r, c)]) continue;
                for (int rr = std::max(0, r - k); rr <= std::min(rows - 1, r + k); rr++)
                    for (int cc = std::max(0, c - k); cc <= std::min(cols - 1, c + k); cc++)
                        if (depth_m[at(rr, cc)] > 0) out[at(rr, cc)] = DepthPixel::FlyingPixel;
            }
    }
    for (int r = 0; r < rows; r++)
        for (int c = 0; c < cols; c++)
            if (inBorder(r, c) && depth_m[at(r, c)] > 0) out[at(r, c)] = DepthPixel::FrameBorder;
    return out;
}

}  // namespace multibin::sensors
