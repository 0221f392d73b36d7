/* Part of the multibin elevation-mapping library. */
#include "multibin/io/ErrorMessage.h"

#include <cstdio>
#include <new>
#include <sstream>
#include <stdexcept>
#include <typeinfo>

namespace multibin {
namespace {

/** The length of the valid UTF-8 sequence at `s[i]` that encodes a printable character (not a
 * C1 control, U+0080..U+009F), or 0. */
size_t printableUtf8Length(const std::string& s, size_t i) {
    const auto byte = [&](size_t k) { return static_cast<unsigned char>(s[k]); };
    const unsigned char b = byte(i);
    const size_t n = b >= 0xF0 && b <= 0xF4 ? 4 : b >= 0xE0 ? 3 : b >= 0xC2 && b < 0xE0 ? 2 : 0;
    if (n == 0 || i + n > s.size()) return 0;
    for (size_t k = 1; k < n; k++)
        if ((byte(i + k) & 0xC0) != 0x80) return 0;
    if (b == 0xC2 && byte(i + 1) < 0xA0) return 0;  // C1 controls (0x9B is a terminal's CSI)
    return n;
}

/** A message that says nothing of where it arose: an allocation that failed, a size beyond what
 * a container can hold, libstdc++'s internal function names, an assertion inside MRPT. */
bool isLibraryInternal(const std::exception& e, const std::string& message) {
    if (dynamic_cast<const std::bad_alloc*>(&e) || dynamic_cast<const std::length_error*>(&e))
        return true;
    for (const char* mark : {"_M_", "max_size()", "Assert condition failed", "ASSERT"})
        if (message.find(mark) != std::string::npos) return true;
    return false;
}

}  // namespace

std::string oneLineMessage(const std::exception& e) {
    std::istringstream lines(e.what());
    std::string line, first;
    const auto trimmed = [](const std::string& s) {
        const auto b = s.find_first_not_of(' ');
        return b == std::string::npos ? std::string() : s.substr(b);
    };
    while (std::getline(lines, line)) {
        if (first.empty() && line.find("====") == std::string::npos) first = line;
        const auto m = line.find("Message:");
        if (m != std::string::npos) {
            std::string message = trimmed(line.substr(m + 8));
            // MRPT wraps an error of an object's reader ("Exception while parsing typed
            // object ...") with the reader's own message on the line after "Original
            // exception:": that line says what is wrong, the wrapper where.
            std::string next;
            if (std::getline(lines, next) && next.find("Original exception:") == 0)
                while (std::getline(lines, next)) {
                    if (next.find("====") != std::string::npos) continue;
                    const auto inner = next.find("Message:");
                    next = trimmed(inner == std::string::npos ? next : next.substr(inner + 8));
                    if (!next.empty()) message += (message.empty() ? "" : ": ") + next;
                    break;
                }
            return message;
        }
    }
    if (std::string(e.what()).find("====") != std::string::npos) return first;
    // A plain message on several lines (a label holding a newline): one line, the breaks shown.
    std::string text = e.what();
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    for (size_t at; (at = text.find('\n')) != std::string::npos;) text.replace(at, 1, "\\n");
    return text;
}

std::string printableText(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (size_t i = 0; i < text.size();) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c >= 0x20 && c < 0x7F) {
            out += text[i++];
        } else if (const size_t n = c >= 0x80 ? printableUtf8Length(text, i) : 0) {
            out.append(text, i, n);
            i += n;
        } else {
            char code[8];
            if (c == '\n' || c == '\r' || c == '\t')
                std::snprintf(code, sizeof code, "\\%c", c == '\n' ? 'n' : c == '\r' ? 'r' : 't');
            else
                std::snprintf(code, sizeof code, "\\x%02X", c);
            out += code;
            i++;
        }
    }
    return out;
}

std::string userMessage(const std::exception& e, const std::string& context) {
    std::string message = oneLineMessage(e);
    const bool internal = isLibraryInternal(e, message);
    if (dynamic_cast<const std::bad_alloc*>(&e))
        message = "out of memory (" + message + ")";
    else if (dynamic_cast<const std::length_error*>(&e))
        message = "a size beyond what memory can hold (" + message + ")";
    if (message.find_first_not_of(" \t") == std::string::npos)
        message = std::string("an error without a message (") + typeid(e).name() + ")";
    else if (!internal)
        return printableText(message);
    return printableText(context.empty() ? message : context + ": " + message);
}

}  // namespace multibin
