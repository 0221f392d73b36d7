/* Part of the multibin elevation-mapping library: files written whole or not at all, never
 * through a symlink, never left half-written by a handled signal. */
#include "multibin/io/OutputFile.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <random>
#include <stdexcept>

#include "multibin/io/ErrorMessage.h"

namespace fs = std::filesystem;

namespace multibin {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& why) {
    throw std::runtime_error("cannot write '" + path + "': " + why);
}

// The paths being written now, for the signal handler: fixed storage, no allocation there.
constexpr int kPartialSlots = 16;
constexpr size_t kPartialPathMax = 4096;
enum SlotState : int { kFree = 0, kFilling = 1, kActive = 2 };
struct PartialSlot {
    std::atomic<int> state{kFree};
    char path[kPartialPathMax];
};
PartialSlot g_partials[kPartialSlots];

/** Registers a temporary file or private folder while it exists (RAII): a handled signal removes
 * it. A path too long or a full table only loses that clean-up, never the write. */
class PartialPath {
public:
    explicit PartialPath(const std::string& path) {
        if (path.size() >= kPartialPathMax) return;
        for (int i = 0; i < kPartialSlots; i++) {
            int expected = kFree;
            if (!g_partials[i].state.compare_exchange_strong(expected, kFilling)) continue;
            std::memcpy(g_partials[i].path, path.c_str(), path.size() + 1);
            g_partials[i].state.store(kActive);
            m_slot = i;
            return;
        }
    }
    ~PartialPath() {
        if (m_slot >= 0) g_partials[m_slot].state.store(kFree);
    }
    PartialPath(const PartialPath&) = delete;
    PartialPath& operator=(const PartialPath&) = delete;

private:
    int m_slot = -1;
};

extern "C" void removePartialsAndReraise(int signal) {
    // Files first, then the (then empty) private folders; only async-signal-safe calls.
    for (auto& slot : g_partials)
        if (slot.state.load() == kActive) ::unlink(slot.path);
    for (auto& slot : g_partials)
        if (slot.state.load() == kActive) ::rmdir(slot.path);
    ::signal(signal, SIG_DFL);
    ::raise(signal);
}

/** Random characters for names no other process can predict. */
std::string randomName(size_t length) {
    static const char kChars[] = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
    thread_local std::mt19937_64 gen{std::random_device{}()};
    std::uniform_int_distribution<size_t> pick(0, sizeof kChars - 2);
    std::string s(length, 'x');
    for (char& c : s) c = kChars[pick(gen)];
    return s;
}

fs::path folderOf(const std::string& path) {
    const fs::path parent = fs::path(path).parent_path();
    return parent.empty() ? fs::path(".") : parent;
}

/** Flushes a written file to disk: a full disk may only show here (delayed allocation). */
void syncFile(const std::string& file, const std::string& path) {
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0) fail(path, std::strerror(errno));
    const bool ok = ::fsync(fd) == 0;
    const int err = errno;
    ::close(fd);
    if (!ok) fail(path, std::strerror(err));
}

void renameInto(const std::string& from, const std::string& path) {
    if (::rename(from.c_str(), path.c_str()) != 0) {
        const int err = errno;
        ::unlink(from.c_str());
        fail(path, std::strerror(err));
    }
}

/** Creates a new file beside `path` exclusively (O_EXCL: a planted symlink or file is never
 * opened), hidden, with `path`'s extension; returns its descriptor and sets `tmp`. */
int createTemporaryBeside(const std::string& path, std::string& tmp) {
    const fs::path p(path);
    for (int attempt = 0; attempt < 100; attempt++) {
        tmp = (folderOf(path) /
               ("." + p.stem().string() + ".partial-" + randomName(12) + p.extension().string()))
                  .string();
        const int fd =
            ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
        if (fd >= 0 || errno != EEXIST) return fd;
    }
    errno = EEXIST;
    return -1;
}

}  // namespace

void writeFileAtomically(const std::string& path, const void* bytes, size_t size) {
    std::string tmp;
    const int fd = createTemporaryBeside(path, tmp);
    if (fd < 0) fail(path, std::strerror(errno));
    const PartialPath partial(tmp);
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
    std::string folder;
    try {
        folder = createPrivateFolder(folderOf(path).string(),
                                     "." + fs::path(path).stem().string() + ".partial-");
    } catch (const std::exception& e) {
        fail(path, oneLineMessage(e));
    }
    const PartialPath partialFolder(folder);
    // The writer's file keeps the name (writers pick the format by extension, e.g. OpenCV).
    const std::string tmp = (fs::path(folder) / fs::path(path).filename()).string();
    const PartialPath partialFile(tmp);
    std::error_code ec;
    try {
        if (!write(tmp)) fail(path, "the writer failed");
        syncFile(tmp, path);
        moveIntoPlace(tmp, path);
    } catch (const std::exception& e) {
        fs::remove_all(folder, ec);
        const std::string msg = oneLineMessage(e);
        if (msg.find(path) != std::string::npos) throw;
        // The writer named the temporary file: name the file the user asked for.
        std::string why = msg;
        for (size_t at; (at = why.find(tmp)) != std::string::npos;)
            why.replace(at, tmp.size(), path);
        if (why.find(path) != std::string::npos) throw std::runtime_error(why);
        fail(path, why);
    }
    fs::remove_all(folder, ec);
}

std::string createPrivateFolder(const std::string& parent, const std::string& prefix) {
    std::string pattern = (fs::path(parent.empty() ? "." : parent) / (prefix + "XXXXXX")).string();
    if (::mkdtemp(pattern.data()) == nullptr)
        throw std::runtime_error("cannot create a private folder in '" + parent +
                                 "': " + std::strerror(errno));
    return pattern;
}

void moveIntoPlace(const std::string& from, const std::string& to) {
    struct stat st {};
    if (::lstat(from.c_str(), &st) != 0) fail(to, std::strerror(errno));
    if (!S_ISREG(st.st_mode)) fail(to, "the file written is not a regular file");
    renameInto(from, to);
}

void removePartialFilesOnSignals() {
    struct sigaction action {};
    action.sa_handler = removePartialsAndReraise;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESETHAND;
    for (const int signal : {SIGINT, SIGTERM, SIGHUP}) ::sigaction(signal, &action, nullptr);
}

}  // namespace multibin
