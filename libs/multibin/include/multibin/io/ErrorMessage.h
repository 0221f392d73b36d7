/* Part of the multibin elevation-mapping library. */
#pragma once

#include <exception>
#include <string>

namespace multibin {

/** The one-line message of an exception: for MRPT's multi-line exceptions ("==== MRPT exception
 * ====", "Message: ...", call stack), the text of the Message line; otherwise the first line. */
std::string oneLineMessage(const std::exception& e);

}  // namespace multibin
