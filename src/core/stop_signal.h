// Stopping a run cleanly when a batch system announces the end of a job's time
// (SIGTERM or SIGUSR1, e.g. SLURM's --signal). The handler only records the
// signal; the run loop asks all ranks at every step (with the neighbour-list
// decision's reduction) whether any received one (the signal may reach the
// ranks at different times), and they all stop together at the end of that
// step: thermo line, restart file, files flushed, then the program exits with
// kStopStatus. A second signal ends the program at once (the signal's default
// action). See doc/clusters.md.
#pragma once

#include <mpi.h>

#include <stdexcept>
#include <string>

namespace granary {

/// Exit status after a run stopped by a signal (75, EX_TEMPFAIL: continue later).
constexpr int kStopStatus = 75;

/// Install the handlers of SIGTERM and SIGUSR1 (the program does, tests may).
void install_stop_handlers();
/// The signal received by this process (0: none). Local, not collective.
int stop_signal_received();
/// Collective: the largest signal number any rank received (0: none).
int stop_signal_agreed(MPI_Comm comm);
/// Name of a signal for messages ("SIGTERM").
std::string signal_name(int signum);

/// Thrown (on every rank together) after a run stopped by a signal; the
/// message says at which step and how to continue.
class StopRequested : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace granary
