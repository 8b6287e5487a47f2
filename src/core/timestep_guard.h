// The default timestep safety check of every run: the timestep against the
// Rayleigh time of the smallest particle and the Hertz time of an impact at
// the highest speed seen, and the explanation of particles lost from the box.
#pragma once

#include <cstdint>
#include <string>

namespace granary {

class Engine;

class TimestepGuard {
 public:
  /// Warn above this fraction of the Rayleigh or the Hertz time; stop above the Rayleigh time.
  static constexpr double kWarnFraction = 0.2;
  /// Steps between checks during a run (also checked when the particle count changes).
  static constexpr std::int64_t kEvery = 100;

  explicit TimestepGuard(Engine& engine) : engine_(engine) {}
  /// At the setup of a run (collective): check now; a new timestep is warned about afresh.
  void start_run();
  /// At reneighbouring during a run (collective): check when due.
  void check();
  /// Why particles may have been lost, measured now (collective): a sentence
  /// naming the timestep or the speeds when either explains a loss, else empty.
  std::string explain_loss();

 private:
  struct State {
    double dt, t_rayleigh, t_hertz, vmax, rmin, t_spring;
  };
  static constexpr double kInf = 1e308;
  State measure();
  void check_now(bool at_setup);
  Engine& engine_;
  double vmax_seen_ = 0.0;  // highest speed seen in the simulation
  double warned_dt_ = 0.0;  // the timestep the warnings were given for
  std::int64_t next_check_ = 0, natoms_checked_ = -1;
  State last_{0.0, kInf, kInf, 0.0, 0.0, kInf};  // at the last check
  bool warned_rayleigh_ = false, warned_hertz_ = false, warned_spring_ = false;
};

}  // namespace granary
