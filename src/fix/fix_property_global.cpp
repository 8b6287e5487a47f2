// fix property/global: see fix_property_global.h.
#include "fix/fix_property_global.h"

#include <map>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "core/modify.h"
#include "particles/particles.h"

namespace granary {

namespace {

const char* kUsage =
    "fix ID group property/global NAME scalar V | vector V1 ... | peratomtype V1 ... Vn | "
    "peratomtypepair N V11 ... VNN | matrix NCOLS V11 ...";

/// Kind of the properties the contact models read, for the hint in require().
const std::map<std::string, std::string>& known_kinds() {
  static const std::map<std::string, std::string> kinds = {
      {"youngsModulus", "peratomtype"},
      {"poissonsRatio", "peratomtype"},
      {"coefficientRestitution", "peratomtypepair"},
      {"coefficientFriction", "peratomtypepair"},
      {"coefficientRollingFriction", "peratomtypepair"},
      {"coefficientRollingViscousDamping", "peratomtypepair"},
      {"cohesionEnergyDensity", "peratomtypepair"},
      {"characteristicVelocity", "scalar"},
  };
  return kinds;
}

/// Per-type tables must match the number of atom types (known once the box exists).
void check_types(const Engine& engine, const FixPropertyGlobal& p) {
  if (!engine.domain->box_exist) return;
  const int ntypes = engine.particles->ntypes;
  if (p.kind == "peratomtype" && p.values.size() != static_cast<std::size_t>(ntypes)) {
    throw InputError("property/global " + p.name + " peratomtype needs one value per atom type: " +
                     std::to_string(ntypes) + " (from create_box), got " + std::to_string(p.values.size()));
  }
  if (p.kind == "peratomtypepair" && p.ncols != ntypes) {
    throw InputError("property/global " + p.name + " peratomtypepair " + std::to_string(p.ncols) +
                     ": the size must equal the number of atom types, " + std::to_string(ntypes) +
                     " (from create_box), followed by " + std::to_string(ntypes * ntypes) + " values");
  }
}

}  // namespace

FixPropertyGlobal::FixPropertyGlobal(Engine& engine, const Args& args) : Fix(engine, args) {
  if (args.size() < 6) throw InputError(std::string("wrong number of arguments; usage: ") + kUsage);
  owner_id = id;
  name = args[3];
  kind = args[4];
  if (kind == "atomtype") kind = "peratomtype";  // older LIGGGHTS spellings
  if (kind == "atomtypepair") kind = "peratomtypepair";
  std::size_t first = 5;
  if (kind == "peratomtypepair" || kind == "matrix") {
    const long long n =
        parse_int(args[5], "the " + std::string(kind == "matrix" ? "column count" : "type count") +
                               " of property " + name);
    if (n < 1)
      throw InputError("property/global " + name + ": " + kind + " needs a positive size, got " + args[5]);
    if (n > 100000)
      throw InputError("property/global " + name + ": " + kind + " size " + args[5] +
                       " is too large (at most 100000)");
    ncols = static_cast<int>(n);
    first = 6;
  } else if (kind != "scalar" && kind != "vector" && kind != "peratomtype") {
    const std::string hint =
        did_you_mean(kind, {"scalar", "vector", "peratomtype", "peratomtypepair", "matrix"});
    throw InputError("unknown property/global kind '" + kind + "' for " + name +
                     (hint.empty() ? "" : "; " + hint) + "; usage: " + kUsage);
  }
  for (std::size_t k = first; k < args.size(); ++k) {
    values.push_back(parse_double(args[k], "a value of property " + name));
  }
  const std::size_t n = values.size();
  if (kind == "scalar" && n != 1) {
    throw InputError("property/global " + name + " scalar takes exactly one value, got " + std::to_string(n));
  }
  if (n == 0) throw InputError("property/global " + name + " " + kind + " needs at least one value");
  if (kind == "peratomtypepair" && n != static_cast<std::size_t>(ncols) * ncols) {
    throw InputError("property/global " + name + " peratomtypepair " + std::to_string(ncols) + " needs " +
                     std::to_string(static_cast<long long>(ncols) * ncols) + " values (" +
                     std::to_string(ncols) + " x " + std::to_string(ncols) + "), got " + std::to_string(n));
  }
  if (kind == "matrix" && n % static_cast<std::size_t>(ncols) != 0) {
    throw InputError("property/global " + name + " matrix with " + std::to_string(ncols) +
                     " columns needs a multiple of " + std::to_string(ncols) + " values, got " +
                     std::to_string(n));
  }
  check_types(engine, *this);
  scalar_flag = kind == "scalar";
  size_vector = kind == "scalar" ? 0 : static_cast<int>(n);
}

double FixPropertyGlobal::compute_vector(int i) {
  if (i < 0 || i >= static_cast<int>(values.size())) return 0.0;
  return values[i];
}

FixPropertyGlobal* FixPropertyGlobal::find(const Modify& modify, const std::string& name) {
  // the latest definition wins
  for (auto it = modify.fixes.rbegin(); it != modify.fixes.rend(); ++it) {
    auto* p = dynamic_cast<FixPropertyGlobal*>(it->get());
    if (p && p->name == name) return p;
  }
  return nullptr;
}

FixPropertyGlobal* FixPropertyGlobal::require(const Modify& modify, const std::string& name,
                                              const std::string& needed_by) {
  if (FixPropertyGlobal* p = find(modify, name)) return p;
  std::vector<std::string> defined;
  for (const auto& f : modify.fixes)
    if (auto* p = dynamic_cast<FixPropertyGlobal*>(f.get())) defined.push_back(p->name);
  std::string msg = needed_by + " needs the material property '" + name + "'";
  const std::string hint = did_you_mean(name, defined);
  if (!hint.empty()) msg += "; " + hint;
  const auto k = known_kinds().find(name);
  const std::string kind_hint = k == known_kinds().end() ? "KIND VALUES..." : k->second + " VALUES...";
  msg += "; define it with: fix ID all property/global " + name + " " + kind_hint;
  throw InputError(msg);
}

GRANARY_FIX_STYLE("property/global", FixPropertyGlobal);

}  // namespace granary
