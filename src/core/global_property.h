// A named global material property in LIGGGHTS form: what `fix property/global`
// defines (e.g. youngsModulus peratomtype 5e6 5e6) and what the material table
// of the pair style and the walls reads. Styles find one through
// Modify::find_property / require_property, never by looking at the fixes.
#pragma once

#include <string>
#include <vector>

namespace granary {

struct GlobalProperty {
  std::string name;      ///< property name, e.g. "youngsModulus"
  std::string kind;      ///< scalar, vector, peratomtype, peratomtypepair, matrix
  std::string owner_id;  ///< ID of the fix that defines it (for messages)
  int ncols = 1;         ///< columns of a pair table
  std::vector<double> values;

  /// The value of a scalar (the first value; 0 when there is none).
  double scalar() const { return values.empty() ? 0.0 : values[0]; }
  /// Value for type t (1-based) of a peratomtype property; InputError outside it.
  double per_type(int t) const;
  /// Value for types (a, b) (1-based) of a peratomtypepair/matrix property; InputError outside it.
  double per_pair(int a, int b) const;
};

}  // namespace granary
