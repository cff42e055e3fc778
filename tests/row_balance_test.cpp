// Re-balancing the rows ranks keep for index-local launches (src/core/row_balance.h): the
// shares follow the measured speeds, every index stays with exactly one rank, what a rank
// gives away is exactly what it held and no longer keeps, cuts fall on granules, rows move
// only between neighbours in rank order, and nothing moves when the ranks are balanced or
// a time is missing; the shared tail is the last rows of each rank, in granules.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "core/row_balance.h"

namespace lucent::core {
namespace {

using Pieces = std::vector<std::vector<LaunchPiece>>;

/// Pieces of `piece` indices taken in turn by `ranks` ranks, as from the shared counter,
/// over `count` indices (the last piece shorter).
Pieces taken_in_turn(unsigned ranks, uint64_t count, uint64_t piece) {
    Pieces kept(ranks);
    for (uint64_t first = 0, k = 0; first < count; first += piece, ++k)
        kept[k % ranks].push_back({first, std::min(count, first + piece)});
    return kept;
}

uint64_t held(const std::vector<LaunchPiece>& pieces) {
    uint64_t n = 0;
    for (const LaunchPiece& p : pieces) n += p.last - p.first;
    return n;
}

/// Owner of every index (-1: none; -2: more than one).
std::vector<int> owners(const Pieces& kept, uint64_t count) {
    std::vector<int> owner(count, -1);
    for (size_t r = 0; r < kept.size(); ++r)
        for (const LaunchPiece& p : kept[r])
            for (uint64_t i = p.first; i < p.last; ++i) owner[i] = owner[i] == -1 ? int(r) : -2;
    return owner;
}

void expect_consistent(const Pieces& before, const RowBalance& balance, uint64_t count,
                       uint64_t granule) {
    const std::vector<int> old_owner = owners(before, count),
                           new_owner = owners(balance.kept, count);
    for (uint64_t i = 0; i < count; ++i) {
        ASSERT_EQ(old_owner[i] >= 0, true) << i;
        ASSERT_GE(new_owner[i], 0) << "index " << i << " kept by no rank or by two";
    }
    // Given: exactly the indices whose owner changed, given by their old owner.
    std::vector<int> given_by(count, -1);
    for (size_t r = 0; r < balance.given.size(); ++r)
        for (const LaunchPiece& p : balance.given[r])
            for (uint64_t i = p.first; i < p.last; ++i) {
                ASSERT_EQ(given_by[i], -1) << "index " << i << " given twice";
                given_by[i] = int(r);
            }
    for (uint64_t i = 0; i < count; ++i) {
        if (old_owner[i] != new_owner[i])
            EXPECT_EQ(given_by[i], old_owner[i]) << i;
        else
            EXPECT_EQ(given_by[i], -1) << i;
    }
    // Cuts on granules: every piece starts on one (the launch's end may end a piece).
    for (const auto& pieces : balance.kept)
        for (const LaunchPiece& p : pieces) {
            EXPECT_EQ(p.first % granule, 0u);
            EXPECT_TRUE(p.last % granule == 0 || p.last == count);
        }
}

TEST(RowBalance, SharesFollowTheMeasuredSpeeds) {
    const uint64_t width = 100, count = width * 2160, granule = 8 * width;
    const Pieces before = taken_in_turn(4, count, 32 * width);
    // Rank 2 ran its rows at half the others' speed.
    std::vector<double> busy;
    for (size_t r = 0; r < 4; ++r) busy.push_back(double(held(before[r])) / (r == 2 ? 5.0 : 10.0));
    const RowBalance balance = balance_rows(before, busy, granule, 0.02);
    ASSERT_TRUE(balance.moved);
    // Balanced: count / 35 ms for all; rank 2 took held / 5.
    EXPECT_NEAR(balance.imbalance, 7.0 * double(held(before[2])) / double(count), 1e-9);
    expect_consistent(before, balance, count, granule);
    // Speeds 10 : 10 : 5 : 10 indices per ms: shares 2/7, 2/7, 1/7, 2/7, within a granule.
    const double expected[] = {2.0 / 7, 2.0 / 7, 1.0 / 7, 2.0 / 7};
    for (size_t r = 0; r < 4; ++r)
        EXPECT_NEAR(double(held(balance.kept[r])), expected[r] * count, double(granule)) << r;
}

TEST(RowBalance, RowsMoveOnlyBetweenNeighboursInRankOrder) {
    const uint64_t count = 64 * 1000, granule = 64;
    const Pieces before = taken_in_turn(3, count, 64 * 20);
    const RowBalance balance = balance_rows(before, {30.0, 10.0, 20.0}, granule, 0.0);
    ASSERT_TRUE(balance.moved);
    expect_consistent(before, balance, count, granule);
    // In the sequence of the ranks' old pieces in rank order, each rank's new rows are one
    // stretch, and the stretches are in rank order.
    std::vector<int> sequence_owner;
    const std::vector<int> new_owner = owners(balance.kept, count);
    for (const auto& pieces : before)
        for (const LaunchPiece& p : pieces)
            for (uint64_t i = p.first; i < p.last; ++i) sequence_owner.push_back(new_owner[i]);
    EXPECT_TRUE(std::is_sorted(sequence_owner.begin(), sequence_owner.end()));
    // The slowest (rank 0, 3x rank 1's time for the same rows) now holds the least.
    EXPECT_LT(held(balance.kept[0]), held(balance.kept[2]));
    EXPECT_LT(held(balance.kept[2]), held(balance.kept[1]));
}

TEST(RowBalance, NothingMovesWhenBalancedOrUnmeasured) {
    const uint64_t count = 64 * 960, granule = 64;
    const Pieces before = taken_in_turn(3, count, 64 * 10);
    const RowBalance balanced = balance_rows(before, {10.0, 10.1, 9.9}, granule, 0.02);
    EXPECT_FALSE(balanced.moved);
    EXPECT_EQ(balanced.kept.size(), 3u);
    for (size_t r = 0; r < 3; ++r) EXPECT_EQ(held(balanced.kept[r]), held(before[r]));
    EXPECT_LT(balanced.imbalance, 1.02);
    EXPECT_FALSE(balance_rows(before, {10.0, 0.0, 10.0}, granule, 0.0).moved);
    EXPECT_FALSE(balance_rows(before, {10.0, 20.0}, granule, 0.0).moved);  // a rank missing
    EXPECT_FALSE(balance_rows({before[0]}, {10.0}, granule, 0.0).moved);   // one rank
}

TEST(RowBalance, AVerySlowRankKeepsAGranule) {
    const uint64_t count = 64 * 512, granule = 64 * 8;
    const Pieces before = taken_in_turn(2, count, 64 * 32);
    const RowBalance balance = balance_rows(before, {1.0, 1e6}, granule, 0.02);
    ASSERT_TRUE(balance.moved);
    expect_consistent(before, balance, count, granule);
    EXPECT_EQ(held(balance.kept[1]), granule);
    EXPECT_EQ(held(balance.kept[0]), count - granule);
}

TEST(RowBalance, RepeatedBalancingConverges) {
    // Rank speeds 1 : 2 : 3 indices per ms; each round measures the busy times the current
    // shares would take and re-balances: after the first round the shares stay put.
    const uint64_t count = 64 * 3000, granule = 64;
    Pieces kept = taken_in_turn(3, count, 64 * 16);
    const double speed[] = {1.0, 2.0, 3.0};
    int moves = 0;
    for (int round = 0; round < 5; ++round) {
        std::vector<double> busy;
        for (size_t r = 0; r < 3; ++r) busy.push_back(double(held(kept[r])) / speed[r]);
        const RowBalance balance = balance_rows(kept, busy, granule, 0.01);
        if (balance.moved) {
            expect_consistent(kept, balance, count, granule);
            ++moves;
        }
        kept = balance.kept;
    }
    EXPECT_EQ(moves, 1);
    for (size_t r = 0; r < 3; ++r)
        EXPECT_NEAR(double(held(kept[r])), count * speed[r] / 6.0, double(granule)) << r;
}

TEST(SharedTail, EachRankGivesItsLastRowsInGranules) {
    const uint64_t width = 64, count = width * 480, granule = 8 * width;
    const Pieces before = taken_in_turn(3, count, 16 * width);
    const SharedTail tail = share_tail(before, 1.0 / 16, granule);
    ASSERT_EQ(tail.kept.size(), 3u);
    // Kept and shared cover the launch once; the shared pieces are a granule each.
    std::vector<int> owner = owners(tail.kept, count);
    for (const LaunchPiece& p : tail.shared) {
        EXPECT_EQ(p.last - p.first, granule);
        EXPECT_EQ(p.first % granule, 0u);
        for (uint64_t i = p.first; i < p.last; ++i) {
            ASSERT_EQ(owner[i], -1) << "index " << i << " both kept and shared";
            owner[i] = 99;
        }
    }
    for (uint64_t i = 0; i < count; ++i) ASSERT_NE(owner[i], -1) << i;
    for (size_t r = 0; r < 3; ++r) {
        // A sixteenth of 160 rows is 10: rounded to whole granules of 8 rows, one granule.
        EXPECT_EQ(held(tail.given[r]), granule) << r;
        EXPECT_EQ(held(tail.kept[r]) + held(tail.given[r]), held(before[r])) << r;
        // Given from the end of the rank's pieces.
        EXPECT_EQ(tail.given[r].back().last, before[r].back().last) << r;
    }
    EXPECT_EQ(tail.shared.size(), 3u);
}

TEST(SharedTail, NoneWithoutAFractionOrWithFewRows) {
    const uint64_t granule = 64;
    const Pieces before = taken_in_turn(2, 64 * 3, 64);  // ranks of 2 and 1 granules
    EXPECT_TRUE(share_tail(before, 0.0, granule).shared.empty());
    const SharedTail tail = share_tail(before, 0.5, granule);
    // Rank 0 keeps one of its two granules; rank 1, holding one, gives none.
    EXPECT_EQ(held(tail.kept[0]), 64u);
    EXPECT_EQ(held(tail.kept[1]), 64u);
    EXPECT_EQ(tail.shared.size(), 1u);
}

}  // namespace
}  // namespace lucent::core
