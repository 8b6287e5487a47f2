// Holds the pair style (LAMMPS' Force): `pair_style` and `pair_coeff` land here.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/utils.h"

namespace granary {

class Engine;
class Pair;
class ContactHistory;

class Force {
 public:
  explicit Force(Engine& engine);
  ~Force();
  void create_pair(const Args& args);
  /// The contact history of the pair style, or nullptr (no pair style, or a
  /// model without history).
  ContactHistory* contact_history() const;
  std::unique_ptr<Pair> pair;
  std::string pair_style = "none";
  Args pair_words;           // the words after the style name
  bool newton_pair = false;  // `newton on|off`; see doc/architecture.md
  /// Contact history read from a restart file (ContactHistory::pack_all
  /// layout), taken by the pair style when it first initialises.
  std::vector<double> restart_history;
  std::string restart_pair_style;  // the pair_style words of the run that wrote it

 private:
  Engine& engine_;
};

}  // namespace granary
