// A sample's typed options (--set NAME=VALUE): each declares its kind, default, accepted range
// and help once, and everything else derives from that declaration: `lucent render --help`,
// the checked reading of --set values, and the viewer's controls (slider, checkbox, text).
#pragma once

#include <map>
#include <string>
#include <vector>

namespace lucent::samples {

enum class OptionKind {
    kInteger,  // a whole number in [lo, hi]
    kNumber,   // a real number in [lo, hi]
    kSwitch,   // 0 (off) or 1 (on)
    kText,     // any text (a file name, say)
};

/// One `--set` option of a sample.
struct SampleOption {
    std::string name;
    OptionKind kind = OptionKind::kText;
    std::string default_value;  // as --help shows it and --set would give it
    double lo = 0, hi = 0;      // kInteger and kNumber: the accepted range
    std::string help;  // one line without the range (help_with_range() adds it); a switch's
                       // says what 0 and 1 mean

    static SampleOption integer(std::string name, int default_value, int lo, int hi,
                                std::string help);
    static SampleOption number(std::string name, float default_value, float lo, float hi,
                               std::string help);
    static SampleOption toggle(std::string name, bool default_on, std::string help);
    static SampleOption text(std::string name, std::string default_value, std::string help);

    /// The accepted values as --help shows them: "1..256", "0 or 1"; "" for text.
    std::string range() const;
    /// The help with the range of a number or an integer, "deepest ray tree (1..31)".
    std::string help_with_range() const;
};

/// The option values of one render, every one checked against its declaration: built from
/// the --set values (RenderSettings::sets) and the defaults. Throws SettingsError naming the
/// option, the value and the accepted range for a bad --set, or an unknown name with the
/// list of the sample's options.
class OptionValues {
  public:
    OptionValues(const std::string& sample, const std::vector<SampleOption>& options,
                 const std::map<std::string, std::string>& sets);

    int integer(const std::string& name) const;      // kInteger
    float number(const std::string& name) const;     // kNumber
    bool on(const std::string& name) const;          // kSwitch
    const std::string& text(const std::string& name) const;  // any kind, as given

  private:
    struct Value {
        OptionKind kind;
        std::string text;
        double number = 0;
    };
    const Value& value(const std::string& name, OptionKind kind) const;

    std::string m_sample;
    std::map<std::string, Value> m_values;
};

}  // namespace lucent::samples
