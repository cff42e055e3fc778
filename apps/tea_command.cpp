#include "tea_command.h"

#include <cstdio>
#include <vector>

#include "cli_parse.h"
#include "lucent/device/tea.h"
#include "samples/tea/tea_statistics.h"

namespace lucent::cli {

namespace {
/// "v0,v1,..." with each word in decimal or 0x-hex; exactly `count` of them.
std::vector<unsigned> parse_words(const std::string& flag, const std::string& text, size_t count) {
    std::vector<unsigned> words;
    size_t start = 0;
    while (start <= text.size()) {
        size_t end = text.find(',', start);
        if (end == std::string::npos) end = text.size();
        std::string word = text.substr(start, end - start);
        const bool hex = word.size() > 2 && word[0] == '0' && (word[1] == 'x' || word[1] == 'X');
        const std::string digits = hex ? word.substr(2) : word;
        bool ok = !digits.empty() && digits.size() <= (hex ? 8u : 10u);
        unsigned long long value = 0;
        for (char c : digits) {
            int d = std::isdigit(static_cast<unsigned char>(c)) ? c - '0'
                    : hex && std::isxdigit(static_cast<unsigned char>(c))
                        ? std::tolower(static_cast<unsigned char>(c)) - 'a' + 10
                        : -1;
            if (d < 0) ok = false;
            value = value * (hex ? 16 : 10) + unsigned(d < 0 ? 0 : d);
        }
        if (!ok || value > 0xffffffffull)
            throw UsageError(flag + " " + cli::quoted(text) + ": " + cli::quoted(word) +
                             " is not a 32-bit word (decimal, or hex with 0x)");
        words.push_back(unsigned(value));
        start = end + 1;
    }
    if (words.size() != count)
        throw UsageError(flag + " " + cli::quoted(text) + ": expected " + std::to_string(count) +
                         " words separated by commas, got " + std::to_string(words.size()));
    return words;
}
}  // namespace

CLI::App* add_tea_command(CLI::App& app, TeaArgs& args) {
    CLI::App* cmd =
        app.add_subcommand("tea", "Encrypt a block with TEA (the fog sample's random numbers)");
    cmd->add_option("--block", args.block, "The two 32-bit words to encrypt")
        ->type_name("V0,V1")
        ->capture_default_str();
    cmd->add_option("--key", args.key, "The four 32-bit key words")
        ->type_name("K0,K1,K2,K3")
        ->capture_default_str();
    cmd->add_option("--rounds", args.rounds, "TEA rounds, 1..64 (32 is the cipher)")
        ->type_name("N")
        ->check(CLI::Range(1u, 64u).description(""))
        ->capture_default_str();
    cmd->add_flag("--statistics", args.statistics,
                  "Print bit balance, byte chi-square and serial correlation against the round "
                  "count (counter blocks, Zafar et al.'s key)");
    cmd->add_option("--blocks", args.blocks, "Blocks measured per round count, 1000..2^26")
        ->type_name("N")
        ->check(CLI::Range(1000u, 1u << 26).description(""))
        ->capture_default_str();
    cmd->footer(
        "\nWords are decimal or 0x-hex; the result is two 8-digit hex words.\n"
        "Examples:\n"
        "  lucent tea --block 0,0 --key 0,0,0,0 --rounds 32     # 41ea3a0a 94baa940\n"
        "  lucent tea --block 0x12345678,7 --key 1,2,3,4 --rounds 4\n"
        "  lucent tea --statistics                                # quality against rounds\n");
    return cmd;
}

int run_tea(const TeaArgs& args) {
    if (args.statistics) {
        std::printf(
            "rounds  ones      bit z    byte chi2  p        serial corr  verdict   (%u blocks, %u "
            "bytes)\n",
            args.blocks, args.blocks * 8);
        for (unsigned rounds : {1u, 2u, 3u, 4u, 5u, 6u, 8u, 16u, 32u}) {
            samples::TeaStatistics s = samples::measure_tea(rounds, zafar_tea_key(), args.blocks);
            std::printf("%6u  %.5f  %7.2f  %9.1f  %.4f  %+11.6f  %s\n", rounds, s.ones_fraction,
                        s.bit_balance_z, s.byte_chi_square, s.chi_square_p, s.serial_correlation,
                        s.passes() ? "pass" : "FAIL");
        }
        return 0;
    }
    const std::vector<unsigned> v = parse_words("--block", args.block, 2);
    const std::vector<unsigned> k = parse_words("--key", args.key, 4);
    const uint2 out = tea(make_uint2(v[0], v[1]), make_uint4(k[0], k[1], k[2], k[3]), args.rounds);
    std::printf("%08x %08x\n", out.x, out.y);
    return 0;
}

}  // namespace lucent::cli
