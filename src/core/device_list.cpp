// Device lists: "all", "0,1", "cpu,0", "0,0".
#include <algorithm>
#include <cctype>

#include "backends/backend_factory.h"
#include "lucent/context.h"
#include "lucent/error.h"

namespace lucent {

std::string device_spec_name(const DeviceSpec& device) {
    return device.kind == DeviceSpec::Kind::kCpu ? "cpu" : "cuda:" + std::to_string(device.ordinal);
}

std::vector<DeviceSpec> parse_device_list(const std::string& text) {
    auto lower = [](std::string s) {
        s.erase(std::remove_if(s.begin(), s.end(), [](unsigned char c) { return std::isspace(c); }),
                s.end());
        std::transform(s.begin(), s.end(), s.begin(),
                       [](unsigned char c) { return char(std::tolower(c)); });
        return s;
    };
    const std::string hint = "; write e.g. 0,1 (GPUs 0 and 1), cpu,0 (the CPU and GPU 0) or all";
    const std::string all = lower(text);
    std::vector<DeviceSpec> devices;
    if (all == "all") {
        const int gpus = core::gpu_count();
        for (int g = 0; g < gpus; ++g) devices.push_back({DeviceSpec::Kind::kCuda, g});
        if (devices.empty()) devices.push_back({DeviceSpec::Kind::kCpu, 0});
        devices.resize(std::min<size_t>(devices.size(), kMaxDevices));
        return devices;
    }
    size_t start = 0;
    for (;;) {
        const size_t comma = all.find(',', start);
        const std::string item = all.substr(start, comma == std::string::npos ? comma : comma - start);
        if (item == "cpu") {
            devices.push_back({DeviceSpec::Kind::kCpu, 0});
        } else {
            const bool digits = !item.empty() && item.size() <= 3 &&
                                std::all_of(item.begin(), item.end(),
                                            [](unsigned char c) { return std::isdigit(c); });
            if (!digits)
                throw Error("device list '" + text + "': '" + item +
                            "' is neither a GPU number nor cpu" + hint);
            devices.push_back({DeviceSpec::Kind::kCuda, std::stoi(item)});
        }
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    if (devices.size() > kMaxDevices)
        throw Error("device list '" + text + "': " + std::to_string(devices.size()) +
                    " devices; at most " + std::to_string(kMaxDevices));
    return devices;
}

}  // namespace lucent
