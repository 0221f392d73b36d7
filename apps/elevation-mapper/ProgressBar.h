/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

/** A one-line progress bar on stderr, drawn only when stderr is a terminal. */
class ProgressBar {
public:
    explicit ProgressBar(std::string label);
    /** fraction in [0, 1]; `detail` is printed after the bar. Redraws at most 10 times a second. */
    void update(double fraction, const std::string& detail);
    /** Completes the line. */
    void finish(const std::string& detail);

private:
    void draw(double fraction, const std::string& detail);
    std::string m_label;
    bool m_enabled;
    std::chrono::steady_clock::time_point m_lastDraw;
};
