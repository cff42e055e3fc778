#include "render_worker.h"

#include <algorithm>
#include <chrono>
#include <exception>

#include "lucent/error.h"

namespace lucent::viewer {

RenderWorker::RenderWorker(const samples::Sample& sample, samples::RenderSettings settings,
                           uint64_t frame_limit, samples::ViewDenoiser denoiser)
    : m_sample(sample), m_settings(std::move(settings)), m_frame_limit(frame_limit) {
    m_status.denoiser = denoiser;
    m_settings.repeat = 1;
    m_settings.display_frames = true;  // GPU frames stay on the GPU until shown
    m_settings.progress = nullptr;
    m_settings.on_launch_progress = [this](const LaunchProgress& p) { take_rows(p); };
    m_status.sets = m_settings.sets;
    m_status.spp_limit = m_settings.spp;
    m_thread = std::thread([this] { run(); });
}

void RenderWorker::take_rows(const LaunchProgress& p) {
    // The launch's 2D float4 output the size of the shown image (the frame's final image,
    // or an earlier pass of it: IGI's direct light before the composition).
    const Buffer* out = nullptr;
    for (const Buffer* b : p.outputs)
        if (!out && b->dimensionality() == 2 && b->element().tag == type_info_of<float4>().tag)
            out = b;
    if (!out || p.size.z != 1) return;
    const unsigned w = p.size.x, h = p.size.y;
    // A new launch: its rows start again (one of another size, after a resize, may report
    // more rows in its first band than the last launch had).
    if (p.rows_done <= m_partial_rows || w != m_partial_width || h != m_partial_height)
        m_partial_rows = 0;
    m_partial_width = w;
    m_partial_height = h;
    const unsigned first = m_partial_rows;
    m_partial_rows = p.rows_done;
    std::vector<unsigned char> rgba(size_t(w) * (p.rows_done - first) * 4);
    encode_srgb8_rgba(static_cast<const float4*>(out->raw()) + size_t(first) * w,
                      size_t(w) * (p.rows_done - first), rgba.data());

    std::lock_guard lock(m_mutex);
    if (m_partial.number != m_latest.number + 1 || m_partial.width != w || m_partial.height != h) {
        // A new frame in progress: over the last one where it has the same size.
        m_partial = PartialFrame{};
        m_partial.number = m_latest.number + 1;
        m_partial.width = w;
        m_partial.height = h;
        m_partial.rgba = m_latest.display && m_latest.width == w && m_latest.height == h
                             ? m_latest.display->rgba()
                             : std::vector<unsigned char>(size_t(w) * h * 4, 0);
    }
    std::copy(rgba.begin(), rgba.end(), m_partial.rgba.begin() + size_t(first) * w * 4);
    ++m_partial_version;
}

std::optional<PartialFrame> RenderWorker::partial_after(uint64_t shown, uint64_t& version) {
    std::lock_guard lock(m_mutex);
    if (m_partial_version == version || m_partial.number <= shown) return std::nullopt;
    version = m_partial_version;
    return m_partial;
}

RenderWorker::~RenderWorker() {
    {
        std::lock_guard lock(m_mutex);
        m_stop = true;
    }
    m_wake.notify_all();
    m_thread.join();  // a frame in progress finishes first: launches cannot be interrupted
}

void RenderWorker::set_camera(const scene::Camera& camera) {
    {
        std::lock_guard lock(m_mutex);
        m_pending_camera = camera;
    }
    m_wake.notify_all();
}

void RenderWorker::set_option(const std::string& name, const std::string& value) {
    {
        std::lock_guard lock(m_mutex);
        m_pending_sets[name] = value;
        m_status.sets[name] = value;
    }
    m_wake.notify_all();
}

void RenderWorker::reset() {
    {
        std::lock_guard lock(m_mutex);
        m_pending_reset = true;
    }
    m_wake.notify_all();
}

void RenderWorker::set_spp_limit(unsigned spp) {
    {
        std::lock_guard lock(m_mutex);
        m_status.spp_limit = spp;
        // A higher limit (or none) resumes the refinement where it stopped.
        if (m_status.progressive && (spp == 0 || m_latest.samples < spp)) m_converged = false;
    }
    m_wake.notify_all();
}

void RenderWorker::set_denoiser(samples::ViewDenoiser denoiser) {
    {
        std::lock_guard lock(m_mutex);
        m_status.denoiser = denoiser;
        m_pending_denoiser = true;
    }
    m_wake.notify_all();
}

void RenderWorker::set_size(unsigned width, unsigned height) {
    {
        std::lock_guard lock(m_mutex);
        m_pending_size.emplace(width, height);
    }
    m_wake.notify_all();
}

std::optional<ShownFrame> RenderWorker::frame_after(uint64_t after) {
    std::lock_guard lock(m_mutex);
    if (m_latest.number <= after) return std::nullopt;
    return m_latest;
}

WorkerStatus RenderWorker::status() {
    std::lock_guard lock(m_mutex);
    return m_status;
}

uint64_t RenderWorker::frames_done() {
    std::lock_guard lock(m_mutex);
    return m_latest.number;
}

bool RenderWorker::has_work() const {
    if (m_pending_camera || !m_pending_sets.empty() || m_pending_reset || m_pending_denoiser ||
        m_pending_size)
        return true;
    if (m_frame_limit > 0) return m_latest.number < m_frame_limit && m_status.error.empty();
    return !m_converged;
}

void RenderWorker::open_session() {
    m_session = m_sample.open(m_settings);
    std::lock_guard lock(m_mutex);
    m_status.opened = true;
    m_status.progressive = m_session->progressive();
    m_status.backend = m_session->backend();
    m_status.backend_notice = m_session->backend_notice();
    m_status.initial_camera = m_session->initial_camera();
    m_status.denoises = m_session->denoises();
    m_pending_denoiser = m_status.denoiser != samples::ViewDenoiser::kOff;  // a rebuilt one
}

void RenderWorker::run() {
    try {
        open_session();
    } catch (const std::exception& e) {
        std::lock_guard lock(m_mutex);
        m_status.error = e.what();
        return;  // the window stays up and shows why
    }
    {
        std::lock_guard lock(m_mutex);
        if (!m_status.denoises && m_status.denoiser != samples::ViewDenoiser::kOff) {
            m_status.error = std::string("--denoiser ") +
                             samples::view_denoiser_name(m_status.denoiser) + ": the " +
                             m_sample.name + " sample has no denoiser switch (pathtracer has)";
            return;
        }
    }
    scene::Camera camera = m_status.initial_camera;
    while (true) {
        std::optional<scene::Camera> new_camera;
        std::map<std::string, std::string> new_sets;
        bool reset = false;
        std::optional<samples::ViewDenoiser> new_denoiser;
        std::optional<std::pair<unsigned, unsigned>> new_size;
        {
            std::unique_lock lock(m_mutex);
            m_wake.wait(lock, [this] { return m_stop || has_work(); });
            if (m_stop) return;
            new_camera.swap(m_pending_camera);
            new_sets.swap(m_pending_sets);
            new_size.swap(m_pending_size);
            reset = m_pending_reset;
            m_pending_reset = false;
            if (m_pending_denoiser) new_denoiser = m_status.denoiser;
            m_pending_denoiser = false;
            m_status.busy = true;
        }
        const auto start = std::chrono::steady_clock::now();
        ShownFrame shown;
        std::string error;
        try {
            if (new_camera) {
                camera = *new_camera;
                m_session->set_camera(camera);
            }
            bool rebuild = false;
            if (new_size && (new_size->first != m_settings.width ||
                             new_size->second != m_settings.height)) {
                // A session's buffers have its size: open one at the new size.
                m_settings.width = new_size->first;
                m_settings.height = new_size->second;
                rebuild = true;
            }
            for (const auto& [name, value] : new_sets) {
                samples::RenderSettings changed = m_settings;
                changed.sets[name] = value;
                m_sample.read_options(changed);  // checks the value
                if (!m_session->set_option(name, value)) rebuild = true;
                m_settings = changed;
            }
            if (rebuild) {
                // The option changes the scene's shape: build it again where the camera is.
                open_session();
                m_session->set_camera(camera);
            }
            if (reset) m_session->reset();
            samples::ViewDenoiser denoiser = samples::ViewDenoiser::kOff;
            {
                // A rebuilt session above asks for the denoiser again (m_pending_denoiser).
                std::lock_guard lock(m_mutex);
                if (m_pending_denoiser) new_denoiser = m_status.denoiser;
                m_pending_denoiser = false;
                denoiser = m_status.denoiser;
            }
            if (new_denoiser) m_session->set_denoiser(denoiser);
            samples::FrameResult frame = m_session->frame();
            shown.width = frame.display->width();
            shown.height = frame.display->height();
            shown.display = std::move(frame.display);
            shown.stages = std::move(frame.stages);
            shown.samples = frame.samples;
        } catch (const std::exception& e) {
            error = e.what();
        }
        shown.frame_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        std::lock_guard lock(m_mutex);
        m_status.busy = false;
        m_status.error = error;
        m_status.backend = m_session->backend();
        if (!error.empty()) {
            // Show the message and wait for the next change instead of failing again.
            m_converged = true;
            continue;
        }
        shown.number = m_latest.number + 1;
        const unsigned limit = m_status.spp_limit;
        const bool refining = m_session->progressive() && (limit == 0 || shown.samples < limit);
        m_converged = !refining;
        m_latest = std::move(shown);
    }
}

}  // namespace lucent::viewer
