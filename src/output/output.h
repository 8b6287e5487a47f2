// Output scheduling: dumps and periodic restart files (thermo has its own class).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/utils.h"

namespace granary {

class Engine;
class Dump;

class Output {
 public:
  explicit Output(Engine& engine);
  ~Output();

  void add_dump(const Args& args);
  void delete_dump(const std::string& id);
  Dump* find_dump(const std::string& id) const;
  void modify_dump(const Args& args);

  /// `restart N FILE [FILE2]` / `restart 0`.
  void restart_command(const Args& args);

  /// Start of a run: init dumps, write those due at this step.
  void setup();
  /// End of a step: dumps and restarts that are due.
  void write(std::int64_t step);
  /// The restart file of the `restart` command for `step` (its next name),
  /// unless already written at that step (collective). Returns the file's
  /// name, or "" when the script has no restart command.
  std::string write_restart_now(std::int64_t step);
  /// Steps at which something is due (cheap check in the run loop).
  std::int64_t next = -1;

  std::vector<std::unique_ptr<Dump>> dumps;
  int restart_every = 0;
  std::string restart_file1, restart_file2;
  bool restart_toggle = false;
  std::int64_t restart_step = -1;  // step of the last file written by `restart`
  std::string restart_last;        // and its name

 private:
  void schedule(std::int64_t step);
  Engine& engine_;
};

}  // namespace granary
