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

class MultiContact;

class Force {
 public:
  explicit Force(Engine& engine);
  ~Force();
  void create_pair(const Args& args);
  /// The contact history read from a restart file and not yet taken by the
  /// pair style, else that of the pair style, or nullptr (no pair style, or a
  /// model without history).
  ContactHistory* contact_history() const;
  std::unique_ptr<Pair> pair;
  std::string pair_style = "none";
  Args pair_words;           // the words after the style name
  bool newton_pair = false;  // `newton on|off`; see doc/architecture.md
  /// Contact history read from a restart file: rows for this rank's own
  /// particles, values as seen from the smaller id of each pair. Until the
  /// pair style takes it (when it first initialises) it is the contact
  /// history (contact_history()), so its rows travel with migrating particles.
  std::unique_ptr<ContactHistory> pending_history;
  std::string restart_pair_style;  // the pair_style words of the run that wrote it
  /// The model of fix multicontact/halfspace, when defined: the contact loops with
  /// "surface multicontact" change their overlaps through it, and
  /// Update::compute_forces brackets every force evaluation with its
  /// begin() and finish().
  MultiContact* multicontact = nullptr;

 private:
  Engine& engine_;
};

}  // namespace granary
