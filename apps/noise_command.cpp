#include "noise_command.h"

#include <cstdio>

#include "cli_parse.h"
#include "lucent/device/tea.h"
#include "samples/tea/tea_noise.h"
#include "scene/image_io.h"

namespace lucent::cli {

CLI::App* add_noise_command(CLI::App& app, NoiseArgs& args) {
    CLI::App* cmd =
        app.add_subcommand("noise", "Write a TEA noise image (white, gradient, spectrum)");
    cmd->add_option("--kind", args.kind,
                    "white (64x64), gradient (256x256) or spectrum (1024x1024)")
        ->type_name("KIND")
        ->check(CLI::IsMember({"white", "gradient", "spectrum"}))
        ->capture_default_str();
    cmd->add_option("--rounds", args.rounds, "TEA rounds, 1..64")
        ->type_name("N")
        ->check(CLI::Range(1u, 64u).description(""))
        ->capture_default_str();
    cmd->add_option("--size", args.size, "Image side in pixels, 8..4096 (default: the kind's)")
        ->type_name("N")
        ->check(CLI::Range(8u, 4096u).description(""));
    cmd->add_option("-o,--out", args.out, "Output image: .png, .exr or .pfm")
        ->type_name("FILE")
        ->capture_default_str();
    cmd->add_option("--seed", args.seed,
                    "Draw with a per-device key made from (--device, seed) (Sebald Fig. 4); "
                    "without it, Zafar et al.'s fixed key")
        ->type_name("S")
        ->check(CLI::Range(0ll, 0xffffffffll).description(""));
    cmd->add_option("--device", args.device, "Device identifier for --seed")->type_name("D");
    cmd->footer(
        "\nExamples:\n"
        "  lucent noise --kind white --rounds 4 --out white.png\n"
        "  lucent noise --kind gradient --rounds 2 --seed 1732000000 --out gradient.png\n"
        "  lucent noise --kind spectrum --rounds 4 --out spectrum.png\n");
    return cmd;
}

int run_noise(const NoiseArgs& args) {
    check_image_path("--out", args.out);
    const uint4 key =
        args.seed >= 0
            ? generate_tea_key(zafar_tea_key(), make_uint2(args.device, unsigned(args.seed)))
            : zafar_tea_key();
    scene::Image image;
    if (args.kind == "white") {
        unsigned n = args.size ? args.size : 64;
        image = samples::white_noise(n, n, args.rounds, key);
    } else if (args.kind == "gradient") {
        unsigned n = args.size ? args.size : 256;
        image = samples::gradient_noise(n, n, 32, args.rounds, key);
    } else {
        image = samples::noise_spectrum(args.size ? args.size : 1024, args.rounds, key);
    }
    scene::write_image(args.out, image);
    std::printf("wrote %s (%s noise, %ux%u, %u TEA rounds, %s key)\n", args.out.c_str(),
                args.kind.c_str(), image.width, image.height, args.rounds,
                args.seed >= 0 ? "per-device" : "fixed");
    return 0;
}

}  // namespace lucent::cli
