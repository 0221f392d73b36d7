/* Part of the multibin elevation-mapping library. */
#pragma once

#include <string>

namespace multibin {

/** Parses the whole of `text` as one finite number (strtod syntax, C locale). Returns false, and
 * leaves `value` unspecified, for empty text, trailing characters, NaN or infinity: the one rule
 * every number read from an ini value, a grid file or a command line follows here. */
bool parseFiniteNumber(const std::string& text, double& value);

}  // namespace multibin
