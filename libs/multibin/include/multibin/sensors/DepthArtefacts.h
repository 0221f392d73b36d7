/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "multibin/sensors/SensorModelOptions.h"

namespace multibin::sensors {

/** What a pixel of a depth frame is to the artefact filter. */
enum class DepthPixel : uint8_t {
    Keep = 0,
    FlyingPixel = 1,  //!< at a depth jump: between foreground and background, or their mixed rim
    FrameBorder = 2,  //!< within depth_border_px of the image's edge
};

/** The artefacts of one depth frame, `depth_m` row-major (rows x cols), 0 where there is no
 * return (as the laser's mixed pixels and stereo's halos, removed before the points are made):
 * - flying pixels: every pixel within flyingPixel.radius_px of a jump between two 4-neighbours
 *   larger than flyingPixel.jumpRelative x the nearer depth (a structured-light or time-of-flight
 *   camera returns depths between the two surfaces there);
 * - the frame's border: pixels within borderWidth_px of the image's edge (lens distortion and
 *   the projector's pattern are least reliable there).
 * The border wins where both apply. Empty `depth_m` or a filter turned off marks nothing. */
std::vector<DepthPixel> depthArtefacts(const std::vector<float>& depth_m, int rows, int cols,
                                       const DepthModelOptions& opts);

}  // namespace multibin::sensors
