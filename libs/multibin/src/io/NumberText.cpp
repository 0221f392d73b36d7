/* Part of the multibin elevation-mapping library. */
#include "multibin/io/NumberText.h"

#include <cmath>
#include <cstdlib>

namespace multibin {

bool parseFiniteNumber(const std::string& text, double& value) {
    if (text.empty()) return false;
    char* end = nullptr;
    value = std::strtod(text.c_str(), &end);
    return end == text.c_str() + text.size() && std::isfinite(value);
}

}  // namespace multibin
