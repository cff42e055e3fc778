// What every backend shares: a whole launch as one piece, and copies through host storage.
#include "core/backend.h"

namespace lucent::core {

void Backend::launch(const CompiledScene& scene, const LaunchSpec& spec, LaunchReport& report) {
    begin_launch(scene, spec, report);
    run_piece({0, spec.count()});
    end_launch(report);
    publish_outputs();
}

void Backend::copy_range_to(Backend& target, const Buffer& buffer, size_t offset, size_t bytes) {
    if (!uses_host_storage()) download_range(buffer, offset, bytes);
    if (!target.uses_host_storage()) target.upload_range(buffer, offset, bytes);
}

}  // namespace lucent::core
