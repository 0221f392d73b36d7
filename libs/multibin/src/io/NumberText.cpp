/* Part of the multibin elevation-mapping library. */
#include "multibin/io/NumberText.h"

#include <cctype>
#include <cmath>
#include <cstdlib>

namespace multibin {
namespace {

/** Whether `text` is a plain decimal number: [+-] digits [. digits] [(e|E) [+-] digits], with a
 * digit before the exponent. strtod also takes hexadecimal ("0x10"), hex-float ("0x1p4"),
 * leading blanks and the words inf and nan, none of which a user writing a length means. */
bool isDecimal(const std::string& t) {
    size_t i = 0;
    const auto digits = [&] {
        const size_t from = i;
        while (i < t.size() && std::isdigit(static_cast<unsigned char>(t[i]))) i++;
        return i - from;
    };
    if (i < t.size() && (t[i] == '+' || t[i] == '-')) i++;
    size_t mantissa = digits();
    if (i < t.size() && t[i] == '.') {
        i++;
        mantissa += digits();
    }
    if (mantissa == 0) return false;
    if (i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
        i++;
        if (i < t.size() && (t[i] == '+' || t[i] == '-')) i++;
        if (digits() == 0) return false;
    }
    return i == t.size();
}

}  // namespace

bool parseFiniteNumber(const std::string& text, double& value) {
    if (!isDecimal(text)) return false;
    char* end = nullptr;
    value = std::strtod(text.c_str(), &end);
    return end == text.c_str() + text.size() && std::isfinite(value);
}

}  // namespace multibin
