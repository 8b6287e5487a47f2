// Base class of pair styles (particle-particle contacts).
#pragma once

#include <limits>
#include <string>

#include "core/utils.h"

namespace granary {

class Engine;
class ContactHistory;

/// Time scales a timestep must resolve (seconds; infinite where nothing sets one).
struct ContactTimes {
  double rayleigh = std::numeric_limits<double>::infinity();  ///< smallest Rayleigh time
  double hertz = std::numeric_limits<double>::infinity();     ///< smallest Hertz time at the given speed
  double spring =
      std::numeric_limits<double>::infinity();  ///< linear springs (hooke/stiffness): contact time
};

class Pair {
 public:
  /// args = the words after the style name in `pair_style`.
  Pair(Engine& engine, const Args& args) : engine_(engine), args_(args) {}
  virtual ~Pair() = default;

  /// `pair_coeff` (granular styles take only "* *").
  virtual void coeff(const Args& args) = 0;
  /// Before every run: read materials, check settings.
  virtual void init() = 0;
  /// Add contact forces and torques to f and torque of the particles in the neighbour list.
  virtual void compute() = 0;
  /// Number of contact-history values per contact (0 = none).
  virtual int history_size() const { return 0; }
  /// Sign of each history value when i and j swap roles.
  virtual void history_swap_signs(double* signs) const {}
  /// Contact history aligned with the neighbour list, or nullptr.
  virtual ContactHistory* history() { return nullptr; }
  /// Contact time scales of the owned particles (collective): the smallest
  /// Rayleigh time, and the smallest Hertz time of an impact at speed vmax
  /// among the particles of groupbit. A style without material stiffness
  /// returns infinite times.
  virtual ContactTimes contact_times(double vmax, int groupbit) { return {}; }

  std::string style;

 protected:
  Engine& engine_;
  Args args_;
};

}  // namespace granary
