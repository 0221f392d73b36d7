/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/config/CConfigFileBase.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "multibin/io/StrictConfigSection.h"

namespace multibin {

/** @name The options protocol
 * Every options struct of the library (the map's creation and insertion options, visibility, gap
 * filling, sensor models) lists each of its ini keys once, in a function template
 *
 *     template <class Options, class Visit> void visitKeys(Options& o, Visit&& visit);
 *
 * that calls `visit(key, member)`, `visit(key, member, rule)`, `visit(key, member, names)` (a
 * choice) or `visit(key, customOption(parse, format))` for each key. Reading (OptionReader),
 * writing (OptionWriter) and checking each value against its rule (OptionChecker) are visitors
 * over that one list; checks that involve several keys stay in the struct's validate(), after
 * OptionChecker.
 * @{ */

/** An ini key: its name (with its unit suffix) and, for a key renamed when it got the suffix, its
 * old name, still accepted when reading (giving both is an error). */
struct OptionKey {
    const char* name;
    const char* oldName = nullptr;
    OptionKey(const char* key) : name(key) {}  // NOLINT: a key is written as its name
    OptionKey(const char* key, const char* old) : name(key), oldName(old) {}
};

/** The words a choice key accepts, each with its value; the first word of a value is written. */
template <class T>
using OptionNames = std::vector<std::pair<std::string, T>>;

/** The largest magnitude a value in `unit` can have and still mean something physical: lengths
 * within 1e10 m (map coordinates have a tighter check of their own), times within
 * four months, angles within 1000 rad, pixels within 1e6, cells within 1e6, per-metre rates within
 * 1e6, and pure numbers (counts, factors, gains) within 1e9. A rule with no upper bound of its own
 * gets this one, so every key has a physical range (a 1e308 m cell or a 1e160 m sigma floor is
 * refused, not mapped into an empty raster). */
inline double physicalLimit(const char* unit) {
    // Compared in place: options are checked at every insertion (validate()).
    const auto is = [unit](const char* u) { return std::strcmp(unit, u) == 0; };
    if (is("m")) return 1e10;
    if (is("s")) return 1e7;
    if (is("rad")) return 1e3;
    if (is("px") || is("cells") || is("1/m")) return 1e6;
    return 1e9;
}

/** What a number (or each number of a list) of an option must be: finite, in [lo, hi] (lo
 * excluded if `loExcluded`), and odd if `odd`. `physicalHi`: hi is the unit's physical limit
 * (|value| <= hi), not a bound of the key's own. */
struct OptionRule {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    bool loExcluded = false;
    bool odd = false;
    const char* unit = "";  //!< shown after the rule, as " (m)"
    bool physicalHi = false;

