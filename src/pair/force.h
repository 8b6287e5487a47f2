// Holds the pair style (LAMMPS' Force): `pair_style` and `pair_coeff` land here.
#pragma once

#include <memory>
#include <string>

#include "core/utils.h"

namespace granary {

class Engine;
class Pair;

class Force {
 public:
  explicit Force(Engine& engine);
  ~Force();
  void create_pair(const Args& args);
  std::unique_ptr<Pair> pair;
  std::string pair_style = "none";
  bool newton_pair = false;  // `newton on|off`; see doc/architecture.md

 private:
  Engine& engine_;
};

}  // namespace granary
