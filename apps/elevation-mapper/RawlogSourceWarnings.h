/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#pragma once

#include <cstddef>
#include <sstream>
#include <streambuf>
#include <string>
#include <vector>

/** What MRPT prints on std::cerr while the reading path reads an entry: its deserializers warn
 * once per object ("[CObservation3DRangeScan] Warning: autofixing incorrect camera resolution
 * ..."), so a rawlog of 300 such scans printed 300 lines, interleaved with the progress bar on a
 * terminal. Collected line by line instead; each distinct line is kept once, with how many times
 * it came and where it came first. */
class MrptWarnings {
public:
    struct Line {
        std::string text;
        size_t count;
        std::string firstAt;  //!< e.g. "rawlog 'a.rawlog': entry 3"
    };
    /** The distinct lines kept: at most kMaxLines, each cut to kMaxChars (the rest counted). */
    static constexpr size_t kMaxLines = 20, kMaxChars = 300;
    const std::vector<Line>& lines() const { return m_lines; }
    /** One line each, control characters escaped (multibin::printableText):
     * "MRPT said N times (first at WHERE): TEXT", then "MRPT said N more lines" for those beyond
     * kMaxLines. */
    std::vector<std::string> summary() const;

    /** While alive, what is written to std::cerr goes to `into` (nothing is captured when it is
     * null), as said at `where`. */
    class Capture {
    public:
        Capture(MrptWarnings* into, std::string where);
        ~Capture();
        Capture(const Capture&) = delete;
        Capture& operator=(const Capture&) = delete;

    private:
        MrptWarnings* m_into;
        std::string m_where;
        std::stringbuf m_buffer;
        std::streambuf* m_previous = nullptr;
    };

private:
    void add(const std::string& text, const std::string& where);
    std::vector<Line> m_lines;
    size_t m_more = 0;  //!< lines beyond kMaxLines distinct ones
};
