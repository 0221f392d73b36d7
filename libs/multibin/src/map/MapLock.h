/* Part of the multibin elevation-mapping library.
 * The map's reader-writer lock (doc/reliability.md, "Threads"). */
#pragma once

#include <algorithm>
#include <atomic>
#include <mutex>
#include <shared_mutex>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

namespace multibin {

/** One writer or any number of readers at a time. Every public entry point of the map takes it
 * once: nested calls on the same thread (insertObservation -> recenter, a query inside an
 * insertion) do not lock again. A copy of a map gets its own, unlocked, lock. */
class MapLock {
public:
    MapLock() = default;
    MapLock(const MapLock&) {}
    MapLock& operator=(const MapLock&) { return *this; }

    /** Held for its lifetime, for writing when Exclusive, else for reading (unless this thread
     * holds the lock already; for writing, a read held here is a bug). */
    template <bool Exclusive>
    class Guard {
    public:
        explicit Guard(const MapLock& l) : m_lock(l), m_taken(!l.heldHere(Exclusive)) {
            if (m_taken) l.acquire(Exclusive);
        }
        ~Guard() {
            if (m_taken) m_lock.release(Exclusive);
        }
        Guard(const Guard&) = delete;
        Guard& operator=(const Guard&) = delete;

    private:
        const MapLock& m_lock;
        bool m_taken;
    };
    using Shared = Guard<false>;
    using Exclusive = Guard<true>;

    /** Whether this thread holds the lock (for reading or writing): an entry point called
     * inside another may not take it for writing. */
    bool heldByThisThread() const {
        for (const auto& e : held())
            if (e.first == this) return true;
        return false;
    }

private:
    void acquire(bool exclusive) const {
        if (exclusive) {
            m_writersWaiting.fetch_add(1, std::memory_order_acq_rel);
            m_mutex.lock();
            m_writersWaiting.fetch_sub(1, std::memory_order_acq_rel);
        } else {
            // Writers first: glibc's rwlock prefers readers, and two readers that query
            // back to back would starve the mapping thread.
            while (m_writersWaiting.load(std::memory_order_acquire) > 0) std::this_thread::yield();
            m_mutex.lock_shared();
        }
        held().emplace_back(this, exclusive);
    }
    void release(bool exclusive) const {
        forget(*this);
        if (exclusive)
            m_mutex.unlock();
        else
            m_mutex.unlock_shared();
    }
    using Held = std::vector<std::pair<const MapLock*, bool>>;  // lock, exclusive
    static Held& held() {
        thread_local Held h;
        return h;
    }
    static void forget(const MapLock& l) {
        Held& h = held();
        const auto it =
            std::find_if(h.rbegin(), h.rend(), [&](const auto& e) { return e.first == &l; });
        if (it != h.rend()) h.erase(std::next(it).base());
    }
    /** Whether this thread holds the lock (for writing: a change inside a read is a bug). */
    bool heldHere(bool forWriting) const {
        for (const auto& [l, exclusive] : held())
            if (l == this) {
                if (forWriting && !exclusive)
                    throw std::logic_error(
                        "CMultiBinElevationMap: a change was requested while this thread reads "
                        "the map");
                return true;
            }
        return false;
    }
    mutable std::shared_mutex m_mutex;
    mutable std::atomic<int> m_writersWaiting{0};
};

}  // namespace multibin
