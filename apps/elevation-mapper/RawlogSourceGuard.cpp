/* Part of the multibin elevation-mapping library: the elevation-mapper program.
 * Replaces the C allocation functions and operator new to enforce ReadBudget, forwarding to the
 * allocator the process runs with. This file must not include a header that declares malloc
 * (<cstdlib>, <string>, ...): glibc declares them noexcept, and the aligned ones here throw. */
#include "RawlogSourceGuard.h"

#include <dlfcn.h>

#include <exception>
#include <new>

#if defined(__has_feature)
#if __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define MULTIBIN_GUARD_OFF 1
#endif
#endif
#if defined(__SANITIZE_THREAD__) && !defined(MULTIBIN_GUARD_OFF)
#define MULTIBIN_GUARD_OFF 1
#endif

// The allocation functions run before the sanitizer runtimes have set up (ld.so and ASan's own
// start-up allocate through them): never instrumented. They forward by a tail call, so that the
// allocator sees their caller as its own: LeakSanitizer takes the dynamic loader's allocations
// (dlopen's) for reachable only when the loader called malloc, and reported them as leaks when
// a frame of this file stood between (a suppression in tests/common/lsan.supp hid them).
#if defined(__clang__)
#define GUARD_FN __attribute__((no_sanitize("address", "undefined", "thread")))
#define GUARD_TAIL [[clang::musttail]]
#else
#define GUARD_FN                                                  \
    __attribute__((no_sanitize("address", "undefined", "thread"), \
                   optimize("optimize-sibling-calls")))
#define GUARD_TAIL
#endif
// Static TLS: reading it never allocates (a dynamic TLS block is allocated with malloc).
#define GUARD_TLS thread_local __attribute__((tls_model("initial-exec")))

namespace {
// Set by the first ReadBudget, never cleared: until then (all of the process's start-up) the
// functions below only forward and touch no thread-local variable. The atomics here are
// __atomic builtins: std::atomic's members are instrumented functions the no_sanitize ones
// below may call out of line.
bool g_armed = false;                // read and written with __atomic builtins
GUARD_TLS uint64_t t_limit = 0;      // 0: no budget on this thread
GUARD_TLS uint64_t t_requested = 0;  // sum of the requests since the budget began
GUARD_TLS uint64_t t_largestRefused = 0;
GUARD_TLS bool t_errorPathRoom = false;  // the first refusal raised the limit
GUARD_TLS uint64_t t_inHandler = 0;      // small requests granted while handling an exception

/** Whether an exception is being handled on this thread. Out of line: its exception_ptr gives
 * the frame an object that ASan instruments (this is only called once a budget is active). */
__attribute__((noinline)) bool handlingException() { return std::current_exception() != nullptr; }

GUARD_FN inline uint64_t plus(uint64_t a, uint64_t b) {
    return a > UINT64_MAX - b ? UINT64_MAX : a + b;
}

/** Whether a request of n bytes is refused (and records it). The sum of all requests is
 * bounded, frees not subtracted: containers that grow in small blocks (std::deque) are bounded
 * too, and the sum bounds the peak. MRPT allocates on its error path where std::bad_alloc is
 * std::terminate (inside throw expressions, in what()): small requests get kSlackBytes more,
 * and the first refusal gives the error path kSlackBytes beyond what was taken (once). */
GUARD_FN inline bool refused(std::size_t n) {
    if (!__atomic_load_n(&g_armed, __ATOMIC_RELAXED) || t_limit == 0) return false;
    const uint64_t limit =
        n <= ReadBudget::kSmallBytes ? plus(t_limit, ReadBudget::kSlackBytes) : t_limit;
    if (n <= limit && t_requested + n <= limit) {
        t_requested += n;
        return false;
    }
    // MRPT's catch handlers rethrow with a stack trace and format it in what() (noexcept): a
    // refusal there is std::terminate. A read can spend the whole budget in small blocks without
    // a refusal (a std::deque sized by a count in the file) and then fail on other grounds, so
    // small requests made while an exception is handled draw on an allowance of their own.
    if (n <= ReadBudget::kSmallBytes && t_inHandler + n <= ReadBudget::kSlackBytes &&
        handlingException()) {
        t_inHandler += n;
        return false;
    }
    const uint64_t asked = t_requested + n;
    if (asked > t_largestRefused) t_largestRefused = asked;
    if (!t_errorPathRoom) {
        t_errorPathRoom = true;
        t_limit = plus(t_limit > t_requested ? t_limit : t_requested, ReadBudget::kSlackBytes);
    }
    return true;
}
}  // namespace

