// The three force components of fix addforce, setforce and aveforce and their
// `region` keyword: each component is a number, NULL (left alone), an
// equal-style variable or (where the style allows it) an atom-style variable,
// written v_name and evaluated every step.
#pragma once

#include <string>
#include <vector>

#include "core/utils.h"
#include "fix/fix.h"

namespace granary {

class Engine;
class Region;

class ForceComponents {
 public:
  enum Kind { NONE, CONSTANT, EQUAL, ATOM };

  struct Options {
    bool allow_null = true;  // NULL leaves the component alone
    bool allow_atom = true;  // atom-style variables (one value per particle)
    bool allow_energy = false;
  };

  /// Parses args[3..5] (fx fy fz) and the keywords after them of fix
  /// `style` (usage: the syntax line for messages).
  ForceComponents(Engine& engine, const Args& args, const std::string& style, const std::string& usage,
                  Options options);

  /// Before every run: the variables exist and have the style each use allows;
  /// the region is looked up again (it may have been redefined).
  void init();
  /// Evaluates the variables for this step (collective when a variable needs it).
  void update();

  Kind kind(int d) const { return kind_[d]; }
  bool any_variable() const;
  bool constant() const { return !any_variable(); }
  /// Value of component d for owned particle i (after update()).
  double value(int d, int i) const { return kind_[d] == ATOM ? atom_[d][i] : value_[d]; }
  /// Whether owned particle i is acted on: in the group and, with `region`, in the region.
  bool selected(int i, int groupbit) const;
  /// The atom-style energy variable of `energy v_name` (empty when not given).
  const std::string& energy_variable() const { return energy_; }
  const std::vector<double>& energy_values() const { return energy_values_; }

 private:
  Engine& engine_;
  std::string style_;
  Kind kind_[3] = {CONSTANT, CONSTANT, CONSTANT};
  double value_[3] = {0, 0, 0};
  std::string var_[3];
  std::vector<double> atom_[3];
  std::string region_id_, energy_;
  std::vector<double> energy_values_;
  const Region* region_ = nullptr;
  Options options_;
};

/// Base of fix addforce, setforce and aveforce: the components and the global
/// vector they share, the total force on the acted-on particles before the fix
/// changed it on the last step (f_ID[1..3], summed over the ranks when asked).
class FixForceComponents : public Fix {
 public:
  FixForceComponents(Engine& engine, const Args& args, const std::string& usage,
                     ForceComponents::Options options);
  unsigned hooks() const override { return POST_FORCE; }
  void init() override { comp_.init(); }
  double compute_vector(int i) override;

 protected:
  /// Throws RunError for a sphere of a clump in the group: the fix cannot
  /// act on clumps (fix multisphere sums the forces of their spheres).
  void refuse_clump_sphere(int i) const;
  ForceComponents comp_;
  double before_[3] = {0, 0, 0};  // this rank's part of the vector
};

}  // namespace granary
