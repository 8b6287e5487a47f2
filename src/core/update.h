// Timestep, step counter, simulated time and the run loop (velocity Verlet).
#pragma once

#include <cstdint>
#include <string>

#include "core/timestep_guard.h"
#include "core/utils.h"

namespace granary {

class Engine;

class Update {
 public:
  explicit Update(Engine& engine);

  double dt = 1.0e-8;          // [s]; LAMMPS' default for units si
  std::int64_t ntimestep = 0;  // current step
  double atime = 0.0;          // simulated time at step atimestep
  std::int64_t atimestep = 0;
  std::int64_t firststep = 0, laststep = 0;  // of the current run
  std::int64_t beginstep = 0, endstep = 0;   // of the current run (start/stop keywords)
  bool running = false;
  bool first_run = true;
  bool halt_requested = false;  // set by fixes to end the current run early
  /// SIGTERM or SIGUSR1 received by some rank (agreed on by all at the start
  /// of a step; 0: none): the run ends after that step and the program stops
  /// (core/stop_signal.h).
  int stop_signal = 0;

  /// Time increment for contact-history integration: dt during steps, 0 in the
  /// force pass at run setup (forces of the current state, history unchanged).
  double history_dt() const { return in_setup_forces ? 0.0 : dt; }
  bool in_setup_forces = false;

  /// Simulated time at the current step.
  double time() const { return atime + static_cast<double>(ntimestep - atimestep) * dt; }
  void set_timestep(double new_dt);
  /// The `run` command.
  void run_command(const Args& args);
  /// Set up and run n steps (used by run and by tests).
  void run(std::int64_t n, bool pre = true, bool post = true);

  double run_wall_time = 0.0;    // seconds of the last run's loop
  double loop_start_wall = 0.0;  // MPI_Wtime() when the current run's loop started

  /// Forces and torques read from a restart file: a per-particle field of
  /// kRestartForceValues values (force, torque, 1 = read from the file) that
  /// migrates with its particle and is released by the first run, which uses
  /// them in place of the recomputed ones when every particle of the file and
  /// no other is still there, so a restarted run continues bit for bit.
  static constexpr const char* kRestartForcesField = "restart_forces";
  static constexpr int kRestartForceValues = 7;
  /// Particles the restart file held (when the field exists).
  std::int64_t restart_forces_natoms = 0;
  /// True while the stored forces belong to the current particle state: set at
  /// the end of a run (and by read_restart from the file), cleared by commands
  /// that change particles between runs (create_atoms, set, velocity,
  /// delete_atoms, create_clump). write_restart records it; a file written
  /// after such a change makes the next run recompute its forces, as the
  /// uninterrupted script does at its next run's setup.
  bool forces_current = false;
  /// Called by commands that add, remove or change particles between runs.
  void particles_changed() { forces_current = false; }

  enum TimerSlot { kPair, kNeigh, kComm, kModify, kOutput, kNumTimers };
  double timers[kNumTimers] = {0, 0, 0, 0, 0};

  /// Whether anything reads the particles after the end-of-step fixes of the
  /// current step: the step ends the run, writes thermo or output, or runs an
  /// end-of-step fix. Integrators may leave derived per-particle state (e.g.
  /// the velocities of clump sub-spheres, recomputed at the start of every
  /// step) out of date at the end of steps nobody observes.
  bool step_observed() const;

  /// Global particle count (collective).
  std::int64_t count_global() const;

 private:
  void setup();
  void step_loop(std::int64_t n);
  void reneighbor(bool save_history);
  void compute_forces();
  void check_lost();
  void report();
  void report_fixes();  // per-fix lines of the timing report
  void use_restart_forces();
  [[noreturn]] void stop_after_signal();
  Engine& engine_;
  TimestepGuard timestep_guard_{engine_};
  bool bounds_set_ = false;
  bool loss_explained_ = false;     // this run's lost particles were explained (thermo_modify lost ignore)
  std::string stop_restart_;        // restart file written when a signal stopped the run
  std::int64_t command_end_ = 0;    // last step of the current run command
  std::int64_t builds_before_ = 0;  // Neighbor::nbuilds when the current run began
};

}  // namespace granary
