/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace multibin {

/** Writes `bytes` to `path` through a temporary file in the same folder, flushed to disk (fsync)
 * and then renamed over `path`: a full disk or a crash leaves the previous file or none, never a
 * truncated one. The temporary file is created exclusively (O_EXCL, O_NOFOLLOW) under a name no
 * other process can predict, so a symlink planted in the folder is never followed; the rename
 * replaces a symlink at `path` itself, never its target. Throws std::runtime_error naming `path`
 * and the system's reason (e.g. "No space left on device"); the temporary file is removed. */
void writeFileAtomically(const std::string& path, const void* bytes, size_t size);
void writeFileAtomically(const std::string& path, const std::vector<uint8_t>& bytes);
void writeFileAtomically(const std::string& path, const std::string& text);

/** The same for a writer that only takes a path (it must throw or return false on failure):
 * write(temporaryPath) fills a file of the same name and extension in a private folder (see
 * createPrivateFolder), which is then flushed and renamed over `path`. */
void writeFileAtomically(const std::string& path,
                         const std::function<bool(const std::string& temporaryPath)>& write);

/** Creates a new folder inside `parent` that only this user can enter (mode 0700, a name
 * starting with `prefix` and ending in random characters, made by mkdtemp): other programs (a
 * plotter, a writer that opens by name) write there, and their files are then moved into place
 * with moveIntoPlace(). Throws naming `parent`. */
std::string createPrivateFolder(const std::string& parent, const std::string& prefix);

/** Renames the regular file `from` (in a private folder) over `to`; a symlink at `to` is
 * replaced, not followed. Throws naming `to` if `from` is not a regular file or the rename fails.
 */
void moveIntoPlace(const std::string& from, const std::string& to);

/** Installs handlers of SIGINT, SIGTERM and SIGHUP that remove the temporary files and private
 * folders being written at that moment, then end the process as the signal would: a killed run
 * leaves no partial file (SIGKILL cannot be handled: its partial files keep their hidden
 * ".partial-" names). For programs; a library never installs signal handlers by itself. */
void removePartialFilesOnSignals();

}  // namespace multibin
