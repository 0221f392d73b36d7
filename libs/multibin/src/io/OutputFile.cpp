/* Part of the multibin elevation-mapping library: files written whole or not at all. */
#include "multibin/io/OutputFile.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "multibin/io/ErrorMessage.h"

namespace fs = std::filesystem;

namespace multibin {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& why) {
    throw std::runtime_error("cannot write '" + path + "': " + why);
}

/** Flushes a written file to disk: a full disk may only show here (delayed allocation). */
void syncFile(const std::string& tmp, const std::string& path) {
    const int fd = ::open(tmp.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) fail(path, std::strerror(errno));
    const bool ok = ::fsync(fd) == 0;
    const int err = errno;
    ::close(fd);
    if (!ok) fail(path, std::strerror(err));
}

void renameInto(const std::string& tmp, const std::string& path) {
    std::error_code ec;
    fs::rename(tmp, path, ec);
    if (ec) {
        fs::remove(tmp, ec);
        fail(path, ec.message());
    }
}

}  // namespace

std::string temporaryPathFor(const std::string& path) {
    const fs::path p(path);
    // Same folder (rename stays on one file system) and extension (writers that pick the format
    // by extension, e.g. OpenCV); the pid keeps two concurrent runs apart.
    return (p.parent_path() / ("." + p.stem().string() + ".partial-" + std::to_string(::getpid()) +
                               p.extension().string()))
        .string();
}

void writeFileAtomically(const std::string& path, const void* bytes, size_t size) {
    const std::string tmp = temporaryPathFor(path);
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) fail(path, std::strerror(errno));
    const char* p = static_cast<const char*>(bytes);
    size_t left = size;
    int err = 0;
    while (left > 0) {
        const ssize_t n = ::write(fd, p, left);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            err = n < 0 ? errno : EIO;
            break;
        }
        p += n;
        left -= size_t(n);
    }
    if (err == 0 && ::fsync(fd) != 0) err = errno;
    if (::close(fd) != 0 && err == 0) err = errno;
    if (err != 0) {
        ::unlink(tmp.c_str());
        fail(path, std::strerror(err));
    }
    renameInto(tmp, path);
}

void writeFileAtomically(const std::string& path, const std::vector<uint8_t>& bytes) {
    writeFileAtomically(path, bytes.data(), bytes.size());
}

void writeFileAtomically(const std::string& path, const std::string& text) {
    writeFileAtomically(path, text.data(), text.size());
}

void writeFileAtomically(const std::string& path,
                         const std::function<bool(const std::string& temporaryPath)>& write) {
    const std::string tmp = temporaryPathFor(path);
    try {
        if (!write(tmp)) fail(path, "the writer failed");
        syncFile(tmp, path);
    } catch (const std::exception& e) {
        std::error_code ec;
        fs::remove(tmp, ec);
        const std::string msg = oneLineMessage(e);
        if (msg.find(path) != std::string::npos) throw;
        // The writer named the temporary file: name the file the user asked for.
        std::string why = msg;
        for (size_t at; (at = why.find(tmp)) != std::string::npos;)
            why.replace(at, tmp.size(), path);
        if (why.find(path) != std::string::npos) throw std::runtime_error(why);
        fail(path, why);
    }
    renameInto(tmp, path);
}

}  // namespace multibin
