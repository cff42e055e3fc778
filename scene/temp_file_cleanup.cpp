#include "scene/temp_file_cleanup.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstring>

namespace lucent::scene {

namespace {

constexpr int kSlots = 16;
constexpr size_t kPathBytes = 4096;

/// Fixed storage, so the handler reads it without allocating. A slot is free, being filled
/// by the writer that claimed it, or holds a path: the path is complete before the state
/// says so (release), and the handler reads it only after seeing that (acquire).
enum SlotState : int { kFree, kFilling, kHolding };
struct Slot {
    std::atomic<int> state{kFree};
    char path[kPathBytes];
};
Slot g_slots[kSlots];

void remove_and_reraise(int signal_number) {
    for (Slot& slot : g_slots)
        if (slot.state.load(std::memory_order_acquire) == kHolding)
            ::unlink(slot.path);  // async-signal-safe
    ::signal(signal_number, SIG_DFL);
    ::raise(signal_number);
}

}  // namespace

void remove_temp_files_on_signals() {
    static std::atomic<bool> installed{false};
    if (installed.exchange(true)) return;
    for (int s : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) {
        struct sigaction action {};
        action.sa_handler = remove_and_reraise;
        sigemptyset(&action.sa_mask);
        // A signal the process ignores (nohup's SIGHUP) stays ignored.
        struct sigaction previous {};
        if (::sigaction(s, nullptr, &previous) == 0 && previous.sa_handler == SIG_IGN) continue;
        ::sigaction(s, &action, nullptr);
    }
}

TempFileGuard::TempFileGuard(const std::string& path) {
    if (path.size() >= kPathBytes) return;
    for (int i = 0; i < kSlots; ++i) {
        int expected = kFree;
        if (!g_slots[i].state.compare_exchange_strong(expected, kFilling)) continue;
        std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
        g_slots[i].state.store(kHolding, std::memory_order_release);
        m_slot = i;
        return;
    }
}

TempFileGuard::~TempFileGuard() {
    if (m_slot >= 0) g_slots[m_slot].state.store(kFree, std::memory_order_release);
}

}  // namespace lucent::scene
