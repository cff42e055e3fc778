// The list of samples, and the checked reading of their --set options.
#include <charconv>
#include <cmath>
#include <sstream>
#include <type_traits>
#include <utility>

#include "samples/direct/direct.h"
#include "samples/fog/fog.h"
#include "samples/igi/igi.h"
#include "samples/pathtracer/pathtracer.h"
#include "samples/radiosity/radiosity.h"
#include "samples/sample.h"
#include "samples/settings_error.h"
#include "samples/whitted/whitted.h"

namespace lucent::samples {
namespace {

std::string option_names(const SampleInfo& info) {
    if (info.options.empty()) return "it has no options";
    std::string names = "its options are ";
    for (size_t i = 0; i < info.options.size(); ++i)
        names += (i ? ", " : "") + info.options[i].name;
    return names;
}

const SampleOption& declared_option(const SampleInfo& info, const std::string& name) {
    for (const SampleOption& option : info.options)
        if (option.name == name) return option;
    // The sample reads an option it never declared: a bug in the sample, not user input.
    throw Error("sample '" + info.name + "' reads option '" + name +
                "' that its SampleInfo does not declare; add it to SampleInfo::options");
}

/// The --set value if given, else the declared default; and whether it came from --set.
std::pair<std::string, bool> option_text(const RenderSettings& s, const SampleInfo& info,
                                         const std::string& name) {
    const SampleOption& option = declared_option(info, name);
    auto it = s.sets.find(name);
    if (it != s.sets.end()) return {it->second, true};
    return {option.default_value, false};
}

template <class T>
[[noreturn]] void bad_value(const SampleInfo& info, const std::string& name,
                            const std::string& text, bool from_set, const char* reason, T lo,
                            T hi) {
    std::ostringstream msg;
    if (from_set)
        msg << "--set " << name << "=" << text << ": " << reason;
    else  // a default outside its own range is the sample's bug, reported the same way
        msg << "sample '" << info.name << "': the default " << name << "=" << text << " is "
            << reason;
    msg << "; expected " << (std::is_integral_v<T> ? "an integer" : "a number") << " in [" << lo
        << ", " << hi << "]";
    const std::string& help = declared_option(info, name).help;
    if (!help.empty()) msg << " (" << name << ": " << help << ")";
    if (from_set) throw SettingsError(msg.str());
    throw Error(msg.str());
}

template <class T>
T parse_option(const RenderSettings& s, const SampleInfo& info, const std::string& name, T lo,
               T hi) {
    auto [text, from_set] = option_text(s, info, name);
    // from_chars rejects a leading '+', which people write; accept it.
    const char* begin = text.data() + (!text.empty() && text[0] == '+' ? 1 : 0);
    const char* end = text.data() + text.size();
    T value{};
    auto [ptr, ec] = std::from_chars(begin, end, value);
    if (text.empty() || ec == std::errc::invalid_argument || ptr != end)
        bad_value(info, name, text, from_set,
                  std::is_integral_v<T> ? "not an integer" : "not a number", lo, hi);
    if (ec == std::errc::result_out_of_range || !std::isfinite(double(value)) || value < lo ||
        value > hi)
        bad_value(info, name, text, from_set, "out of range", lo, hi);
    return value;
}

}  // namespace

const std::vector<SampleInfo>& all_samples() {
    static const std::vector<SampleInfo> samples = {
        whitted_sample_info(), direct_sample_info(),     igi_sample_info(),
        radiosity_sample_info(), pathtracer_sample_info(), fog_sample_info()};
    return samples;
}

const SampleInfo& find_sample(const std::string& name) {
    std::string names;
    for (const SampleInfo& info : all_samples()) {
        if (info.name == name) return info;
        names += (names.empty() ? "" : ", ") + info.name;
    }
    throw SettingsError("--sample " + name + ": no such sample; the samples are " + names);
}

float get_float_option(const RenderSettings& s, const SampleInfo& info, const std::string& name,
                       float lo, float hi) {
    return parse_option<float>(s, info, name, lo, hi);
}

int get_int_option(const RenderSettings& s, const SampleInfo& info, const std::string& name, int lo,
                   int hi) {
    return parse_option<int>(s, info, name, lo, hi);
}

std::string get_string_option(const RenderSettings& s, const SampleInfo& info,
                              const std::string& name) {
    return option_text(s, info, name).first;
}

void check_options(const RenderSettings& s, const SampleInfo& info) {
    for (const auto& [name, value] : s.sets) {
        bool known = false;
        for (const SampleOption& option : info.options) known |= option.name == name;
        if (!known)
            throw SettingsError("--set " + name + "=" + value + ": sample '" + info.name +
                                "' has no option '" + name + "'; " + option_names(info));
    }
}

}  // namespace lucent::samples
