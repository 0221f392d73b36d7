/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>

namespace multibin {

/** The disk side of a map's memory budget (BinStore::spillTile): an append-only scratch file of
 * tile records, each written once and read back by its offset.
 *
 * The file has no name: it is created unlinked in `directory` (O_TMPFILE; where the file system
 * lacks it, a random name opened exclusively and unlinked at once), so no other process or
 * symlink can reach it and it vanishes with the process, even a killed one. Writes and reads use
 * explicit offsets under a mutex: copies of a store may share one file. Space is not reused: a
 * tile written again is appended again (a route rarely comes back to a tile it left). */
class TileStoreFile {
public:
    /** Opens the scratch file in `directory` (empty: $TMPDIR, else /tmp). Throws
     * std::runtime_error naming the directory and the system's reason if it cannot. */
    explicit TileStoreFile(const std::string& directory);
    ~TileStoreFile();
    TileStoreFile(const TileStoreFile&) = delete;
    TileStoreFile& operator=(const TileStoreFile&) = delete;

    /** Appends `bytes` bytes; returns their offset. Throws std::runtime_error (disk full, I/O
     * error) naming the directory. */
    uint64_t append(const void* data, size_t bytes);
    /** Reads `bytes` bytes at `offset` (written by append). Throws std::runtime_error if the
     * file is shorter or unreadable. */
    void read(uint64_t offset, void* data, size_t bytes) const;
    /** Bytes written so far. */
    uint64_t size() const;
    const std::string& directory() const { return m_directory; }

private:
    [[noreturn]] void fail(const char* what) const;

    std::string m_directory;
    int m_fd = -1;
    uint64_t m_end = 0;
    mutable std::mutex m_mutex;
};

}  // namespace multibin
