// The CUDA backend's launch shapes (src/cuda/backend/launch_shapes.h): which carveouts it tries and
// how it settles on one. Pure host logic; the driver's occupancy answer is modelled here on
// sm_90's shared-memory configurations.
#include <gtest/gtest.h>

#ifdef LUCENT_HAVE_CUDA
#include <algorithm>
#include <vector>

#include "cuda/backend/launch_shapes.h"

namespace {

using lucent::cuda::launch_shape_carveouts;
using lucent::cuda::SharedMemoryNeeds;
using lucent::cuda::ShapeTuning;

/// sm_90: the SM's shared memory is one of these configurations (KB); the driver picks the
/// smallest at least the carveout's share of 228 KB, and as many blocks as fit run, at most
/// `by_registers`.
struct Sm90 {
    static constexpr int kConfigsKb[] = {8, 16, 32, 64, 100, 132, 164, 196, 228};
    int by_registers;
    int bytes_per_block;
    /// The configuration the driver picks for a carveout: the smallest holding its share
    /// (8 KB at least, for a kernel with shared memory).
    static int config_kb(int carveout) {
        const double wanted = carveout / 100.0 * 228 * 1024;
        for (int c : kConfigsKb)
            if (c * 1024 >= wanted) return c;
        return 228;
    }
    int operator()(int carveout) const {
        return std::max(1, std::min(by_registers, config_kb(carveout) * 1024 / bytes_per_block));
    }
};

TEST(LaunchShapes, OneCarveoutPerResidentBlockCountFromMostToOne) {
    // The megakernel: 4 blocks by its registers, 5.1 KB of state + 1 KB reserved a block.
    const Sm90 sm{4, 5120 + 1024};
    const SharedMemoryNeeds needs{5120, 1024, 228 * 1024};
    const std::vector<int> carveouts = launch_shape_carveouts(4, needs, sm);
    std::vector<int> blocks;
    for (int c : carveouts) blocks.push_back(sm(c));
    // 3 blocks need the 32 KB configuration, which holds 4: that count is tried once.
    EXPECT_EQ(blocks, (std::vector<int>{4, 2, 1}));
    EXPECT_EQ(carveouts.back(), 0) << "one block: all of L1 but the smallest configuration";
    // Each carveout gets the smallest configuration that holds its blocks: the rest is L1.
    for (size_t i = 0; i < carveouts.size(); ++i) {
        int smallest = 228;
        for (int c : Sm90::kConfigsKb)
            if (c * 1024 >= blocks[i] * sm.bytes_per_block) {
                smallest = c;
                break;
            }
        EXPECT_EQ(Sm90::config_kb(carveouts[i]), smallest) << "carveout " << carveouts[i];
    }
}

TEST(LaunchShapes, WithoutSharedMemoryOneShape) {
    // A kernel without shared memory: every carveout runs every block, so there is one shape.
    const auto any = [](int) { return 8; };
    EXPECT_EQ(launch_shape_carveouts(8, SharedMemoryNeeds{0, 0, 228 * 1024}, any).size(), 1u);
}

TEST(LaunchShapes, TuningTriesEachShapeOnceAfterTwoLaunchesOfTheFirstThenKeepsTheFastest) {
    ShapeTuning tuning(3);
    const double ms[] = {2.0, 1.5, 3.0};  // shape 1 is the fastest
    std::vector<int> tried;
    for (int launch = 0; launch < 4; ++launch) {
        EXPECT_EQ(tuning.choice(), -1) << "still trying at launch " << launch;
        const int shape = tuning.next_shape();
        tried.push_back(shape);
        tuning.record(shape, launch == 0 ? 100.0 : ms[shape]);  // the warm-up is not counted
    }
    EXPECT_EQ(tried, (std::vector<int>{0, 0, 1, 2}));
    EXPECT_EQ(tuning.choice(), 1);
    EXPECT_EQ(tuning.next_shape(), 1);
    tuning.record(1, 50.0);  // later launches do not reopen the choice
    EXPECT_EQ(tuning.choice(), 1);
}

TEST(LaunchShapes, AddedShapesReopenTheChoiceAfterOneUntimedLaunch) {
    ShapeTuning tuning(2);
    for (const auto& [shape, ms] :
         std::vector<std::pair<int, double>>{{0, 9.0}, {0, 2.0}, {1, 3.0}})
        tuning.record(shape, ms);
    ASSERT_EQ(tuning.choice(), 0);
    tuning.add_shapes(2);  // shapes 2 and 3: shape 3 is the fastest of all
    const double ms[] = {2.0, 3.0, 2.5, 1.0};
    std::vector<int> tried;
    for (int launch = 0; launch < 3; ++launch) {
        EXPECT_EQ(tuning.choice(), -1) << "still trying at launch " << launch;
        const int shape = tuning.next_shape();
        tried.push_back(shape);
        tuning.record(shape, launch == 0 ? 100.0 : ms[shape]);  // the new code warms up first
    }
    EXPECT_EQ(tried, (std::vector<int>{2, 2, 3}));
    EXPECT_EQ(tuning.choice(), 3);
    EXPECT_EQ(tuning.next_shape(), 3);
}

TEST(LaunchShapes, OneShapeNeedsNoTrials) {
    ShapeTuning tuning(1);
    EXPECT_EQ(tuning.next_shape(), 0);
    tuning.record(0, 1.0);
    tuning.record(0, 1.0);
    EXPECT_EQ(tuning.choice(), 0);
}

}  // namespace
#endif  // LUCENT_HAVE_CUDA
