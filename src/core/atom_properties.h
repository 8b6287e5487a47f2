// The per-particle properties a script can name: dump custom fields, compute
// property/atom and atom-style variables read them from this one table, and
// the set command writes the ones with a writer through it.
#pragma once

#include <string>
#include <vector>

namespace granary {

class Engine;

/// What set accepts as a value of a property.
enum class SetCheck {
  Any,       ///< any finite number
  Positive,  ///< > 0 (sizes, densities, masses)
  Type,      ///< a particle type, 1 .. ntypes
};

struct AtomProperty {
  const char* name;
  bool integer;                             ///< an integer quantity (id, type, image flags, body)
  double (*value)(const Engine& e, int i);  ///< the value of owned or ghost particle i
  /// set's writer for owned particle i (what follows from the value, e.g. the
  /// mass of a new diameter, included), or nullptr: set cannot write it
  void (*assign)(Engine& e, int i, double v) = nullptr;
  SetCheck check = SetCheck::Any;  ///< the values set accepts
};

/// Every property: id type body mol id_multisphere mass density radius
/// diameter x y z xs ys zs xu yu zu ix iy iz vx vy vz fx fy fz omegax omegay
/// omegaz tqx tqy tqz proc (the rank that owns the particle), and rho, meso_rho
/// and p of atom_style sph (an InputError without it).
const std::vector<AtomProperty>& atom_properties();
/// The property called `name`, or nullptr.
const AtomProperty* find_atom_property(const std::string& name);
/// The names, for "did you mean" in messages.
std::vector<std::string> atom_property_names();
/// The names of the properties set can write (type mass density diameter x y
/// z vx vy vz omegax omegay omegaz).
std::vector<std::string> settable_atom_property_names();

}  // namespace granary
