// The per-particle properties a script can name: dump custom fields, compute
// property/atom and atom-style variables read them from this one table (the
// set command, which writes them, has its own keywords).
#pragma once

#include <string>
#include <vector>

namespace granary {

class Engine;

struct AtomProperty {
  const char* name;
  bool integer;                             ///< an integer quantity (id, type, image flags, body)
  double (*value)(const Engine& e, int i);  ///< the value of owned or ghost particle i
};

/// Every property: id type body mol id_multisphere mass density radius
/// diameter x y z xs ys zs xu yu zu ix iy iz vx vy vz fx fy fz omegax omegay
/// omegaz tqx tqy tqz.
const std::vector<AtomProperty>& atom_properties();
/// The property called `name`, or nullptr.
const AtomProperty* find_atom_property(const std::string& name);
/// The names, for "did you mean" in messages.
std::vector<std::string> atom_property_names();

}  // namespace granary
