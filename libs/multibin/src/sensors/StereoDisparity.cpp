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
    const int W = m.cols, H = m.rows;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (int v = 0; v < H; v++) {
        const uint16_t* __restrict row = m.ptr<uint16_t>(v);
        float* __restrict o = out.disparity_px.data() + size_t(v) * size_t(W);
        // Branch-free, so the loop vectorises: / 16 is exact, and 0 becomes NaN.
        for (int u = 0; u < W; u++) {
            const int32_t d = row[u];
            o[u] = float(d) * 0.0625f + (d == 0 ? nan : 0.f);
        }
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
    // OpenCV gives no disparity to the leftmost minDisparity + numDisparities columns (a quarter
    // of the image by default), where part of the search range lies left of the right image.
    const int pad =
        o.sgbmFullWidth ? std::max(0, o.sgbmMinDisparity + sgbm->getNumDisparities()) : 0;
    if (pad > 0) {
        cv::Mat lp, rp, dp;
        cv::copyMakeBorder(lg, lp, 0, 0, pad, 0, cv::BORDER_REPLICATE);
        cv::copyMakeBorder(rg, rp, 0, 0, pad, 0, cv::BORDER_REPLICATE);
        sgbm->compute(lp, rp, dp);
        disp16 = dp(cv::Rect(pad, 0, lg.cols, lg.rows));
    } else {
        sgbm->compute(lg, rg, disp16);  // CV_16S, disparity * 16, < minDisparity * 16 = invalid
    }
    DisparityImage out(disp16.cols, disp16.rows);
    const int invalidBelow = o.sgbmMinDisparity * 16;
    for (int v = 0; v < disp16.rows; v++) {
        const int16_t* row = disp16.ptr<int16_t>(v);
        for (int u = 0; u < disp16.cols; u++)
            // With padding, a match in the padding (right pixel u - d < 0) is no match.
            if (row[u] >= invalidBelow && row[u] > 0 && (pad == 0 || row[u] <= 16 * u))
                out.at(u, v) = float(row[u]) / 16.f;
    }
    return out;
}

size_t removeTextureless(DisparityImage& d, const mrpt::img::CImage& left,
                         const StereoModelOptions& o) {
    if (o.texture.minStd_grey <= 0) return 0;
    const cv::Mat& l = left.asCvMatRef();
    if (l.cols != d.width || l.rows != d.height)
        throw std::invalid_argument(
            "removeTextureless: left image and disparity image differ in size");
    cv::Mat grey = l, g, g2, mean, mean2;
    if (l.channels() == 3) cv::cvtColor(l, grey, cv::COLOR_BGR2GRAY);
    grey.convertTo(g, CV_32F);
    g2 = g.mul(g);
    const int k = 2 * o.texture.radius_px + 1;
    cv::boxFilter(g, mean, CV_32F, cv::Size(k, k));
    cv::boxFilter(g2, mean2, CV_32F, cv::Size(k, k));
    const float minVar = float(o.texture.minStd_grey * o.texture.minStd_grey);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    size_t removed = 0;
    for (int v = 0; v < d.height; v++) {
        float* row = d.disparity_px.data() + size_t(v) * size_t(d.width);
        const float* m = mean.ptr<float>(v);
        const float* m2 = mean2.ptr<float>(v);
        for (int u = 0; u < d.width; u++) {
            const bool flat = std::isfinite(row[u]) && (m2[u] - m[u] * m[u] < minVar);
            removed += flat;
            row[u] = flat ? nan : row[u];
        }
    }
    return removed;
}

size_t removeHalos(DisparityImage& d, const StereoModelOptions& o) {
    // Smallest valid disparity in the window: erosion with invalid pixels set to +large.
    cv::Mat m(d.height, d.width, CV_32F);
    for (int v = 0; v < d.height; v++) {
        const float* in = d.disparity_px.data() + size_t(v) * size_t(d.width);
        float* row = m.ptr<float>(v);
        for (int u = 0; u < d.width; u++) row[u] = std::isfinite(in[u]) ? in[u] : 1e9f;
    }
    cv::Mat minWin;
    const int k = 2 * o.halo.radius_px + 1;
    cv::erode(m, minWin, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(k, k)));
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const double jump = o.halo.jump_px;
    size_t removed = 0;
    for (int v = 0; v < d.height; v++) {
        float* row = d.disparity_px.data() + size_t(v) * size_t(d.width);
        const float* mins = minWin.ptr<float>(v);
        size_t rowRemoved = 0;  // branch-free, so the loop vectorises
        for (int u = 0; u < d.width; u++) {
            const bool halo = std::isfinite(row[u]) & (row[u] - mins[u] > jump);
            row[u] = halo ? nan : row[u];
            rowRemoved += halo;
        }
        removed += rowRemoved;
    }
    return removed;
}

