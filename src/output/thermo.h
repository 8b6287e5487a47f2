// Thermodynamic output (`thermo`, `thermo_style custom`, `thermo_modify`) and run progress.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/utils.h"

namespace granary {

class Engine;

class Thermo {
 public:
  explicit Thermo(Engine& engine);

  enum class Lost { Error, Warn, Ignore };

  int every = 0;  // 0: first and last step only
  std::vector<std::string> keywords{"step", "atoms", "ke"};
  bool norm = false;  // LIGGGHTS default for granular runs (see doc)
  bool flush = false;
  Lost lost = Lost::Error;
  std::string format_float = "%14.8g";
  std::string format_int = "%10lld";

  void style_command(const Args& args);
  void modify_command(const Args& args);
  void header();
  /// Print one line for the current step (collective).
  void line();
  /// Progress line (step, simulated time, rate, time left) every 10 s of a run.
  void progress();
  /// Value of one keyword (collective).
  double keyword_value(const std::string& key, bool& found);

  double wall_start = 0.0;

 private:
  double last_progress_ = -1.0;
  Engine& engine_;
};

}  // namespace granary
