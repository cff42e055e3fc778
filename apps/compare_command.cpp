#include "compare_command.h"

#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "cli_parse.h"
#include "scene/image_compare.h"
#include "scene/image_read.h"

namespace lucent::cli {

CLI::App* add_compare_command(CLI::App& app, CompareArgs& args) {
    CLI::App* cmd = app.add_subcommand(
        "compare", "Compare a test image with a reference: RMSE, relative MSE, PSNR and FLIP");
    cmd->add_option("reference", args.reference, "Reference image (.exr .pfm .hdr .png .jpg ...)")
        ->required()
        ->type_name("REFERENCE");
    cmd->add_option("test", args.test, "Test image, of the reference's size")
        ->required()
        ->type_name("TEST");
    cmd->add_option("--error-image", args.error_image,
                    "Write the FLIP map (grey, 1 = the largest difference): .png, .exr or .pfm")
        ->type_name("FILE");
    cmd->add_option("--ppd", args.pixels_per_degree,
                    "FLIP's observer: pixels per degree of visual angle, 1..1000 (default 67.0: "
                    "a 0.7 m wide 4K monitor seen from 0.7 m)")
        ->type_name("N")
        ->check(CLI::Range(1.0, 1000.0).description(""));
    cmd->add_option("--fail-above", args.fail_above,
                    "Exit 1 when the mean FLIP is above this, for scripts and tests")
        ->type_name("FLIP")
        ->check(CLI::Range(0.0, 1.0).description(""));
    cmd->add_flag("--json", args.json, "Print the figures as one JSON object");
    cmd->footer(
        "RMSE is over linear RGB; relative MSE is (test - ref)^2 / (ref^2 + 0.01) averaged over\n"
        "the channels; PSNR is of the images clamped to [0, 1]; FLIP (Andersson et al. 2020) is\n"
        "LDR-FLIP of the images as displayed, in [0, 1], 0 for identical images.\n"
        "\nExamples:\n"
        "  lucent compare reference.exr render.exr\n"
        "  lucent compare ref.png test.png --error-image flip.png --json\n"
        "  lucent compare ref.pfm test.pfm --fail-above 0.05   # exit 1 when they differ\n");
    return cmd;
}

int run_compare(const CompareArgs& args) {
    if (!args.error_image.empty()) check_image_path("--error-image", args.error_image);
    const scene::Image reference = scene::read_image(args.reference);
    const scene::Image test = scene::read_image(args.test);
    const double ppd = args.pixels_per_degree > 0 ? args.pixels_per_degree : scene::kFlipPixelsPerDegree;
    const scene::ImageComparison c = scene::compare_images(reference, test, ppd);
    if (!args.error_image.empty()) scene::write_image(args.error_image, scene::flip_image(c));
    const bool failed = args.fail_above >= 0 && c.flip_mean > args.fail_above;
    if (args.json) {
        nlohmann::ordered_json j{{"reference", args.reference},
                                 {"test", args.test},
                                 {"width", c.width},
                                 {"height", c.height},
                                 {"rmse", c.rmse},
                                 {"relmse", c.relmse},
                                 {"psnr_db", std::isinf(c.psnr_db) ? nlohmann::ordered_json(nullptr)
                                                                    : nlohmann::ordered_json(c.psnr_db)},
                                 {"flip_mean", c.flip_mean},
                                 {"flip_median", c.flip_median},
                                 {"flip_max", c.flip_max},
                                 {"pixels_per_degree", ppd}};
        if (!args.error_image.empty()) j["error_image"] = args.error_image;
        std::printf("%s\n", j.dump(2).c_str());
    } else {
        std::printf("%ux%u  rmse %.6g  relmse %.6g  psnr %s  flip %.6f (median %.6f, max %.6f)\n",
                    c.width, c.height, c.rmse, c.relmse,
                    std::isinf(c.psnr_db) ? "inf (identical)" : (std::to_string(c.psnr_db) + " dB").c_str(),
                    c.flip_mean, c.flip_median, c.flip_max);
        if (!args.error_image.empty()) std::printf("wrote %s\n", args.error_image.c_str());
    }
    if (failed) {
        std::fflush(stdout);
        std::fprintf(stderr, "lucent compare: mean FLIP %.6f is above --fail-above %g\n",
                     c.flip_mean, args.fail_above);
        return 1;
    }
    return 0;
}

}  // namespace lucent::cli
