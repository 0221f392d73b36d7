/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#pragma once

#include <cstddef>
#include <cstdint>

/** Bounds the memory that reading one file may request. MRPT's deserializers allocate what a
 * file declares (a count of objects, beams, points) before reading the data, so a 31-byte file
 * can ask for 16 GB. While a ReadBudget is alive on a thread, the allocations of that thread may
 * add up to its limit (frees are not subtracted, so the sum bounds the peak); a request beyond
 * it is refused: malloc, calloc, realloc and memalign return null (operator
 * new then throws std::bad_alloc), posix_memalign and aligned_alloc throw std::bad_alloc (MRPT's
 * aligned allocator does not check for null). The allocation functions and operator new are
 * replaced in every program that links this file (RawlogSourceGuard.cpp) and forward to the
 * allocator the process runs with: a sanitizer runtime's (gcc's or clang's, built in or
 * preloaded), else the next definition (glibc's, or one preloaded). Before the first ReadBudget
 * they only forward. In a build instrumented for TSan or MSan the guard is off. */
class ReadBudget {
public:
    /** The limit for `bytesLeft` bytes still to read: kFixedBytes + kPerByte * bytesLeft. */
    static constexpr uint64_t kFixedBytes = uint64_t(64) << 20;
    static constexpr uint64_t kPerByte = 16;
    /** MRPT allocates on its error path where a std::bad_alloc is std::terminate (an
     * exception's message and stack trace inside the throw expression, what()): requests of up
     * to kSmallBytes may go kSlackBytes beyond the limit, the first refusal raises the limit
     * to kSlackBytes beyond what was taken, once, and requests of up to kSmallBytes made while
     * an exception is being handled (MRPT's handlers rethrow with a stack trace) have kSlackBytes
     * of their own. The peak stays under the limit + 4 x kSlackBytes. */
    static constexpr uint64_t kSmallBytes = uint64_t(64) << 10;
    static constexpr uint64_t kSlackBytes = uint64_t(64) << 20;
    static uint64_t limitFor(uint64_t bytesLeft);

    explicit ReadBudget(uint64_t limitBytes);
    ~ReadBudget();
    ReadBudget(const ReadBudget&) = delete;
    ReadBudget& operator=(const ReadBudget&) = delete;

    /** The largest total (requests so far plus the refused one) refused since construction
     * (0: none). */
    static uint64_t largestRefused();
    /** Whether this build enforces the limit (false in TSan and MSan builds). */
    static bool enforced();

private:
    uint64_t m_previous;
};
