#include "samples/aov.h"

#include <sstream>

#include "samples/nearest_name.h"
#include "samples/settings_error.h"

namespace lucent::samples {

const std::vector<std::string>& aov_names() {
    static const std::vector<std::string> names = {"albedo", "normal", "depth", "position",
                                                   "instance"};
    return names;
}

namespace {
std::string accepted() {
    std::string out;
    for (const std::string& name : aov_names()) out += (out.empty() ? "" : ", ") + name;
    return out;
}
}  // namespace

AovSelection parse_aovs(const std::string& flag, const std::vector<std::string>& names) {
    std::string all;
    for (const std::string& name : names) all += (all.empty() ? "" : ",") + name;
    AovSelection s;
    if (names.empty())
        throw SettingsError(flag + " '" + all + "': no AOV named; accepted: " + accepted());
    for (const std::string& name : names) {
        bool* field = name == "albedo"     ? &s.albedo
                      : name == "normal"   ? &s.normal
                      : name == "depth"    ? &s.depth
                      : name == "position" ? &s.position
                      : name == "instance" ? &s.instance
                                           : nullptr;
        if (!field)
            throw SettingsError(flag + " '" + all + "': " +
                                (name.empty() ? std::string("an empty AOV name")
                                              : "unknown AOV '" + name + "'" +
                                                    did_you_mean(name, aov_names())) +
                                "; accepted: " + accepted());
        *field = true;
    }
    return s;
}

AovSelection parse_aovs(const std::string& flag, const std::string& text) {
    std::vector<std::string> names;
    std::string name;
    std::istringstream in(text);
    while (std::getline(in, name, ',')) names.push_back(name);
    if (!text.empty() && text.back() == ',') names.push_back("");
    if (text.empty()) names.clear();
    try {
        return parse_aovs(flag, names);
    } catch (const SettingsError& e) {
        // Quote the value as typed, not as re-joined.
        std::string message = e.what();
        const std::string prefix = flag + " '";
        const size_t end = message.find("': ");
        if (message.rfind(prefix, 0) == 0 && end != std::string::npos)
            message = prefix + text + message.substr(end);
        throw SettingsError(message);
    }
}

}  // namespace lucent::samples
