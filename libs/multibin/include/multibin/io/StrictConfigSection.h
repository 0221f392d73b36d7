/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/config/CConfigFileBase.h>

#include <set>
#include <string>
#include <utility>
#include <vector>

namespace multibin {

/** Strict reader of one ini section.
 *
 * MRPT's read_double()/read_int() turn a malformed value into 0 without a word. This reader parses
 * every value strictly and, in finish(), refuses any key of the section that nobody read, so a typo
 * in an ini file is an error naming the section and the key instead of a silently ignored option.
 *
 * Use: one reader per section; each options struct reads its keys with read(); keys that belong
 * to MRPT itself are declared with allow(); then finish(). Keys absent from the section leave the
 * destination untouched (its default). A key given twice in the section is an error (MRPT keeps
 * the last one silently). All errors are std::invalid_argument naming the file (when the source
 * is a CConfigFile), the section and the key. */
class StrictConfigSection {
public:
    StrictConfigSection(const mrpt::config::CConfigFileBase& source, std::string section);

    const std::string& section() const { return m_section; }
    /** "ini file 'F', section 'S'" (the file when the source is a CConfigFile): the start of
     * every error message, for callers that add their own (validate()). */
    std::string where() const;
    bool has(const std::string& key) const;

    void read(const std::string& key, double& value);
    void read(const std::string& key, float& value);
    void read(const std::string& key, int& value);
    void read(const std::string& key, unsigned& value);
    void read(const std::string& key, bool& value);  //!< true/false/1/0/yes/no
    void read(const std::string& key, std::string& value);
    /** Comma- or space-separated numbers; the count must equal `expected_size` when non-zero. */
    void read(const std::string& key, std::vector<double>& value, size_t expected_size = 0);
    /** Comma- or space-separated words. */
    void read(const std::string& key, std::vector<std::string>& value);

    /** Reads a double and checks lo <= value <= hi (inclusive). */
    void readInRange(const std::string& key, double& value, double lo, double hi);

    /** Reads one word of a fixed set into `value` (an enum, typically): `choices` pairs each
     * accepted word with its value; any other word fails naming the accepted ones. */
    template <typename T>
    void readChoice(const std::string& key, T& value,
                    const std::vector<std::pair<std::string, T>>& choices) {
        if (!has(key)) return;
        std::string word;
        read(key, word);
        std::vector<std::string> words;
        for (const auto& [name, v] : choices) {
            if (name == word) {
                value = v;
                return;
            }
            words.push_back(name);
        }
        fail(key, "expected " + listOfWords(words) + ", got '" + word + "'");
    }

    /** Declares keys that may appear without being read (MRPT's generic map keys). */
    void allow(const std::vector<std::string>& keys);

    /** Throws if the section holds a key that was neither read nor allowed. */
    void finish() const;

    /** Throws an error that names the section and `key`. */
    [[noreturn]] void fail(const std::string& key, const std::string& problem) const;

private:
    const std::string* raw(const std::string& key);
    /** "a, b or c". */
    static std::string listOfWords(const std::vector<std::string>& words);

    const mrpt::config::CConfigFileBase& m_source;
    std::string m_section;
    std::string m_file;  //!< empty unless the source is a file
    std::vector<std::string> m_keys;
    std::vector<std::string> m_values;
    std::set<std::string> m_used;
};

}  // namespace multibin
