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

    /** Held for reading for its lifetime (unless this thread holds the lock already). */
    class Shared {
    public:
        explicit Shared(const MapLock& l) : m_lock(l), m_taken(!l.heldHere(false)) {
            if (m_taken) {
                // Writers first: glibc's rwlock prefers readers, and two readers that query
                // back to back would starve the mapping thread.
                while (l.m_writersWaiting.load(std::memory_order_acquire) > 0)
                    std::this_thread::yield();
                l.m_mutex.lock_shared();
                held().emplace_back(&l, false);
            }
        }
        ~Shared() {
            if (!m_taken) return;
            forget(m_lock);
            m_lock.m_mutex.unlock_shared();
        }
        Shared(const Shared&) = delete;
        Shared& operator=(const Shared&) = delete;

    private:
        const MapLock& m_lock;
        bool m_taken;
    };
    /** Held for writing for its lifetime (unless this thread holds it for writing already). */
    class Exclusive {
    public:
        explicit Exclusive(const MapLock& l) : m_lock(l), m_taken(!l.heldHere(true)) {
            if (m_taken) {
                l.m_writersWaiting.fetch_add(1, std::memory_order_acq_rel);
                l.m_mutex.lock();
                l.m_writersWaiting.fetch_sub(1, std::memory_order_acq_rel);
                held().emplace_back(&l, true);
            }
        }
        ~Exclusive() {
            if (!m_taken) return;
            forget(m_lock);
            m_lock.m_mutex.unlock();
        }
        Exclusive(const Exclusive&) = delete;
        Exclusive& operator=(const Exclusive&) = delete;

    private:
        const MapLock& m_lock;
        bool m_taken;
    };

private:
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
