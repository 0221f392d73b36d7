/* Part of the multibin elevation-mapping library: terrain-sim. */
#include "StereoSim.h"

#include <mrpt/poses/CPose3DQuat.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace terrain_sim {

mrpt::poses::CPose3D StereoConfig::leftPose() const {
    const double c = std::cos(pitch_rad), s = std::sin(pitch_rad);
    // Columns: camera x (right = robot -y), y (down and back), z (forward and down).
    mrpt::math::CMatrixDouble33 R;
    R(0, 0) = 0, R(0, 1) = -s, R(0, 2) = c;
    R(1, 0) = -1, R(1, 1) = 0, R(1, 2) = 0;
    R(2, 0) = 0, R(2, 1) = -c, R(2, 2) = -s;
    mrpt::math::CVectorFixedDouble<3> t;
    t[0] = forward_m, t[1] = 0.5 * baseline_m, t[2] = height_m;
    return mrpt::poses::CPose3D(R, t);
}

StereoSim::StereoSim(const StereoConfig& cfg, const Terrain& terrain, const SurfaceTexture& texture)
    : cfg_(cfg), terrain_(&terrain), texture_(&texture) {}

double StereoSim::shade(const Eigen::Vector3d& p, const Eigen::Vector3d& n) const {
    static const Eigen::Vector3d light = Eigen::Vector3d(0.3, 0.2, 1.0).normalized();
    return 255.0 * texture_->albedo(p.x(), p.y()) * (0.35 + 0.65 * std::max(0.0, n.dot(light)));
}

void StereoSim::renderView(const mrpt::poses::CPose3D& cam, double rowError_px, cv::Mat& grey,
                           cv::Mat& zcam) const {
    const int W = cfg_.width_px, H = cfg_.height_px;
    // The true principal point (the observation keeps the nominal one).
    const double f = cfg_.fx_px(), cx = cfg_.cx_px() + cfg_.cxError_px,
                 cy = cfg_.cy_px() + cfg_.cyError_px + rowError_px;
    grey.create(H, W, CV_64F);
    zcam.create(H, W, CV_64F);
    const Eigen::Matrix3d R = cam.getRotationMatrix().asEigen();
    const Eigen::Vector3d o(cam.x(), cam.y(), cam.z());
    for (int v = 0; v < H; ++v)
        for (int u = 0; u < W; ++u) {
            const Eigen::Vector3d dc = Eigen::Vector3d((u - cx) / f, (v - cy) / f, 1.0);
            const double len = dc.norm();
            const Eigen::Vector3d d = R * (dc / len);
            const double t = terrain_->castRay(o, d, 20.0);
            if (!std::isfinite(t)) {
                grey.at<double>(v, u) = 230.0;  // featureless sky / far wall
                zcam.at<double>(v, u) = 0.0;
                continue;
            }
            const Eigen::Vector3d p = o + t * d;
            grey.at<double>(v, u) = shade(p, terrain_->normal(p.x(), p.y()));
            zcam.at<double>(v, u) = t / len;
        }
}

