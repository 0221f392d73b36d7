/* Part of the multibin elevation-mapping library. */
#pragma once

#include <string>

namespace multibin {

/** Parses the whole of `text` as one finite decimal number ([+-] digits [. digits] [e [+-]
 * digits], C locale). Returns false, and leaves `value` unspecified, for empty text, blanks,
 * trailing characters, hexadecimal or hex-float, NaN or infinity, or a number beyond double's
 * range: the one rule every number read from an ini value, a grid file or a command line follows
 * here. */
bool parseFiniteNumber(const std::string& text, double& value);

}  // namespace multibin
