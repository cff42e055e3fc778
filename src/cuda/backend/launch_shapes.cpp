#include "cuda/backend/launch_shapes.h"

#include <algorithm>

namespace lucent::cuda {

std::vector<int> launch_shape_carveouts(int by_registers, const SharedMemoryNeeds& needs,
                                        const std::function<int(int)>& resident_blocks) {
    auto carveout_for = [&](int blocks) {  // the smallest that holds `blocks`
        if (blocks <= 1) return 0;
        const long long needed =
            1ll * blocks * (needs.static_per_block + needs.reserved_per_block);
        if (needs.per_sm <= 0) return 100;
        return int(std::min(100ll, (100 * needed + needs.per_sm - 1) / needs.per_sm + 1));
    };
    std::vector<int> carveouts, counts_seen;
    for (int blocks = std::max(1, by_registers); blocks >= 1; --blocks) {
        const int carveout = carveout_for(blocks);
        const int resident = resident_blocks(carveout);
        if (std::find(counts_seen.begin(), counts_seen.end(), resident) != counts_seen.end())
            continue;  // the configuration's granularity gave a count already tried
        counts_seen.push_back(resident);
        carveouts.push_back(carveout);
    }
    return carveouts;
}

int ShapeTuning::next_shape() const {
    if (m_choice >= 0) return m_choice;
    // During a warm-up the first shape still to time runs (untimed); shape 0 at the start.
    const auto untimed = std::find(m_timed.begin(), m_timed.end(), false);
    return untimed == m_timed.end() ? 0 : int(untimed - m_timed.begin());
}

void ShapeTuning::record(int shape, double ms_per_index) {
    if (m_choice >= 0) return;
    if (m_warm_ups > 0) {
        --m_warm_ups;
        return;
    }
    if (shape < 0 || size_t(shape) >= m_ms.size()) return;
    m_ms[size_t(shape)] = ms_per_index;
    m_timed[size_t(shape)] = true;
    if (std::find(m_timed.begin(), m_timed.end(), false) == m_timed.end())
        m_choice = int(std::min_element(m_ms.begin(), m_ms.end()) - m_ms.begin());
}

void ShapeTuning::add_shapes(size_t count) {
    if (count == 0) return;
    m_ms.resize(m_ms.size() + count, 0.0);
    m_timed.resize(m_ms.size(), false);
    m_choice = -1;
    m_warm_ups = 1;  // a new kernel's first launch loads its code: not a fair time
}

}  // namespace lucent::cuda
