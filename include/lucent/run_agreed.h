// Work that may fail on one rank only (a scene file missing on one node), closed by the
// agreement that tells every rank (docs/distributed.md, "Divergence and faults").
#pragma once

#include <functional>
#include <memory>

#include "lucent/ranks.h"

namespace lucent {

/// Runs `work`, then agrees with every rank: an exception on any rank becomes the
/// RankError "rank R: <what>" every rank throws, so no rank waits in its next launch for
/// one that failed before it; a RankError from inside `work` (a launch's own agreement)
/// passes through, as every rank has it already. Without ranks (null): runs `work`.
void run_agreed(const std::shared_ptr<Ranks>& ranks, const std::function<void()>& work);

}  // namespace lucent
