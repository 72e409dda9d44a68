// quadlod — "nothing lost" on SIGINT / SIGTERM / SIGHUP (issue 23): the temporary files that
// write_file_atomically() is writing are removed before the process dies of the signal, so an
// interrupted run leaves the previous complete output (the rename never happened) and no stray
// temp file. SIGKILL cannot be caught: it leaves the previous output too, plus at most one
// dot-named temp file (.NAME.tmp-PID-…) that no glob on *.obj picks up.
//
// The registry is a fixed array of slots so that the handler only reads memory that is always
// valid and calls nothing but unlink(), raise() and sigaction(), all async-signal-safe.
#include "io/io_common.h"

#include <csignal>
#include <unistd.h>

#include <atomic>
#include <climits>

namespace quadlod {

namespace {

constexpr int kSlots = 8;
// 0 = free, 1 = being filled or emptied (the handler skips it), 2 = holds a path to remove.
std::atomic<int> slot_state[kSlots];
char slot_path[kSlots][PATH_MAX];
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs lock-free atomics");

extern "C" void remove_temporaries_and_die(int signal_number) {
  for (int i = 0; i < kSlots; ++i)
    if (slot_state[i].load() == 2) ::unlink(slot_path[i]);
  // Die of the same signal, so the parent sees how the run ended (shell: 130 for SIGINT).
  struct sigaction dfl {};
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  ::sigaction(signal_number, &dfl, nullptr);
  ::raise(signal_number);
}

}  // namespace

namespace io_detail {

int register_temporary(const char* path) {
  const std::size_t n = std::strlen(path);
  if (n >= PATH_MAX) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (!slot_state[i].compare_exchange_strong(expected, 1)) continue;
    std::memcpy(slot_path[i], path, n + 1);
    slot_state[i].store(2);
    return i;
  }
  return -1;  // more than kSlots concurrent writes: this one is not cleaned on a signal
}

void unregister_temporary(int slot) {
  if (slot >= 0 && slot < kSlots) slot_state[slot].store(0);
}

}  // namespace io_detail

void install_interrupt_cleanup() {
  struct sigaction sa {};
  sa.sa_handler = remove_temporaries_and_die;
  sigemptyset(&sa.sa_mask);
  for (int s : {SIGINT, SIGTERM, SIGHUP}) ::sigaction(s, &sa, nullptr);
}

}  // namespace quadlod
