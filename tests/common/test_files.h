/* Files of tests: scratch folders under the build tree, whole-file reads and writes. */
#pragma once

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace test_files {

/** An empty folder `name` under the build tree's `group` folder. */
inline std::filesystem::path scratchDir(const std::string& group, const std::string& name) {
    const std::filesystem::path d = std::filesystem::path(MULTIBIN_BINARY_DIR) / group / name;
    std::filesystem::remove_all(d);
    std::filesystem::create_directories(d);
    return d;
}

/** A file's bytes. */
inline std::string readAll(const std::filesystem::path& p) {
    std::ifstream f(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

/** Writes `bytes` as the whole file `p`. */
inline void writeAll(const std::filesystem::path& p, const std::string& bytes) {
    std::ofstream f(p, std::ios::binary);
    f << bytes;
}

}  // namespace test_files
