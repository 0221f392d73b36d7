/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#include "ProgressBar.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <future>

namespace {
constexpr int kWidth = 30;
}

ProgressBar::ProgressBar(std::string label)
    : m_label(std::move(label)),
      m_enabled(isatty(STDERR_FILENO) != 0),
      m_start(std::chrono::steady_clock::now()) {}

void ProgressBar::update(double fraction, const std::string& detail) {
    const auto now = std::chrono::steady_clock::now();
    if (now - m_lastDraw < std::chrono::milliseconds(100)) return;
    m_lastDraw = now;
    draw(fraction, detail);
}

void ProgressBar::spin(const std::string& detail) {
    const auto now = std::chrono::steady_clock::now();
    if (now - m_lastDraw < std::chrono::milliseconds(100)) return;
    m_lastDraw = now;
    char elapsed[32];
    std::snprintf(elapsed, sizeof elapsed, "%.1f s",
                  std::chrono::duration<double>(now - m_start).count());
    const int period = 2 * (kWidth - 1);  // the marker goes back and forth
    const int k = m_spinStep++ % period;
    draw(0, std::string(elapsed) + (detail.empty() ? "" : " " + detail),
         k < kWidth ? k : period - k);
}

void ProgressBar::finish(const std::string& detail) {
    draw(1.0, detail);
    if (m_enabled) std::fputc('\n', stderr);
}

void ProgressBar::draw(double fraction, const std::string& detail, int marker) {
    if (!m_enabled) return;
    std::string bar;
    if (marker >= 0) {
        bar.assign(size_t(kWidth), '.');
        bar[size_t(marker)] = '#';
        std::fprintf(stderr, "\r%s [%s]      %s\033[K", m_label.c_str(), bar.c_str(),
                     detail.c_str());
    } else {
        const double f = std::clamp(fraction, 0.0, 1.0);
        const int filled = static_cast<int>(f * kWidth + 0.5);
        bar = std::string(size_t(filled), '#') + std::string(size_t(kWidth - filled), '.');
        std::fprintf(stderr, "\r%s [%s] %3d%% %s\033[K", m_label.c_str(), bar.c_str(),
                     static_cast<int>(f * 100), detail.c_str());
    }
    std::fflush(stderr);
}

void ProgressBar::runWithProgress(const std::string& label, const std::function<void()>& work) {
    ProgressBar bar(label);
    if (!bar.m_enabled) {
        work();
        return;
    }
    auto done = std::async(std::launch::async, work);
    while (done.wait_for(std::chrono::milliseconds(100)) != std::future_status::ready) bar.spin();
    const double elapsed_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - bar.m_start).count();
    char detail[48];
    std::snprintf(detail, sizeof detail, "done in %.1f s", elapsed_s);
    bar.finish(detail);
    done.get();  // rethrows
}
