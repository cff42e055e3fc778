#include "lucent/run_agreed.h"

#include <exception>
#include <string>

namespace lucent {

void run_agreed(const std::shared_ptr<Ranks>& ranks, const std::function<void()>& work) {
    if (!ranks) return work();
    try {
        work();
    } catch (const RankError&) {
        throw;  // already agreed on by every rank
    } catch (const std::exception& e) {
        const std::string failure = e.what();
        ranks->agree(&failure);  // throws the RankError every rank throws
    }
    ranks->agree();
}

}  // namespace lucent
