// The G-buffer pass (samples/common/gbuffer_programs.h) on a sample's Context: its ray type,
// entry point and three float4 images, the closest hit each material needs for it, and its
// images as EXR channels.
#pragma once

#include <memory>
#include <vector>

#include "lucent/context.h"
#include "samples/aov.h"
#include "scene/exr_encoder.h"

namespace lucent::samples {

class GBufferPass {
  public:
    /// Declares ray type `ray_type` ("gbuffer") and entry point `entry` on `ctx` (both must be
    /// free: the sample's own come first), reading the 1-element PinholeCamera `camera` and
    /// tracing "top_object".
    GBufferPass(Context& ctx, unsigned ray_type, unsigned entry, std::shared_ptr<Buffer> camera,
                unsigned width, unsigned height);

    /// Gives `material` the G-buffer closest hit; it reads the material's Kd and diffuse_map.
    void add_to(Material& material) const;
    /// The graphs G-buffer rays trace, when the scene holds others whose materials have no
    /// G-buffer hit (IGI's box graph): Context::set_ray_type's roots.
    void set_roots(std::vector<std::shared_ptr<Node>> roots);
    /// Launches the pass; returns its report.
    const LaunchReport& launch();

    /// rgb albedo, a coverage; xyz normal, w instance (-1 background); xyz position, w depth.
    const std::shared_ptr<Buffer>& albedo() const { return m_albedo; }
    const std::shared_ptr<Buffer>& normal() const { return m_normal; }
    const std::shared_ptr<Buffer>& position() const { return m_position; }

    /// The selected layers (and "A", coverage, when `alpha`) as EXR channels, read back.
    std::vector<scene::ExrChannel> channels(const AovSelection& aovs, bool alpha) const;

  private:
    Context& m_ctx;
    unsigned m_ray_type, m_entry, m_width, m_height;
    std::shared_ptr<Program> m_hit;
    std::shared_ptr<Buffer> m_albedo, m_normal, m_position;
};

}  // namespace lucent::samples
