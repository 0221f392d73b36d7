/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#include "RawlogSourceWarnings.h"

#include <iostream>

#include "multibin/io/ErrorMessage.h"

MrptWarnings::Capture::Capture(MrptWarnings* into, std::string where)
    : m_into(into), m_where(std::move(where)) {
    if (m_into) m_previous = std::cerr.rdbuf(&m_buffer);
}

MrptWarnings::Capture::~Capture() {
    if (!m_into) return;
    std::cerr.rdbuf(m_previous);
    try {
        std::istringstream text(m_buffer.str());
        for (std::string line; std::getline(text, line);)
            if (line.find_first_not_of(" \t\r") != std::string::npos) m_into->add(line, m_where);
    } catch (...) {  // out of memory while unwinding: the warnings are lost, not the process
    }
}

void MrptWarnings::add(const std::string& line, const std::string& where) {
    const std::string text = line.size() > kMaxChars ? line.substr(0, kMaxChars) + "..." : line;
    for (Line& l : m_lines)
        if (l.text == text) {
            l.count++;
            return;
        }
    if (m_lines.size() < kMaxLines)
        m_lines.push_back({text, 1, where});
    else
        m_more++;
}

std::vector<std::string> MrptWarnings::summary() const {
    std::vector<std::string> out;
    for (const Line& l : m_lines)
        out.push_back("MRPT said " + std::to_string(l.count) + (l.count == 1 ? " time" : " times") +
                      " (first at " + multibin::printableText(l.firstAt) +
                      "): " + multibin::printableText(l.text));
    if (m_more > 0) out.push_back("MRPT said " + std::to_string(m_more) + " more lines");
    return out;
}
