#include "cpu/thread_pool.h"

namespace lucent::cpu {

ThreadPool::ThreadPool(unsigned threads) {
    m_size = threads ? threads : std::max(1u, std::thread::hardware_concurrency());
    for (unsigned w = 1; w < m_size; ++w) m_threads.emplace_back([this, w] { worker_loop(w); });
}

ThreadPool::~ThreadPool() {
    {
        std::lock_guard lock(m_mutex);
        m_stop = true;
    }
    m_start.notify_all();
    for (auto& t : m_threads) t.join();
}

void ThreadPool::run(const std::function<void(unsigned)>& job) {
    {
        std::lock_guard lock(m_mutex);
        m_job = &job;
        m_running = m_size - 1;
        ++m_round;
    }
    m_start.notify_all();
    job(0);
    std::unique_lock lock(m_mutex);
    m_done.wait(lock, [this] { return m_running == 0; });
    m_job = nullptr;
}

void ThreadPool::worker_loop(unsigned worker) {
    uint64_t seen = 0;
    for (;;) {
        const std::function<void(unsigned)>* job;
        {
            std::unique_lock lock(m_mutex);
            m_start.wait(lock, [&] { return m_stop || m_round != seen; });
            if (m_stop) return;
            seen = m_round;
            job = m_job;
        }
        (*job)(worker);
        {
            std::lock_guard lock(m_mutex);
            if (--m_running == 0) m_done.notify_one();
        }
    }
}

}  // namespace lucent::cpu
