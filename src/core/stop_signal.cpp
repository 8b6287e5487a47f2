#include "core/stop_signal.h"

#include <csignal>

namespace granary {

namespace {

volatile std::sig_atomic_t g_received = 0;

// Only records the signal. A second one (either kind) restores the default
// action and raises it again, which ends the process at once.
extern "C" void on_stop_signal(int signum) {
  if (g_received != 0) {
    std::signal(signum, SIG_DFL);
    std::raise(signum);
    return;
  }
  g_received = signum;
}

}  // namespace

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;  // system calls (file writes, MPI) go on
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGUSR1, &action, nullptr);
}

int stop_signal_received() {
  return static_cast<int>(g_received);
}

int stop_signal_agreed(MPI_Comm comm) {
  int mine = static_cast<int>(g_received), any = 0;
  MPI_Allreduce(&mine, &any, 1, MPI_INT, MPI_MAX, comm);
  return any;
}

std::string signal_name(int signum) {
  if (signum == SIGTERM) return "SIGTERM";
  if (signum == SIGUSR1) return "SIGUSR1";
  return "signal " + std::to_string(signum);
}

}  // namespace granary
