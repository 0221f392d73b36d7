/* Part of the multibin elevation-mapping library. */
#include "multibin/io/StrictConfigSection.h"

#include "multibin/io/NumberText.h"

#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace multibin {

namespace {
std::string trim(const std::string& s) {
    const auto b = s.find_first_not_of(" \t\r\n");
    if (b == std::string::npos) return {};
    const auto e = s.find_last_not_of(" \t\r\n");
    std::string out = s.substr(b, e - b + 1);
    // Strip a trailing comment ("value  // note" or "value # note"): a mark that starts the value
    // or follows a blank, so that a label holding one ("cam#2") is kept whole.
    for (size_t at = 0; at < out.size(); at++) {
        const bool mark = out[at] == '#' || out[at] == ';' || out.compare(at, 2, "//") == 0;
        if (mark && (at == 0 || out[at - 1] == ' ' || out[at - 1] == '\t')) {
            out.resize(at);
            break;
        }
    }
    const auto e2 = out.find_last_not_of(" \t");
    return e2 == std::string::npos ? std::string() : out.substr(0, e2 + 1);
}

std::string lower(std::string s) {
    for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

std::vector<std::string> splitList(const std::string& s) {
    std::vector<std::string> out;
    std::string cur;
    for (char c : s) {
        if (c == ',' || std::isspace(static_cast<unsigned char>(c))) {
            if (!cur.empty()) out.push_back(cur);
            cur.clear();
        } else {
            cur += c;
        }
    }
    if (!cur.empty()) out.push_back(cur);
    return out;
}

/** The ini text behind `source` when it can be had (a file or memory), else empty. */
std::string iniText(const mrpt::config::CConfigFileBase& source, const std::string& file) {
    if (const auto* mem = dynamic_cast<const mrpt::config::CConfigFileMemory*>(&source)) {
        std::string text;
        mem->getContent(text);
        return text;
    }
    if (file.empty()) return {};
    std::ifstream f(file);
    return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

/** The first key given more than once in `section` of ini `text` ("" if none), compared as MRPT
 * compares them, ignoring case (also across headers of the section in different case): MRPT's
 * reader keeps the last value without a word. */
std::string duplicatedKey(const std::string& text, const std::string& section) {
    std::set<std::string> seen;
    bool inSection = false;
    size_t start = 0;
    while (start <= text.size()) {
        size_t end = text.find('\n', start);
        if (end == std::string::npos) end = text.size();
        const std::string line = trim(text.substr(start, end - start));
        start = end + 1;
        if (line.empty()) continue;
        if (line.front() == '[') {
            const auto close = line.find(']');
            inSection = close != std::string::npos &&
                        lower(trim(line.substr(1, close - 1))) == lower(section);
            continue;
        }
        const auto eq = line.find('=');
        if (!inSection || eq == std::string::npos) continue;
        const std::string key = trim(line.substr(0, eq));
        if (!seen.insert(lower(key)).second) return key;
    }
    return {};
}
}  // namespace

StrictConfigSection::StrictConfigSection(const mrpt::config::CConfigFileBase& source,
                                         std::string section)
    : m_source(source), m_section(std::move(section)) {
    if (const auto* f = dynamic_cast<const mrpt::config::CConfigFile*>(&source))
        m_file = f->getAssociatedFile();
    if (m_source.sectionExists(m_section)) {
        m_source.getAllKeys(m_section, m_keys);
        for (const auto& k : m_keys)
            m_values.push_back(trim(m_source.read_string(m_section, k, "")));
        if (const std::string dup = duplicatedKey(iniText(source, m_file), m_section); !dup.empty())
            fail(dup, "given more than once in the section");
    }
}

std::string StrictConfigSection::where() const {
    // No brackets: MRPT's exception wrapper takes the text up to a ']' for a source location.
    return (m_file.empty() ? std::string("ini") : "ini file '" + m_file + "',") + " section '" +
           m_section + "'";
}

bool StrictConfigSection::has(const std::string& key) const {
    return std::find(m_keys.begin(), m_keys.end(), key) != m_keys.end();
}

const std::string* StrictConfigSection::raw(const std::string& key) {
    const auto it = std::find(m_keys.begin(), m_keys.end(), key);
    if (it == m_keys.end()) return nullptr;
    m_used.insert(key);
    const std::string& value = m_values[static_cast<size_t>(it - m_keys.begin())];
    // MRPT's ini writer takes a trailing backslash for a line continuation, so such a value would
    // not load back the same from saved options (or from the options inside a serialized map).
    if (!value.empty() && value.back() == '\\')
        fail(key, "a value must not end in a backslash, got '" + value + "'");
    for (const char c : value)
        if (std::iscntrl(static_cast<unsigned char>(c)) && c != '\t')
            fail(key, "the value holds a control character (byte " +
                          std::to_string(static_cast<unsigned char>(c)) + ")");
    return &value;
}

std::string StrictConfigSection::listOfWords(const std::vector<std::string>& words) {
    std::string out;
    for (size_t i = 0; i < words.size(); i++)
        out += (i == 0 ? "" : i + 1 == words.size() ? " or " : ", ") + words[i];
    return out;
}

void StrictConfigSection::fail(const std::string& key, const std::string& problem) const {
    throw std::invalid_argument(where() + ", key '" + key + "': " + problem);
}

void StrictConfigSection::read(const std::string& key, double& value) {
    const std::string* s = raw(key);
    if (!s) return;
    double v;
    if (!parseFiniteNumber(*s, v)) fail(key, "expected a finite number, got '" + *s + "'");
    value = v;
}

void StrictConfigSection::read(const std::string& key, float& value) {
    double v = value;
    read(key, v);
    if (std::abs(v) > std::numeric_limits<float>::max()) fail(key, "value out of float range");
    value = static_cast<float>(v);
}

void StrictConfigSection::read(const std::string& key, int& value) {
    const std::string* s = raw(key);
    if (!s) return;
    char* end = nullptr;
    const long v = s->empty() ? 0 : std::strtol(s->c_str(), &end, 10);
    if (s->empty() || end != s->c_str() + s->size() || v < std::numeric_limits<int>::min() ||
        v > std::numeric_limits<int>::max())
        fail(key, "expected a whole number, got '" + *s + "'");
    value = static_cast<int>(v);
}

void StrictConfigSection::read(const std::string& key, unsigned& value) {
    int v = static_cast<int>(value);
    read(key, v);
    if (v < 0) fail(key, "expected a non-negative whole number, got " + std::to_string(v));
    value = static_cast<unsigned>(v);
}

void StrictConfigSection::read(const std::string& key, bool& value) {
    const std::string* s = raw(key);
    if (!s) return;
    const std::string l = lower(*s);
    if (l == "true" || l == "1" || l == "yes" || l == "on")
        value = true;
    else if (l == "false" || l == "0" || l == "no" || l == "off")
        value = false;
    else
        fail(key, "expected true or false, got '" + *s + "'");
}

void StrictConfigSection::read(const std::string& key, std::string& value) {
    const std::string* s = raw(key);
    if (s) value = *s;
}

void StrictConfigSection::read(const std::string& key, std::vector<double>& value,
                               size_t expected_size) {
    const std::string* s = raw(key);
    if (!s) return;
    std::vector<double> out;
    for (const auto& tok : splitList(*s)) {
        double v;
        if (!parseFiniteNumber(tok, v)) fail(key, "expected a list of numbers, got '" + tok + "'");
        out.push_back(v);
    }
    if (expected_size && out.size() != expected_size)
        fail(key, "expected " + std::to_string(expected_size) + " numbers, got " +
                      std::to_string(out.size()));
    value = std::move(out);
}

void StrictConfigSection::read(const std::string& key, std::vector<std::string>& value) {
    const std::string* s = raw(key);
    if (!s) return;
    std::vector<std::string> items = splitList(*s);
    // A list names each thing once: a repeated item would silently keep one of its meanings.
    std::set<std::string> seen;
    for (const std::string& item : items)
        if (!seen.insert(item).second) fail(key, "'" + item + "' is listed twice");
    value = std::move(items);
}

void StrictConfigSection::readInRange(const std::string& key, double& value, double lo, double hi) {
    double v = value;
    read(key, v);
    if (!(v >= lo && v <= hi)) {
        std::ostringstream os;
        os << "value " << v << " outside [" << lo << ", " << hi << "]";
        fail(key, os.str());
    }
    value = v;
}

void StrictConfigSection::allow(const std::vector<std::string>& keys) {
    for (const auto& k : keys)
        if (has(k)) m_used.insert(k);
}

void StrictConfigSection::finish() const {
    for (const auto& k : m_keys)
        if (!m_used.count(k)) fail(k, "unknown key");
}

}  // namespace multibin
