/* Part of the multibin elevation-mapping library. */
#include "multibin/io/ErrorMessage.h"

#include <sstream>

namespace multibin {

std::string oneLineMessage(const std::exception& e) {
    std::istringstream lines(e.what());
    std::string line, first;
    while (std::getline(lines, line)) {
        if (first.empty() && line.find("====") == std::string::npos) first = line;
        const auto m = line.find("Message:");
        if (m != std::string::npos) {
            line = line.substr(m + 8);
            const auto b = line.find_first_not_of(' ');
            return b == std::string::npos ? std::string() : line.substr(b);
        }
    }
    return first.empty() ? std::string(e.what()) : first;
}

}  // namespace multibin
