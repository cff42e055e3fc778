// A fixed set of worker threads that run one job at a time (the caller joins in).
#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace lucent::cpu {

class ThreadPool {
  public:
    /// `threads` workers in all, counting the calling thread; 0 = one per core.
    explicit ThreadPool(unsigned threads);
    ~ThreadPool();
    unsigned size() const { return m_size; }
    /// Runs job(worker) on every worker (0 .. size()-1) and returns when all are done.
    void run(const std::function<void(unsigned worker)>& job);

  private:
    void worker_loop(unsigned worker);
    unsigned m_size;
    std::vector<std::thread> m_threads;
    std::mutex m_mutex;
    std::condition_variable m_start, m_done;
    const std::function<void(unsigned)>* m_job = nullptr;
    uint64_t m_round = 0;
    unsigned m_running = 0;
    bool m_stop = false;
};

}  // namespace lucent::cpu
