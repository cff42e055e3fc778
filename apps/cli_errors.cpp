#include "cli_errors.h"

#include <algorithm>
#include <cctype>
#include <regex>
#include <sstream>
#include <vector>

#include "samples/nearest_name.h"

namespace lucent::cli {

namespace {

/// The subcommands on the command line, outermost first (CLI11 marks each parsed as it
/// reaches it, also when a later argument fails).
std::vector<CLI::App*> parsed_chain(CLI::App& app) {
    std::vector<CLI::App*> chain{&app};
    for (;;) {
        CLI::App* next = nullptr;
        for (CLI::App* sub : chain.back()->get_subcommands({}))
            if (sub->parsed()) next = sub;
        if (!next) return chain;
        chain.push_back(next);
    }
}

std::vector<std::string> subcommand_names(CLI::App& app) {
    std::vector<std::string> names;
    for (CLI::App* sub : app.get_subcommands({})) names.push_back(sub->get_name());
    return names;
}

std::vector<std::string> flag_names(const CLI::App& app) {
    std::vector<std::string> names;
    for (const CLI::Option* option : app.get_options()) {
        for (const std::string& l : option->get_lnames()) names.push_back("--" + l);
        for (const std::string& s : option->get_snames()) names.push_back("-" + s);
    }
    return names;
}

std::string join(const std::vector<std::string>& names) {
    std::string out;
    for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
    return out;
}

/// The word after the last parsed subcommand's name on the command line: the one that
/// should have been a subcommand.
std::string word_after(const std::vector<CLI::App*>& chain, int argc, const char* const* argv) {
    size_t matched = 1;  // chain[0] is the program itself
    for (int i = 1; i < argc; ++i) {
        const std::string word = argv[i];
        if (matched < chain.size() && word == chain[matched]->get_name()) {
            ++matched;
            continue;
        }
        if (matched == chain.size() && !word.empty() && word[0] != '-') return word;
    }
    return "";
}

/// CLI11's own wording, reworded where it is unclear.
std::string reworded(const std::string& what) {
    static const std::regex range(R"((\S+): Value (\S*) not in range (\S+) to (\S+))");
    static const std::regex missing(R"(1 required (\S+) missing)");
    std::string text = std::regex_replace(what, range, "$1 '$2': expected a number in [$3, $4]");
    text = std::regex_replace(text, missing, "needs a value ($1)");
    return text;
}

}  // namespace

UsageMessage usage_message(CLI::App& app, const CLI::ParseError& error, int argc,
                           const char* const* argv) {
    const std::vector<CLI::App*> chain = parsed_chain(app);
    CLI::App& command = *chain.back();
    UsageMessage out;
    out.where = "lucent";
    for (size_t i = 1; i < chain.size(); ++i) out.where += " " + chain[i]->get_name();
    const std::string help = "; run `" + out.where + " --help`";
    const std::string what = error.what();

    if (what.find("subcommand is required") != std::string::npos) {
        const std::vector<std::string> names = subcommand_names(command);
        const std::string typed = word_after(chain, argc, argv);
        out.text = typed.empty()
                       ? "a command is needed: " + join(names) + help
                       : "'" + typed + "' is not a command" +
                             samples::did_you_mean(typed, names) + "; the commands are " +
                             join(names);
        return out;
    }
    if (dynamic_cast<const CLI::RequiredError*>(&error)) {
        // A required argument missing beside a flag the command does not have: the unknown
        // flag is the likelier mistake (a typo that swallowed the argument), so it is named.
        const std::vector<std::string> flags = flag_names(command);
        for (int i = 1; i < argc; ++i) {
            std::string word = argv[i];
            if (word.size() < 2 || word[0] != '-' || std::isdigit((unsigned char)word[1]) || word[1] == '.')
                continue;  // not a flag: a word or a negative number
            word = word.substr(0, word.find('='));
            if (std::find(flags.begin(), flags.end(), word) != flags.end() || word == "--help" ||
                word == "-h")
                continue;
            out.text = "unknown flag " + word + samples::did_you_mean(word, flags) + help;
            return out;
        }
    }
    if (dynamic_cast<const CLI::ExtrasError*>(&error)) {
        // "The following argument(s) was/were not expected: b a": CLI11 lists them last first.
        std::vector<std::string> extras;
        std::istringstream words(what.substr(what.find(": ") + 2));
        for (std::string w; words >> w;) extras.insert(extras.begin(), w);
        std::string text;
        bool after_flag = false;
        for (const std::string& w : extras) {
            const bool flag = !w.empty() && w[0] == '-';
            if (!flag && after_flag) {  // the unknown flag's value
                after_flag = false;
                continue;
            }
            after_flag = flag;
            if (!text.empty()) text += "; ";
            if (flag)
                text += "unknown flag " + w + samples::did_you_mean(w, flag_names(command));
            else
                text += "unexpected argument '" + w + "'" +
                        samples::did_you_mean(w, subcommand_names(command));
        }
        out.text = text + help;
        return out;
    }
    out.text = reworded(what) + help;
    return out;
}

}  // namespace lucent::cli
