/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/StereoDisparity.h"

#include <algorithm>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace multibin::sensors {

DisparityImage::DisparityImage(int w, int h)
    : width(w),
      height(h),
      disparity_px(size_t(w) * size_t(h), std::numeric_limits<float>::quiet_NaN()) {}

size_t DisparityImage::validCount() const {
    return size_t(std::count_if(disparity_px.begin(), disparity_px.end(),
                                [](float d) { return std::isfinite(d); }));
}

DisparityImage decodeDisparityImage(const mrpt::img::CImage& image16) {
    const cv::Mat& m = image16.asCvMatRef();
    if (m.empty() || m.type() != CV_16UC1)
        throw std::invalid_argument(
            "CObservationStereoImages::imageDisparity: expected a single-channel 16-bit image "
            "(disparity * 16, 0 = invalid)");
    DisparityImage out(m.cols, m.rows);
    for (int v = 0; v < m.rows; v++) {
        const uint16_t* row = m.ptr<uint16_t>(v);
        for (int u = 0; u < m.cols; u++)
            if (row[u] > 0) out.at(u, v) = float(row[u]) / 16.f;
    }
    return out;
}

mrpt::img::CImage encodeDisparityImage(const DisparityImage& d) {
    cv::Mat m(d.height, d.width, CV_16UC1, cv::Scalar(0));
    for (int v = 0; v < d.height; v++)
        for (int u = 0; u < d.width; u++) {
            const float x = d.at(u, v);
            if (std::isfinite(x) && x > 0)
                m.at<uint16_t>(v, u) = uint16_t(std::min(65535.f, std::round(x * 16.f)));
        }
    return mrpt::img::CImage(m, mrpt::img::DEEP_COPY);
}

DisparityImage computeDisparitySGBM(const mrpt::img::CImage& left, const mrpt::img::CImage& right,
                                    const StereoModelOptions& o) {
    const cv::Mat& l = left.asCvMatRef();
    const cv::Mat& r = right.asCvMatRef();
    if (l.empty() || r.empty())
        throw std::invalid_argument("CObservationStereoImages: left or right image is empty");
    if (l.size() != r.size())
        throw std::invalid_argument(
            "CObservationStereoImages: left and right images differ in size");
    cv::Mat lg = l, rg = r;
    if (l.channels() == 3) cv::cvtColor(l, lg, cv::COLOR_BGR2GRAY);
    if (r.channels() == 3) cv::cvtColor(r, rg, cv::COLOR_BGR2GRAY);
    const int area = o.sgbmBlockSize * o.sgbmBlockSize;
    int mode = cv::StereoSGBM::MODE_SGBM;
    if (o.sgbmMode == "hh") mode = cv::StereoSGBM::MODE_HH;
    if (o.sgbmMode == "sgbm_3way") mode = cv::StereoSGBM::MODE_SGBM_3WAY;
    if (o.sgbmMode == "hh4") mode = cv::StereoSGBM::MODE_HH4;
    auto sgbm = cv::StereoSGBM::create(o.sgbmMinDisparity, o.numDisparitiesFor(lg.cols),
                                       o.sgbmBlockSize, o.sgbmP1 > 0 ? o.sgbmP1 : 8 * area,
                                       o.sgbmP2 > 0 ? o.sgbmP2 : 32 * area, o.sgbmDisp12MaxDiff, 0,
                                       o.sgbmUniquenessRatio, o.sgbmSpeckleWindowSize,
                                       o.sgbmSpeckleRange, mode);
    cv::Mat disp16;
    sgbm->compute(lg, rg, disp16);  // CV_16S, disparity * 16, < minDisparity * 16 = invalid
    DisparityImage out(disp16.cols, disp16.rows);
    const int invalidBelow = o.sgbmMinDisparity * 16;
    for (int v = 0; v < disp16.rows; v++) {
        const int16_t* row = disp16.ptr<int16_t>(v);
        for (int u = 0; u < disp16.cols; u++)
            if (row[u] >= invalidBelow && row[u] > 0) out.at(u, v) = float(row[u]) / 16.f;
    }
    return out;
}

size_t removeHalos(DisparityImage& d, const StereoModelOptions& o) {
    // Smallest valid disparity in the window: erosion with invalid pixels set to +large.
    cv::Mat m(d.height, d.width, CV_32F);
    for (int v = 0; v < d.height; v++)
        for (int u = 0; u < d.width; u++) m.at<float>(v, u) = d.valid(u, v) ? d.at(u, v) : 1e9f;
    cv::Mat minWin;
    const int k = 2 * o.haloRadius_px + 1;
    cv::erode(m, minWin, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(k, k)));
    size_t removed = 0;
    for (int v = 0; v < d.height; v++)
        for (int u = 0; u < d.width; u++)
            if (d.valid(u, v) && d.at(u, v) - minWin.at<float>(v, u) > o.haloJump_px) {
                d.at(u, v) = std::numeric_limits<float>::quiet_NaN();
                removed++;
            }
    return removed;
}

size_t removeNearClusters(DisparityImage& d, const StereoModelOptions& o) {
    const int W = d.width, H = d.height;
    std::vector<int32_t> label(size_t(W) * size_t(H), -1);
    std::vector<int> stack, members;
    std::vector<float> around;
    std::vector<int32_t> aroundSeen;  // pixel -> component that last counted it as surrounding
    aroundSeen.assign(label.size(), -1);
    size_t removed = 0;
    int32_t next = 0;
    const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
    for (int start = 0; start < W * H; start++) {
        if (label[size_t(start)] >= 0 || !std::isfinite(d.disparity_px[size_t(start)])) continue;
        const int32_t id = next++;
        stack.assign(1, start);
        members.clear();
        around.clear();
        label[size_t(start)] = id;
        double sum = 0;
        bool small = true;
        while (!stack.empty()) {
            const int p = stack.back();
            stack.pop_back();
            members.push_back(p);
            const float dp = d.disparity_px[size_t(p)];
            sum += dp;
            const int u = p % W, v = p / W;
            for (int k = 0; k < 4; k++) {
                const int uu = u + du[k], vv = v + dv[k];
                if (uu < 0 || vv < 0 || uu >= W || vv >= H) continue;
                const int q = vv * W + uu;
                const float dq = d.disparity_px[size_t(q)];
                if (!std::isfinite(dq)) continue;
                if (std::abs(dq - dp) <= o.nearClusterStep_px) {
                    if (label[size_t(q)] < 0) {
                        label[size_t(q)] = id;
                        stack.push_back(q);
                    }
                } else if (small && aroundSeen[size_t(q)] != id) {
                    aroundSeen[size_t(q)] = id;
                    around.push_back(dq);
                }
            }
            // Keep labelling a large region (so it is visited once) but stop collecting.
            if (small && int(members.size()) >= o.nearClusterMaxArea_px) small = false;
        }
        if (!small) continue;
        bool remove = around.empty();
        if (!remove) {
            std::nth_element(around.begin(), around.begin() + long(around.size() / 2),
                             around.end());
            const double median = around[around.size() / 2];
            remove = sum / double(members.size()) > median + o.nearClusterJump_px;
        }
        if (remove) {
            for (int p : members)
                d.disparity_px[size_t(p)] = std::numeric_limits<float>::quiet_NaN();
            removed += members.size();
        }
    }
    return removed;
}

}  // namespace multibin::sensors
