// What the samples share between `lucent render` and `lucent view`: the camera buffer their
// ray-generation program reads, and the interactive session over a scene built once.
#pragma once

#include <memory>
#include <string>

#include "lucent/context.h"
#include "samples/common/camera.h"
#include "samples/sample.h"

namespace lucent::samples {

/// The 1-element sample_common::PinholeCamera buffer a ray-generation program reads.
class CameraBuffer {
  public:
    explicit CameraBuffer(Context& ctx);
    void set(const sample_common::PinholeCamera& camera);
    const std::shared_ptr<Buffer>& buffer() const { return m_buffer; }

  private:
    std::shared_ptr<Buffer> m_buffer;
};

/// An interactive session over a scene built once into context() by the derived class's
/// constructor, which also calls start_at() with the sample's own camera (so the first frame
/// is the render's image); set_camera() puts the viewer's camera in the buffer. A frame
/// launches entry point 0 once into the output set by set_output(); a sample of several
/// passes overrides frame().
class CameraSession : public InteractiveSession {
  public:
    CameraSession(const Sample& sample, const RenderSettings& settings);

    std::string backend() const override { return m_ctx.backend_name(); }
    std::string backend_notice() const override { return m_ctx.backend_notice(); }
    scene::Camera initial_camera() const override { return m_initial; }
    void set_camera(const scene::Camera& camera) override;
    /// Checks the value, then hands every option's value to apply_options().
    bool set_option(const std::string& name, const std::string& value) override;
    FrameResult frame() override;

  protected:
    /// Changes the options in place and returns true, or false when they need the scene
    /// rebuilt. The default: false.
    virtual bool apply_options(const OptionValues&) { return false; }

    Context& context() { return m_ctx; }
    const RenderSettings& settings() const { return m_settings; }
    /// Where the sample's render puts the camera: the viewer's start, and the first frame's.
    void start_at(const scene::Camera& camera, const sample_common::PinholeCamera& pinhole);
    void set_output(std::shared_ptr<Buffer> output) { m_output = std::move(output); }
    /// A frame of several passes: their stages and report, and the pixels of `output`.
    FrameResult frame_of(RenderResult passes, const Buffer& output);
    CameraBuffer& camera() { return m_camera; }

  private:
    const Sample& m_sample;
    RenderSettings m_settings;
    Context m_ctx;
    CameraBuffer m_camera;
    std::shared_ptr<Buffer> m_output;
    scene::Camera m_initial;
};

}  // namespace lucent::samples