StereoRender StereoSim::render(const mrpt::poses::CPose3D& robot, std::mt19937_64& rng) const {
    const mrpt::poses::CPose3D left = robot + cfg_.leftPose();
    const double trueBaseline_m = cfg_.baseline_m + cfg_.baselineError_m;
    const mrpt::poses::CPose3D right = left + mrpt::poses::CPose3D(trueBaseline_m, 0, 0, 0, 0, 0);
    cv::Mat gl, zl, gr, zr;
    renderView(left, 0.0, gl, zl);
    renderView(right, cfg_.rightRowError_px, gr, zr);
    const int W = cfg_.width_px, H = cfg_.height_px;
    std::normal_distribution<double> gauss(0.0, 1.0);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    StereoRender out;
    out.left.create(H, W, CV_8U);
    out.right.create(H, W, CV_8U);
    for (int v = 0; v < H; ++v)
        for (int u = 0; u < W; ++u) {
            const double a = gl.at<double>(v, u) + cfg_.pixelNoise_grey * gauss(rng);
            const double b =
                cfg_.rightGain * gr.at<double>(v, u) + cfg_.pixelNoise_grey * gauss(rng);
            out.left.at<uint8_t>(v, u) = cv::saturate_cast<uint8_t>(std::lround(a));
            out.right.at<uint8_t>(v, u) = cv::saturate_cast<uint8_t>(std::lround(b));
        }
    const double fB = cfg_.fx_px() * trueBaseline_m;
    out.trueDisparity.create(H, W, CV_32F);
    for (int v = 0; v < H; ++v)
        for (int u = 0; u < W; ++u) {
            const double z = zl.at<double>(v, u);
            out.trueDisparity.at<float>(v, u) = z > 0 ? static_cast<float>(fB / z) : 0.f;
        }
    if (!cfg_.disparity) return out;

    // STOC-style disparity: the truth with matching noise, foreground fattening at depth edges,
    // no match in textureless areas except for a few near-camera blobs, none at the left border.
    cv::Mat img, mean, sq;
    out.left.convertTo(img, CV_64F);
    cv::boxFilter(img, mean, CV_64F, cv::Size(7, 7));
    cv::boxFilter(img.mul(img), sq, CV_64F, cv::Size(7, 7));
    cv::Mat textureless(H, W, CV_8U);
    for (int v = 0; v < H; ++v)
        for (int u = 0; u < W; ++u) {
            const double m = mean.at<double>(v, u);
            const double var = std::max(0.0, sq.at<double>(v, u) - m * m);
            textureless.at<uint8_t>(v, u) = std::sqrt(var) < cfg_.texturelessStd_grey;
        }
    cv::Mat d(H, W, CV_64F, cv::Scalar(0));
    out.matchKind = cv::Mat(H, W, CV_8U, cv::Scalar(StereoRender::kNone));
    const cv::Mat& dt = out.trueDisparity;
    for (int v = 0; v < H; ++v)
        for (int u = 0; u < W; ++u) {
            // Optional errors draw from the stream only when on, so matched runs keep their bytes.
            const double noise = cfg_.errors.drawnErrorScale * cfg_.matchingSigma_px * gauss(rng) *
                                 cfg_.errors.tailFactor(rng);
            const double d0 = dt.at<float>(v, u);
            if (d0 <= 0 || textureless.at<uint8_t>(v, u)) continue;
            double dmax = d0;
            for (int k = std::max(0, u - cfg_.haloWidth_px);
                 k <= std::min(W - 1, u + cfg_.haloWidth_px); ++k)
                dmax = std::max(dmax, double(dt.at<float>(v, k)));
            const bool halo = dmax - d0 > cfg_.haloJump_px;
            d.at<double>(v, u) = (halo ? dmax : d0) + noise;
            auto& kind = out.matchKind.at<uint8_t>(v, u);
            kind = halo ? StereoRender::kHalo : StereoRender::kNoise;
            if (cfg_.mixedProbability > 0) {
                // The 4-neighbour with the largest true-disparity jump, if it makes an edge.
                double dn = d0;
                const int nb[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
                for (const auto& o : nb) {
                    const int uu = u + o[0], vv = v + o[1];
                    if (uu < 0 || uu >= W || vv < 0 || vv >= H) continue;
                    const double x = dt.at<float>(vv, uu);
                    if (x > 0 && std::abs(x - d0) > std::abs(dn - d0)) dn = x;
                }
                const double pick = uni(rng), w = uni(rng);
                if (std::abs(dn - d0) > cfg_.haloJump_px && pick < cfg_.mixedProbability) {
                    d.at<double>(v, u) = d0 + w * (dn - d0) + noise;
                    kind = StereoRender::kMixed;
                }
            }
            double factor = 1.0;
            if (cfg_.errors.drawOutlier(rng, factor)) {
                d.at<double>(v, u) = d0 * factor;
                kind = StereoRender::kOutlier;
            }
        }
    for (int b = 0; b < cfg_.blobsPerFrame; ++b) {
        const int uc = static_cast<int>(uni(rng) * W),
                  vc = H / 2 + static_cast<int>(uni(rng) * (H / 2));
        const double radius = 4 + 6 * uni(rng), factor = 1.3 + 0.5 * uni(rng);
        if (!textureless.at<uint8_t>(vc, uc) || dt.at<float>(vc, uc) <= 0) continue;
        const double db = dt.at<float>(vc, uc) * factor;
        for (int v = std::max(0, int(vc - radius)); v <= std::min(H - 1, int(vc + radius)); ++v)
            for (int u = std::max(0, int(uc - radius)); u <= std::min(W - 1, int(uc + radius)); ++u)
                if ((u - uc) * (u - uc) + (v - vc) * (v - vc) <= radius * radius &&
                    textureless.at<uint8_t>(v, u)) {
                    d.at<double>(v, u) = db;
                    out.matchKind.at<uint8_t>(v, u) = StereoRender::kBlob;
                }
    }
    out.disparity16.create(H, W, CV_16U);
    for (int v = 0; v < H; ++v)
        for (int u = 0; u < W; ++u) {
            const double x = d.at<double>(v, u);
            const bool ok = x > 0 && u - x >= 0;
            out.disparity16.at<uint16_t>(v, u) =
                ok ? cv::saturate_cast<uint16_t>(std::lround(16.0 * x)) : 0;
        }
    return out;
}

mrpt::obs::CObservationStereoImages::Ptr StereoSim::observation(
    const StereoRender& r, mrpt::Clock::time_point stamp) const {
    auto obs = mrpt::obs::CObservationStereoImages::Create();
    obs->sensorLabel = cfg_.label;
    obs->timestamp = stamp;
    obs->imageLeft = mrpt::img::CImage(r.left.clone(), mrpt::img::DEEP_COPY);
    obs->imageRight = mrpt::img::CImage(r.right.clone(), mrpt::img::DEEP_COPY);
    obs->hasImageRight = true;
    if (cfg_.disparity && !r.disparity16.empty()) {
        obs->imageDisparity = mrpt::img::CImage(r.disparity16.clone(), mrpt::img::DEEP_COPY);
        obs->hasImageDisparity = true;
    }
    mrpt::img::TCamera cam;
    cam.ncols = cfg_.width_px;
    cam.nrows = cfg_.height_px;
    cam.setIntrinsicParamsFromValues(cfg_.fx_px(), cfg_.fx_px(), cfg_.cx_px(), cfg_.cy_px());
    cam.dist.fill(0.0);
    obs->leftCamera = cam;
    obs->rightCamera = cam;
    obs->rightCameraPose =
        mrpt::poses::CPose3DQuat(mrpt::poses::CPose3D(cfg_.baseline_m, 0, 0, 0, 0, 0));
    obs->cameraPose = mrpt::poses::CPose3DQuat(cfg_.leftPose());
    return obs;
}

}  // namespace terrain_sim
