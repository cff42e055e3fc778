// A fixed set of worker threads that run one job at a time (the caller joins in).
#pragma once

#include <atomic>
#include <condition_variable>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <semaphore>
#include <thread>
#include <vector>

namespace lucent::cpu {

class ThreadPool {
  public:
    /// The most workers a pool takes (the CLI's --threads range): far more than any machine's
    /// cores, few enough that the threads' stacks fit in memory.
    static constexpr unsigned kMaxThreads = 4096;

    /// `threads` workers in all, counting the calling thread; 0 = one per core. Throws
    /// lucent::Error for more than kMaxThreads, or when the system refuses a thread (after
    /// joining those already started, so nothing is left waiting).
    explicit ThreadPool(unsigned threads);
    ~ThreadPool();
    unsigned size() const { return m_size; }
    /// Runs job(worker) on workers 0 .. min(size(), max_workers)-1 and returns when all are
    /// done. Only those workers are woken (each has its own semaphore), so a pool far larger
    /// than the work (--threads 4096 on a 32x32 image) costs nothing per launch. An
    /// exception thrown by the job on any worker is rethrown here once every worker is done
    /// (the calling thread's own first).
    void run(const std::function<void(unsigned worker)>& job, unsigned max_workers = ~0u);

  private:
    void worker_loop(unsigned worker);
    void stop_and_join();
    unsigned m_size;
    std::vector<std::thread> m_threads;
    // m_wake[w - 1] starts worker w for one job (or, with m_stop, ends it).
    std::vector<std::unique_ptr<std::binary_semaphore>> m_wake;
    std::mutex m_mutex;
    std::condition_variable m_done;
    const std::function<void(unsigned)>* m_job = nullptr;
    unsigned m_running = 0;  // woken workers not finished yet (under m_mutex)
    std::exception_ptr m_worker_error;  // the first a worker's job threw (under m_mutex)
    std::atomic<bool> m_stop{false};
};

}  // namespace lucent::cpu
