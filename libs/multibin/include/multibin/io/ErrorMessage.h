/* Part of the multibin elevation-mapping library. */
#pragma once

#include <exception>
#include <string>

namespace multibin {

/** The one-line message of an exception: for MRPT's multi-line exceptions ("==== MRPT exception
 * ====", "Message: ...", call stack), the text of the Message line; otherwise the whole text, a
 * line break inside it (from user text such as a sensor label) written as \n. */
std::string oneLineMessage(const std::exception& e);

/** `text` safe to print on a terminal: control characters (a newline that would forge a line,
 * ESC that would start a terminal escape sequence), C1 controls and bytes that are not valid
 * UTF-8 written as \n, \r, \t or \xNN; printable ASCII and UTF-8 kept. For user-supplied text
 * (sensor labels, paths) in messages. */
std::string printableText(const std::string& text);

/** What a user is shown for `e`: oneLineMessage() never empty (an empty one becomes "an error
 * without a message" and the exception's type), an allocation failure or a size beyond a
 * container's limit in words, and such messages (and libstdc++'s or MRPT's internals) after
 * `context` (e.g. "reading rawlog 'x.rawlog'"), which names what was being done; all of it
 * through printableText(). */
std::string userMessage(const std::exception& e, const std::string& context = "");

}  // namespace multibin
