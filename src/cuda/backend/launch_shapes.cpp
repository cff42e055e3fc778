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
    return m_launches <= 1 ? 0 : int(m_launches - 1);
}

void ShapeTuning::record(int shape, double ms_per_index) {
    if (m_choice >= 0) return;
    if (m_launches >= 1 && shape >= 0 && size_t(shape) < m_ms.size())
        m_ms[size_t(shape)] = ms_per_index;
    if (++m_launches == m_ms.size() + 1)
        m_choice = int(std::min_element(m_ms.begin(), m_ms.end()) - m_ms.begin());
}

}  // namespace lucent::cuda
