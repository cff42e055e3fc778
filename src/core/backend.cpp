// What every backend shares: a whole launch as one piece, and copies through host storage.
#include "core/backend.h"

#include <algorithm>

namespace lucent::core {

void Backend::launch(const CompiledScene& scene, const LaunchSpec& spec, LaunchReport& report) {
    begin_launch(scene, spec, report);
    if (spec.next_piece) {
        while (auto piece = spec.next_piece()) run_piece(*piece);
    } else if (spec.on_rows && uses_host_storage() && spec.by_rows()) {
        // Bands of rows, each reported as it finishes: about 32 per launch, at least 8 rows
        // (the CPU's tile height), so the pauses between bands cost little.
        const uint64_t rows = uint64_t(spec.size.y) * spec.size.z;
        const uint64_t band = std::max<uint64_t>(8, (rows / 32 + 7) / 8 * 8);
        for (uint64_t r = 0; r < rows; r += band) {
            const uint64_t end = std::min(rows, r + band);
            run_piece({r * spec.size.x, end * spec.size.x});
            spec.on_rows(unsigned(end), unsigned(rows));
        }
    } else {
        run_piece({0, spec.count()});
    }
    end_launch(report);
    publish_outputs();
}

std::shared_ptr<DisplayFrame> Backend::display_frame(const Buffer& output) {
    const uint3 size = output.size();
    return DisplayFrame::from_linear(size.x, size.y, output.data<float4>());  // data() fetches
}

void Backend::copy_range_to(Backend& target, const Buffer& buffer, size_t offset, size_t bytes) {
    if (!uses_host_storage()) download_range(buffer, offset, bytes);
    if (!target.uses_host_storage()) target.upload_range(buffer, offset, bytes);
}

}  // namespace lucent::core