uint64_t ReadBudget::limitFor(uint64_t bytesLeft) {
    const uint64_t maxLeft = (UINT64_MAX - kFixedBytes) / kPerByte;
    return kFixedBytes + kPerByte * (bytesLeft < maxLeft ? bytesLeft : maxLeft);
}
ReadBudget::ReadBudget(uint64_t limitBytes) : m_previous(t_limit) {
    t_limit = limitBytes == 0 ? 1 : limitBytes;
    t_requested = 0;
    t_largestRefused = 0;
    t_errorPathRoom = false;
    t_inHandler = 0;
    __atomic_store_n(&g_armed, true, __ATOMIC_RELAXED);
}
ReadBudget::~ReadBudget() { t_limit = m_previous; }
uint64_t ReadBudget::largestRefused() { return t_largestRefused; }

#ifdef MULTIBIN_GUARD_OFF
bool ReadBudget::enforced() { return false; }
#else
bool ReadBudget::enforced() { return true; }

// The allocator the process runs with. A sanitizer runtime (gcc's or clang's, linked or
// preloaded) defines __interceptor_<name>, and its malloc is a weak alias that this file's
// replaces; otherwise the next definition after this program's (glibc's, or an allocator
// preloaded with LD_PRELOAD). free forwards to the same one, and the functions not replaced here
// (malloc_usable_size, ...) reach it directly: every pointer goes back to the allocator that
// made it. Resolved at the first allocation (start-up, one thread).
extern "C" {
void* __interceptor_malloc(std::size_t) __attribute__((weak));
void* __interceptor_calloc(std::size_t, std::size_t) __attribute__((weak));
void* __interceptor_realloc(void*, std::size_t) __attribute__((weak));
void* __interceptor_memalign(std::size_t, std::size_t) __attribute__((weak));
int __interceptor_posix_memalign(void**, std::size_t, std::size_t) __attribute__((weak));
void* __interceptor_aligned_alloc(std::size_t, std::size_t) __attribute__((weak));
void __interceptor_free(void*) __attribute__((weak));
}

namespace {
struct Allocator {
    void* (*malloc)(std::size_t);
    void* (*calloc)(std::size_t, std::size_t);
    void* (*realloc)(void*, std::size_t);
    void* (*memalign)(std::size_t, std::size_t);
    int (*posix_memalign)(void**, std::size_t, std::size_t);
    void* (*aligned_alloc)(std::size_t, std::size_t);
    void (*free)(void*);
};
Allocator g_next;     // zero until resolved (plain data: no constructor); free is stored last
int g_resolving = 0;  // dlsym may allocate while it resolves
alignas(64) char g_bootstrap[4096];  // what is allocated then (never freed)
std::size_t g_bootstrapUsed = 0;

template <typename F>
GUARD_FN F resolved(F interceptor, const char* name) {
    return interceptor ? interceptor : reinterpret_cast<F>(dlsym(RTLD_NEXT, name));
}

GUARD_FN const Allocator& next() {
    if (__builtin_expect(__atomic_load_n(&g_next.free, __ATOMIC_ACQUIRE) != nullptr, 1))
        return g_next;
    __atomic_fetch_add(&g_resolving, 1, __ATOMIC_SEQ_CST);
    Allocator a{};
    a.malloc = resolved(&__interceptor_malloc, "malloc");
    a.calloc = resolved(&__interceptor_calloc, "calloc");
    a.realloc = resolved(&__interceptor_realloc, "realloc");
    a.memalign = resolved(&__interceptor_memalign, "memalign");
    a.posix_memalign = resolved(&__interceptor_posix_memalign, "posix_memalign");
    a.aligned_alloc = resolved(&__interceptor_aligned_alloc, "aligned_alloc");
    g_next = a;  // threads racing here store the same values
    __atomic_store_n(&g_next.free, resolved(&__interceptor_free, "free"), __ATOMIC_RELEASE);
    __atomic_fetch_sub(&g_resolving, 1, __ATOMIC_SEQ_CST);
    return g_next;
}

/** An allocation made while dlsym resolves the allocator (glibc's does not on success). */
GUARD_FN void* bootstrap(std::size_t n) {
    const std::size_t size = (n + 15) & ~std::size_t(15);
    const std::size_t at = __atomic_fetch_add(&g_bootstrapUsed, size, __ATOMIC_RELAXED);
    return at + size <= sizeof g_bootstrap ? g_bootstrap + at : nullptr;
}
GUARD_FN bool isBootstrap(const void* p) {
    return p >= g_bootstrap && p < g_bootstrap + sizeof g_bootstrap;
}
}  // namespace

