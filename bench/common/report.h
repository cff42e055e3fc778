// The one reporter of the benchmarks: each benchmark measures into a result struct and
// says how that result reads as text and as JSON; report() prints one or the other. The
// JSON is built with nlohmann-json, so any text in it (a scene path with a quote, a
// device name) is escaped, and the document always parses.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "bench/common/rate.h"
#include "lucent/error.h"

namespace lucent::bench {

/// Keys stay in the order they were written, as the text reports list them.
using Json = nlohmann::ordered_json;

/// `value` rounded to `decimals` places: the JSON figures keep the precision the
/// benchmark measures to, not the noise below it.
double rounded(double value, int decimals);

/// {"mrays": median, "min": .., "max": ..}, each to 4 places.
Json rate_json(const Rate& rate);

/// The document as printed: two-space indents, one key per line, then a newline; bytes
/// of a string that are not UTF-8 are written as U+FFFD.
std::string json_text(const Json& document);

/// Writes json_text(document) to stdout, or, while a JsonCapture lives on this thread, hands
/// it to that capture instead.
void print_json(const Json& document);

/// While it lives, the documents print_json() would write on this thread come here instead
/// of stdout: a benchmark's measurement returned to the program that ran it
/// (bench_rays_json) rather than printed. Captures nest; the innermost takes the document.
class JsonCapture {
  public:
    JsonCapture();
    ~JsonCapture();
    JsonCapture(const JsonCapture&) = delete;
    JsonCapture& operator=(const JsonCapture&) = delete;
    /// The last captured document's text (json_text's form); empty when none came.
    const std::string& text() const { return m_text; }

  private:
    friend void print_json(const Json& document);
    std::string m_text;
    JsonCapture* m_outer;
};

/// A benchmark as a call (bench_rays_json and the others): runs `run(options)` with
/// options.json set and returns the document it would have printed, printing nothing. A
/// benchmark reports a failure by throwing, so a run that printed no document is a fault in
/// it, named by `command`.
template <class Options, class Run>
std::string captured_document(const char* command, Options options, Run run) {
    options.json = true;
    JsonCapture capture;
    run(options);
    if (capture.text().empty())
        throw Error(std::string(command) + ": the benchmark finished without a result");
    return capture.text();
}

/// Prints `result` as JSON (to_json(result), found by argument-dependent lookup) when `json`,
/// else as text (print_text(result)).
template <class Result>
void report(const Result& result, bool json) {
    if (json)
        print_json(to_json(result));
    else
        print_text(result);
}

}  // namespace lucent::bench
