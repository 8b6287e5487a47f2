// fix property/global: named global material properties in LIGGGHTS form.
//
//   fix ID all property/global NAME scalar V
//   fix ID all property/global NAME vector V1 V2 ...
//   fix ID all property/global NAME peratomtype V1 ... Vn          (n = number of atom types)
//   fix ID all property/global NAME peratomtypepair N V11 V12 ... VNN
//   fix ID all property/global NAME matrix N V11 ...
// Styles look properties up by NAME (e.g. "youngsModulus").
#pragma once

#include <string>
#include <vector>

#include "fix/fix.h"

namespace granary {

class Modify;

class FixPropertyGlobal : public Fix {
 public:
  FixPropertyGlobal(Engine& engine, const Args& args);
  unsigned hooks() const override { return 0; }
  double compute_scalar() override { return values.empty() ? 0.0 : values[0]; }
  double compute_vector(int i) override;

  std::string name;  // property name
  std::string kind;  // scalar, vector, peratomtype, peratomtypepair, matrix
  int ncols = 1;     // columns of a pair table
  std::vector<double> values;

  /// Value for type t (1-based) of a peratomtype property.
  double per_type(int t) const;
  /// Value for types (a, b) (1-based) of a peratomtypepair/matrix property.
  double per_pair(int a, int b) const;

  /// Find the property NAME among the fixes, or nullptr.
  static FixPropertyGlobal* find(const Modify& modify, const std::string& name);
  /// As find(), or InputError telling the user which fix to add.
  static FixPropertyGlobal* require(const Modify& modify, const std::string& name,
                                    const std::string& needed_by);
};

}  // namespace granary
