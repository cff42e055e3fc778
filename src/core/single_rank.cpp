// A group of ranks that is this process alone: what a Context spanning ranks runs on in a
// build without MPI, or without a launcher. Its collectives return what this rank gave.
#include <atomic>

#include "core/rank_group.h"

namespace lucent::core {

namespace {

class SingleRank final : public Ranks::Impl {
  public:
    int rank() const override { return 0; }
    int size() const override { return 1; }
    std::vector<std::array<uint64_t, 2>> all_gather_words(std::array<uint64_t, 2> words) override {
        return {words};
    }
    std::string broadcast_text(int, const std::string& text) override { return text; }
    void all_gather_bytes(const std::vector<unsigned char>& mine, std::vector<unsigned char>& all,
                          std::vector<uint64_t>& counts) override {
        all = mine;
        counts = {mine.size()};
    }
    void reset_counter() override { m_counter = 0; }
    uint64_t fetch_add_counter(uint64_t n) override { return m_counter.fetch_add(n); }

  private:
    std::atomic<uint64_t> m_counter{0};
};

}  // namespace

std::unique_ptr<Ranks::Impl> make_single_rank() {
    return std::make_unique<SingleRank>();
}

}  // namespace lucent::core
