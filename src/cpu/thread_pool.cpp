#include "cpu/thread_pool.h"

#include <algorithm>
#include <exception>

#include "lucent/error.h"

namespace lucent::cpu {

ThreadPool::ThreadPool(unsigned threads) {
    m_size = threads ? threads : std::max(1u, std::thread::hardware_concurrency());
    if (m_size > kMaxThreads)
        throw Error("CPU backend: " + std::to_string(m_size) + " threads requested; at most " +
                    std::to_string(kMaxThreads) + " (0 = one per core)");
    try {
        m_threads.reserve(m_size - 1);
        m_wake.reserve(m_size - 1);
        for (unsigned w = 1; w < m_size; ++w) {
            m_wake.push_back(std::make_unique<std::binary_semaphore>(0));
            m_threads.emplace_back([this, w] { worker_loop(w); });
        }
    } catch (const std::exception& e) {
        // The system refused a thread (a process or memory limit): stop and join the ones
        // already started, which would otherwise wait for a job for ever, then say so.
        const size_t started = m_threads.size() + 1;  // with the calling thread
        stop_and_join();
        throw Error("CPU backend: cannot start thread " + std::to_string(started + 1) + " of " +
                    std::to_string(m_size) + " (" + e.what() +
                    "); ask for fewer (--threads N, ContextOptions::threads; 0 = one per core) "
                    "or raise the process limit (ulimit -u)");
    }
}

ThreadPool::~ThreadPool() {
    stop_and_join();
}

void ThreadPool::stop_and_join() {
    m_stop = true;
    for (size_t i = 0; i < m_threads.size(); ++i) m_wake[i]->release();
    for (auto& t : m_threads) t.join();
    m_threads.clear();
}

void ThreadPool::run(const std::function<void(unsigned)>& job, unsigned max_workers) {
    const unsigned workers = std::clamp(max_workers, 1u, m_size);
    {
        std::lock_guard lock(m_mutex);
        m_job = &job;
        m_running = workers - 1;
    }
    for (unsigned w = 1; w < workers; ++w) m_wake[w - 1]->release();
    std::exception_ptr error;
    try {
        job(0);
    } catch (...) {
        error = std::current_exception();  // rethrown once no worker still runs `job`
    }
    {
        std::unique_lock lock(m_mutex);
        m_done.wait(lock, [this] { return m_running == 0; });
        m_job = nullptr;
        if (!error) error = m_worker_error;  // the caller's own first, else a worker's
        m_worker_error = nullptr;
    }
    if (error) std::rethrow_exception(error);
}

void ThreadPool::worker_loop(unsigned worker) {
    for (;;) {
        m_wake[worker - 1]->acquire();
        if (m_stop) return;
        const std::function<void(unsigned)>* job;
        {
            std::lock_guard lock(m_mutex);
            job = m_job;
        }
        std::exception_ptr error;
        try {
            (*job)(worker);
        } catch (...) {
            // Thrown on a worker thread it would end the process: run() rethrows it.
            error = std::current_exception();
        }
        {
            std::lock_guard lock(m_mutex);
            if (error && !m_worker_error) m_worker_error = error;
            if (--m_running == 0) m_done.notify_one();
        }
    }
}

}  // namespace lucent::cpu
