// The benchmarks' reporter (bench/common/report.h): whatever text a result holds, its JSON
// parses back to the same values.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "bench/common/rate.h"
#include "bench/common/report.h"

namespace {

using lucent::bench::Json;

TEST(BenchReport, QuotesBackslashesAndNewlinesInTextParseBack) {
    const std::string scene = "scenes/my \"best\" scene\\v2\n.obj";
    const Json document{{"scene", scene}, {"triangles", 32}};
    const nlohmann::json back = nlohmann::json::parse(lucent::bench::json_text(document));
    EXPECT_EQ(back.at("scene").get<std::string>(), scene);
    EXPECT_EQ(back.at("triangles").get<int>(), 32);
}

TEST(BenchReport, BytesThatAreNotUtf8StillGiveValidJson) {
    const Json document{{"scene", std::string("caf\xe9.obj")}};  // Latin-1, not UTF-8
    const nlohmann::json back = nlohmann::json::parse(lucent::bench::json_text(document));
    EXPECT_EQ(back.at("scene").get<std::string>(), "caf\xef\xbf\xbd.obj");  // U+FFFD
}

TEST(BenchReport, KeysKeepTheOrderTheyWereWrittenIn) {
    const std::string text = lucent::bench::json_text(Json{{"scene", "a"}, {"backend", "b"}});
    EXPECT_LT(text.find("\"scene\""), text.find("\"backend\"")) << text;
}

TEST(BenchReport, RatesAreRoundedToFourPlaces) {
    const Json rate = lucent::bench::rate_json({12.345678, 11.00004, 13.99996});
    EXPECT_DOUBLE_EQ(rate.at("mrays").get<double>(), 12.3457);
    EXPECT_DOUBLE_EQ(rate.at("min").get<double>(), 11.0);
    EXPECT_DOUBLE_EQ(rate.at("max").get<double>(), 14.0);
}

TEST(BenchReport, MedianOfAnEvenCountIsTheMeanOfTheMiddleTwo) {
    EXPECT_DOUBLE_EQ(lucent::bench::median_of({4, 1, 3, 2}), 2.5);
    EXPECT_DOUBLE_EQ(lucent::bench::median_of({5, 1, 3}), 3.0);
    EXPECT_DOUBLE_EQ(lucent::bench::median_of({}), 0.0);
}

}  // namespace
