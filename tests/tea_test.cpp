// TEA as the fog sample's generator (Sebald §3.2): the cipher's published vector, the
// per-device keys of Figure 4, and the statistical quality of the output against rounds.
#include <gtest/gtest.h>

#include <vector>

#include <cstdio>
#include <set>
#include <string>

#include "lucent/context.h"
#include "lucent/device/tea.h"
#include "samples/tea/tea_programs.h"
#include "samples/tea/tea_statistics.h"

namespace {

using lucent::tea;

TEST(Tea, PublishedVectorWithThirtyTwoRounds) {
    // Key 0, block 0, 32 rounds: 41ea3a0a 94baa940 (the TEA reference test vector).
    uint2 unrolled = tea<32>(make_uint2(0, 0), make_uint4(0, 0, 0, 0));
    EXPECT_EQ(unrolled.x, 0x41ea3a0au);
    EXPECT_EQ(unrolled.y, 0x94baa940u);
    uint2 looped = tea(make_uint2(0, 0), make_uint4(0, 0, 0, 0), 32);
    EXPECT_EQ(looped.x, 0x41ea3a0au);
    EXPECT_EQ(looped.y, 0x94baa940u);
}

TEST(Tea, UnrolledAndRunTimeRoundCountsAgree) {
    const uint4 key = lucent::zafar_tea_key();
    for (unsigned i = 0; i < 100; ++i) {
        uint2 v = make_uint2(i * 2654435761u, i ^ 0xdeadbeefu);
        auto same = [&](uint2 a, uint2 b) { return a.x == b.x && a.y == b.y; };
        EXPECT_TRUE(same(tea<2>(v, key), tea(v, key, 2)));
        EXPECT_TRUE(same(tea<4>(v, key), tea(v, key, 4)));
        EXPECT_TRUE(same(tea<16>(v, key), tea(v, key, 16)));
    }
}

TEST(Tea, EveryRoundAddsDelta) {
    // The seed's Figure 3 never advances `sum`; with it fixed at 0 two rounds would be the
    // same function twice. Ours differs from that variant from the first round on.
    unsigned v0 = 1, v1 = 2;
    lucent::tea_round(v0, v1, make_uint4(0, 0, 0, 0), 0);
    uint2 ours = tea<1>(make_uint2(1, 2), make_uint4(0, 0, 0, 0));
    EXPECT_TRUE(ours.x != v0 || ours.y != v1);
}

TEST(TeaKeys, EachDeviceAndSeedGetsItsOwnKeyReproducibly) {
    const uint4 initial = lucent::zafar_tea_key();
    std::set<std::string> keys;
    for (unsigned device = 0; device < 16; ++device)
        for (unsigned seed : {0u, 1u, 1732000000u}) {
            uint4 k = lucent::generate_tea_key(initial, make_uint2(device, seed));
            uint4 again = lucent::generate_tea_key(initial, make_uint2(device, seed));
            EXPECT_TRUE(k.x == again.x && k.y == again.y && k.z == again.z && k.w == again.w);
            char text[40];
            std::snprintf(text, sizeof text, "%08x%08x%08x%08x", k.x, k.y, k.z, k.w);
            keys.insert(text);
        }
    EXPECT_EQ(keys.size(), 48u) << "every (device, seed) pair must give a distinct key";
}

TEST(TeaKeys, DevicesDrawDifferentStreams) {
    const uint4 a = lucent::generate_tea_key(lucent::zafar_tea_key(), make_uint2(0, 42));
    const uint4 b = lucent::generate_tea_key(lucent::zafar_tea_key(), make_uint2(1, 42));
    unsigned equal = 0;
    for (unsigned i = 0; i < 1000; ++i) {
        uint2 x = tea<2>(make_uint2(i, 0), a), y = tea<2>(make_uint2(i, 0), b);
        equal += x.x == y.x;
    }
    EXPECT_LT(equal, 3u);
}

TEST(TeaStatistics, FourRoundsAndMorePassTheBitByteAndSerialTests) {
    for (unsigned rounds : {4u, 5u, 6u, 8u, 16u, 32u}) {
        auto s = lucent::samples::measure_tea(rounds, lucent::zafar_tea_key(), 1u << 19);
        EXPECT_TRUE(s.passes()) << rounds << " rounds: bit z " << s.bit_balance_z << ", chi2 "
                                << s.byte_chi_square << " (p " << s.chi_square_p << "), serial "
                                << s.serial_correlation;
    }
}

TEST(TeaStatistics, OneAndTwoRoundsFailThem) {
    // The same tests reject too few rounds: they are not vacuous.
    for (unsigned rounds : {1u, 2u})
        EXPECT_FALSE(
            lucent::samples::measure_tea(rounds, lucent::zafar_tea_key(), 1u << 19).passes())
            << rounds << " rounds";
}

TEST(TeaPrograms, LaunchFillsTheBufferWithTheStreamOfEachKey) {
    // The bench's programs through the engine: both variants give tea(first + i, 0) with
    // their key; on the CUDA build the megakernel of the pair must also compile.
    lucent::ContextOptions options{lucent::BackendKind::kCpu, 2};
#if LUCENT_HAVE_CUDA
    options.jit_check_sm = 90;
#endif
    lucent::Context ctx(options);
    ctx.set_entry_point_count(3);
    ctx.set_ray_generation_program(0, ctx.create_program(LUCENT_PROGRAM(tea_sample::tea_fixed_key)));
    ctx.set_ray_generation_program(1, ctx.create_program(LUCENT_PROGRAM(tea_sample::tea_device_key)));
    ctx.set_ray_generation_program(2, ctx.create_program(LUCENT_PROGRAM(tea_sample::tea_copy)));
    auto out = ctx.create_buffer<uint2>(lucent::BufferType::kOutput, 1000);
    auto first_block = ctx.create_buffer<unsigned>(lucent::BufferType::kInput, 1);
    auto source = ctx.create_buffer<uint2>(lucent::BufferType::kInput, 1000);
    std::vector<uint2> source_words(1000);
    for (unsigned i = 0; i < 1000; ++i) source_words[i] = make_uint2(i * 7u, ~i);
    source->upload(source_words);
    const uint4 device_key = lucent::generate_tea_key(lucent::zafar_tea_key(), make_uint2(3, 7));
    ctx["out"] = out;
    ctx["source"] = source;
    ctx["rounds"] = 4u;
    ctx["first_block"] = first_block;
    ctx["key"] = device_key;
    // The first block is data (a buffer), so the next launch's counter costs no recompile.
    for (unsigned first : {500u, 9000u})
        for (unsigned entry : {0u, 1u}) {
            first_block->upload(std::vector<unsigned>{first});
            ctx.launch(entry, 1000);
            EXPECT_TRUE(ctx.last_launch().recompiled == (first == 500u && entry == 0u));
            const uint4 key = entry == 0 ? lucent::zafar_tea_key() : device_key;
            const uint2* words = out->data<uint2>();
            for (unsigned i = 0; i < 1000; ++i) {
                uint2 expected = tea(make_uint2(first + i, 0), key, 4);
                ASSERT_EQ(words[i].x, expected.x) << "entry " << entry << ", block " << i;
                ASSERT_EQ(words[i].y, expected.y);
            }
        }
    // The bench's copy baseline copies.
    ctx.launch(2, 1000);
    const uint2* copied = out->data<uint2>();
    for (unsigned i = 0; i < 1000; ++i) {
        ASSERT_EQ(copied[i].x, source_words[i].x);
        ASSERT_EQ(copied[i].y, source_words[i].y);
    }
}

TEST(TeaCli, PrintsTheEncryptedPairAsHexWords) {
    FILE* pipe = popen(LUCENT_CLI " tea --block 0,0 --key 0x0,0,0,0 --rounds 32", "r");
    ASSERT_NE(pipe, nullptr);
    char line[64] = {};
    ASSERT_NE(std::fgets(line, sizeof line, pipe), nullptr);
    EXPECT_EQ(pclose(pipe), 0);
    EXPECT_EQ(std::string(line), "41ea3a0a 94baa940\n");
}

TEST(TeaCli, RejectsAWordThatIsNotAWord) {
    EXPECT_NE(std::system(LUCENT_CLI " tea --block 0,0x1g --key 1,2,3,4 2>/dev/null"), 0);
}

}  // namespace
