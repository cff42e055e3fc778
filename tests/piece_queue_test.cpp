// The host queue a multi-device launch is taken from (src/core/piece_queue.h): pieces cover
// the launch once, in order, in whole rows; they shrink towards the end; a device's share
// follows its speed; a device too slow to finish a piece before the others finish the rest
// takes none.
#include <gtest/gtest.h>

#include "core/piece_queue.h"

namespace lucent::core {
namespace {

LaunchSpec spec_of(unsigned w, unsigned h) {
    LaunchSpec s;
    s.size = uint3{w, h, 1};
    return s;
}

TEST(PieceQueue, PiecesCoverTheLaunchOnceInWholeRows) {
    const LaunchSpec s = spec_of(100, 1000);
    PieceQueue queue(s, {0.0, 0.0}, 0);
    uint64_t next = 0;
    std::vector<uint64_t> sizes;
    for (unsigned turn = 0;; ++turn) {
        auto piece = queue.take(turn % 2);
        if (!piece) break;
        EXPECT_EQ(piece->first, next);
        EXPECT_EQ(piece->first % 100, 0u);
        EXPECT_EQ(piece->last % 100, 0u);
        EXPECT_GT(piece->last, piece->first);
        sizes.push_back(piece->last - piece->first);
        next = piece->last;
    }
    EXPECT_EQ(next, 100u * 1000u);
    // Guided: each piece half an equal share of what is left (1000 / 4 = 250 rows first),
    // never below 4 rows, shrinking towards the end.
    EXPECT_EQ(sizes.front(), 250u * 100u);
    for (size_t i = 1; i < sizes.size(); ++i) EXPECT_LE(sizes[i], sizes[i - 1]);
    EXPECT_GE(sizes.back(), 1u * 100u);
}

TEST(PieceQueue, AFasterDeviceTakesLargerPieces) {
    PieceQueue queue(spec_of(10, 1000), {3.0, 1.0}, 0);
    const auto fast = queue.take(0), slow = queue.take(1);
    ASSERT_TRUE(fast && slow);
    // Half of 3/4 of 1000 rows, then half of 1/4 of the 625 left.
    EXPECT_EQ(fast->last - fast->first, 375u * 10u);
    EXPECT_EQ(slow->last - slow->first, 79u * 10u);
}

TEST(PieceQueue, ADeviceThatWouldFinishLastTakesNothing) {
    // The CPU beside a GPU 1000 times faster: the GPU finishes all 1000 rows before the CPU
    // finishes 4.
    PieceQueue queue(spec_of(10, 1000), {1000.0, 1.0}, 0);
    EXPECT_FALSE(queue.take(1));
    uint64_t taken = 0;
    while (auto piece = queue.take(0)) taken += piece->last - piece->first;
    EXPECT_EQ(taken, 10u * 1000u) << "the fastest device always takes, so all is handed out";
}

TEST(PieceQueue, FixedPiecesAndOneRowLaunches) {
    PieceQueue rows(spec_of(10, 9), {0.0}, 4);
    EXPECT_EQ(rows.take(0)->last, 40u);
    EXPECT_EQ(rows.take(0)->last, 80u);
    EXPECT_EQ(rows.take(0)->last, 90u);
    EXPECT_FALSE(rows.take(0));
    // A one-row launch is cut in runs of 64 indices, the last one short.
    PieceQueue line(spec_of(1000, 1), {0.0}, 2);
    EXPECT_EQ(line.take(0)->last, 128u);
    uint64_t last = 0;
    while (auto piece = line.take(0)) last = piece->last;
    EXPECT_EQ(last, 1000u);
}

}  // namespace
}  // namespace lucent::core
