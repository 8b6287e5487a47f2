// fix property/global: named global material properties in LIGGGHTS form.
//
//   fix ID all property/global NAME scalar V
//   fix ID all property/global NAME vector V1 V2 ...
//   fix ID all property/global NAME peratomtype V1 ... Vn          (n = number of atom types)
//   fix ID all property/global NAME peratomtypepair N V11 V12 ... VNN
//   fix ID all property/global NAME matrix N V11 ...
// Styles look properties up by NAME (e.g. "youngsModulus") through
// Modify::find_property / require_property.
#pragma once

#include <string>
#include <vector>

#include "core/global_property.h"
#include "fix/fix.h"

namespace granary {

class Modify;

class FixPropertyGlobal : public Fix, public GlobalProperty {
 public:
  FixPropertyGlobal(Engine& engine, const Args& args);
  unsigned hooks() const override { return 0; }
  double compute_scalar() override { return values.empty() ? 0.0 : values[0]; }
  double compute_vector(int i) override;

  // name, kind, ncols, values, per_type(), per_pair(): GlobalProperty

  /// Find the property NAME among the fixes, or nullptr.
  static FixPropertyGlobal* find(const Modify& modify, const std::string& name);
  /// As find(), or InputError telling the user which fix to add.
  static FixPropertyGlobal* require(const Modify& modify, const std::string& name,
                                    const std::string& needed_by);
};

}  // namespace granary
