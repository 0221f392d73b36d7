/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace multibin {

/** Writes `bytes` to `path` through a temporary file in the same folder (a hidden name with the
 * same extension), flushed to disk (fsync) and then renamed over `path`: a full disk or a crash
 * leaves the previous file or none, never a truncated one. Throws std::runtime_error naming
 * `path` and the system's reason (e.g. "No space left on device"); the temporary file is removed.
 */
void writeFileAtomically(const std::string& path, const void* bytes, size_t size);
void writeFileAtomically(const std::string& path, const std::vector<uint8_t>& bytes);
void writeFileAtomically(const std::string& path, const std::string& text);

/** The same for a writer that only takes a path (it must throw or return false on failure):
 * write(temporaryPath) fills the temporary file, which is then flushed and renamed. */
void writeFileAtomically(const std::string& path,
                         const std::function<bool(const std::string& temporaryPath)>& write);

/** The temporary name writeFileAtomically() uses for `path`: same folder and extension. */
std::string temporaryPathFor(const std::string& path);

}  // namespace multibin
