/* Part of the multibin elevation-mapping library. */
#include "multibin/grid/TileStoreFile.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <random>
#include <stdexcept>

namespace multibin {

namespace {
std::string scratchDirectory(const std::string& given) {
    if (!given.empty()) return given;
    const char* tmp = std::getenv("TMPDIR");
    return tmp && *tmp ? tmp : "/tmp";
}

/** A random name opened exclusively (never through an existing file or symlink), unlinked at
 * once: for file systems without O_TMPFILE. */
int openUnlinked(const std::string& dir) {
    std::random_device rd;
    for (int attempt = 0; attempt < 16; attempt++) {
        const std::string path =
            dir + "/.multibin-tiles-" + std::to_string(rd()) + std::to_string(rd());
        const int fd =
            ::open(path.c_str(), O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
        if (fd >= 0) {
            ::unlink(path.c_str());
            return fd;
        }
        if (errno != EEXIST) return -1;
    }
    return -1;
}
}  // namespace

TileStoreFile::TileStoreFile(const std::string& directory)
    : m_directory(scratchDirectory(directory)) {
#ifdef O_TMPFILE
    m_fd = ::open(m_directory.c_str(), O_TMPFILE | O_RDWR | O_EXCL | O_CLOEXEC, 0600);
    if (m_fd < 0 && (errno == EOPNOTSUPP || errno == EISDIR || errno == EINVAL))
        m_fd = openUnlinked(m_directory);
#else
    m_fd = openUnlinked(m_directory);
#endif
    if (m_fd < 0) fail("cannot create its scratch file there");
}

TileStoreFile::~TileStoreFile() {
    if (m_fd >= 0) ::close(m_fd);
}

void TileStoreFile::fail(const char* what) const {
    throw std::runtime_error("CMultiBinElevationMap: the tile store in '" + m_directory +
                             "' (tile_store_dir, for memory_budget_mb): " + what + ": " +
                             std::strerror(errno));
}

uint64_t TileStoreFile::append(const void* data, size_t bytes) {
    const std::lock_guard<std::mutex> lock(m_mutex);
    const uint64_t offset = m_end;
    const char* p = static_cast<const char*>(data);
    for (size_t done = 0; done < bytes;) {
        const ssize_t n = ::pwrite(m_fd, p + done, bytes - done, off_t(offset + done));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) fail("cannot write a tile");
        done += size_t(n);
    }
    m_end += bytes;
    return offset;
}

void TileStoreFile::read(uint64_t offset, void* data, size_t bytes) const {
    const std::lock_guard<std::mutex> lock(m_mutex);
    char* p = static_cast<char*>(data);
    for (size_t done = 0; done < bytes;) {
        const ssize_t n = ::pread(m_fd, p + done, bytes - done, off_t(offset + done));
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) fail("cannot read a tile back");
        if (n == 0) {
            errno = EIO;
            fail("a tile record is cut short");
        }
        done += size_t(n);
    }
}

uint64_t TileStoreFile::size() const {
    const std::lock_guard<std::mutex> lock(m_mutex);
    return m_end;
}

}  // namespace multibin
