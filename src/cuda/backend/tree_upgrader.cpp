#include "cuda/backend/tree_upgrader.h"

#include <exception>

#include "cuda/backend/driver_api.h"

namespace lucent::cuda {

TreeUpgrader::~TreeUpgrader() {
    {
        std::lock_guard lock(m_mutex);
        m_stop = true;
        m_queue.clear();  // frees their copies here, where the caller's context is current
    }
    m_wake.notify_all();
    if (m_thread.joinable()) m_thread.join();
}

void TreeUpgrader::submit(const void* group, uint64_t version, const GpuTriangleBvhDevice& tree,
                          const GpuBvhBuildOptions& options) {
    const DriverApi& api = require_driver("tree upgrade");
    Job job;
    job.group = group;
    job.version = version;
    job.count = tree.triangle_count;
    job.options = options;
    job.submitted = std::chrono::steady_clock::now();
    const size_t triangle_bytes = job.count * gpu::kGpuTriangleFloat4s * sizeof(float4);
    const size_t id_bytes = job.count * sizeof(uint32_t);
    job.triangles.alloc(triangle_bytes);
    job.ids.alloc(id_bytes);
    // On the legacy stream, as the GPU build: behind it, and ahead of any later rebuild.
    check(api.cuMemcpyDtoDAsync(job.triangles.ptr(), tree.triangles.ptr(), triangle_bytes, 0),
          "tree upgrade: copy the triangles");
    check(api.cuMemcpyDtoDAsync(job.ids.ptr(), tree.triangle_ids.ptr(), id_bytes, 0),
          "tree upgrade: copy the triangle ids");
    {
        std::lock_guard lock(m_mutex);
        std::erase_if(m_queue, [&](const Job& queued) { return queued.group == group; });
        m_queue.push_back(std::move(job));
        if (!m_thread.joinable()) m_thread = std::thread([this] { run(); });
    }
    m_wake.notify_all();
}

std::vector<TreeUpgrader::Finished> TreeUpgrader::take_finished() {
    std::lock_guard lock(m_mutex);
    return std::exchange(m_finished, {});
}

void TreeUpgrader::wait_idle() {
    std::unique_lock lock(m_mutex);
    m_idle.wait(lock, [&] { return m_queue.empty() && !m_busy; });
}

TreeUpgrader::Finished TreeUpgrader::build(Job& job) {
    Finished done;
    done.group = job.group;
    done.version = job.version;
    try {
        std::vector<float4> triangles(job.count * gpu::kGpuTriangleFloat4s);
        std::vector<uint32_t> ids(job.count);
        // Synchronous copies on the legacy stream: after the device copies submit() queued.
        job.triangles.download(triangles.data(), triangles.size() * sizeof(float4));
        job.ids.download(ids.data(), ids.size() * sizeof(uint32_t));
        const std::vector<float3> positions = layout_input_triangles(triangles, ids);
        done.tree = build_gpu_triangle_bvh(positions, {}, job.options);
    } catch (const std::exception& e) {
        done.tree = {};
        done.error = e.what();
    }
    job.triangles.reset();
    job.ids.reset();
    done.ready_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - job.submitted)
            .count();
    return done;
}

void TreeUpgrader::run() {
    const DriverApi& api = require_driver("tree upgrade");
    const bool current = api.cuCtxSetCurrent(m_context) == CUDA_SUCCESS;
    for (;;) {
        Job job;
        {
            std::unique_lock lock(m_mutex);
            m_wake.wait(lock, [&] { return m_stop || !m_queue.empty(); });
            if (m_stop) break;
            job = std::move(m_queue.front());
            m_queue.pop_front();
            m_busy = true;
        }
        Finished done;
        if (current) {
            done = build(job);
        } else {
            done.group = job.group;
            done.version = job.version;
            done.error = "tree upgrade: cannot make the GPU's context current on its thread";
        }
        {
            std::lock_guard lock(m_mutex);
            m_finished.push_back(std::move(done));
            m_busy = false;
        }
        m_idle.notify_all();
    }
    m_idle.notify_all();
}

}  // namespace lucent::cuda