    bool holds(double v) const {
        if (!std::isfinite(v) || (loExcluded ? !(v > lo) : !(v >= lo)) || !(v <= hi)) return false;
        return !odd || std::fmod(std::abs(v), 2.0) == 1.0;
    }
    /** "must be positive and finite (m), at most 1e+10 m", "must be from 3 to 15 (cells)", ... */
    std::string text() const {
        std::ostringstream os;
        os << "must be ";
        if (odd) os << "an odd number ";
        const bool bounded = std::isfinite(hi) && !physicalHi;
        if (loExcluded && lo == 0 && !bounded)
            os << "positive and finite";
        else if (!bounded && (!std::isfinite(lo) || lo == -hi))
            os << "finite";
        else if (bounded)
            os << "from " << lo << " to " << hi;
        else
            os << ">= " << lo << " and finite";
        // "(m)", not "[m]": MRPT's exception wrapper cuts a message at its first ']'.
        if (*unit) os << " (" << unit << ")";
        if (physicalHi) {
            os << (lo == -hi ? ", within +-" : ", at most ") << hi;
            if (*unit) os << " " << unit;
        }
        return os.str();
    }
};
/** Any finite number within the unit's physical limit. */
inline OptionRule finite(const char* unit = "") {
    return {-physicalLimit(unit), physicalLimit(unit), false, false, unit, true};
}
/** > 0, at most the unit's physical limit. */
inline OptionRule positive(const char* unit = "") {
    return {0, physicalLimit(unit), true, false, unit, true};
}
/** >= lo, at most the unit's physical limit. */
inline OptionRule atLeast(double lo, const char* unit = "") {
    return {lo, physicalLimit(unit), false, false, unit, true};
}
/** In [lo, hi]. */
inline OptionRule between(double lo, double hi, const char* unit = "") {
    return {lo, hi, false, false, unit};
}
/** Odd, in [lo, hi]. */
inline OptionRule oddBetween(double lo, double hi, const char* unit = "") {
    return {lo, hi, false, true, unit};
}

/** A key whose value has a text form of its own (a label map, a sensor preset, a curve):
 * `parse(StrictConfigSection&, key)` reads it when present, `format()` gives the text to write. */
template <class Parse, class Format>
struct CustomOption {
    Parse parse;
    Format format;
};
template <class Parse, class Format>
CustomOption<Parse, Format> customOption(Parse parse, Format format) {
    return {std::move(parse), std::move(format)};
}

/** Reads every visited key present in a section; absent keys keep their value. */
class OptionReader {
public:
    explicit OptionReader(StrictConfigSection& section) : m_s(section) {}

    template <class T>
    void operator()(const OptionKey& key, T& value, const OptionRule& = {}) const {
        const std::string name = nameGiven(key);
        if constexpr (std::is_same_v<T, std::vector<double>>) {
            m_s.read(name, value);
        } else if constexpr (isDoubleArray<T>::value) {
            if (!m_s.has(name)) return;
            std::vector<double> v;
            m_s.read(name, v, value.size());
            std::copy(v.begin(), v.end(), value.begin());
        } else {
            m_s.read(name, value);
        }
    }
    template <class T>
    void operator()(const OptionKey& key, T& value, const OptionNames<T>& names) const {
        m_s.readChoice(nameGiven(key), value, names);
    }
    template <class Parse, class Format>
    void operator()(const OptionKey& key, const CustomOption<Parse, Format>& custom) const {
        const std::string name = nameGiven(key);
        if (m_s.has(name)) custom.parse(m_s, name);
    }

private:
    template <class T>
    struct isDoubleArray : std::false_type {};
    template <size_t N>
    struct isDoubleArray<std::array<double, N>> : std::true_type {};

    /** The name under which the key is given: its old name if only that is. */
    std::string nameGiven(const OptionKey& key) const {
        if (!key.oldName || !m_s.has(key.oldName)) return key.name;
        if (m_s.has(key.name))
            m_s.fail(key.name, std::string("given twice: as '") + key.name +
                                   "' and as its old name '" + key.oldName + "'");
        return key.oldName;
    }

    StrictConfigSection& m_s;
};

/** Writes every visited key, under its current name, so that OptionReader reads back the same
 * values (numbers with 17 significant digits). */
class OptionWriter {
public:
    OptionWriter(mrpt::config::CConfigFileBase& target, std::string section)
        : m_c(target), m_section(std::move(section)) {}

    template <class T>
    void operator()(const OptionKey& key, const T& value, const OptionRule& = {}) const {
        if constexpr (std::is_same_v<T, unsigned>)
            m_c.write(m_section, key.name, int(value));
        else if constexpr (std::is_same_v<T, std::vector<std::string>>)
            m_c.write(m_section, key.name, joined(value, ","));
        else if constexpr (std::is_arithmetic_v<T> || std::is_same_v<T, std::string>)
            m_c.write(m_section, key.name, value);
        else  // a list of numbers
            m_c.write(m_section, key.name, joined(value, " "));
    }
    template <class T>
    void operator()(const OptionKey& key, const T& value, const OptionNames<T>& names) const {
        for (const auto& [word, v] : names)
            if (v == value) return m_c.write(m_section, key.name, word);
        m_c.write(m_section, key.name, names.front().first);
    }
    template <class Parse, class Format>
    void operator()(const OptionKey& key, const CustomOption<Parse, Format>& custom) const {
        m_c.write(m_section, key.name, std::string(custom.format()));
    }

