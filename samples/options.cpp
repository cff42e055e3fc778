// Typed sample options: the declarations' defaults and ranges, and the checked reading of
// --set values against them.
#include "samples/options.h"

#include "samples/nearest_name.h"

#include <charconv>
#include <cmath>
#include <sstream>
#include <system_error>

#include "samples/settings_error.h"

namespace lucent::samples {
namespace {

/// The shortest text that reads back as `value` ("0.1", "1e+06" → "1e+06").
std::string shortest(float value) {
    char text[32];
    const auto [end, ec] = std::to_chars(text, text + sizeof text, value);
    return std::string(text, ec == std::errc() ? end : text);
}

bool is_integral(OptionKind kind) {
    return kind == OptionKind::kInteger || kind == OptionKind::kSwitch;
}

/// "[lo, hi]" as the message of a value out of range shows it: in the option's own type.
std::string bracketed(const SampleOption& option) {
    std::ostringstream out;
    if (is_integral(option.kind))
        out << "[" << int(option.lo) << ", " << int(option.hi) << "]";
    else
        out << "[" << float(option.lo) << ", " << float(option.hi) << "]";
    return out.str();
}

template <class T>
bool parse(const std::string& text, T& value) {
    // from_chars rejects a leading '+', which people write; accept it.
    const char* begin = text.data() + (!text.empty() && text[0] == '+' ? 1 : 0);
    const char* end = text.data() + text.size();
    auto [ptr, ec] = std::from_chars(begin, end, value);
    if (text.empty() || ec == std::errc::invalid_argument || ptr != end) return false;
    return ec != std::errc::result_out_of_range;
}

}  // namespace

SampleOption SampleOption::integer(std::string name, int default_value, int lo, int hi,
                                   std::string help) {
    return {std::move(name), OptionKind::kInteger, std::to_string(default_value), double(lo),
            double(hi), std::move(help)};
}

SampleOption SampleOption::number(std::string name, float default_value, float lo, float hi,
                                  std::string help) {
    return {std::move(name), OptionKind::kNumber, shortest(default_value), double(lo), double(hi),
            std::move(help)};
}

SampleOption SampleOption::toggle(std::string name, bool default_on, std::string help) {
    return {std::move(name), OptionKind::kSwitch, default_on ? "1" : "0", 0, 1, std::move(help)};
}

SampleOption SampleOption::text(std::string name, std::string default_value, std::string help) {
    return {std::move(name), OptionKind::kText, std::move(default_value), 0, 0, std::move(help)};
}

std::string SampleOption::range() const {
    switch (kind) {
        case OptionKind::kInteger: return std::to_string(int(lo)) + ".." + std::to_string(int(hi));
        case OptionKind::kNumber: return shortest(float(lo)) + ".." + shortest(float(hi));
        case OptionKind::kSwitch: return "0 or 1";
        case OptionKind::kText: break;
    }
    return "";
}

std::string SampleOption::help_with_range() const {
    // A switch's help says what 0 and 1 mean; a text takes any value.
    if (kind == OptionKind::kSwitch || kind == OptionKind::kText) return help;
    return help + " (" + range() + ")";
}

OptionValues::OptionValues(const std::string& sample, const std::vector<SampleOption>& options,
                           const std::map<std::string, std::string>& sets)
    : m_sample(sample) {
    for (const auto& [name, text] : sets) {
        bool known = false;
        for (const SampleOption& option : options) known |= option.name == name;
        if (known) continue;
        std::string names = options.empty() ? "it has no options" : "its options are ";
        std::vector<std::string> all;
        for (size_t i = 0; i < options.size(); ++i) {
            names += (i ? ", " : "") + options[i].name;
            all.push_back(options[i].name);
        }
        throw SettingsError("--set " + name + "=" + text + ": sample '" + sample +
                            "' has no option '" + name + "'" + did_you_mean(name, all) + "; " +
                            names);
    }
    for (const SampleOption& option : options) {
        const auto given = sets.find(option.name);
        const bool from_set = given != sets.end();
        Value v{option.kind, from_set ? given->second : option.default_value};
        const char* reason = nullptr;
        if (is_integral(option.kind)) {
            int i = 0;
            if (!parse(v.text, i)) reason = "not an integer";
            v.number = i;
        } else if (option.kind == OptionKind::kNumber) {
            float f = 0;
            if (!parse(v.text, f)) reason = "not a number";
            v.number = f;
        }
        if (!reason && option.kind != OptionKind::kText &&
            (!std::isfinite(v.number) || v.number < option.lo || v.number > option.hi))
            reason = "out of range";
        if (reason) {
            std::ostringstream msg;
            if (from_set)
                msg << "--set " << option.name << "=" << v.text << ": " << reason;
            else  // a default outside its own range is the sample's bug, reported the same way
                msg << "sample '" << sample << "': the default " << option.name << "=" << v.text
                    << " is " << reason;
            msg << "; expected " << (is_integral(option.kind) ? "an integer" : "a number")
                << " in " << bracketed(option) << " (" << option.name << ": "
                << option.help_with_range() << ")";
            if (from_set) throw SettingsError(msg.str());
            throw Error(msg.str());
        }
        m_values.emplace(option.name, std::move(v));
    }
}

const OptionValues::Value& OptionValues::value(const std::string& name, OptionKind kind) const {
    const auto it = m_values.find(name);
    // Reading an option the sample never declared, or as another kind, is a bug in the
    // sample, not user input.
    if (it == m_values.end())
        throw Error("sample '" + m_sample + "' reads option '" + name +
                    "' that it does not declare; add it to the sample's options");
    if (it->second.kind != kind)
        throw Error("sample '" + m_sample + "' reads option '" + name +
                    "' as another kind than it declares");
    return it->second;
}

int OptionValues::integer(const std::string& name) const {
    return int(value(name, OptionKind::kInteger).number);
}

float OptionValues::number(const std::string& name) const {
    return float(value(name, OptionKind::kNumber).number);
}

bool OptionValues::on(const std::string& name) const {
    return value(name, OptionKind::kSwitch).number != 0;
}

const std::string& OptionValues::text(const std::string& name) const {
    const auto it = m_values.find(name);
    if (it == m_values.end())
        throw Error("sample '" + m_sample + "' reads option '" + name +
                    "' that it does not declare; add it to the sample's options");
    return it->second.text;
}

}  // namespace lucent::samples
