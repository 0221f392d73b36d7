/* Part of the multibin elevation-mapping library. Private to src/. */
#pragma once

#include <atomic>
#include <cstddef>
#include <memory>
#include <thread>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "../util/HelperThread.h"

namespace multibin {

/** The insertion core on two cores (BinGrid::insertBlocks with `insertion_threads = 2`): a
 * lock-free ring of blocks between two stages. The helper thread (HelperThread) fills and
 * classifies blocks ahead while the calling thread updates the bins in block order, so the bins
 * are those of one thread, bit for bit; only the calling thread touches the grid. */
namespace pipeline {

/** Blocks in flight between the two stages: 8 x 14 kB, inside the L2 cache. */
constexpr size_t kRing = 8;
/** The pipeline pays from about this many blocks on (handing a task to the helper thread costs
 * about as much as a few blocks' work): a 30 000-return lidar revolution, a stereo or depth frame,
 * not a 683-beam laser scan. */
constexpr size_t kMinBlocks = 16;

inline void pauseCore() {
#if defined(__x86_64__) || defined(__i386__)
    _mm_pause();  // a spin-wait hint: frees the core's resources for its other hyperthread
#endif
}

/** Waits for `ready()` (the helper thread, for a free slot of the ring): spins briefly (the other
 * stage is usually a block away), then yields the core. */
template <class Ready>
void waitUntil(Ready&& ready) {
    for (int spins = 0; !ready(); spins++) {
        if (spins < 1024)
            pauseCore();
        else
            std::this_thread::yield();
    }
}

/** Runs blocks 0 .. blocks - 1 through the two stages: `classify(j, stage)` fills and classifies
 * block j into a `Stage` (on the helper thread), `update(stage)` runs on this thread in block
 * order. This thread does not wait for the helper: a block the helper has not delivered when its
 * turn comes (the helper not awake yet, or its core taken by another process) is classified here,
 * and the helper moves past it. False, with nothing done, if the helper thread is busy (another
 * map inserting from another thread): the caller then does all the work itself. */
template <class Stage, class Classify, class Update>
bool run(size_t blocks, Classify& classify, Update& update) {
    std::unique_ptr<Stage[]> ring(new Stage[kRing]);
    std::atomic<size_t> slotHolds[kRing];  // 1 + the block a slot holds; 0: none yet
    for (std::atomic<size_t>& h : slotHolds) h.store(0, std::memory_order_relaxed);
    std::atomic<size_t> nextForHelper{0}, consumed{0};
    std::atomic<bool> done{false};
    auto produce = [&]() {
        try {
            for (;;) {
                const size_t j = nextForHelper.fetch_add(1, std::memory_order_relaxed);
                if (j >= blocks) return;
                // Slot j % ring is free once block j - ring has been consumed.
                waitUntil([&] {
                    return j < consumed.load(std::memory_order_acquire) + kRing ||
                           done.load(std::memory_order_relaxed);
                });
                if (done.load(std::memory_order_relaxed)) return;
                if (j < consumed.load(std::memory_order_acquire)) continue;  // done here
                classify(j, ring[j % kRing]);
                slotHolds[j % kRing].store(j + 1, std::memory_order_release);
            }
        } catch (...) {
            // Nothing is lost: this thread classifies every block the helper does not deliver.
        }
    };
    HelperThread& helper = HelperThread::shared();
    if (!helper.tryStart(produce)) return false;  // busy with another map: one core
    auto stopHelper = [&] {
        done.store(true, std::memory_order_relaxed);
        helper.wait();  // at most the block it is classifying
    };
    Stage own;  // a block classified on this thread
    try {
        for (size_t j = 0; j < blocks; j++) {
            const std::atomic<size_t>& holds = slotHolds[j % kRing];
            bool ready = holds.load(std::memory_order_acquire) == j + 1;
            // Wait briefly for a block the helper has claimed (about one block's work).
            for (int spin = 0;
                 !ready && spin < 64 && nextForHelper.load(std::memory_order_relaxed) > j; spin++) {
                pauseCore();
                ready = holds.load(std::memory_order_acquire) == j + 1;
            }
            if (ready) {
                update(ring[j % kRing]);
            } else {
                // Keep the helper off block j if it has not claimed it yet.
                size_t next = nextForHelper.load(std::memory_order_relaxed);
                while (next <= j && !nextForHelper.compare_exchange_weak(
                                        next, j + 1, std::memory_order_relaxed)) {
                }
                classify(j, own);
                update(own);
            }
            consumed.store(j + 1, std::memory_order_release);
        }
    } catch (...) {
        stopHelper();
        throw;
    }
    stopHelper();
    return true;
}

}  // namespace pipeline
}  // namespace multibin