namespace {
/** The near-cluster decision for one region, given one of its pixels: a flood fill of the region
 * (neighbour order +u, -u, +v, -v; depth first), collecting the distinct valid pixels across a
 * jump from its members; if the region has fewer than maxArea pixels and its mean disparity
 * exceeds their median by more than the jump (or nothing surrounds it), its pixels are
 * invalidated. Returns the number removed. `mark` (one entry per pixel, zero or older stamps)
 * holds, for the fill `id` (> 0), id * 4 + 1 (member) | 2 (counted around). */
size_t decideRegion(DisparityImage& d, const StereoModelOptions& o, int start, uint32_t id,
                    std::vector<uint32_t>& mark, std::vector<int>& stack, std::vector<int>& members,
                    std::vector<float>& around) {
    const int W = d.width, H = d.height;
    float* disp = d.disparity_px.data();
    const uint32_t tag = id << 2;
    auto flags = [&](int q) { return (mark[size_t(q)] >> 2) == id ? mark[size_t(q)] & 3u : 0u; };
    stack.assign(1, start);
    members.clear();
    around.clear();
    mark[size_t(start)] = tag | 1u;
    double sum = 0;
    bool small = true;
    const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
    while (!stack.empty()) {
        const int p = stack.back();
        stack.pop_back();
        members.push_back(p);
        const float dp = disp[p];
        sum += dp;
        const int u = p % W, v = p / W;
        for (int k = 0; k < 4; k++) {
            const int uu = u + du[k], vv = v + dv[k];
            if (uu < 0 || vv < 0 || uu >= W || vv >= H) continue;
            const int q = vv * W + uu;
            const float dq = disp[q];
            if (!std::isfinite(dq)) continue;
            const uint32_t f = flags(q);
            if (std::abs(dq - dp) <= o.nearCluster.step_px) {
                if (!(f & 1u)) {
                    mark[size_t(q)] = tag | f | 1u;
                    stack.push_back(q);
                }
            } else if (small && !(f & 2u)) {
                mark[size_t(q)] = tag | f | 2u;
                around.push_back(dq);
            }
        }
        if (small && int(members.size()) >= o.nearCluster.maxArea_px) small = false;
    }
    if (!small) return 0;
    bool remove = around.empty();
    if (!remove) {
        std::nth_element(around.begin(), around.begin() + long(around.size() / 2), around.end());
        const double median = around[around.size() / 2];
        remove = sum / double(members.size()) > median + o.nearCluster.jump_px;
    }
    if (!remove) return 0;
    for (int p : members) disp[p] = std::numeric_limits<float>::quiet_NaN();
    return members.size();
}

/** Union-find over row runs, the smaller index always the root (so a root is its region's first
 * run in raster order). */
int32_t findRoot(std::vector<int32_t>& parent, int32_t a) {
    while (parent[size_t(a)] != a) {
        parent[size_t(a)] = parent[size_t(parent[size_t(a)])];  // path halving
        a = parent[size_t(a)];
    }
    return a;
}
}  // namespace

size_t removeNearClusters(DisparityImage& d, const StereoModelOptions& o) {
    // Regions are found first without the flood fill: runs of horizontally connected pixels per
    // row, joined through their vertical connections by union-find; a region's size is the sum
    // of its runs. Only regions below the size limit are then filled one by one, in raster order
    // of their first pixel and on the image as the earlier removals left it, exactly as a flood
    // fill of every region in raster order decides (large regions are never removed and never
    // change another region's decision).
    const int W = d.width, H = d.height;
    if (W <= 0 || H <= 0) return 0;
    const float* disp = d.disparity_px.data();
    const double step = o.nearCluster.step_px;
    std::vector<int32_t> parent, length, first;  // per run: union-find parent, pixels, 1st pixel
    parent.reserve(size_t(H) * 16);
    length.reserve(size_t(H) * 16);
    first.reserve(size_t(H) * 16);
    std::vector<int32_t> runs2(2 * size_t(W), -1);  // run of each column: row above, this row
    int32_t* runAbove = runs2.data();  // raw pointers: not reloaded after each push_back
    int32_t* runHere = runAbove + W;
    for (int v = 0; v < H; v++) {
        const float* row = disp + size_t(v) * size_t(W);
        const float* above = row - W;
        int32_t run = -1, joinedRun = -1, joinedAbove = -1;
        int runStart = 0;  // the current run's first column; its length is set when it ends
        for (int u = 0; u < W; u++) {
            const float dp = row[u];
            if (!std::isfinite(dp)) {
                if (run >= 0) length[size_t(run)] = u - runStart;
                runHere[u] = run = -1;
                continue;
            }
            if (run < 0 || !(std::abs(dp - row[u - 1]) <= step)) {
                if (run >= 0) length[size_t(run)] = u - runStart;
                run = int32_t(parent.size());
                runStart = u;
                parent.push_back(run);
                length.push_back(0);
                first.push_back(v * W + u);
            }
            runHere[u] = run;
            const int32_t a = v > 0 ? runAbove[u] : -1;
            if (a >= 0 && (a != joinedAbove || run != joinedRun) &&
                std::abs(dp - above[u]) <= step) {
                const int32_t ra = findRoot(parent, a), rb = findRoot(parent, run);
                if (ra < rb) parent[size_t(rb)] = ra;
                if (rb < ra) parent[size_t(ra)] = rb;
                joinedAbove = a;
                joinedRun = run;
            }
        }
        if (run >= 0) length[size_t(run)] = W - runStart;
        std::swap(runAbove, runHere);
    }
    // Region sizes at the roots (a root precedes its runs).
    const int32_t runs = int32_t(parent.size());
    for (int32_t r = 0; r < runs; r++) {
        const int32_t root = findRoot(parent, r);
        if (root != r) length[size_t(root)] += length[size_t(r)];
    }
    std::vector<uint32_t> mark;
    std::vector<int> stack, members;
    std::vector<float> around;
    uint32_t id = 0;
    size_t removed = 0;
    for (int32_t r = 0; r < runs; r++) {
        if (parent[size_t(r)] != r || length[size_t(r)] >= o.nearCluster.maxArea_px) continue;
        if (mark.empty()) mark.assign(size_t(W) * size_t(H), 0);
        removed += decideRegion(d, o, first[size_t(r)], ++id, mark, stack, members, around);
    }
    return removed;
}

}  // namespace multibin::sensors
