// A Context spanning ranks (lucent/ranks.h), at the library's level. ctest runs this binary
// under `mpirun -np 3` (tests/CMakeLists.txt); every rank runs every test, as an SPMD
// program does. Without MPI (or a launcher) the group is this process alone, and the same
// tests check the distributed path with one rank.
#include <gtest/gtest.h>

#include <cstring>

#include "lucent/ranks.h"
#include "samples/sample.h"

namespace {

using lucent::RankError;
using lucent::Ranks;
using lucent::samples::find_sample;
using lucent::samples::RenderResult;
using lucent::samples::RenderSettings;

std::shared_ptr<Ranks> world() {
    static std::shared_ptr<Ranks> ranks = Ranks::world();
    return ranks;
}

RenderSettings small(const std::string& sample_spp = "") {
    RenderSettings s;
    s.width = 48;
    s.height = 40;
    s.backend = lucent::BackendKind::kCpu;
    s.threads = 1;
    if (!sample_spp.empty()) s.spp = unsigned(std::stoul(sample_spp));
    return s;
}

bool same_bytes(const lucent::scene::Image& a, const lucent::scene::Image& b) {
    return a.width == b.width && a.height == b.height && a.pixels.size() == b.pixels.size() &&
           std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(a.pixels[0])) ==
               0;
}

/// Each rank renders once across all ranks and once alone: both images must be the same
/// bytes, on every rank (every rank's outputs hold the whole image after a launch).
/// `last_spread`: the sample's last launch writes only launch-shaped outputs, so it is spread
/// (IGI's last one, at a quarter of the image, is too small to be).
void expect_one_process_image(const std::string& sample, RenderSettings settings,
                              bool last_spread = true) {
    const RenderResult alone = find_sample(sample).render(settings);
    settings.ranks = world();
    const RenderResult spread = find_sample(sample).render(settings);
    EXPECT_TRUE(same_bytes(alone.image, spread.image))
        << sample << " on rank " << world()->rank() << " of " << world()->size();
    if (!last_spread) return;
    if (world()->size() == 1) {  // one rank: launches run whole, as without ranks
        EXPECT_TRUE(spread.report.ranks.empty());
        return;
    }
    // The last launch was spread: the ranks' pieces cover it exactly once. (Which rank took
    // how many depends on timing: on CI's two cores a descheduled rank may take none.)
    ASSERT_EQ(spread.report.ranks.size(), size_t(world()->size()));
    uint64_t indices = 0, pieces = 0;
    for (const auto& share : spread.report.ranks) {
        indices += share.indices;
        pieces += share.pieces;
    }
    EXPECT_EQ(indices, uint64_t(settings.width) * settings.height);
    EXPECT_GE(pieces, 2u * uint64_t(world()->size()));
}

TEST(Distributed, WhittedEqualsOneProcessOnEveryRank) {
    expect_one_process_image("whitted", small());
}

TEST(Distributed, PathTracerFramesEqualOneProcess) {
    expect_one_process_image("pathtracer", small("6"));
}

TEST(Distributed, IgiPassesEqualOneProcess) {
    RenderSettings s = small();
    s.sets = {{"vpls", "16"}};
    expect_one_process_image("igi", s, false);
}

TEST(Distributed, DivergedVariableIsAnErrorOnEveryRank) {
    RenderSettings s = small("1");
    s.ranks = world();
    // The last rank traces shorter paths: a record's variable differs.
    if (world()->rank() == world()->size() - 1 && world()->size() > 1)
        s.sets = {{"max_depth", "3"}};
    if (world()->size() == 1) GTEST_SKIP() << "one rank: nothing can diverge";
    try {
        find_sample("pathtracer").render(s);
        FAIL() << "rank " << world()->rank() << ": no error";
    } catch (const RankError& e) {
        EXPECT_EQ(e.failed_rank(), -1);
        EXPECT_NE(std::string(e.what()).find("ranks diverged: the launch of rank " +
                                             std::to_string(world()->size() - 1)),
                  std::string::npos)
            << e.what();
    }
}

TEST(Distributed, FailureOnOneRankReachesEveryRank) {
    if (world()->size() == 1) GTEST_SKIP() << "one rank: nothing to reach";
    const int failing = 1;
    RenderSettings s = small();
    s.ranks = world();
    try {
        if (world()->rank() == failing) {
            // What a missing scene file on one node does: this rank never reaches the launch.
            const std::string failure = "cannot open scene file '/data/missing.obj'";
            world()->agree(&failure);
        } else {
            find_sample("whitted").render(s);  // waits in the first launch's agreement
        }
        FAIL() << "rank " << world()->rank() << ": no error";
    } catch (const RankError& e) {
        EXPECT_EQ(e.failed_rank(), failing);
        EXPECT_STREQ(e.what(), "rank 1: cannot open scene file '/data/missing.obj'");
    }
    // The ranks are in step again: a launch after the failure runs.
    expect_one_process_image("whitted", small());
}

TEST(Distributed, AgreementWithoutFailureReturns) {
    EXPECT_NO_THROW(world()->agree());
    EXPECT_GE(world()->rank(), 0);
    EXPECT_LT(world()->rank(), world()->size());
}

}  // namespace
