/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <string>

/** A one-line progress bar on stderr, drawn only when stderr is a terminal. */
class ProgressBar {
public:
    explicit ProgressBar(std::string label);
    /** fraction in [0, 1]; `detail` is printed after the bar. Redraws at most 10 times a second. */
    void update(double fraction, const std::string& detail);
    /** For stages of unknown length: a moving marker and the time elapsed since construction. */
    void spin(const std::string& detail = {});
    /** Completes the line. */
    void finish(const std::string& detail);

    /** Runs work() while a spinning bar labelled `label` shows the elapsed time (on a terminal:
     * work runs on a worker thread and must not print). Rethrows what work throws. */
    static void runWithProgress(const std::string& label, const std::function<void()>& work);

private:
    void draw(double fraction, const std::string& detail, int marker = -1);
    std::string m_label;
    bool m_enabled;
    std::chrono::steady_clock::time_point m_start, m_lastDraw;
    int m_spinStep = 0;
};
