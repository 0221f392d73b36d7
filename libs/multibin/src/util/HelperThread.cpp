/* Part of the multibin elevation-mapping library. */
#include "HelperThread.h"

namespace multibin {

HelperThread& HelperThread::shared() {
    static HelperThread helper;
    return helper;
}

HelperThread::HelperThread() : m_thread([this] { run(); }) {}

HelperThread::~HelperThread() {
    {
        const std::lock_guard<std::mutex> lock(m_mutex);
        m_stop = true;
    }
    m_wake.notify_one();
    m_thread.join();
}

bool HelperThread::tryStart(std::function<void()> task) {
    {
        const std::lock_guard<std::mutex> lock(m_mutex);
        if (m_busy || m_stop) return false;
        m_busy = true;
        m_task = std::move(task);
    }
    m_wake.notify_one();
    return true;
}

void HelperThread::wait() {
    std::unique_lock<std::mutex> lock(m_mutex);
    m_done.wait(lock, [this] { return !m_busy; });
}

void HelperThread::run() {
    std::unique_lock<std::mutex> lock(m_mutex);
    for (;;) {
        m_wake.wait(lock, [this] { return m_stop || m_task; });
        if (m_stop) return;
        std::function<void()> task = std::move(m_task);
        m_task = nullptr;
        lock.unlock();
        task();  // tasks catch their own exceptions (BinGrid::insertBlocks passes them back)
        lock.lock();
        m_busy = false;
        m_done.notify_all();
    }
}

}  // namespace multibin
