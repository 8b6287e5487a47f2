// Owns fixes and computes; keeps one list of fixes per timestep hook.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/utils.h"

namespace granary {

class Engine;
class Fix;
class Compute;
struct GlobalProperty;

class Modify {
 public:
  explicit Modify(Engine& engine);
  ~Modify();

  /// `fix ID group style args`: a fix with an existing ID is replaced in place.
  Fix* add_fix(const Args& args);
  void delete_fix(const std::string& id);
  Fix* find_fix(const std::string& id) const;
  Fix* fix_or_error(const std::string& id, const std::string& what) const;
  /// First fix of a given style, or nullptr.
  Fix* find_fix_by_style(const std::string& style) const;

  Compute* add_compute(const Args& args);
  void delete_compute(const std::string& id);
  Compute* find_compute(const std::string& id) const;
  Compute* compute_or_error(const std::string& id, const std::string& what) const;

  void init();  // before every run (fixes and computes)
  void setup();
  void initial_integrate();
  void post_integrate();
  void pre_exchange();
  void pre_neighbor();
  void post_neighbor();
  void pre_force();
  void post_force();
  void final_integrate();
  void end_of_step(std::int64_t step);
  /// Whether end_of_step(step) calls any fix.
  bool end_of_step_due(std::int64_t step) const;
  void reset_dt();

  bool has_integrator() const;

  /// The global property NAME (fix property/global; the latest definition
  /// wins), or nullptr.
  const GlobalProperty* find_property(const std::string& name) const;
  /// As find_property(), or InputError naming `needed_by` and the fix to add.
  const GlobalProperty& require_property(const std::string& name, const std::string& needed_by) const;
  /// The fix or compute that uses group bit `igroup` ("fix ID", "compute ID"), or "".
  std::string group_user(int igroup) const;

  std::vector<std::unique_ptr<Fix>> fixes;
  std::vector<std::unique_ptr<Compute>> computes;

  // State read from a restart file, handed to fixes defined afterwards.
  struct RestartState {
    std::string style, data;
  };
  std::map<std::string, RestartState> restart_states;  // by fix ID
  /// Material properties stored in the restart file (name -> values), checked
  /// against the script's fix property/global when the pair style initialises.
  std::map<std::string, std::vector<double>> restart_materials;

 private:
  void rebuild_hook_lists();
  Engine& engine_;
  std::vector<Fix*> initial_integrate_, post_integrate_, pre_exchange_, pre_neighbor_, post_neighbor_,
      pre_force_, post_force_, final_integrate_, end_of_step_;
};

}  // namespace granary
