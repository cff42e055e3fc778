// The samples registered by their own .cpp files (RegisterSample), in --help order.
#include <algorithm>
#include <memory>
#include <vector>

#include "samples/nearest_name.h"
#include "samples/sample.h"
#include "samples/settings_error.h"

namespace lucent::samples {
namespace {

struct Registered {
    std::unique_ptr<Sample> sample;
    int help_order;
};

/// Filled during static initialisation, by the registrars of the samples' .cpp files; a
/// function-local static, so it exists before the first registrar runs.
std::vector<Registered>& registry() {
    static std::vector<Registered> samples;
    return samples;
}

}  // namespace

void register_sample(std::unique_ptr<Sample> sample, int help_order) {
    for (const Registered& r : registry())
        if (r.sample->name == sample->name)
            throw Error("two samples are named '" + sample->name + "'; rename one");
    registry().push_back({std::move(sample), help_order});
}

const std::vector<const Sample*>& all_samples() {
    static const std::vector<const Sample*> samples = [] {
        std::vector<Registered*> sorted;
        for (Registered& r : registry()) sorted.push_back(&r);
        std::sort(sorted.begin(), sorted.end(), [](const Registered* a, const Registered* b) {
            return a->help_order != b->help_order ? a->help_order < b->help_order
                                                  : a->sample->name < b->sample->name;
        });
        std::vector<const Sample*> out;
        for (const Registered* r : sorted) out.push_back(r->sample.get());
        return out;
    }();
    return samples;
}

const Sample& find_sample(const std::string& name) {
    std::string names;
    std::vector<std::string> all;
    for (const Sample* sample : all_samples()) {
        if (sample->name == name) return *sample;
        names += (names.empty() ? "" : ", ") + sample->name;
        all.push_back(sample->name);
    }
    throw SettingsError("--sample " + name + ": no such sample" + did_you_mean(name, all) +
                        "; the samples are " + names);
}

void check_aov_support(const Sample& sample, const RenderSettings& settings) {
    if (sample.writes_aovs() || (!settings.aovs.any() && !settings.denoise)) return;
    std::string with;
    for (const Sample* s : all_samples())
        if (s->writes_aovs()) with += (with.empty() ? "" : ", ") + s->name;
    throw SettingsError(std::string(settings.aovs.any() ? "--aov" : "--denoise") +
                        ": sample '" + sample.name +
                        "' has no G-buffer pass; the samples with one are " + with);
}

}  // namespace lucent::samples
