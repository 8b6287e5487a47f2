// Timestep, step counter, simulated time and the run loop (velocity Verlet).
#pragma once

#include <cstdint>
#include <string>

#include "core/utils.h"

namespace granary {

class Engine;

class Update {
 public:
  explicit Update(Engine& engine);

  double dt = 1.0e-8;          // [s]; LAMMPS' default for units si
  bool dt_set = false;
  std::int64_t ntimestep = 0;  // current step
  double atime = 0.0;          // simulated time at step atimestep
  std::int64_t atimestep = 0;
  std::int64_t firststep = 0, laststep = 0;    // of the current run
  std::int64_t beginstep = 0, endstep = 0;     // of the current run (start/stop keywords)
  bool running = false;
  bool first_run = true;
  bool halt_requested = false;  // set by fixes to end the current run early

  /// Simulated time at the current step.
  double time() const { return atime + static_cast<double>(ntimestep - atimestep) * dt; }
  void set_timestep(double new_dt);
  /// The `run` command.
  void run_command(const Args& args);
  /// Set up and run n steps (used by run and by tests).
  void run(std::int64_t n, bool pre = true, bool post = true);

  double run_wall_time = 0.0;  // seconds of the last run's loop

  enum TimerSlot { kPair, kNeigh, kComm, kModify, kOutput, kNumTimers };
  double timers[kNumTimers] = {0, 0, 0, 0, 0};

  /// Global particle count (collective).
  std::int64_t count_global() const;

 private:
  void setup();
  void step_loop(std::int64_t n);
  void reneighbor(bool save_history);
  void compute_forces();
  void check_lost();
  void report();
  Engine& engine_;
  bool bounds_set_ = false;
};

}  // namespace granary
