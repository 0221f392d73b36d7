/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/img/CImage.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "multibin/sensors/SensorModelOptions.h"

namespace multibin::sensors {

/** Disparity of the left image [px], NaN where unknown. */
struct DisparityImage {
    int width = 0, height = 0;
    std::vector<float> disparity_px;  //!< row-major, width * height

    DisparityImage() = default;
    DisparityImage(int w, int h);
    float at(int u, int v) const { return disparity_px[size_t(v) * size_t(width) + size_t(u)]; }
    float& at(int u, int v) { return disparity_px[size_t(v) * size_t(width) + size_t(u)]; }
    bool valid(int u, int v) const { return std::isfinite(at(u, v)); }
    size_t validCount() const;
};

/** The project's disparity image format (mrpt::obs::CObservationStereoImages::imageDisparity,
 * whose scale MRPT leaves undefined): one channel of 16-bit unsigned integers (CV_16U), value =
 * disparity [px] * 16, 0 = invalid: OpenCV StereoSGBM's fixed-point output clamped to >= 0.
 * Throws std::invalid_argument if the image is not single-channel 16-bit. */
DisparityImage decodeDisparityImage(const mrpt::img::CImage& image16);
/** The inverse of decodeDisparityImage() (NaN and disparities <= 0 become 0). */
mrpt::img::CImage encodeDisparityImage(const DisparityImage& disparity);

/** Disparity of a rectified pair (8-bit grey or colour, converted to grey) with OpenCV StereoSGBM
 * and the `stereo_sgbm_*` options. Throws std::invalid_argument if the images are empty or of
 * different sizes. */
DisparityImage computeDisparitySGBM(const mrpt::img::CImage& left, const mrpt::img::CImage& right,
                                    const StereoModelOptions& opts);

/** Halo filter: invalidates every pixel whose disparity exceeds the smallest valid disparity within
 * opts.halo.radius_px (square window) by more than opts.halo.jump_px, i.e. the near side of a depth
 * boundary, where block matching stretches the foreground over the background. Returns the number
 * of pixels removed. */
size_t removeHalos(DisparityImage& disparity, const StereoModelOptions& opts);

/** Near-cluster filter: 4-connected regions whose neighbouring disparities differ by at most
 * opts.nearCluster.step_px, smaller than opts.nearCluster.maxArea_px, are invalidated when their
 * mean disparity exceeds the median disparity of the valid pixels around them by more than
 * opts.nearCluster.jump_px (a group of points floating in front of the scene: textureless areas,
 * out-of-horopter matches), or when no valid pixel surrounds them. Returns the number of pixels
 * removed. */
size_t removeNearClusters(DisparityImage& disparity, const StereoModelOptions& opts);

/** Texture filter for disparities computed by SGBM from `left` (8-bit grey or colour): invalidates
 * every pixel whose grey standard deviation over the (2 opts.texture.radius_px + 1)^2 window of
 * the left image is below opts.texture.minStd_grey. Such a pixel has no match of its own; SGBM's
 * smoothness term carries a neighbour's disparity into it. Returns the number of pixels removed
 * (none if opts.texture.minStd_grey is 0). Throws std::invalid_argument if the sizes differ. */
size_t removeTextureless(DisparityImage& disparity, const mrpt::img::CImage& left,
                         const StereoModelOptions& opts);

}  // namespace multibin::sensors