    /** The items of a list, separated by `separator`; numbers with 17 significant digits. */
    template <class Seq>
    static std::string joined(const Seq& items, const char* separator) {
        std::ostringstream os;
        os.precision(17);
        bool first = true;
        for (const auto& item : items) {
            os << (first ? "" : separator) << item;
            first = false;
        }
        return os.str();
    }

private:
    mrpt::config::CConfigFileBase& m_c;
    std::string m_section;
};

/** Checks every visited number against its rule: std::invalid_argument "<what> '<key>': must be
 * ..." at the first that breaks it. */
class OptionChecker {
public:
    explicit OptionChecker(std::string what) : m_what(std::move(what)) {}

    template <class T>
    void operator()(const OptionKey& key, const T& value, const OptionRule& rule = {}) const {
        if constexpr (std::is_arithmetic_v<T>) {
            if (!rule.holds(double(value))) fail(key.name, rule.text());
        } else if constexpr (!std::is_same_v<T, std::string> &&
                             !std::is_same_v<T, std::vector<std::string>>) {
            for (double v : value)  // a list of numbers: each one
                if (!rule.holds(v)) fail(key.name, "values " + rule.text());
        }
    }
    /** A choice set in code must still be one of its words' values. */
    template <class T>
    void operator()(const OptionKey& key, const T& value, const OptionNames<T>& names) const {
        for (const auto& name : names)
            if (name.second == value) return;
        std::string words;  // the message only: options are checked at every insertion
        for (const auto& name : names) words += (words.empty() ? "" : ", ") + name.first;
        fail(key.name, "not one of the accepted values (" + words + ")");
    }
    template <class Parse, class Format>
    void operator()(const OptionKey&, const CustomOption<Parse, Format>&) const {}

    /** Throws "<what> '<key>': <problem>": for the checks of validate() that involve several
     * keys. */
    [[noreturn]] void fail(const std::string& key, const std::string& problem) const {
        throw std::invalid_argument(m_what + " '" + key + "': " + problem);
    }

private:
    std::string m_what;
};
/** options.validate(), its error prefixed with where the options were read from ("ini file 'F',
 * section 'S': ..."). */
template <class Options>
void validateAsReadFrom(const StrictConfigSection& section, const Options& options) {
    try {
        options.validate();
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(section.where() + ": " + e.what());
    }
}

/** Reads options from one section of `source` that holds only theirs: `readKeys(section)` reads
 * their keys, any other key of the section (but `allowed`) is an error, then options.validate();
 * every error names the file and the section. */
template <class Options, class ReadKeys>
void loadStrictly(const mrpt::config::CConfigFileBase& source, const std::string& section,
                  const Options& options, ReadKeys&& readKeys,
                  const std::vector<std::string>& allowed = {}) {
    StrictConfigSection s(source, section);
    readKeys(s);
    s.allow(allowed);
    s.finish();
    validateAsReadFrom(s, options);
}
/** An options struct's read(section) and loadFromConfigFile(), given its key list as a callable
 * `keys(options, visitor)` (its visitKeys). */
template <class Options, class Keys>
void readOptionKeys(StrictConfigSection& section, Options& options, Keys&& keys) {
    keys(options, OptionReader{section});
    validateAsReadFrom(section, options);
}
template <class Options, class Keys>
void loadOptionKeys(const mrpt::config::CConfigFileBase& source, const std::string& section,
                    Options& options, Keys&& keys) {
    loadStrictly(source, section, options,
                 [&](StrictConfigSection& s) { keys(options, OptionReader{s}); });
}
/** @} */

}  // namespace multibin
