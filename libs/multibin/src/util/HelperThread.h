/* Part of the multibin elevation-mapping library. Private to src/. */
#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

namespace multibin {

/** One thread shared by the whole process that runs one task at a time beside its caller: the
 * second core of the insertion pipeline (BinGrid::insertBlocks) and of the stereo rows
 * (StereoCovarianceTable::appendPoints). A caller that finds it busy
 * (another map inserting from another thread) does all the work itself, so callers never wait on
 * each other. Started on first use, joined at exit. */
class HelperThread {
public:
    static HelperThread& shared();

    /** Starts `task` on the helper if it is idle and returns true; false if it is busy. A
     * started task must be waited for with wait() by the same caller. */
    bool tryStart(std::function<void()> task);
    /** Blocks until the started task has returned. */
    void wait();

    HelperThread(const HelperThread&) = delete;
    HelperThread& operator=(const HelperThread&) = delete;
    ~HelperThread();

private:
    HelperThread();
    void run();

    std::mutex m_mutex;
    std::condition_variable m_wake, m_done;
    std::function<void()> m_task;
    bool m_busy = false, m_stop = false;
    std::thread m_thread;  // last: started once the members above exist
};

}  // namespace multibin