extern "C" {
GUARD_FN void* malloc(std::size_t n) {
    if (__atomic_load_n(&g_resolving, __ATOMIC_RELAXED) != 0) return bootstrap(n);
    if (refused(n)) return nullptr;
    GUARD_TAIL return next().malloc(n);
}
GUARD_FN void* calloc(std::size_t count, std::size_t size) {
    const std::size_t n = count * size;
    if (size != 0 && n / size != count) return nullptr;
    if (__atomic_load_n(&g_resolving, __ATOMIC_RELAXED) != 0)
        return bootstrap(n);  // static storage: zero already
    if (refused(n)) return nullptr;
    GUARD_TAIL return next().calloc(count, size);
}
GUARD_FN void* realloc(void* p, std::size_t n) {
    if (refused(n)) return nullptr;
    if (!isBootstrap(p)) GUARD_TAIL return next().realloc(p, n);
    void* q = next().malloc(n);  // never made bigger in place; copied as far as it can reach
    const char* from = static_cast<const char*>(p);
    for (std::size_t i = 0; q && i < n && from + i < g_bootstrap + sizeof g_bootstrap; i++)
        static_cast<char*>(q)[i] = from[i];
    return q;
}
GUARD_FN void free(void* p) {
    if (p && !isBootstrap(p)) next().free(p);
}
GUARD_FN void* memalign(std::size_t alignment, std::size_t n) {
    return refused(n) ? nullptr : next().memalign(alignment, n);
}
GUARD_FN int posix_memalign(void** out, std::size_t alignment, std::size_t n) {
    if (refused(n)) throw std::bad_alloc();  // MRPT's aligned allocator does not check
    return next().posix_memalign(out, alignment, n);
}
GUARD_FN void* aligned_alloc(std::size_t alignment, std::size_t n) {
    if (refused(n)) throw std::bad_alloc();
    return next().aligned_alloc(alignment, n);
}
}  // extern "C"

// A sanitizer's operator new does not call malloc: route every one through the guarded malloc,
// whatever the runtime (libstdc++'s calls malloc anyway). Deletes go to free so a sanitizer sees
// matching pairs (its new/delete mismatch check is lost in these programs).
namespace {
void* newOrThrow(std::size_t n) {
    if (void* p = malloc(n == 0 ? 1 : n)) return p;
    throw std::bad_alloc();
}
void* newAlignedOrThrow(std::size_t n, std::align_val_t a) {
    return aligned_alloc(std::size_t(a),
                         ((n == 0 ? 1 : n) + std::size_t(a) - 1) & ~(std::size_t(a) - 1));
}
}  // namespace
void* operator new(std::size_t n) { return newOrThrow(n); }
void* operator new[](std::size_t n) { return newOrThrow(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return malloc(n ? n : 1); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return malloc(n ? n : 1); }
void* operator new(std::size_t n, std::align_val_t a) { return newAlignedOrThrow(n, a); }
void* operator new[](std::size_t n, std::align_val_t a) { return newAlignedOrThrow(n, a); }
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
    try {
        return newAlignedOrThrow(n, a);
    } catch (...) {
        return nullptr;
    }
}
void* operator new[](std::size_t n, std::align_val_t a, const std::nothrow_t& t) noexcept {
    return operator new(n, a, t);
}
void operator delete(void* p) noexcept { free(p); }
void operator delete[](void* p) noexcept { free(p); }
void operator delete(void* p, std::size_t) noexcept { free(p); }
void operator delete[](void* p, std::size_t) noexcept { free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { free(p); }
void operator delete(void* p, std::align_val_t) noexcept { free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { free(p); }
#endif  // MULTIBIN_GUARD_OFF
