/* Part of the multibin elevation-mapping library: the elevation-mapper program.
 * Replaces the C allocation functions to enforce ReadBudget. This file must not include a header
 * that declares malloc (<cstdlib>, <string>, ...): glibc declares them noexcept, and the aligned
 * ones here throw. */
#include "RawlogSourceGuard.h"

#include <exception>
#include <new>

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MULTIBIN_GUARD_ASAN 1
#elif __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define MULTIBIN_GUARD_OFF 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) && !defined(MULTIBIN_GUARD_ASAN)
#define MULTIBIN_GUARD_ASAN 1
#endif
#if defined(__SANITIZE_THREAD__) && !defined(MULTIBIN_GUARD_OFF)
#define MULTIBIN_GUARD_OFF 1
#endif

namespace {
thread_local uint64_t t_limit = 0;      // 0: no budget on this thread
thread_local uint64_t t_requested = 0;  // sum of the requests since the budget began
thread_local uint64_t t_largestRefused = 0;
thread_local bool t_errorPathRoom = false;  // the first refusal raised the limit
thread_local uint64_t t_inHandler = 0;      // small requests granted while handling an exception

/** Whether an exception is being handled on this thread. Out of line: its exception_ptr gives
 * the frame an object that ASan instruments, and malloc runs before ASan has mapped its shadow
 * memory (this is only called once a budget is active). */
__attribute__((noinline)) bool handlingException() { return std::current_exception() != nullptr; }

/** Whether a request of n bytes is refused (and records it). The sum of all requests is
 * bounded, frees not subtracted: containers that grow in small blocks (std::deque) are bounded
 * too, and the sum bounds the peak. MRPT allocates on its error path where std::bad_alloc is
 * std::terminate (inside throw expressions, in what()): small requests get kSlackBytes more,
 * and the first refusal gives the error path kSlackBytes beyond what was taken (once). */
inline bool refused(std::size_t n) {
    if (t_limit == 0) return false;
    auto plus = [](uint64_t a, uint64_t b) { return a > UINT64_MAX - b ? UINT64_MAX : a + b; };
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
}
ReadBudget::~ReadBudget() { t_limit = m_previous; }
uint64_t ReadBudget::largestRefused() { return t_largestRefused; }

#ifdef MULTIBIN_GUARD_OFF
bool ReadBudget::enforced() { return false; }
#else
bool ReadBudget::enforced() { return true; }

extern "C" {
#ifdef MULTIBIN_GUARD_ASAN
void* __interceptor_malloc(std::size_t);
void* __interceptor_calloc(std::size_t, std::size_t);
void* __interceptor_realloc(void*, std::size_t);
void* __interceptor_memalign(std::size_t, std::size_t);
int __interceptor_posix_memalign(void**, std::size_t, std::size_t);
void* __interceptor_aligned_alloc(std::size_t, std::size_t);
void __interceptor_free(void*);
#define REAL(f) __interceptor_##f
#else
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
#define REAL(f) __libc_##f
#endif

void* malloc(std::size_t n) { return refused(n) ? nullptr : REAL(malloc)(n); }
void* calloc(std::size_t count, std::size_t size) {
    const std::size_t n = count * size;
    if ((size != 0 && n / size != count) || refused(n)) return nullptr;
    return REAL(calloc)(count, size);
}
void* realloc(void* p, std::size_t n) { return refused(n) ? nullptr : REAL(realloc)(p, n); }
void* memalign(std::size_t alignment, std::size_t n) {
    return refused(n) ? nullptr : REAL(memalign)(alignment, n);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t n) {
    if (refused(n)) throw std::bad_alloc();
#ifdef MULTIBIN_GUARD_ASAN
    return __interceptor_posix_memalign(out, alignment, n);
#else
    if (alignment < sizeof(void*) || (alignment & (alignment - 1)) != 0) return 22;  // EINVAL
    *out = __libc_memalign(alignment, n);
    return *out ? 0 : 12;  // ENOMEM
#endif
}
void* aligned_alloc(std::size_t alignment, std::size_t n) {
    if (refused(n)) throw std::bad_alloc();
    return REAL(memalign)(alignment, n);
}
}  // extern "C"

#ifdef MULTIBIN_GUARD_ASAN
// ASan's operator new does not call malloc: route it through the guarded malloc. Deletes go to
// free so ASan sees matching pairs (its new/delete mismatch check is lost in these programs).
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
void operator delete(void* p) noexcept { __interceptor_free(p); }
void operator delete[](void* p) noexcept { __interceptor_free(p); }
void operator delete(void* p, std::size_t) noexcept { __interceptor_free(p); }
void operator delete[](void* p, std::size_t) noexcept { __interceptor_free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { __interceptor_free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { __interceptor_free(p); }
void operator delete(void* p, std::align_val_t) noexcept { __interceptor_free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { __interceptor_free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { __interceptor_free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { __interceptor_free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept {
    __interceptor_free(p);
}
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept {
    __interceptor_free(p);
}
#endif  // MULTIBIN_GUARD_ASAN
#endif  // MULTIBIN_GUARD_OFF
