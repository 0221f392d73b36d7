/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#include "ProgressBar.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

ProgressBar::ProgressBar(std::string label)
    : m_label(std::move(label)), m_enabled(isatty(STDERR_FILENO) != 0) {}

void ProgressBar::update(double fraction, const std::string& detail) {
    const auto now = std::chrono::steady_clock::now();
    if (now - m_lastDraw < std::chrono::milliseconds(100)) return;
    m_lastDraw = now;
    draw(fraction, detail);
}

void ProgressBar::finish(const std::string& detail) {
    draw(1.0, detail);
    if (m_enabled) std::fputc('\n', stderr);
}

void ProgressBar::draw(double fraction, const std::string& detail) {
    if (!m_enabled) return;
    constexpr int kWidth = 30;
    const double f = std::clamp(fraction, 0.0, 1.0);
    const int filled = static_cast<int>(f * kWidth + 0.5);
    std::fprintf(stderr, "\r%s [%s%s] %3d%% %s\033[K", m_label.c_str(),
                 std::string(size_t(filled), '#').c_str(),
                 std::string(size_t(kWidth - filled), '.').c_str(), static_cast<int>(f * 100),
                 detail.c_str());
    std::fflush(stderr);
}
